// SPDX-License-Identifier: MIT
//
// `iclap simulate`: writes a simulated haptic dataset, exactly as the rig
// recorder would, from built-in objects or a folder of meshes.

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <optional>
#include <set>
#include <string>

#include "cli.hpp"
#include "sim_options.hpp"
#include "iclap/data/csv_writer.hpp"
#include "iclap/data/dataset.hpp"
#include "iclap/io/atomic_file.hpp"
#include "iclap/mesh/load.hpp"
#include "iclap/sim/builtin_objects.hpp"
#include "iclap/sim/objects.hpp"
#include "iclap/sim/simulator.hpp"

namespace {

namespace fs = std::filesystem;

/// Throws UsageError when --out `out` is a file the run reads from `dir`:
/// one of its meshes or its meshes.json (the dataset would replace it).
void check_out_is_no_input(const std::string& out, const std::string& dir) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string file = it->path().string();
    if (!iclap::is_mesh_file(file) && it->path().filename() != "meshes.json") continue;
    std::error_code same_ec;  // set when OUT does not exist yet: no conflict
    if (fs::equivalent(out, it->path(), same_ec))
      throw iclap::cli::UsageError("--out " + iclap::quote_text(out) + " is " + iclap::quote_text(file) +
                                   ", an input of --objects " + iclap::quote_text(dir) +
                                   ", which the dataset would replace");
  }
}

/// Throws UsageError naming --out unless the dataset can be written to
/// `out`, before the simulation (minutes for many explorations or large
/// meshes) rather than after it: not a directory, and a new file can be
/// created beside it (tried and removed at once).
void check_out_writable(const std::string& out) {
  std::error_code ec;
  if (fs::is_directory(out, ec))
    throw iclap::cli::UsageError("--out " + iclap::quote_text(out) + ": is a directory; give a file name");
  try {
    iclap::AtomicFileWriter probe(out);  // removed again (no commit)
  } catch (const iclap::IoError& e) {
    throw iclap::cli::UsageError(std::string("--out: ") + e.what());
  }
}

int run_simulate(const iclap::cli::Args& args) {
  using namespace iclap::cli;
  std::set<std::string> names = simulation_option_names();
  names.insert({"objects", "unit", "explorations", "seed", "out", "threads"});
  const Options opt(args, names);
  opt.expect_positional(0, 0, "no positional arguments");
  const std::string objects_arg = opt.string("objects", "builtin");
  const std::string unit = opt.choice("unit", {"auto", "m", "mm"}, "auto");
  const std::string out = opt.string("out", "-");
  if (out == "-" && isatty(1))
    throw UsageError("refusing to write the dataset to a terminal: give --out FILE or redirect the output");

  iclap::SimulationSettings settings;
  settings.explorations = static_cast<int>(opt.integer("explorations", 5, 1, 1000));
  settings.threads = static_cast<unsigned>(opt.integer("threads", 0, 0, 256));
  parse_simulation_options(opt, settings.exploration);
  const long long seed = opt.integer("seed", 1, 0);
  if (out != "-") {
    check_out_writable(out);
    if (objects_arg != "builtin") check_out_is_no_input(out, objects_arg);
  }

  // The built-in objects have their own size: a --unit with them would be
  // ignored without a word.
  if (objects_arg == "builtin" && opt.has("unit"))
    throw UsageError("--unit gives the unit of mesh files (--objects DIR); the built-in objects have their own size");

  std::vector<iclap::SimObject> objects;
  if (objects_arg == "builtin") {
    objects = iclap::builtin_objects();
  } else {
    std::optional<iclap::LengthUnit> u;
    if (unit != "auto") u = iclap::parse_length_unit(unit, "--unit");
    Progress loading("loading meshes");
    // The loader names its arguments "dir" and "unit"; the user gave them as
    // --objects and --unit.
    objects = iclap::rename_argument("dir", "--objects", [&] {
      return iclap::rename_argument("unit", "--unit",
                                    [&] { return iclap::load_mesh_objects(objects_arg, u, std::ref(loading)); });
    });
  }
  iclap::Dataset ds;
  {
    Progress progress("simulating explorations");
    ds = iclap::simulate_dataset(objects, settings, static_cast<std::uint64_t>(seed), std::ref(progress));
  }
  if (out == "-") {
    iclap::write_dataset_csv(std::cout, ds);
    std::cout.flush();
    if (!std::cout) throw iclap::WriteError("<stdout>", "write failed");
  } else {
    iclap::write_dataset_csv(out, ds);
  }
  std::fprintf(stderr, "iclap simulate: %zu objects, %zu explorations, %zu frames (%zu contact) -> %s\n",
               objects.size(), objects.size() * static_cast<std::size_t>(settings.explorations), ds.frames.size(),
               iclap::contact_frame_count(ds), out == "-" ? "<stdout>" : out.c_str());
  return kExitOk;
}

}  // namespace

ICLAP_COMMAND("simulate", "write a simulated dataset of the WTS/Omni rig (built-in objects or meshes)",
              "usage: iclap simulate [--objects builtin|DIR] [--unit auto|m|mm] [--explorations N]\n"
              "                      [--seed S] [--out FILE] [--threads T]\n"
              "                      [--shift-mm D] [--yaw-deg A] [--frames F]\n"
              "                      [--sweep-min-mm L] [--sweep-max-mm L] [--turn-probability P]\n"
              "                      [--start-candidates K]\n\n"
              "Simulates the paper's data collection (uninformed sweeps at 5 mm/s, 5 frames/s,\n"
              "the pad kept normal to the surface) and writes the dataset CSV the rig recorder\n"
              "would write (README, \"Dataset format\").\n\n"
              "  --objects builtin  the 20 built-in tool-like objects (default)\n"
              "  --objects DIR      every .obj/.stl/.ply in DIR, named after its file stem, put in\n"
              "                     a stable resting pose on the table\n"
              "  --unit U           unit of the mesh files: m, mm, or auto (default): each file's\n"
              "                     scale_to_metres from DIR/meshes.json (only with --objects DIR)\n"
              "  --explorations N   explorations per object (default 5)\n"
              "  --seed S           seed of all randomness (default 1); same seed and options give\n"
              "                     byte-identical files\n"
              "  --out FILE         output file, written atomically (default '-': standard output,\n"
              "                     unless it is a terminal)\n"
              "  --threads T        worker threads, 0 = all (default 0); the output does not depend on it\n"
              "  --shift-mm D       object re-placed before each exploration within D mm (default 10)\n"
              "  --yaw-deg A        ... and turned by up to +-A degrees (default 10)\n"
              "  --frames F         mean frames per exploration (default 85, the paper's 8492/100)\n"
              "  --sweep-min-mm L   each sweep's planned length is uniform in [min, max] mm\n"
              "  --sweep-max-mm L   (defaults 30 and 80, each in [0.1, 1000])\n"
              "  --turn-probability P  at the end of a sweep the operator turns and slides on with\n"
              "                     probability P, else lifts the pad and starts anew at a random\n"
              "                     point of the object (default 0.75, in [0, 1]; a sweep that\n"
              "                     ran off the object always ends in a lift)\n"
              "  --start-candidates K  1 (default): each new start point drawn by area over the\n"
              "                     object (uninformed); K in [2, 64]: the operator covers the\n"
              "                     object, taking of K draws the one farthest from where the pad\n"
              "                     has been in this exploration",
              run_simulate);
