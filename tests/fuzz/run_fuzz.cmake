# Runs one fuzz target for a fixed time from a fresh copy of its seeds; fails on any finding or if it did not fuzz.
#
# cmake -DFUZZER=path -DKIND=equation|scene|jsurf|surf|pov|jobs -DSOURCE_DIR=repo -DWORK=scratch-dir [-DSECONDS=30]
#       [-DDICT=file] -P run_fuzz.cmake
# -timeout=60: the worst equation the parser admits (degree 32, dense, long constants) takes seconds in Release and
# about 30x that in this -O0 sanitizer build; a hang is what it must catch, not that.
# WORK is emptied first; the corpus grows there, never in the repository. A crash, leak, timeout or out-of-memory
# input is kept in WORK (crash-*, leak-*, timeout-*, oom-*) and printed in hex, so that a CI log alone reproduces it.

foreach(var FUZZER KIND SOURCE_DIR WORK)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_fuzz.cmake needs -D${var}=...")
  endif()
endforeach()
if(NOT DEFINED SECONDS)
  set(SECONDS 30)
endif()

file(REMOVE_RECURSE ${WORK})
execute_process(COMMAND ${CMAKE_COMMAND} -DKIND=${KIND} -DSOURCE_DIR=${SOURCE_DIR} -DOUT=${WORK}/corpus
                        -P ${CMAKE_CURRENT_LIST_DIR}/make_seeds.cmake
                COMMAND_ERROR_IS_FATAL ANY)

set(args -max_total_time=${SECONDS} -max_len=65536 -timeout=60 -rss_limit_mb=2048 -print_final_stats=1
         -artifact_prefix=${WORK}/)
if(DEFINED DICT)
  list(APPEND args -dict=${DICT})
endif()
execute_process(COMMAND ${FUZZER} ${args} ${WORK}/corpus
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
file(WRITE ${WORK}/fuzzer.log "${out}")
# On failure the end of the log is what matters: the report and its stack, not thousands of "NEW" lines.
string(LENGTH "${out}" length)
if(length GREATER 20000)
  math(EXPR from "${length} - 20000")
  string(SUBSTRING "${out}" ${from} -1 tail)
  set(tail "[... the whole log is ${WORK}/fuzzer.log]\n${tail}")
else()
  set(tail "${out}")
endif()

file(GLOB artifacts ${WORK}/crash-* ${WORK}/leak-* ${WORK}/timeout-* ${WORK}/oom-*)
if(NOT rc EQUAL 0 OR artifacts)
  message("${tail}")
  foreach(a ${artifacts})
    file(SIZE ${a} size)
    file(READ ${a} hex LIMIT 4096 HEX)
    message("reproducer ${a} (${size} bytes; first 4096 in hex):\n${hex}")
  endforeach()
  message(FATAL_ERROR "${KIND}: the fuzzer found a problem (exit ${rc}); rerun one input with: ${FUZZER} <file>")
endif()

# A run that never got going (no seeds read, no input past them executed) must not pass as "found nothing". The
# bar is relative to the seeds: a slow target under the sanitizers (pov: 15 inputs a second in a cold run on two
# busy cores, 93 in its 5 s) still fuzzed; a fixed 100 inputs failed it there.
set(seeds 0)
if(out MATCHES "INFO: seed corpus: files: ([0-9]+)")
  set(seeds ${CMAKE_MATCH_1})
endif()
set(runs 0)
if(out MATCHES "Done ([0-9]+) runs in ([0-9]+) second")
  set(runs ${CMAKE_MATCH_1})
  set(secs ${CMAKE_MATCH_2})
endif()
math(EXPR wanted "${seeds} + 20")
if(seeds EQUAL 0 OR runs LESS wanted)
  message("${tail}")
  message(FATAL_ERROR "${KIND}: the fuzzer read ${seeds} seeds and ran ${runs} inputs; it did not really fuzz")
endif()
string(REGEX MATCHALL "#[0-9]+[ \t]+[A-Z]+[ \t]+cov: [0-9]+ ft: [0-9]+ corp: [0-9]+/[0-9]+[a-zA-Z]*" statuses "${out}")
list(POP_BACK statuses final)
message(STATUS "${KIND}: ${seeds} seeds, ${runs} runs in ${secs} s, no findings; last: ${final}")
