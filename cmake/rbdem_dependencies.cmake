# Third-party packages, all from Debian (scripts/setup.sh installs them).
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(fmt REQUIRED)
find_package(tomlplusplus REQUIRED)
find_package(nlohmann_json 3.2 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(OpenMP REQUIRED)

# gmsh ships no CMake package on Debian: find the C++ API header and library by hand.
find_path(GMSH_INCLUDE_DIR gmsh.h REQUIRED)
find_library(GMSH_LIBRARY NAMES gmsh REQUIRED)
# gmsh is linked by full path (see dem/CMakeLists.txt), so the exported targets need no gmsh package.
find_package(Threads REQUIRED)
