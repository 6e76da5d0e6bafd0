# Every external dependency, with the Debian package that provides it named in
# the error so a missing one says what to install (`make deps` installs all).

macro(ofn_require found what package)
  if(NOT ${found})
    message(FATAL_ERROR "${what} not found: install the Debian package '${package}' (or run `make deps`)")
  endif()
endmacro()

# Debian's LCM 1.3.1 ships no CMake package: find header, library and lcm-gen.
find_path(LCM_INCLUDE_DIR lcm/lcm-cpp.hpp)
find_library(LCM_LIBRARY lcm)
find_program(LCM_GEN lcm-gen)
ofn_require(LCM_INCLUDE_DIR "LCM headers" liblcm-dev)
ofn_require(LCM_LIBRARY "LCM library" liblcm-dev)
ofn_require(LCM_GEN "lcm-gen" liblcm-bin)
add_library(lcm::lcm UNKNOWN IMPORTED)
set_target_properties(lcm::lcm PROPERTIES IMPORTED_LOCATION ${LCM_LIBRARY}
                                          INTERFACE_INCLUDE_DIRECTORIES ${LCM_INCLUDE_DIR})

find_package(Eigen3 3.3 QUIET NO_MODULE)
ofn_require(Eigen3_FOUND "Eigen3" libeigen3-dev)
find_package(yaml-cpp QUIET)
ofn_require(yaml-cpp_FOUND "yaml-cpp" libyaml-cpp-dev)
find_package(spdlog QUIET)
ofn_require(spdlog_FOUND "spdlog" libspdlog-dev)
# fmt (spdlog's formatting) formats the RH optimiser core's log lines.
find_package(fmt QUIET CONFIG)
ofn_require(fmt_FOUND "fmt" libfmt-dev)
find_package(CLI11 QUIET CONFIG)
ofn_require(CLI11_FOUND "CLI11" libcli11-dev)
find_package(Threads REQUIRED)

# Java is only needed for the lcm-spy types jar; the flight stack builds without it.
find_package(Java COMPONENTS Development QUIET)
find_file(LCM_JAR lcm.jar PATHS /usr/share/java NO_DEFAULT_PATH)

# OctoMap: the mapper's 3-D probabilistic occupancy (Debian ships its CMake package).
find_package(octomap QUIET)
ofn_require(octomap_FOUND "OctoMap" liboctomap-dev)
add_library(ofn::octomap INTERFACE IMPORTED)
set_target_properties(ofn::octomap PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${OCTOMAP_INCLUDE_DIRS}"
                                              INTERFACE_LINK_LIBRARIES "${OCTOMAP_LIBRARIES}")

# NLopt: SLSQP for the RH trajectory optimiser (nlopt.hpp is a header-only wrapper of the C library).
find_package(NLopt QUIET CONFIG)
ofn_require(NLopt_FOUND "NLopt" libnlopt-dev)
find_file(NLOPT_CXX_HEADER nlopt.hpp)
ofn_require(NLOPT_CXX_HEADER "NLopt C++ header" libnlopt-cxx-dev)

# The live viewer: JSON snapshots (nlohmann-json) served over HTTP
# (cpp-httplib; Debian ships it as a library with a pkg-config file).
find_package(nlohmann_json 3 QUIET)
ofn_require(nlohmann_json_FOUND "nlohmann-json" nlohmann-json3-dev)
find_package(PkgConfig QUIET)
if(PkgConfig_FOUND)
  pkg_check_modules(HTTPLIB QUIET IMPORTED_TARGET cpp-httplib)
endif()
ofn_require(HTTPLIB_FOUND "cpp-httplib" libcpp-httplib-dev)
add_library(ofn::httplib INTERFACE IMPORTED)
set_target_properties(ofn::httplib PROPERTIES INTERFACE_LINK_LIBRARIES PkgConfig::HTTPLIB)

# libsodium: Ed25519 signatures of the authenticated bus.
if(PkgConfig_FOUND)
  pkg_check_modules(SODIUM QUIET IMPORTED_TARGET libsodium)
endif()
ofn_require(SODIUM_FOUND "libsodium" libsodium-dev)
