# Helpers of the CMake test scripts (cmake -P script.cmake), included as
#   include(${CMAKE_CURRENT_LIST_DIR}/../cmake/script_util.cmake)
#
# run_expect(<exit status> <command> [<arg>...])
#   Runs the command; the test fails unless it exits with <exit status>.
#   Sets `out` and `err` (its stdout and stderr) in the caller.
# run(<command> [<arg>...])
#   run_expect(0 ...).
# expect_match(<text> <regex>)
#   The test fails unless <text> matches <regex>.
# expect_file_lines(<file> <count> <regex>)
#   The test fails unless <file> has <count> lines and one of them matches
#   <regex> ("" matches any).
function(run_expect expect_exit)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr)
  if(NOT "${rc}" STREQUAL "${expect_exit}")
    message(FATAL_ERROR "exit ${rc}, expected ${expect_exit}: ${ARGN}\nstdout:\n${stdout}\nstderr:\n${stderr}")
  endif()
  set(out "${stdout}" PARENT_SCOPE)
  set(err "${stderr}" PARENT_SCOPE)
endfunction()

macro(run)
  run_expect(0 ${ARGN})
endmacro()

function(expect_match text regex)
  if(NOT "${text}" MATCHES "${regex}")
    message(FATAL_ERROR "output does not match '${regex}':\n${text}")
  endif()
endfunction()

function(expect_file_lines file count regex)
  file(STRINGS ${file} lines)
  list(LENGTH lines n)
  if(NOT n EQUAL ${count} OR NOT lines MATCHES "${regex}")
    message(FATAL_ERROR "${file}: ${n} lines, expected ${count} with one matching '${regex}':\n${lines}")
  endif()
endfunction()
