# Finds the Debian-packaged dependencies (installed by tools/setup).
find_package(yaml-cpp REQUIRED)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(HDF5 REQUIRED COMPONENTS C)
find_package(OpenMP REQUIRED COMPONENTS CXX)
find_package(GTest REQUIRED)
find_package(benchmark REQUIRED)
find_package(Threads REQUIRED)

# Gmsh ships no CMake package on Debian: find its C++ API header and library.
find_path(GMSH_INCLUDE_DIR gmsh.h REQUIRED)
find_library(GMSH_LIBRARY NAMES gmsh REQUIRED)
add_library(Gmsh::gmsh UNKNOWN IMPORTED)
set_target_properties(Gmsh::gmsh PROPERTIES
  IMPORTED_LOCATION ${GMSH_LIBRARY}
  INTERFACE_INCLUDE_DIRECTORIES ${GMSH_INCLUDE_DIR})

# deal.II only for the field solver; DEAL_II_DIR may point at a custom install.
find_package(deal.II 9.3 REQUIRED HINTS ${DEAL_II_DIR} $ENV{DEAL_II_DIR})

# yaml-cpp's Debian config names its target yaml-cpp (newer versions: yaml-cpp::yaml-cpp).
if(TARGET yaml-cpp::yaml-cpp)
  set(MAGBRUSH_YAML_TARGET yaml-cpp::yaml-cpp)
else()
  set(MAGBRUSH_YAML_TARGET yaml-cpp)
endif()
