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
file(REMOVE_RECURSE "${WORK}")
