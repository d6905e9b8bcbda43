# `iclap evaluate --out DIR`: a run that fails leaves DIR exactly as it was
# (same entries, same bytes), and a bad DIR fails before the run (nothing
# printed on stdout, which the run fills from reading the dataset on).
#   cmake -DICLAP=path -DOBJECTS=dir -DWORK_DIR=dir -DCASE=name -P evaluate_output_test.cmake
# CASE:
#   conflict_before_run  DIR/sweeps.csv is a directory: refused before the run
#   conflict_at_commit   DIR/fig_single.svg is a directory (figures are known
#                        only after the run): refused before DIR is touched
#   rollback             DIR/references is a link to another file system, so
#                        moving the new clouds there fails after the tables and
#                        figures were replaced: every old file is put back
#   missing_parents      DIR's missing parent directories are created; a
#                        refused run leaves none behind
#   bad_parent           a parent of DIR is a regular file: refused before the
#                        run, naming DIR (not the staging directory)
#   references_file      DIR/references is a regular file, with --export-ply:
#                        refused before the run
#   input_in_out         the dataset is DIR/results.csv (or a link to DIR's
#                        fig_single.svg): refused before the run, the dataset
#                        unchanged (the run would have replaced it)
#   long_cloud_name      --export-ply with an object whose OBJECT.ply name is
#                        longer than a file name may be: refused before the
#                        run (it failed at the end, keeping nothing of it)
#   stale_outputs        figures and clouds an earlier run left in DIR that
#                        this run does not write are named on stdout, kept
cmake_minimum_required(VERSION 3.16)  # policies: GLOB_RECURSE does not follow links
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
include(${CMAKE_CURRENT_LIST_DIR}/../cmake/script_util.cmake)

# A listing of `dir`: every entry (recursively, links not followed) with the
# SHA-256 of each file's bytes.
function(snapshot dir var)
  file(GLOB_RECURSE entries LIST_DIRECTORIES true RELATIVE ${dir} ${dir}/*)
  list(SORT entries)
  set(s "")
  foreach(e IN LISTS entries)
    if(IS_SYMLINK ${dir}/${e})
      file(READ_SYMLINK ${dir}/${e} t)
      string(APPEND s "${e} -> ${t}\n")
    elseif(IS_DIRECTORY ${dir}/${e})
      string(APPEND s "${e}/\n")
    else()
      file(SHA256 ${dir}/${e} h)
      string(APPEND s "${e} ${h}\n")
    endif()
  endforeach()
  set(${var} "${s}" PARENT_SCOPE)
endfunction()

function(expect_same dir before)
  snapshot(${dir} after)
  if(NOT after STREQUAL before)
    message(FATAL_ERROR "a failed run changed ${dir}:\nbefore:\n${before}after:\n${after}")
  endif()
  file(GLOB staging ${WORK_DIR}/*.partial-*)
  if(staging)
    message(FATAL_ERROR "a failed run left ${staging}")
  endif()
endfunction()

function(expect_no_run)
  if(NOT out STREQUAL "")
    message(FATAL_ERROR "the run started before the bad --out was refused; stdout:\n${out}")
  endif()
endfunction()

run(${ICLAP} simulate --objects ${OBJECTS} --unit m --explorations 3 --seed 5 --out ${WORK_DIR}/three.csv)
set(evaluate ${ICLAP} evaluate ${WORK_DIR}/three.csv --touches 1,2 --repeats 2 --weight-repeats 1)
set(res ${WORK_DIR}/res)
# The first run writes DIR; the second, with one more method, would change
# results.csv and weights.csv and add fig_decision_fusion.svg.
set(second ${evaluate} --methods bow,icp,icp+bow --out ${res})

if(CASE STREQUAL "conflict_before_run")
  run(${evaluate} --methods bow,icp --out ${res})
  file(REMOVE ${res}/sweeps.csv)
  file(MAKE_DIRECTORY ${res}/sweeps.csv)
  snapshot(${res} before)
  run_expect(2 ${second})
  expect_same(${res} "${before}")
  expect_no_run()
  expect_match("${err}" "res/sweeps\\.csv: is a directory, which the new sweeps\\.csv cannot replace; .*res was left as it was")

elseif(CASE STREQUAL "conflict_at_commit")
  run(${evaluate} --methods bow,icp --out ${res})
  file(REMOVE ${res}/fig_single.svg)
  file(MAKE_DIRECTORY ${res}/fig_single.svg/inside)
  snapshot(${res} before)
  run_expect(2 ${second})
  expect_same(${res} "${before}")
  expect_match("${err}" "res/fig_single\\.svg: is a directory, which the new fig_single\\.svg cannot replace; .*res was left as it was")

elseif(CASE STREQUAL "rollback")
  # Needs a directory on another file system than WORK_DIR: /dev/shm (tmpfs).
  set(other /dev/shm)
  execute_process(COMMAND stat -c %d ${WORK_DIR} ${other} RESULT_VARIABLE rc OUTPUT_VARIABLE devices ERROR_QUIET)
  string(REGEX MATCHALL "[0-9]+" devices "${devices}")
  list(LENGTH devices n)
  if(NOT rc EQUAL 0 OR NOT n EQUAL 2)
    message(STATUS "skipped: no ${other}")
    return()
  endif()
  list(GET devices 0 dev_a)
  list(GET devices 1 dev_b)
  if(dev_a STREQUAL dev_b)
    message(STATUS "skipped: ${other} is on the file system of ${WORK_DIR}")
    return()
  endif()
  string(SHA256 tag "${WORK_DIR}")
  string(SUBSTRING "${tag}" 0 16 tag)
  set(refs ${other}/iclap-evaluate-output-test-${tag})
  file(REMOVE_RECURSE ${refs})
  run(${evaluate} --methods bow,icp --export-ply --out ${res})
  file(COPY ${res}/references/ DESTINATION ${refs})
  file(REMOVE_RECURSE ${res}/references)
  file(CREATE_LINK ${refs} ${res}/references SYMBOLIC)
  # With old clouds (kept aside while replaced), then without (new files).
  foreach(old_clouds TRUE FALSE)
    if(NOT old_clouds)
      file(GLOB clouds ${refs}/*)
      file(REMOVE ${clouds})
    endif()
    snapshot(${res} before)
    snapshot(${refs} before_refs)
    execute_process(COMMAND ${second} --export-ply RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    set(failure "")
    if(NOT rc EQUAL 2 OR NOT err MATCHES "res/references/[a-z_]+\\.ply: .*; .*res was left as it was")
      set(failure "exit ${rc}, expected 2 and a message naming the cloud:\n${err}")
    endif()
    snapshot(${res} after)
    snapshot(${refs} after_refs)
    if(NOT after STREQUAL before OR NOT after_refs STREQUAL before_refs)
      string(APPEND failure "\na failed run changed ${res}:\nbefore:\n${before}${before_refs}after:\n${after}${after_refs}")
    endif()
    if(failure)
      file(REMOVE_RECURSE ${refs})
      message(FATAL_ERROR "${failure}")
    endif()
  endforeach()
  file(REMOVE_RECURSE ${refs})
  expect_same(${res} "${before}")

elseif(CASE STREQUAL "missing_parents")
  run(${evaluate} --methods bow,icp --out ${WORK_DIR}/new/sub/res)
  expect_file_lines(${WORK_DIR}/new/sub/res/results.csv 5 "icp,2,")
  # A run refused for its input leaves no directory behind.
  run_expect(2 ${evaluate} --methods bow,icp --contact-threshold 1e9 --out ${WORK_DIR}/new2/sub/res)
  expect_match("${err}" "has no contact frame")
  if(EXISTS ${WORK_DIR}/new2)
    message(FATAL_ERROR "a refused evaluate left ${WORK_DIR}/new2 behind")
  endif()

elseif(CASE STREQUAL "bad_parent")
  file(WRITE ${WORK_DIR}/a_file "x")
  run_expect(2 ${evaluate} --methods bow,icp --out ${WORK_DIR}/a_file/sub/res)
  expect_no_run()
  expect_match("${err}" "a_file/sub/res: cannot create the output directory: .*a_file is not a directory")
  if(err MATCHES "partial")
    message(FATAL_ERROR "the message names the staging directory:\n${err}")
  endif()
  file(READ ${WORK_DIR}/a_file x)
  if(NOT x STREQUAL "x")
    message(FATAL_ERROR "a_file changed")
  endif()
  # DIR itself a regular file.
  run_expect(2 ${evaluate} --methods bow,icp --out ${WORK_DIR}/a_file)
  expect_match("${err}" "--out: '.*a_file' exists and is not a directory")
  expect_no_run()

elseif(CASE STREQUAL "references_file")
  run(${evaluate} --methods bow,icp --out ${res})
  file(WRITE ${res}/references "not a directory\n")
  snapshot(${res} before)
  run_expect(2 ${evaluate} --methods bow,icp --export-ply --out ${res})
  expect_same(${res} "${before}")
  expect_no_run()
  expect_match("${err}" "res/references: is not a directory; .*res was left as it was")

elseif(CASE STREQUAL "input_in_out")
  file(MAKE_DIRECTORY ${res})
  configure_file(${WORK_DIR}/three.csv ${res}/results.csv COPYONLY)
  configure_file(${WORK_DIR}/three.csv ${res}/fig_single.svg COPYONLY)
  file(CREATE_LINK ${res}/fig_single.svg ${WORK_DIR}/link.csv SYMBOLIC)
  snapshot(${res} before)
  run_expect(2 ${ICLAP} evaluate ${res}/results.csv --methods bow,icp --touches 1 --repeats 1 --out ${res})
  expect_no_run()
  expect_match("${err}" "--out '[^']*res' would replace the dataset '[^']*res/results\\.csv' with the run's results\\.csv")
  run_expect(2 ${ICLAP} evaluate ${WORK_DIR}/link.csv --methods bow,icp --touches 1 --repeats 1 --out ${res})
  expect_no_run()
  expect_match("${err}" "would replace the dataset '[^']*link\\.csv' with the run's fig_single\\.svg")
  expect_same(${res} "${before}")
  # The same file name elsewhere is no conflict.
  run(${ICLAP} evaluate ${res}/results.csv --methods bow,icp --touches 1 --repeats 1 --out ${WORK_DIR}/other)
  expect_file_lines(${WORK_DIR}/other/results.csv 3 "icp,1,")

elseif(CASE STREQUAL "long_cloud_name")
  # 100 x e-acute (UTF-8 C3 A9): 200 bytes of name, 600 as %C3%A9.
  string(REPEAT "é" 100 long)
  file(READ ${WORK_DIR}/three.csv data)
  string(REPLACE "\nwedge," "\n${long}," data "${data}")
  file(WRITE ${WORK_DIR}/long.csv "${data}")
  run_expect(2 ${ICLAP} evaluate ${WORK_DIR}/long.csv --methods bow,icp --touches 1 --repeats 1 --export-ply --out ${res})
  expect_no_run()
  expect_match("${err}" "^iclap evaluate: --export-ply: object '[^']+' would be written to a file name of 604 bytes \\('%C3%A9%C3%A9[^']*'\\), longer than a file name may be \\(255\\)\n$")
  if(EXISTS ${res})
    message(FATAL_ERROR "a refused run created ${res}")
  endif()
  # Without --export-ply the name is no file name.
  run(${ICLAP} evaluate ${WORK_DIR}/long.csv --methods bow,icp --touches 1 --repeats 1 --out ${res})
  expect_file_lines(${res}/results.csv 3 "icp,1,")

elseif(CASE STREQUAL "stale_outputs")
  # Figures and clouds of an earlier run that this one does not write are
  # kept (nothing in DIR is removed) and named, so that they do not pass
  # for this run's; a run that writes them all names nothing.
  run(${second} --export-ply)
  run(${evaluate} --methods bow,icp --out ${res})
  expect_match("${out}" "\nnote: [^\n]*res also holds fig_weights_icppbow\\.svg, references/ from an earlier run, which this run did not write\n")
  if(NOT EXISTS ${res}/fig_weights_icppbow.svg OR NOT IS_DIRECTORY ${res}/references)
    message(FATAL_ERROR "the earlier run's figure or clouds were removed")
  endif()
  run(${second} --export-ply)
  if(out MATCHES "note: [^\n]*also holds")
    message(FATAL_ERROR "a run that wrote every output named some as an earlier run's:\n${out}")
  endif()

else()
  message(FATAL_ERROR "unknown CASE '${CASE}'")
endif()
