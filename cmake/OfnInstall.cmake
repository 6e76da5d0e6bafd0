# What `cmake --install build --prefix P` puts under P besides the libraries
# and headers that services/*/ and sim/ install (docs/INSTALL.md):
#   include/ofn/*.hpp              lcm-gen's C++ message headers (hardened)
#   share/ofn/lcmtypes/*.lcm       the message definitions
#   share/ofn/python/ofn/*.py      Python message types (standard library only)
#   share/ofn/lua/ofn/*.lua        Lua message types (need liblcm-lua)
#   share/java/ofn_lcmtypes.jar    Java types for lcm-spy, when the build made it
#   lib/cmake/ofn/                 ofnConfig.cmake, ofnConfigVersion.cmake,
#                                  ofnTargets*.cmake and Dependencies.cmake
#   lib/pkgconfig/ofn.pc           the message headers and LCM for pkg-config
# Included from the top-level CMakeLists.txt after every target exists.

include(CMakePackageConfigHelpers)
set(OFN_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/ofn)
set(OFN_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/ofn)
set(OFN_PACKAGE_OUT ${CMAKE_BINARY_DIR}/ofn-package)

# The message types. In the build tree their headers are generated under the
# build folder; installed, they sit with the other headers. A consumer's
# compiler needs -fno-strict-aliasing for LCM 1.3.1's decoders as much as this
# project's does (top-level CMakeLists.txt), so the installed target carries it.
set_property(TARGET ofn_lcmtypes PROPERTY INTERFACE_INCLUDE_DIRECTORIES
             $<BUILD_INTERFACE:${OFN_LCM_OUT}/cpp> $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
target_compile_options(ofn_lcmtypes INTERFACE $<INSTALL_INTERFACE:-fno-strict-aliasing>)
install(TARGETS ofn_lcmtypes EXPORT ofnTargets)
install(DIRECTORY ${OFN_LCM_OUT}/cpp/ofn DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.hpp")
install(FILES ${OFN_LCM_FILES} DESTINATION ${OFN_INSTALL_DATADIR}/lcmtypes)
install(DIRECTORY ${OFN_LCM_PYTHON_DIR}/ofn DESTINATION ${OFN_INSTALL_DATADIR}/python
        FILES_MATCHING PATTERN "*.py")
install(DIRECTORY ${OFN_LCM_LUA_DIR}/ofn DESTINATION ${OFN_INSTALL_DATADIR}/lua
        FILES_MATCHING PATTERN "*.lua")
if(OFN_LCM_JAR)
  install(FILES ${OFN_LCM_JAR} DESTINATION ${CMAKE_INSTALL_DATADIR}/java)
endif()

# CMake package: find_package(ofn) gives ofn::<library> for every installed
# library. The config finds the targets' dependencies with the project's own
# Dependencies.cmake (LCM has no CMake package on Debian).
install(EXPORT ofnTargets NAMESPACE ofn:: DESTINATION ${OFN_INSTALL_CMAKEDIR})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/ofnConfig.cmake.in
                              ${OFN_PACKAGE_OUT}/ofnConfig.cmake
                              INSTALL_DESTINATION ${OFN_INSTALL_CMAKEDIR}
                              PATH_VARS OFN_INSTALL_DATADIR CMAKE_INSTALL_DATADIR)
# 0.x: a minor version may change the interfaces.
write_basic_package_version_file(${OFN_PACKAGE_OUT}/ofnConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${OFN_PACKAGE_OUT}/ofnConfig.cmake ${OFN_PACKAGE_OUT}/ofnConfigVersion.cmake
              ${CMAKE_CURRENT_LIST_DIR}/Dependencies.cmake
        DESTINATION ${OFN_INSTALL_CMAKEDIR})

# pkg-config: the message headers and LCM. Debian's lcm.pc requires glib-2.0's
# .pc files, which liblcm-dev does not pull in, so ofn.pc names LCM's header
# folder and library itself rather than `Requires: lcm`. The prefix is taken
# from the .pc file's own place, so the file is right wherever it is installed.
file(RELATIVE_PATH OFN_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
string(REGEX REPLACE "/$" "" OFN_PC_TO_PREFIX "${OFN_PC_TO_PREFIX}")
get_filename_component(OFN_PC_LCM_LIBDIR ${LCM_LIBRARY} DIRECTORY)
configure_file(${CMAKE_CURRENT_LIST_DIR}/ofn.pc.in ${OFN_PACKAGE_OUT}/ofn.pc @ONLY)
install(FILES ${OFN_PACKAGE_OUT}/ofn.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
