# The runtime's header-only dependencies for the WebAssembly build: Debian's Eigen and
# nlohmann-json headers, as the imported targets the native build gets from find_package.
# Their CMake packages cannot serve as they are: emscripten's toolchain finds packages only in
# its sysroot, and nlohmann-json's target adds /usr/include, whose C library headers would then
# hide emscripten's. So each gets an include folder holding nothing else (for nlohmann-json a
# link in the build tree).
find_path(CHAINTUBE_EIGEN_INCLUDE_DIR Eigen/Dense PATHS /usr/include/eigen3
          NO_CMAKE_FIND_ROOT_PATH REQUIRED)
find_path(CHAINTUBE_NLOHMANN_JSON_INCLUDE_DIR nlohmann/json.hpp PATHS /usr/include
          NO_CMAKE_FIND_ROOT_PATH REQUIRED)

add_library(Eigen3::Eigen INTERFACE IMPORTED GLOBAL)
set_target_properties(Eigen3::Eigen PROPERTIES
  INTERFACE_INCLUDE_DIRECTORIES "${CHAINTUBE_EIGEN_INCLUDE_DIR}")

set(chaintube_json_headers "${CMAKE_BINARY_DIR}/host-headers/nlohmann-json")
file(MAKE_DIRECTORY "${chaintube_json_headers}")
file(CREATE_LINK "${CHAINTUBE_NLOHMANN_JSON_INCLUDE_DIR}/nlohmann"
     "${chaintube_json_headers}/nlohmann" SYMBOLIC)
add_library(nlohmann_json::nlohmann_json INTERFACE IMPORTED GLOBAL)
set_target_properties(nlohmann_json::nlohmann_json PROPERTIES
  INTERFACE_INCLUDE_DIRECTORIES "${chaintube_json_headers}")
