# Installs a build tree into a fresh prefix.
# Usage: cmake -DBUILD_DIR=... -DPREFIX=... [-DCONFIG=...] -P install_tree.cmake
file(REMOVE_RECURSE ${PREFIX})
set(_config)
if(CONFIG)
  set(_config --config ${CONFIG})
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${PREFIX} ${_config}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install ${BUILD_DIR} failed (${rc})")
endif()
if(NOT EXISTS ${PREFIX}/include/avatarmap/avatarmap.h)
  message(FATAL_ERROR "the install has no include/avatarmap/avatarmap.h")
endif()
file(GLOB_RECURSE _configs ${PREFIX}/*/avatarmapConfig.cmake)
if(NOT _configs)
  message(FATAL_ERROR "the install has no avatarmapConfig.cmake")
endif()
