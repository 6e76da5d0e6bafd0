# The version every program's --version prints (ofn::version(),
# services/common/include/ofn/common/command_line.hpp): the project version
# and, when the source is a git checkout, its `git describe` at configure
# time, e.g. "0.1.0 (git ecda934)". Without git, or outside a checkout (a
# release tarball), the project version alone. The describe is not followed
# commit by commit: it changes when CMake runs again.
set(OFN_VERSION_STRING ${PROJECT_VERSION})
find_package(Git QUIET)
if(GIT_FOUND)
  execute_process(COMMAND ${GIT_EXECUTABLE} describe --tags --always --dirty
                  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR}
                  OUTPUT_VARIABLE OFN_GIT_DESCRIBE OUTPUT_STRIP_TRAILING_WHITESPACE
                  RESULT_VARIABLE OFN_GIT_RESULT ERROR_QUIET TIMEOUT 10)
  if(OFN_GIT_RESULT EQUAL 0 AND OFN_GIT_DESCRIBE)
    set(OFN_VERSION_STRING "${PROJECT_VERSION} (git ${OFN_GIT_DESCRIBE})")
  endif()
endif()
message(STATUS "ofn version: ${OFN_VERSION_STRING}")
