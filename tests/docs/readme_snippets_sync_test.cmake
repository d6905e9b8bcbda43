# readme_snippets_sync.cmake checked on altered copies of the README, so that
# it cannot pass by checking nothing: a changed snippet line fails, naming
# its README line; an unclosed ```cpp block and a README without any fail.
#   cmake -DREADME=README.md -DSNIPPETS=test_readme_snippets.cpp -DWORK=scratch/dir -P readme_snippets_sync_test.cmake
include(${CMAKE_CURRENT_LIST_DIR}/../cmake/script_util.cmake)
set(sync ${CMAKE_CURRENT_LIST_DIR}/readme_snippets_sync.cmake)
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
file(READ "${README}" text)

# The first line of the first block, with an 'x' appended.
string(FIND "${text}" "```cpp\n" open)
if(open EQUAL -1)
  message(FATAL_ERROR "${README} has no ```cpp block")
endif()
math(EXPR first "${open} + 7")
string(SUBSTRING "${text}" ${first} -1 rest)
string(FIND "${rest}" "\n" length)
string(SUBSTRING "${rest}" 0 ${length} line)
string(SUBSTRING "${text}" 0 ${first} before)
string(REGEX MATCHALL "\n" breaks "${before}")
list(LENGTH breaks number)
math(EXPR number "${number} + 1")
math(EXPR after "${first} + ${length}")
string(SUBSTRING "${text}" ${after} -1 tail)
file(WRITE "${WORK}/changed.md" "${before}${line}x${tail}")
run_expect(1 "${CMAKE_COMMAND}" -DREADME=${WORK}/changed.md -DSNIPPETS=${SNIPPETS} -P ${sync})
string(FIND "${err}" "README.md:${number}: ${line}x\n" at)
if(at EQUAL -1)
  message(FATAL_ERROR "the changed line ${number} ('${line}x') is not named:\n${err}")
endif()

file(WRITE "${WORK}/unclosed.md" "${text}\n```cpp\nint x;\n")
run_expect(1 "${CMAKE_COMMAND}" -DREADME=${WORK}/unclosed.md -DSNIPPETS=${SNIPPETS} -P ${sync})
expect_match("${err}" "README.md:[0-9]+: the ```cpp block opened here is not closed")

string(REPLACE "```cpp" "```c++" other "${text}")
file(WRITE "${WORK}/no_blocks.md" "${other}")
run_expect(1 "${CMAKE_COMMAND}" -DREADME=${WORK}/no_blocks.md -DSNIPPETS=${SNIPPETS} -P ${sync})
expect_match("${err}" "no ```cpp block with a line to check")
file(REMOVE_RECURSE "${WORK}")
