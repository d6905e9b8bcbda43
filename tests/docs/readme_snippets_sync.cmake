# Every line of README.md's ```cpp blocks (indented ones too) must be a line
# of test_readme_snippets.cpp, compared with the whitespace at both ends
# trimmed, so that a snippet edited in the README and not in the test (or
# the other way round) fails here instead of rotting unchecked. Blank lines,
# lines that are only a comment and lines holding the README's `...`
# placeholders are not compared.
#   cmake -DREADME=README.md -DSNIPPETS=tests/docs/test_readme_snippets.cpp -P readme_snippets_sync.cmake
# Fails naming README.md:LINE and the line for each one missing.
foreach(var README SNIPPETS)
  if(NOT EXISTS "${${var}}")
    message(FATAL_ERROR "${var}='${${var}}' does not exist")
  endif()
endforeach()

# Lines of a file as a CMake list, empty lines kept. ';', '\' (which would
# escape the ';' of a line break) and the square brackets (which would stop
# a list from splitting) are stood in for by placeholders, undone by
# `unescape` for messages.
function(read_lines file out)
  file(READ "${file}" text)
  string(REPLACE "\r" "" text "${text}")
  string(REPLACE "\\" "<backslash>" text "${text}")
  string(REPLACE ";" "<semicolon>" text "${text}")
  string(REPLACE "[" "<lbracket>" text "${text}")
  string(REPLACE "]" "<rbracket>" text "${text}")
  string(REPLACE "\n" ";" text "${text}")
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

# The number of lines of a file, counted apart from the list (a check of it).
function(count_lines file out)
  file(READ "${file}" text)
  string(LENGTH "${text}" with)
  string(REPLACE "\n" "" text "${text}")
  string(LENGTH "${text}" without)
  math(EXPR n "${with} - ${without} + 1")
  set(${out} ${n} PARENT_SCOPE)
endfunction()

function(unescape text out)
  string(REPLACE "<semicolon>" ";" text "${text}")
  string(REPLACE "<lbracket>" "[" text "${text}")
  string(REPLACE "<rbracket>" "]" text "${text}")
  string(REPLACE "<backslash>" "\\" text "${text}")
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

# The test's lines, trimmed, as one string "\nline\nline\n...\n" to search.
read_lines("${SNIPPETS}" cpp_lines)
set(cpp "\n")
foreach(line IN LISTS cpp_lines)
  string(STRIP "${line}" line)
  string(APPEND cpp "${line}\n")
endforeach()

read_lines("${README}" readme_lines)
set(number 0)
set(in_block FALSE)
set(blocks 0)
set(checked 0)
set(missing "")
foreach(line IN LISTS readme_lines)
  math(EXPR number "${number} + 1")
  if(NOT in_block)
    if(line MATCHES "^([ ]*)```cpp[ \t]*$")
      set(in_block TRUE)
      set(indent "${CMAKE_MATCH_1}")
      set(opened ${number})
      math(EXPR blocks "${blocks} + 1")
    endif()
    continue()
  endif()
  if(line MATCHES "^[ ]*```[ \t]*$")
    set(in_block FALSE)
    continue()
  endif()
  # The block's own indentation first (CommonMark strips it), then any.
  string(LENGTH "${indent}" n)
  string(LENGTH "${line}" length)
  if(n GREATER 0 AND length GREATER_EQUAL n)
    string(SUBSTRING "${line}" 0 ${n} head)
    if(head STREQUAL indent)
      string(SUBSTRING "${line}" ${n} -1 line)
    endif()
  endif()
  string(STRIP "${line}" text)
  if(text STREQUAL "" OR text MATCHES "^//" OR text MATCHES "\\.\\.\\.")
    continue()
  endif()
  math(EXPR checked "${checked} + 1")
  string(FIND "${cpp}" "\n${text}\n" at)
  if(at EQUAL -1)
    unescape("${text}" shown)
    string(APPEND missing "\n  README.md:${number}: ${shown}")
  endif()
endforeach()

count_lines("${README}" expected)
if(NOT number EQUAL expected)
  message(FATAL_ERROR "README.md: read ${number} lines, the file has ${expected}: the line numbers would be wrong")
endif()
if(in_block)
  message(FATAL_ERROR "README.md:${opened}: the ```cpp block opened here is not closed")
endif()
if(blocks EQUAL 0 OR checked EQUAL 0)
  message(FATAL_ERROR "README.md: no ```cpp block with a line to check (${blocks} blocks): has the fence changed?")
endif()
if(missing)
  get_filename_component(name "${SNIPPETS}" NAME)
  message(FATAL_ERROR "README C++ snippet lines that are not lines of ${name} (edit the README and the test "
                      "together):${missing}")
endif()
message(STATUS "readme_snippets_sync: ${checked} lines of ${blocks} ```cpp blocks found in the test")
