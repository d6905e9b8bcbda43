# End-to-end test of the main job on a 3-object dataset: simulate it from the
# fixture meshes, run `iclap evaluate` with 1 and 2 threads, and check that
# the results files are complete and identical.
#   cmake -DICLAP=path -DOBJECTS=dir -DWORK_DIR=dir -P evaluate_test.cmake
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
include(${CMAKE_CURRENT_LIST_DIR}/../cmake/script_util.cmake)
run(${ICLAP} simulate --objects ${OBJECTS} --unit m --explorations 3 --seed 5 --out ${WORK_DIR}/three.csv)
set(common evaluate ${WORK_DIR}/three.csv --touches 1,2,5 --repeats 3 --weight-repeats 1 --seed 7)
run(${ICLAP} ${common} --threads 1 --out ${WORK_DIR}/one)
set(printed "${out}")
run(${ICLAP} ${common} --threads 2 --out ${WORK_DIR}/two)
foreach(f results.csv weights.csv confusion.csv sweeps.csv)
  file(READ ${WORK_DIR}/one/${f} a)
  file(READ ${WORK_DIR}/two/${f} b)
  if(NOT a STREQUAL b)
    message(FATAL_ERROR "${f} differs between 1 and 2 threads")
  endif()
endforeach()
# The overlap line: the same share as `iclap info --overlap 5` counts.
if(NOT printed MATCHES "\noverlap: ([0-9]+\\.[0-9])% of the touches lie within 5 mm of a touch of another exploration of the same object\n")
  message(FATAL_ERROR "no overlap line in:\n${printed}")
endif()
set(evaluate_overlap "${CMAKE_MATCH_1}")
run(${ICLAP} info ${WORK_DIR}/three.csv --overlap 5)
if(NOT out MATCHES "contact frames \\(([0-9]+\\.[0-9])%\\) within 5 mm" OR NOT CMAKE_MATCH_1 STREQUAL evaluate_overlap)
  message(FATAL_ERROR "iclap info --overlap 5 does not give evaluate's ${evaluate_overlap}%:\n${out}")
endif()
# Every method and every number of touches, with a rate in [0, 1].
file(STRINGS ${WORK_DIR}/one/results.csv lines)
list(GET lines 0 header)
if(NOT header MATCHES "^method,touches,rate,")
  message(FATAL_ERROR "unexpected header: ${header}")
endif()
foreach(m bow icp iclap icp+bow icp*bow iclap+icp iclap*icp iclap+bow iclap*bow iclap+icp+bow iclap*icp*bow)
  foreach(t 1 2 5)
    string(REPLACE "+" "\\+" mre "${m}")
    string(REPLACE "*" "\\*" mre "${mre}")
    set(found FALSE)
    foreach(l IN LISTS lines)
      if(l MATCHES "^${mre},${t},(0(\\.[0-9]+)?|1),")
        set(found TRUE)
      endif()
    endforeach()
    if(NOT found)
      message(FATAL_ERROR "results.csv lacks a valid row for method ${m} at ${t} touches")
    endif()
  endforeach()
endforeach()
list(LENGTH lines n)
if(NOT n EQUAL 34)
  message(FATAL_ERROR "results.csv has ${n} lines, expected 1 + 11 methods x 3 touch counts")
endif()
foreach(f fig_single.svg fig_hybrid_all.svg fig_weights_iclappicppbow.svg)
  if(NOT EXISTS ${WORK_DIR}/one/${f})
    message(FATAL_ERROR "missing ${f}")
  endif()
endforeach()
# The three-term weight figure has one line per weight on bow: the paper's
# grid (steps of 0.1, each weight at least 0.1) gives it 8 values, 0.1 to 0.8,
# each once in the legend (the last weight is 1 minus the others, so equal
# values must not be told apart by their rounding).
file(READ ${WORK_DIR}/one/fig_weights_iclappicppbow.svg svg)
string(REGEX MATCHALL ">w\\(bow\\) = [0-9.]+<" legend "${svg}")
set(distinct ${legend})
list(REMOVE_DUPLICATES distinct)
list(LENGTH legend n_legend)
list(LENGTH distinct n_distinct)
if(NOT n_legend EQUAL 8 OR NOT n_distinct EQUAL 8)
  message(FATAL_ERROR "fig_weights_iclappicppbow.svg: ${n_legend} legend entries, ${n_distinct} distinct, expected 8: ${legend}")
endif()
if(NOT printed MATCHES "3 objects, [0-9]+ frames, [0-9]+ touches.*3 folds" OR NOT printed MATCHES "iclap\\+icp\\+bow: \\[0\\]")
  message(FATAL_ERROR "unexpected report:\n${printed}")
endif()
# A different seed gives different draws (the rates may coincide; the
# confusion counts of 11 methods essentially never do).
run(${ICLAP} evaluate ${WORK_DIR}/three.csv --touches 1,2,5 --repeats 3 --weight-repeats 1 --seed 8 --out ${WORK_DIR}/other)
file(READ ${WORK_DIR}/one/confusion.csv a)
file(READ ${WORK_DIR}/other/confusion.csv b)
if(a STREQUAL b)
  message(FATAL_ERROR "seed 8 gave the same confusion counts as seed 7")
endif()
# Trimmed ICP (--trim): reported with the ICP settings; the untrimmed run
# reports every pair.
expect_match("${printed}" "ICP \\(auto; at most 50 iterations, relative tolerance 1e-06; every pair\\)")
run(${ICLAP} evaluate ${WORK_DIR}/three.csv --methods icp,iclap --touches 5 --repeats 3 --seed 7 --trim 0.5,iclap=0.7
    --out ${WORK_DIR}/trimmed)
expect_match("${out}" "ICP \\(auto; at most 50 iterations, relative tolerance 1e-06; trimmed: icp 50%, iclap 70%\\)")
expect_file_lines(${WORK_DIR}/trimmed/results.csv 3 "")  # 1 + 2 methods x 1 touch count
# Trim chosen on the training folds (--trim NAME=auto): one variant per
# choice, the chosen one reported per fold, the same rows as any method.
run(${ICLAP} evaluate ${WORK_DIR}/three.csv --methods patch,iclap+patch --touches 5 --repeats 3 --weight-repeats 1
    --seed 7 --trim patch=auto --trim-choices 1,0.5 --out ${WORK_DIR}/auto)
expect_match("${out}" "trimmed: patch 100%/50% chosen on the training folds\\)")
expect_match("${out}" "fusions chosen on the training folds \\(fold: fusion\\):\n  patch: \\[0\\] patch-trim(100|50) \\[1\\] patch-trim(100|50) \\[2\\] patch-trim(100|50)\n  iclap\\+patch: \\[0\\] [0-9.]+\\*iclap\\+[0-9.]+\\*patch-trim(100|50) ")
expect_file_lines(${WORK_DIR}/auto/weights.csv 7 "patch,0,patch-trim(100|50)")
expect_file_lines(${WORK_DIR}/auto/results.csv 3 "")
# Zero weights (--zero-weights): the grid and the sweep include dropping a term.
run(${ICLAP} evaluate ${WORK_DIR}/three.csv --methods icp+bow --touches 5 --repeats 3 --weight-repeats 1 --seed 7
    --zero-weights --out ${WORK_DIR}/zero)
expect_match("${out}" "fusion weights chosen on the training folds \\(fold: weights; the grid allows 0\\)")
# 1 + 11 grid rows, from 0*icp+1*bow.
expect_file_lines(${WORK_DIR}/zero/sweeps.csv 12 "icp\\+bow,0\\*icp\\+1\\*bow,5,")
# Strictly nested weights (--inner-codebooks): every inner fold fits its own
# codebook, and the run says so; the fold's codebook and so the outer test of
# a single classifier stay as they were.
run(${ICLAP} evaluate ${WORK_DIR}/three.csv --methods bow,icp+bow --touches 5 --repeats 3 --weight-repeats 1 --seed 7
    --out ${WORK_DIR}/outer)
file(STRINGS ${WORK_DIR}/outer/results.csv outer_bow REGEX "^bow,")
run(${ICLAP} evaluate ${WORK_DIR}/three.csv --methods bow,icp+bow --touches 5 --repeats 3 --weight-repeats 1 --seed 7
    --inner-codebooks --out ${WORK_DIR}/nested)
expect_match("${out}" "fusion weights chosen on the training folds \\(fold: weights; every inner fold with a codebook of its own\\)")
file(STRINGS ${WORK_DIR}/nested/results.csv nested_bow REGEX "^bow,")
if(NOT outer_bow OR NOT outer_bow STREQUAL nested_bow)
  message(FATAL_ERROR "--inner-codebooks changed bow's outer rate: '${outer_bow}' against '${nested_bow}'")
endif()
# The same for the weights of `iclap live --cross-validate`.
run(${ICLAP} live --references ${WORK_DIR}/three.csv --cross-validate --method icp+bow --max-touches 2 --fixed 2
    --repeats 1 --weight-repeats 1 --seed 7 --inner-codebooks)
expect_match("${out}" "\nfusion of each fold \\(weights chosen on its training explorations, every inner fold with a codebook of its own\\): \\[0\\] ")
# The height classifier (beyond the paper): heights and tilts of the touches,
# alone and fused; its tilt scale is reported.
run(${ICLAP} evaluate ${WORK_DIR}/three.csv --methods height,height+patch --touches 1,5 --repeats 3 --weight-repeats 1
    --seed 7 --tilt-scale 0.02 --out ${WORK_DIR}/height)
expect_match("${out}" "height: tilt scale 0.02 m/rad")
expect_file_lines(${WORK_DIR}/height/results.csv 5 "height,5,(0(\\.[0-9]+)?|1),")  # 1 + 2 methods x 2 touch counts
# With the size of each contact patch (height_contact); its scales are reported.
run(${ICLAP} evaluate ${WORK_DIR}/three.csv --methods height_contact,height_contact+patch --touches 1,5 --repeats 3
    --weight-repeats 1 --seed 7 --contact-scale 0.5 --out ${WORK_DIR}/height_contact)
expect_match("${out}" "height_contact: tilt scale 0.01 m/rad, contact scale 0.5 m/m")
expect_file_lines(${WORK_DIR}/height_contact/results.csv 5 "height_contact\\+patch,5,(0(\\.[0-9]+)?|1),")
# Two explorations per object: fixed weights run, fitted ones are refused
# before anything is written, with the object, the method and what they need.
run(${ICLAP} simulate --objects ${OBJECTS} --unit m --explorations 2 --seed 5 --out ${WORK_DIR}/two.csv)
run(${ICLAP} evaluate ${WORK_DIR}/two.csv --methods icp,0.5*icp+0.5*bow --touches 1,2 --repeats 2 --out ${WORK_DIR}/fixed2)
expect_file_lines(${WORK_DIR}/fixed2/results.csv 5 "0\\.5\\*icp\\+0\\.5\\*bow,2,(0(\\.[0-9]+)?|1),")
run_expect(2 ${ICLAP} evaluate ${WORK_DIR}/two.csv --methods icp,icp+bow --touches 1,2 --repeats 2 --out ${WORK_DIR}/fitted2)
expect_match("${err}" "two\\.csv: object '[a-z_]+' has 2 explorations with touches; method 'icp\\+bow' is chosen on inner folds .*which needs at least 3")
if(EXISTS ${WORK_DIR}/fitted2)
  message(FATAL_ERROR "a refused evaluate left ${WORK_DIR}/fitted2 behind")
endif()
# Output that cannot be written part-way (a file size limit of 2 KiB, as on a
# full disk; the figures are larger) fails with exit status 1 and leaves the
# output directory as it was, with no staging directory beside it. The
# program ignores SIGXFSZ itself: with the signal's default action it was
# killed (exit 153) and left OUT.partial-PID-N behind.
file(MAKE_DIRECTORY ${WORK_DIR}/full)
file(WRITE ${WORK_DIR}/full/results.csv "old results\n")
# (Lines, not semicolons, in the script: run_expect's arguments are a list.)
run_expect(1 bash -c "trap - XFSZ\nulimit -f 2\nexec \"$0\" \"$@\"" ${ICLAP} evaluate ${WORK_DIR}/three.csv
           --touches 1,2 --repeats 2 --weight-repeats 1 --out ${WORK_DIR}/full)
expect_match("${err}" "full/[a-z_]+\\.(csv|svg): write failed; .*full was left as it was")
file(READ ${WORK_DIR}/full/results.csv old)
file(GLOB full_files ${WORK_DIR}/full/*)
file(GLOB staging ${WORK_DIR}/full.partial*)
if(NOT old STREQUAL "old results\n" OR NOT full_files STREQUAL "${WORK_DIR}/full/results.csv" OR staging)
  message(FATAL_ERROR "a failed write changed ${WORK_DIR}/full (${full_files}) or left ${staging}")
endif()
# Lost standard output is a failure too.
if(EXISTS /dev/full)
  run_expect(1 bash -c "exec \"$0\" \"$@\" > /dev/full" ${ICLAP} info ${WORK_DIR}/three.csv)
  expect_match("${err}" "<stdout>: write failed")
  # Help and version text too (they exited 0).
  run_expect(1 bash -c "exec \"$0\" \"$@\" > /dev/full" ${ICLAP} evaluate --help)
  expect_match("${err}" "iclap evaluate: <stdout>: write failed")
  run_expect(1 bash -c "exec \"$0\" \"$@\" > /dev/full" ${ICLAP} --version)
  expect_match("${err}" "iclap: <stdout>: write failed")
endif()
# An --out that is a symbolic link to a missing path is refused before the
# run (the run was done, then creating OUT failed).
file(CREATE_LINK ${WORK_DIR}/nowhere ${WORK_DIR}/dangling SYMBOLIC)
run_expect(2 ${ICLAP} evaluate ${WORK_DIR}/three.csv --touches 1 --out ${WORK_DIR}/dangling)
expect_match("${err}" "dangling: is a symbolic link to .*nowhere, which does not exist; create it or name another directory")
if(out MATCHES "touches")
  message(FATAL_ERROR "the run went ahead with a dangling --out:\n${out}")
endif()
# Bad --out values are refused before the run.
file(WRITE ${WORK_DIR}/a_file "x")
run_expect(2 ${ICLAP} evaluate ${WORK_DIR}/three.csv --out ${WORK_DIR}/a_file)
expect_match("${err}" "--out: '.*a_file' exists and is not a directory")
run_expect(2 ${ICLAP} evaluate ${WORK_DIR}/three.csv --out=)  # (CMake drops an empty argument)
expect_match("${err}" "option --out: empty value")
run_expect(2 ${ICLAP} evaluate ${WORK_DIR}/three.csv --k --out ${WORK_DIR}/k)
expect_match("${err}" "option --k needs a value \\(got the option '--out'\\)")
# Reference clouds of objects whose names differ only in bytes that are not
# letters or digits get distinct files.
file(READ ${WORK_DIR}/three.csv text)
string(REPLACE "\nlong_bar," "\na b," text "${text}")
string(REPLACE "\nshort_bar," "\na_b," text "${text}")
file(WRITE ${WORK_DIR}/names.csv "${text}")
run(${ICLAP} evaluate ${WORK_DIR}/names.csv --methods icp --touches 1 --repeats 1 --export-ply --out ${WORK_DIR}/names)
foreach(f "a%20b.ply" "a_b.ply")
  if(NOT EXISTS "${WORK_DIR}/names/references/${f}")
    message(FATAL_ERROR "--export-ply wrote no references/${f}")
  endif()
endforeach()
# A position the reader takes (finite) but the ICP's scalar cannot square
# (a unit error) is refused before the run, naming the file and the row by
# object, exploration and frame; bow, which reads no position, runs.
file(READ ${WORK_DIR}/three.csv three)
string(REGEX REPLACE "\nlong_bar,([0-9]+),([0-9]+),([^,]+),[^,]+," "\nlong_bar,\\1,\\2,\\3,1e300," far "${three}")
file(WRITE ${WORK_DIR}/far.csv "${far}")
run_expect(2 ${ICLAP} evaluate ${WORK_DIR}/far.csv --methods icp --touches 1 --repeats 1 --out ${WORK_DIR}/far)
expect_match("${err}" "far\\.csv: object 'long_bar' exploration [0-9]+ frame [0-9]+: position coordinate 1e\\+300 m is beyond the float ICP's range \\(\\|v\\| <= 1\\.84467e\\+15 m\\); check the unit of x, y, z, or use --scalar double")
run_expect(2 ${ICLAP} evaluate ${WORK_DIR}/far.csv --methods iclap --scalar double --touches 1 --repeats 1 --out ${WORK_DIR}/far)
expect_match("${err}" "beyond the double ICP's range")
if(EXISTS ${WORK_DIR}/far)
  message(FATAL_ERROR "a refused evaluate left ${WORK_DIR}/far behind")
endif()
run(${ICLAP} evaluate ${WORK_DIR}/far.csv --methods bow --touches 1 --repeats 1 --out ${WORK_DIR}/far_bow)
expect_file_lines(${WORK_DIR}/far_bow/results.csv 2 "bow,1,(0(\\.[0-9]+)?|1),")
# The height classifier computes in double: a coordinate beyond the float
# ICP's range but within double's (1e20 m) is its to take. It was refused as
# the float ICP's, naming --scalar double, which no method it runs reads.
string(REGEX REPLACE "\nlong_bar,([0-9]+),([0-9]+),([^,]+),[^,]+," "\nlong_bar,\\1,\\2,\\3,1e20," far20 "${three}")
file(WRITE ${WORK_DIR}/far20.csv "${far20}")
run(${ICLAP} evaluate ${WORK_DIR}/far20.csv --methods height --touches 1 --repeats 1 --out ${WORK_DIR}/far_height)
expect_file_lines(${WORK_DIR}/far_height/results.csv 2 "height,1,(0(\\.[0-9]+)?|1),")
run_expect(2 ${ICLAP} evaluate ${WORK_DIR}/far20.csv --methods height,icp --touches 1 --repeats 1 --out ${WORK_DIR}/far_height_icp)
expect_match("${err}" "position coordinate 1e\\+20 m is beyond the float ICP's range")
# A codebook larger than the training touches names --k, not the library's setting.
run_expect(2 ${ICLAP} evaluate ${WORK_DIR}/three.csv --methods bow --k 100000 --touches 1 --repeats 1 --out ${WORK_DIR}/bigk)
expect_match("${err}" "--k: k = 100000 exceeds the number of features \\([0-9]+\\) of the training touches from .*three\\.csv")
# ... before anything is printed (the banner came first, as if the run had
# started).
if(NOT out STREQUAL "")
  message(FATAL_ERROR "evaluate printed before refusing --k:\n${out}")
endif()
# The largest k every fold's codebook allows (the smallest training set: the
# refusal names a fold's), then the inner folds' own codebooks, on fewer
# touches, refuse it, also before anything is printed.
set(k 100000)
while(err MATCHES "features \\(([0-9]+)\\)")
  set(k ${CMAKE_MATCH_1})
  execute_process(COMMAND ${ICLAP} evaluate ${WORK_DIR}/three.csv --methods bow --k ${k} --touches 1 --repeats 1
                  --out ${WORK_DIR}/smallest_k OUTPUT_VARIABLE out ERROR_VARIABLE err)
endwhile()
run_expect(2 ${ICLAP} evaluate ${WORK_DIR}/three.csv --methods icp+bow --k ${k} --inner-codebooks --touches 1
           --repeats 1 --weight-repeats 1 --out ${WORK_DIR}/bigk)
expect_match("${err}" "--k: k = ${k} exceeds the number of features \\([0-9]+\\) of the training touches from .*three\\.csv")
if(NOT out STREQUAL "")
  message(FATAL_ERROR "evaluate printed before refusing --k for the inner codebooks:\n${out}")
endif()
# Counts of touches above both 20 and the largest held-out exploration's
# touches are refused before anything is printed: every draw would use all
# of its exploration's touches, as at that count (--touches 1..100000 on a
# small dataset ran for 33 s to fill such rows). That count itself runs,
# one more does not.
run_expect(2 ${ICLAP} evaluate ${WORK_DIR}/three.csv --methods bow --touches 1..1000 --repeats 1 --out ${WORK_DIR}/many)
expect_match("${err}" "^iclap evaluate: --touches: [0-9]+ counts, up to 1000, are more than the ([0-9]+) touches of the largest held-out exploration of [^\n]*three\\.csv: every draw would use all the touches of its exploration, as at [0-9]+, repeating that work; ask for at most [0-9]+\n$")
string(REGEX MATCH "more than the ([0-9]+) touches" _ "${err}")
set(largest "${CMAKE_MATCH_1}")
if(NOT out STREQUAL "" OR NOT largest GREATER 20)
  message(FATAL_ERROR "refused --touches after printing, or the largest exploration has ${largest} touches:\n${out}")
endif()
math(EXPR beyond "${largest} + 1")
run_expect(2 ${ICLAP} evaluate ${WORK_DIR}/three.csv --methods bow --touches 1,${beyond} --repeats 1 --out ${WORK_DIR}/many)
expect_match("${err}" "--touches: ${beyond} is more than the ${largest} touches of the largest held-out exploration of [^\n]*three\\.csv: [^\n]*; ask for at most ${largest}\n$")
run(${ICLAP} evaluate ${WORK_DIR}/three.csv --methods bow --touches 1,${largest} --repeats 1 --out ${WORK_DIR}/many)
expect_file_lines(${WORK_DIR}/many/results.csv 3 ";bow,${largest},")
if(EXISTS ${WORK_DIR}/bigk OR EXISTS ${WORK_DIR}/far)
  message(FATAL_ERROR "a refused evaluate left its --out behind")
endif()
# No touch at all names the file and the threshold as given.
run_expect(2 ${ICLAP} evaluate ${WORK_DIR}/three.csv --contact-threshold 1e9 --out ${WORK_DIR}/none)
expect_match("${err}" "three\\.csv: has no contact frame \\(no taxel above 1e\\+09\\)")
