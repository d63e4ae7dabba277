# A fast linker: every test program links deal.II, Trilinos and the project's libraries, and GNU
# ld (bfd) takes about 19 s per program where mold or lld take under 1 s (measured on
# tests/studies_tests; docs/measurements/build_times.md). mold is installed by
# scripts/install_deps.sh; lld is the fallback. Off: -DVESSEL_FAST_LINKER=OFF.
option(VESSEL_FAST_LINKER "Link with mold or lld when one is installed" ON)
if(VESSEL_FAST_LINKER)
  include(CheckCXXSourceCompiles)
  foreach(linker mold lld)
    set(CMAKE_REQUIRED_LINK_OPTIONS -fuse-ld=${linker})
    check_cxx_source_compiles("int main() { return 0; }" VESSEL_LINKS_WITH_${linker})
    unset(CMAKE_REQUIRED_LINK_OPTIONS)
    if(VESSEL_LINKS_WITH_${linker})
      add_link_options(-fuse-ld=${linker})
      message(STATUS "Linking with ${linker}")
      break()
    endif()
  endforeach()
endif()
