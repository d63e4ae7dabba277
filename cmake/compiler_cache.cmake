# ccache, when installed (scripts/install_deps.sh installs it): a rebuild, or a fresh clone of the
# same sources elsewhere (CI on this machine), reuses compiled objects. base_dir and nohashdir make
# the cache key independent of where the checkout lives.
option(VESSEL_CCACHE "Compile through ccache when it is installed" ON)
find_program(VESSEL_CCACHE_PROGRAM ccache)
if(VESSEL_CCACHE AND VESSEL_CCACHE_PROGRAM)
  set(CMAKE_CXX_COMPILER_LAUNCHER
      ${CMAKE_COMMAND} -E env CCACHE_BASEDIR=${CMAKE_SOURCE_DIR} CCACHE_NOHASHDIR=true
      CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime
      ${VESSEL_CCACHE_PROGRAM})
  message(STATUS "Compiling through ccache: ${VESSEL_CCACHE_PROGRAM}")
endif()
