# Script mode (test_installed_package): installs the build tree into a fresh prefix, builds tests/consumer against
# it with find_package(algray), and runs the program; then checks that the installed command line finds algray-full.
#   cmake -DBINARY_DIR=<build> -DSOURCE_DIR=<consumer> -DWORK=<dir> -DGENERATOR=<gen> -P run_consumer.cmake
file(REMOVE_RECURSE ${WORK})
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()
run(${CMAKE_COMMAND} --install ${BINARY_DIR} --prefix ${WORK}/prefix)
run(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK}/build -G ${GENERATOR} -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_PREFIX_PATH=${WORK}/prefix)
run(${CMAKE_COMMAND} --build ${WORK}/build)
run(${WORK}/build/algray_consumer)

# The installed command line hands `algray view` to the installed algray-full (apps/algray/hand_off.h): the error
# must be algray-full's own about the address, not that algray-full was not found.
execute_process(COMMAND ${WORK}/prefix/bin/algray view --host 256.0.0.1 RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
if(NOT err MATCHES "cannot listen on 256.0.0.1" OR err MATCHES "needs algray-full")
  message(FATAL_ERROR "the installed algray did not hand `view` to algray-full (exit ${rc}):\n${out}\n${err}")
endif()
message(STATUS "the installed algray handed `algray view` to algray-full")
