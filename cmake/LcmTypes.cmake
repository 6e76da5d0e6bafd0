# Generates C++ headers (and, when Java is present, a jar for lcm-spy) from
# lcmtypes/*.lcm at build time; nothing generated is committed.

file(GLOB OFN_LCM_FILES CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/lcmtypes/*.lcm)
set(OFN_LCM_OUT ${CMAKE_BINARY_DIR}/lcmtypes)
set(OFN_LCM_HEADERS)
foreach(lcm_file ${OFN_LCM_FILES})
  get_filename_component(type_name ${lcm_file} NAME_WE)
  list(APPEND OFN_LCM_HEADERS ${OFN_LCM_OUT}/cpp/ofn/${type_name}.hpp)
endforeach()

add_custom_command(
  OUTPUT ${OFN_LCM_HEADERS}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${OFN_LCM_OUT}/cpp
  COMMAND ${LCM_GEN} --cpp --cpp-std=c++11 --cpp-hpath ${OFN_LCM_OUT}/cpp ${OFN_LCM_FILES}
  COMMAND ${CMAKE_COMMAND} -DHEADER_DIR=${OFN_LCM_OUT}/cpp/ofn -P
          ${CMAKE_SOURCE_DIR}/cmake/HardenLcmDecode.cmake
  DEPENDS ${OFN_LCM_FILES} ${CMAKE_SOURCE_DIR}/cmake/HardenLcmDecode.cmake
  COMMENT "lcm-gen: C++ message headers"
  VERBATIM)
add_custom_target(ofn_lcmtypes_cpp DEPENDS ${OFN_LCM_HEADERS})
add_library(ofn_lcmtypes INTERFACE)
add_dependencies(ofn_lcmtypes ofn_lcmtypes_cpp)
target_include_directories(ofn_lcmtypes INTERFACE ${OFN_LCM_OUT}/cpp)
target_link_libraries(ofn_lcmtypes INTERFACE lcm::lcm)

if(Java_FOUND AND LCM_JAR)
  set(OFN_LCM_JAR ${OFN_LCM_OUT}/ofn_lcmtypes.jar)
  add_custom_command(
    OUTPUT ${OFN_LCM_JAR}
    COMMAND ${CMAKE_COMMAND} -E remove_directory ${OFN_LCM_OUT}/java
    COMMAND ${CMAKE_COMMAND} -E make_directory ${OFN_LCM_OUT}/java/classes
    COMMAND ${LCM_GEN} --java --jpath ${OFN_LCM_OUT}/java/src ${OFN_LCM_FILES}
    COMMAND ${CMAKE_COMMAND} -E chdir ${OFN_LCM_OUT}/java/src
            sh -c "${Java_JAVAC_EXECUTABLE} -nowarn -cp ${LCM_JAR} -d ../classes ofn/*.java"
    COMMAND ${Java_JAR_EXECUTABLE} cf ${OFN_LCM_JAR} -C ${OFN_LCM_OUT}/java/classes .
    DEPENDS ${OFN_LCM_FILES}
    COMMENT "lcm-gen: Java types jar for lcm-spy"
    VERBATIM)
  add_custom_target(ofn_lcmtypes_jar ALL DEPENDS ${OFN_LCM_JAR})
else()
  message(WARNING "javac or /usr/share/java/lcm.jar missing: no types jar for lcm-spy "
                  "(install default-jdk-headless and liblcm-java)")
endif()
