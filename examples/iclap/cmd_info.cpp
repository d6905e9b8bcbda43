// SPDX-License-Identifier: MIT
//
// `iclap info FILE.csv`: validates a dataset file and prints what it holds.

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "cli.hpp"
#include "iclap/data/csv_reader.hpp"
#include "iclap/data/dataset.hpp"
#include "iclap/data/overlap.hpp"

namespace {

int run_info(const iclap::cli::Args& args) {
  using namespace iclap::cli;
  const Options opt(args, {"threshold", "overlap"});
  opt.expect_positional(1, 1, "one dataset file");
  const double threshold = opt.number("threshold", iclap::kDefaultContactThreshold, 0.0);
  const double overlap_mm = opt.number("overlap", 0.0, 0.0, 1e6);
  // exploration_overlap's smallest radius, refused before anything is printed.
  if (overlap_mm > 0 && overlap_mm * 1e-3 < iclap::smallest_spread<double>())
    throw UsageError("--overlap: " + iclap::format_value(overlap_mm) + " mm is below the smallest radius, " +
                     iclap::format_value(iclap::smallest_spread<double>() * 1e3) +
                     " mm (squared distances would underflow); 0 turns the overlap off");
  const std::string path = opt.positional()[0];
  const iclap::Dataset ds = iclap::read_dataset_csv(path, [](const iclap::DatasetWarning& w) {
    std::fprintf(stderr, "%s\n", w.to_string().c_str());
  });
  const auto objects = iclap::summarize(ds, threshold);
  std::size_t explorations = 0, contacts = 0;
  std::size_t name_width = 6;
  for (const auto& o : objects) {
    explorations += o.explorations.size();
    contacts += o.contact_frames;
    name_width = std::max(name_width, o.name.size());
  }
  const bool time = !ds.frames.empty() && ds.frames.front().time.has_value();
  const bool orientation = !ds.frames.empty() && ds.frames.front().orientation.has_value();
  std::printf("file:           %s\n", path.c_str());
  for (const auto& c : ds.comments) std::printf("comment:        %s\n", c.c_str());
  std::printf("taxel grid:     %lld x %lld (rows x cols)\n", static_cast<long long>(ds.rows),
              static_cast<long long>(ds.cols));
  std::printf("columns:        t %s, orientation %s\n", time ? "yes" : "no", orientation ? "yes" : "no");
  std::printf("objects:        %zu\n", objects.size());
  std::printf("explorations:   %zu\n", explorations);
  std::printf("frames:         %zu\n", ds.frames.size());
  std::printf("contact frames: %zu (max taxel pressure > %g)\n", contacts, threshold);
  // Per object: contact frames within --overlap mm of another exploration's.
  std::vector<std::size_t> near(objects.size(), 0);
  if (overlap_mm > 0) {
    std::size_t total_near = 0, k = 0;
    for (const auto& e : iclap::exploration_overlap(ds, overlap_mm * 1e-3, threshold)) {
      while (objects[k].name != e.object) ++k;  // same order of first appearance
      near[k] += e.near;
      total_near += e.near;
    }
    std::printf("overlap:        %zu of %zu contact frames (%.1f%%) within %g mm of a contact frame of\n"
                "                another exploration of the same object\n",
                total_near, contacts,
                contacts > 0 ? 100.0 * static_cast<double>(total_near) / static_cast<double>(contacts) : 0.0, overlap_mm);
  }
  if (!objects.empty()) {
    std::printf("\n%-*s  %12s  %8s  %8s%s\n", static_cast<int>(name_width), "object", "explorations",
                "frames", "contact", overlap_mm > 0 ? "   overlap" : "");
    for (std::size_t i = 0; i < objects.size(); ++i) {
      const auto& o = objects[i];
      std::printf("%-*s  %12zu  %8zu  %8zu", static_cast<int>(name_width), o.name.c_str(), o.explorations.size(),
                  o.frames, o.contact_frames);
      if (overlap_mm > 0) {
        if (o.contact_frames > 0)
          std::printf("  %7.1f%%", 100.0 * static_cast<double>(near[i]) / static_cast<double>(o.contact_frames));
        else
          std::printf("  %8s", "-");
      }
      std::printf("\n");
    }
  }
  return kExitOk;
}

}  // namespace

ICLAP_COMMAND("info", "validate a dataset CSV and print its objects, explorations and frames",
              "usage: iclap info FILE.csv [--threshold P] [--overlap MM]\n\n"
              "Reads a haptic dataset file (README, \"Dataset format\"), checks it and prints\n"
              "its taxel grid and, in total and per object, the explorations, frames and\n"
              "contact frames. Warnings (e.g. ignored unknown columns) go to stderr.\n\n"
              "  --threshold P  a frame is a contact when its largest taxel pressure is\n"
              "                 above P (sensor raw units, default 20)\n"
              "  --overlap MM   also count the contact frames whose pad centre lies within\n"
              "                 MM millimetres of a contact frame of another exploration of the\n"
              "                 same object, as recorded: the part of a held-out exploration\n"
              "                 that references built from the others can match (0: off)\n\n"
              "Exit status 0 for a valid file; 2 for an invalid one, with FILE:LINE: reason\n"
              "on stderr.",
              run_info);
