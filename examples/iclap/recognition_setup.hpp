// SPDX-License-Identifier: MIT
#pragma once

// The recognition system as the `iclap` commands configure it from their
// options (shared by `evaluate` and `live`): descriptor, codebook and the
// classifiers with their ICP settings.

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "cli.hpp"
#include "iclap/data/dataset.hpp"
#include "iclap/recognition/classifier.hpp"
#include "iclap/recognition/methods.hpp"
#include "iclap/recognition/touch_table.hpp"
#include "iclap/tactile/kmeans.hpp"

namespace iclap::cli {

/// The classifiers that register (every one but bow), in build order.
inline const std::vector<std::string>& registration_classifiers() {
  static const std::vector<std::string> names = {"icp", "iclap", "iclapn", "patch", "iclap_patch"};
  return names;
}

inline bool is_registration_classifier(const std::string& name) {
  const auto& r = registration_classifiers();
  return std::find(r.begin(), r.end(), name) != r.end();
}

struct RecognitionOptions {
  std::string descriptor = "sift";   ///< sift | raw | moments
  std::string transform = "planar";  ///< full | spatial | planar | translation
  std::string scalar = "float";      ///< float | double
  std::string search = "kdtree";     ///< kdtree | brute
  Index k = 50;                      ///< codebook size (paper: 50)
  std::uint64_t codebook_seed = 1;
  double label_scale = 0.001;        ///< metres per word step (iCLAP's 4th axis)
  double descriptor_scale = 0.01;    ///< metres per descriptor unit (iCLAP-N)
  int max_iterations = 50;
  double relative_tolerance = 1e-6;
  /// Trimmed ICP (Chetverikov et al.): the motion and the distance use the
  /// closest fraction of the pairs; 1 keeps all, the paper's plain ICP.
  /// `trim` applies to every registration classifier not in `trim_by_name`.
  /// No distance cut-off is offered: E sums the kept pairs, so an object
  /// that kept fewer would look closer; with trimming every object keeps
  /// the same number.
  double trim = 1;
  std::map<std::string, double> trim_by_name;  ///< e.g. {"patch", 0.5}
  double contact_threshold = kDefaultContactThreshold;
  Index patch_points = 8;            ///< contact points per test touch (patch classifiers)
  double patch_voxel = 0.002;        ///< reference voxel, metres (patch classifiers)

  /// The trimmed fraction of classifier `name`.
  double trim_of(const std::string& name) const {
    const auto it = trim_by_name.find(name);
    return it == trim_by_name.end() ? trim : it->second;
  }

  /// The ICP settings of the registration classifiers among `names` as the
  /// reports print them: "at most 50 iterations, relative tolerance 1e-06;
  /// every pair" or "...; trimmed: patch 50%, iclap_patch 70%".
  std::string icp_summary(const std::vector<std::string>& names) const {
    char buf[160];
    std::snprintf(buf, sizeof buf, "at most %d iterations, relative tolerance %g; ", max_iterations, relative_tolerance);
    std::string out = buf, trimmed;
    for (const auto& n : names)
      if (is_registration_classifier(n) && trim_of(n) < 1) {
        std::snprintf(buf, sizeof buf, "%s%s %g%%", trimmed.empty() ? "" : ", ", n.c_str(), 100 * trim_of(n));
        trimmed += buf;
      }
    return out + (trimmed.empty() ? "every pair" : "trimmed: " + trimmed);
  }

  /// The option names `parse` reads (value options).
  static std::set<std::string> value_options() {
    return {"descriptor", "transform", "scalar", "search", "k", "label-scale", "descriptor-scale",
            "max-iterations", "relative-tolerance", "trim", "contact-threshold", "patch-points", "patch-voxel"};
  }
  /// Usage lines of those options.
  static const char* usage() {
    return "  --descriptor sift|raw|moments   tactile feature (default sift: Tactile-SIFT 3x3x8)\n"
           "  --k N                   codebook size (default 50, as in the paper)\n"
           "  --transform full|spatial|planar|translation   motion between a test and a\n"
           "                          reference (default planar: objects lie on a table;\n"
           "                          full is the paper's 4-D rigid iCLAP)\n"
           "  --label-scale S         metres per word step on iCLAP's label axis (default 0.001:\n"
           "                          the paper's rig gave millimetres and integer labels)\n"
           "  --descriptor-scale S    metres per descriptor unit for iclapn (default 0.01)\n"
           "  --scalar float|double   ICP arithmetic (default float)\n"
           "  --search kdtree|brute   closest-point search (default kdtree)\n"
           "  --max-iterations N      ICP iteration cap (default 50)\n"
           "  --relative-tolerance R  ICP relative-change stop (default 1e-6)\n"
           "  --trim F|NAME=F,...     trimmed ICP: the distance and the motion use the closest\n"
           "                          fraction F of the pairs, in (0, 1]; F alone for every\n"
           "                          registration classifier, NAME=F for one (e.g. patch=0.5);\n"
           "                          default 1: all pairs, the paper's\n"
           "  --contact-threshold P   a frame is a touch when a taxel exceeds P raw units\n"
           "  --patch-points N        contact points per test touch for patch, iclap_patch (default 8)\n"
           "  --patch-voxel V         reference voxel for patch, iclap_patch, metres (default 0.002)\n";
  }
  void parse(const Options& o) {
    descriptor = o.choice("descriptor", {"sift", "raw", "moments"}, descriptor);
    transform = o.choice("transform", {"full", "spatial", "planar", "translation"}, transform);
    scalar = o.choice("scalar", {"float", "double"}, scalar);
    search = o.choice("search", {"kdtree", "brute"}, search);
    k = static_cast<Index>(o.integer("k", k, 1, 100000));
    label_scale = o.number("label-scale", label_scale, 0.0);
    if (!(label_scale > 0)) throw UsageError("--label-scale must be > 0");
    descriptor_scale = o.number("descriptor-scale", descriptor_scale, 0.0);
    if (!(descriptor_scale > 0)) throw UsageError("--descriptor-scale must be > 0");
    max_iterations = static_cast<int>(o.integer("max-iterations", max_iterations, 0, 100000));
    relative_tolerance = o.number("relative-tolerance", relative_tolerance, 0.0);
    if (o.has("trim")) parse_trim(o.string("trim"));
    contact_threshold = o.number("contact-threshold", contact_threshold, 0.0);
    patch_points = static_cast<Index>(o.integer("patch-points", patch_points, 1, 84 * 100));
    patch_voxel = o.number("patch-voxel", patch_voxel, 0.0, 1.0);
  }

  /// "--trim": "F" for every registration classifier, "NAME=F" for one;
  /// comma-separated, each name at most once.
  void parse_trim(const std::string& value) {
    bool all_given = false;
    for (const auto& item : Options::split(value, ',')) {
      const auto eq = item.find('=');
      const std::string name = eq == std::string::npos ? "" : item.substr(0, eq);
      const std::string text = eq == std::string::npos ? item : item.substr(eq + 1);
      const double f = Options::parse_number(text, "--trim " + item, -std::numeric_limits<double>::infinity(),
                                             std::numeric_limits<double>::infinity());
      if (!(f > 0 && f <= 1)) throw UsageError("--trim " + item + ": the fraction must be in (0, 1]");
      if (name.empty()) {
        if (all_given) throw UsageError("--trim gives the fraction of every classifier twice");
        trim = f;
        all_given = true;
        continue;
      }
      if (!is_registration_classifier(name))
        throw UsageError("--trim " + item + ": '" + name + "' is not a registration classifier (" +
                         Options::join(registration_classifiers(), ", ") + ")");
      if (!trim_by_name.emplace(name, f).second) throw UsageError("--trim names '" + name + "' twice");
    }
  }
};

/// The classifiers named in `names` ("bow", "icp", "iclap", "iclapn", "patch",
/// "iclap_patch"),
/// configured by `options`. Throws UsageError for an unknown name.
std::vector<std::unique_ptr<Classifier>> make_classifiers(const RecognitionOptions& options,
                                                          const std::vector<std::string>& names);

/// Every classifier name the commands know, in the order they are built.
inline const std::vector<std::string>& known_classifiers() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = {"bow"};
    for (const auto& r : registration_classifiers()) n.push_back(r);
    return n;
  }();
  return names;
}

/// The classifiers `methods` use, in the order of known_classifiers();
/// UsageError naming the method and the classifier for an unknown one.
inline std::vector<std::string> needed_classifiers(const std::vector<Method>& methods) {
  const auto& known = known_classifiers();
  std::vector<std::string> out;
  for (const auto& m : methods)
    for (const auto& c : m.fusion.classifiers())
      if (std::find(known.begin(), known.end(), c) == known.end())
        throw UsageError("method '" + m.name + "' uses unknown classifier '" + c + "' (known: " + Options::join(known, ", ") +
                         ")");
  for (const auto& k : known)
    for (const auto& m : methods) {
      const auto used = m.fusion.classifiers();
      if (std::find(used.begin(), used.end(), k) != used.end()) {
        out.push_back(k);
        break;
      }
    }
  return out;
}

/// The touches of `dataset` described by the chosen descriptor.
TouchTable make_touch_table(const Dataset& dataset, const RecognitionOptions& options,
                            const ProgressCallback& progress = {});

/// The codebook prototype (k, seed) the options ask for.
inline KMeansQuantizer<float> make_quantizer(const RecognitionOptions& options) {
  KMeansQuantizer<float> q;
  q.settings.k = options.k;
  q.settings.seed = options.codebook_seed;
  return q;
}

}  // namespace iclap::cli
