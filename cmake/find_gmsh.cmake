# Debian's libgmsh-dev ships gmsh.h and libgmsh.so but no CMake config: wrap them in gmsh::gmsh.
find_path(GMSH_INCLUDE_DIR gmsh.h REQUIRED)
find_library(GMSH_LIBRARY NAMES gmsh REQUIRED)
add_library(gmsh::gmsh UNKNOWN IMPORTED)
set_target_properties(gmsh::gmsh PROPERTIES IMPORTED_LOCATION "${GMSH_LIBRARY}"
                                            INTERFACE_INCLUDE_DIRECTORIES "${GMSH_INCLUDE_DIR}")
