# Runs one command and checks its exit status and output; the driver of
# iclap_cli_test (tests/CMakeLists.txt):
#   cmake -DCMD=prog@@arg1@@arg2 -DEXPECT_EXIT=2
#         [-DSTDOUT_MATCHES=re1@@re2] [-DSTDERR_MATCHES=re1@@re2]
#         [-DSTDERR_EMPTY=1] -P run_cli.cmake
# Arguments and regular expressions are separated by "@@" (CTest would split
# on ";").
string(REPLACE "@@" ";" _cmd "${CMD}")
execute_process(COMMAND ${_cmd} RESULT_VARIABLE _rc OUTPUT_VARIABLE _out ERROR_VARIABLE _err)
set(_fail "")
if(NOT "${_rc}" STREQUAL "${EXPECT_EXIT}")
  string(APPEND _fail "exit status ${_rc}, expected ${EXPECT_EXIT}\n")
endif()
foreach(_stream out err)
  string(TOUPPER "STD${_stream}_MATCHES" _var)
  if(DEFINED ${_var})
    string(REPLACE "@@" ";" _res "${${_var}}")
    foreach(_re IN LISTS _res)
      if(NOT "${_${_stream}}" MATCHES "${_re}")
        string(APPEND _fail "std${_stream} does not match '${_re}'\n")
      endif()
    endforeach()
  endif()
endforeach()
if(STDERR_EMPTY AND NOT "${_err}" STREQUAL "")
  string(APPEND _fail "stderr is not empty\n")
endif()
if(_fail)
  message(FATAL_ERROR "${_fail}--- command: ${_cmd}\n--- stdout:\n${_out}\n--- stderr:\n${_err}")
endif()
