# `iclap simulate` end to end: a small run twice (same bytes), then
# `iclap info` on the output; a run on a mesh folder; bad options.
#   cmake -DICLAP=path/to/iclap -DWORK=scratch/dir -DMESHES=fixture/dir -P cli_simulate.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

include(${CMAKE_CURRENT_LIST_DIR}/../cmake/script_util.cmake)

# Built-in objects, one exploration each, twice with the same seed.
run("${ICLAP}" simulate --explorations 1 --seed 7 --threads 2 --out "${WORK}/a.csv")
expect_match("${err}" "iclap simulate: 20 objects, 20 explorations, [0-9]+ frames \\([0-9]+ contact\\) -> ")
run("${ICLAP}" simulate --explorations 1 --seed 7 --threads 1 --out "${WORK}/b.csv")
file(SHA256 "${WORK}/a.csv" ha)
file(SHA256 "${WORK}/b.csv" hb)
if(NOT ha STREQUAL hb)
  message(FATAL_ERROR "same seed, different bytes")
endif()
file(GLOB leftovers "${WORK}/*.partial*")
if(leftovers)
  message(FATAL_ERROR "temporary file left behind: ${leftovers}")
endif()
run("${ICLAP}" info "${WORK}/a.csv")
expect_match("${out}" "taxel grid: +14 x 6")
expect_match("${out}" "columns: +t yes, orientation yes")
expect_match("${out}" "objects: +20\n")
expect_match("${out}" "explorations: +20\n")
expect_match("${out}" "frames: +[0-9][0-9][0-9][0-9]?\n")
expect_match("${out}" "\npliers_1 +1 +[0-9]+ +[0-9]+\n")
expect_match("${out}" "\nmallet +1 +[0-9]+ +[0-9]+\n")
expect_match("${out}" "comment: +sensor: WTS 0614-34A \\(simulated\\) rows=14 cols=6 pitch_m=0.0034")

# A different seed gives different data.
run("${ICLAP}" simulate --explorations 1 --seed 8 --out "${WORK}/c.csv")
file(SHA256 "${WORK}/c.csv" hc)
if(ha STREQUAL hc)
  message(FATAL_ERROR "different seeds, same bytes")
endif()

# The operator's options take effect: short sweeps, a lift after each, the
# covering start points; the same options give the same bytes.
set(_operator --explorations 1 --seed 7 --sweep-min-mm 10 --sweep-max-mm 20 --turn-probability 0 --start-candidates 8)
run("${ICLAP}" simulate ${_operator} --out "${WORK}/d.csv")
run("${ICLAP}" simulate ${_operator} --threads 1 --out "${WORK}/e.csv")
file(SHA256 "${WORK}/d.csv" hd)
file(SHA256 "${WORK}/e.csv" he)
if(ha STREQUAL hd OR NOT hd STREQUAL he)
  message(FATAL_ERROR "the operator options changed nothing, or the same options gave different bytes")
endif()
run("${ICLAP}" info "${WORK}/d.csv" --overlap 5)
expect_match("${out}" "overlap: +0 of [0-9]+ contact frames \\(0.0%\\) within 5 mm")  # one exploration each

# A folder of meshes with a meshes.json (automatic units), to stdout.
run("${ICLAP}" simulate --objects "${MESHES}" --explorations 2 --frames 20)
file(WRITE "${WORK}/m.csv" "${out}")
run("${ICLAP}" info "${WORK}/m.csv")
expect_match("${out}" "objects: +2\n")
expect_match("${out}" "explorations: +4\n")
expect_match("${out}" "\nblock +2 ")
expect_match("${out}" "\nwedge +2 ")

# Bad input: exit status 2 and a message that names the problem.
run_expect(2 "${ICLAP}" simulate --unit cm --objects "${MESHES}")
expect_match("${err}" "--unit: 'cm' is not one of auto\\|m\\|mm")
run_expect(2 "${ICLAP}" simulate --objects "${WORK}/no_such_dir")
expect_match("${err}" "no_such_dir: is not a directory")
run_expect(2 "${ICLAP}" simulate --explorations 0)
expect_match("${err}" "--explorations: 0 is outside")
run_expect(2 "${ICLAP}" simulate --sweep-min-mm 30 --sweep-max-mm 20 --out "${WORK}/x.csv")
expect_match("${err}" "--sweep-max-mm must be >= --sweep-min-mm, got 20 < 30")
run_expect(2 "${ICLAP}" simulate --start-candidates 65 --out "${WORK}/x.csv")
expect_match("${err}" "--start-candidates: 65 is outside")
run_expect(2 "${ICLAP}" simulate --turn-probability 1.5 --out "${WORK}/x.csv")
expect_match("${err}" "--turn-probability: 1.5 is outside \\[0, 1\\]")
if(EXISTS "${WORK}/x.csv")
  message(FATAL_ERROR "a refused run left its output file")
endif()
# An --out that cannot be written is refused before the simulation (a
# directory was "cannot move into place: Is a directory", after it).
run_expect(2 "${ICLAP}" simulate --explorations 1 --frames 10 --out "${WORK}")
expect_match("${err}" "^iclap simulate: --out '[^']*': is a directory; give a file name\n")
run_expect(2 "${ICLAP}" simulate --explorations 1 --frames 10 --out "${WORK}/no_such_dir/x.csv")
expect_match("${err}" "^iclap simulate: --out: [^\n]*/no_such_dir/x\\.csv: cannot open for writing")
file(GLOB leftovers "${WORK}/*.partial*")
if(leftovers)
  message(FATAL_ERROR "a refused --out left ${leftovers}")
endif()
# --out naming one of the run's inputs (a mesh of the folder, its
# meshes.json) is refused before the run: the dataset would replace it.
file(COPY "${MESHES}/" DESTINATION "${WORK}/meshes")
foreach(input wedge.ply meshes.json)
  file(SHA256 "${WORK}/meshes/${input}" before)
  run_expect(2 "${ICLAP}" simulate --objects "${WORK}/meshes" --explorations 1 --frames 10 --out "${WORK}/meshes/${input}")
  expect_match("${err}" "--out '[^']*/meshes/${input}' is '[^']*/meshes/${input}', an input of --objects '[^']*/meshes', which the dataset would replace")
  file(SHA256 "${WORK}/meshes/${input}" after)
  if(NOT before STREQUAL after)
    message(FATAL_ERROR "simulate --out replaced its input ${input}")
  endif()
endforeach()
# A new file in the folder is no input.
run("${ICLAP}" simulate --objects "${WORK}/meshes" --explorations 1 --frames 10 --out "${WORK}/meshes/new.csv")
file(REMOVE_RECURSE "${WORK}")
