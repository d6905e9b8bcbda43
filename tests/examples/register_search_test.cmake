# `iclap register --search auto|kdtree|brute` print the same registration
# (the JSON output apart from its "search" field), to the last digit, for
# float and double and for a 4-D (Dynamic) and a 3-D (compile-time) cloud.
#   cmake -DICLAP=... -DMODEL=... -DTEST=... -DMODEL3=... -P register_search_test.cmake
include(${CMAKE_CURRENT_LIST_DIR}/../cmake/script_util.cmake)

foreach(scalar float double)
  foreach(files "${MODEL};${TEST};--weights;1,1,1,0.01" "${MODEL3};${MODEL3}")
    set(first "")
    foreach(search auto kdtree brute)
      run(${ICLAP} register ${files} --transform planar --scalar ${scalar} --search ${search} --json)
      expect_match("${out}" "\"search\":\"${search}\".*\"converged\":true")
      string(REGEX REPLACE "\"search\":\"[a-z]+\"" "" same "${out}")
      if(first STREQUAL "")
        set(first "${same}")
      elseif(NOT same STREQUAL first)
        message(FATAL_ERROR "--search ${search} (${scalar}, ${files}) differs from auto:\n${same}\nauto:\n${first}")
      endif()
    endforeach()
  endforeach()
endforeach()

# The text report names the default search.
run(${ICLAP} register ${MODEL} ${TEST} --transform planar)
expect_match("${out}" "search: auto\n")
