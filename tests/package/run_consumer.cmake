# Configures, builds and tests examples/consumer in a fresh directory.
# Usage: cmake -DCONSUMER=<source> -DBINARY=<build dir> -DGENERATOR=<generator>
#              [-DCONFIG=<config>] [-DC_COMPILER=...] [-DCXX_COMPILER=...]
#              (-DPREFIX=<install prefix> | -DAVATARMAP_SOURCE_DIR=<source tree>)
#              -P run_consumer.cmake
if(NOT CONFIG)
  set(CONFIG Release)
endif()
file(REMOVE_RECURSE ${BINARY})

set(_args -S ${CONSUMER} -B ${BINARY} -G ${GENERATOR} -DCMAKE_BUILD_TYPE=${CONFIG})
if(C_COMPILER)
  list(APPEND _args -DCMAKE_C_COMPILER=${C_COMPILER})
endif()
if(CXX_COMPILER)
  list(APPEND _args -DCMAKE_CXX_COMPILER=${CXX_COMPILER})
endif()
if(PREFIX)
  list(APPEND _args -DCMAKE_PREFIX_PATH=${PREFIX})
endif()
if(AVATARMAP_SOURCE_DIR)
  list(APPEND _args -DAVATARMAP_SOURCE_DIR=${AVATARMAP_SOURCE_DIR})
endif()

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "consumer: ${what} failed (${rc})")
  endif()
endfunction()

run(configure ${CMAKE_COMMAND} ${_args})
run(build ${CMAKE_COMMAND} --build ${BINARY} --config ${CONFIG} --parallel 2)
run(test ${CMAKE_CTEST_COMMAND} --test-dir ${BINARY} -C ${CONFIG} --output-on-failure)
