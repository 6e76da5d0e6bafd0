# Python and Lua message types from lcmtypes/*.lcm (lcm-gen --python / --lua),
# generated at build time beside the C++ headers (after LcmTypes.cmake, whose
# OFN_LCM_FILES and OFN_LCM_OUT it uses) and installed by OfnInstall.cmake.
#
# Debian has no python3-lcm: the generated Python classes need only the
# standard library to encode and to decode (`nav_state_t.decode(data)`), which
# is how tools read logs without LCM's own bindings. The Lua types need LCM's
# Lua module at run time (Debian package liblcm-lua).
#
# lcm-gen adds an import line per type to an existing __init__.py / init.lua,
# so each run starts from an empty folder: a removed type leaves no stale line.

set(OFN_LCM_PYTHON_DIR ${OFN_LCM_OUT}/python)
set(OFN_LCM_LUA_DIR ${OFN_LCM_OUT}/lua)
set(OFN_LCM_PYTHON_FILES ${OFN_LCM_PYTHON_DIR}/ofn/__init__.py)
set(OFN_LCM_LUA_FILES ${OFN_LCM_LUA_DIR}/ofn/init.lua)
foreach(lcm_file ${OFN_LCM_FILES})
  get_filename_component(type_name ${lcm_file} NAME_WE)
  list(APPEND OFN_LCM_PYTHON_FILES ${OFN_LCM_PYTHON_DIR}/ofn/${type_name}.py)
  list(APPEND OFN_LCM_LUA_FILES ${OFN_LCM_LUA_DIR}/ofn/${type_name}.lua)
endforeach()

add_custom_command(
  OUTPUT ${OFN_LCM_PYTHON_FILES}
  COMMAND ${CMAKE_COMMAND} -E remove_directory ${OFN_LCM_PYTHON_DIR}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${OFN_LCM_PYTHON_DIR}
  COMMAND ${LCM_GEN} --python --ppath ${OFN_LCM_PYTHON_DIR} ${OFN_LCM_FILES}
  DEPENDS ${OFN_LCM_FILES}
  COMMENT "lcm-gen: Python message types"
  VERBATIM)
add_custom_command(
  OUTPUT ${OFN_LCM_LUA_FILES}
  COMMAND ${CMAKE_COMMAND} -E remove_directory ${OFN_LCM_LUA_DIR}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${OFN_LCM_LUA_DIR}
  COMMAND ${LCM_GEN} --lua --lpath ${OFN_LCM_LUA_DIR} ${OFN_LCM_FILES}
  DEPENDS ${OFN_LCM_FILES}
  COMMENT "lcm-gen: Lua message types"
  VERBATIM)
add_custom_target(ofn_lcmtypes_python ALL DEPENDS ${OFN_LCM_PYTHON_FILES})
add_custom_target(ofn_lcmtypes_lua ALL DEPENDS ${OFN_LCM_LUA_FILES})
