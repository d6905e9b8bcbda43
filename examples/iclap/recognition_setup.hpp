// SPDX-License-Identifier: MIT
#pragma once

// The recognition system as the `iclap` commands configure it from their
// options (shared by `evaluate` and `live`): descriptor, codebook and the
// classifiers with their ICP settings.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "cli.hpp"
#include "iclap/data/dataset.hpp"
#include "iclap/recognition/classifier.hpp"
#include "iclap/recognition/height_classifier.hpp"
#include "iclap/recognition/methods.hpp"
#include "iclap/recognition/occupancy_classifier.hpp"
#include "iclap/recognition/registration_classifier.hpp"
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
  std::string search = "auto";       ///< auto | kdtree | brute (see AdaptiveSearch)
  Index k = 50;                      ///< codebook size (paper: 50)
  std::uint64_t codebook_seed = 1;
  double label_scale = 0.001;        ///< metres per word step (iCLAP's 4th axis)
  double descriptor_scale = 0.01;    ///< metres per descriptor unit (iCLAP-N)
  double tilt_scale = 0.01;          ///< metres per radian of pad tilt (height, height_contact)
  double contact_scale = 1;          ///< metres per metre of contact-patch extent (height_contact)
  /// Scales of the height classifiers for the training folds to choose
  /// among (beyond the paper), like the occupancy lists below: every value
  /// --tilt-scale lists is a variant of height, every combination of the
  /// values --tilt-scale and --contact-scale list a variant of
  /// height_contact. Each list holds one value when its option gives one;
  /// the scalars above hold the first.
  std::vector<double> tilt_scales = {0.01}, contact_scales = {1};
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
  /// "--trim auto" / "NAME=auto": the fraction is chosen among
  /// `trim_choices` on the training folds of the cross validation, like the
  /// fusion weights (one classifier variant per choice, named by
  /// trim_variant(), e.g. "patch-trim50"). `trim_auto` applies to every
  /// registration classifier not in `trim_by_name` or `trim_auto_by_name`.
  bool trim_auto = false;
  std::set<std::string> trim_auto_by_name;
  std::vector<double> trim_choices = {1, 0.7, 0.5, 0.3};
  double contact_threshold = kDefaultContactThreshold;
  Index patch_points = 8;            ///< contact points per test touch (patch classifiers)
  double patch_voxel = 0.002;        ///< reference voxel, metres (patch classifiers)
  // The occupancy classifier (OccupancyClassifier's members, metres /
  // radians; configure_occupancy), by default the library's defaults.
  double occupancy_voxel = occupancy_defaults().voxel;
  double occupancy_truncation = occupancy_defaults().truncation;
  double occupancy_free_radius = occupancy_defaults().free_radius;
  double occupancy_conflict = occupancy_defaults().conflict_weight;
  double occupancy_unknown = occupancy_defaults().unknown_cost;
  double occupancy_back = occupancy_defaults().back_depth;
  double placement_shift = occupancy_defaults().placements.max_shift;
  double placement_yaw = occupancy_defaults().placements.max_yaw;
  double placement_shift_step = occupancy_defaults().placements.shift_step;
  double placement_yaw_step = occupancy_defaults().placements.yaw_step;
  /// Settings of the occupancy classifier for the training folds to choose
  /// among (beyond the paper), like --trim auto: every combination of the
  /// values that --occupancy-truncation, -free-radius, -conflict, -unknown
  /// and -back list (a comma-separated list of two or more makes a
  /// choice); empty when each gives one value. The scalars above hold the first
  /// combination.
  struct OccupancyVariant {
    double truncation, free_radius, conflict, unknown, back;
  };
  std::vector<OccupancyVariant> occupancy_variants;
  /// The most combinations the lists may make. Every variant is a classifier
  /// of its own, fitted on every fold and on its inner folds, and they are
  /// all held at once: on the 20 built-in objects each added about 40 MB and
  /// 30-40 s to a one-draw run of 20 touches on 2 threads (`--methods
  /// occupancy --touches 20 --repeats 1 --weight-repeats 1`, 1, 2 and 4
  /// variants: 101, 146 and 219 MB, 11, 51 and 116 s; 2026-11-26), so 256
  /// is some 10 GB and hours, a 4 x 4 x 4 x 4 sweep.
  static constexpr std::size_t kMaxOccupancyVariants = 256;

  /// "occupancy-t0_002-r0_002-c0_3-u1": truncation and free radius
  /// (metres), conflict and unknown cost, and "-b0_006" for a slab behind
  /// the pad (metres; none without it), each exactly (format_exact, so two
  /// variants never share a name), '.' written as '_'.
  static std::string occupancy_variant_name(const OccupancyVariant& v) {
    return "occupancy-t" + variant_number(v.truncation) + "-r" + variant_number(v.free_radius) + "-c" +
           variant_number(v.conflict) + "-u" + variant_number(v.unknown) +
           (v.back > 0 ? "-b" + variant_number(v.back) : "");
  }
  /// A setting's value in a variant's name: exactly (format_exact, so two
  /// variants never share a name), '.' written as '_' and an exponent's '+'
  /// left out (1e+06: "1e06"), since a classifier's name holds only letters,
  /// digits, '_' and '-'.
  static std::string variant_number(double x) {
    std::string t = format_exact(x);
    std::replace(t.begin(), t.end(), '.', '_');
    t.erase(std::remove(t.begin(), t.end(), '+'), t.end());
    return t;
  }
  /// Are occupancy's settings chosen on the training folds?
  bool occupancy_is_auto() const { return occupancy_variants.size() > 1; }
  /// The variant named `label` (occupancy_variant_name), or null.
  const OccupancyVariant* find_occupancy_variant(const std::string& label) const {
    for (const auto& v : occupancy_variants)
      if (occupancy_variant_name(v) == label) return &v;
    return nullptr;
  }
  std::vector<std::string> occupancy_variant_names() const {
    std::vector<std::string> out;
    for (const auto& v : occupancy_variants) out.push_back(occupancy_variant_name(v));
    return out;
  }

  /// The scales of one variant of a height classifier.
  struct HeightVariant {
    std::string base;  ///< "height" or "height_contact"
    double tilt, contact;
  };
  /// The most variants the scale lists may make for one height classifier
  /// (each is a classifier of its own, though a cheap one: a search
  /// structure of a few thousand 4-D points per object).
  static constexpr std::size_t kMaxHeightVariants = 256;
  /// "height-s0_01" (tilt scale), "height_contact-s0_01-c0_5" (tilt and
  /// contact scales), each value as occupancy_variant_name writes it.
  static std::string height_variant_name(const HeightVariant& v) {
    return v.base + "-s" + variant_number(v.tilt) + (v.base == "height_contact" ? "-c" + variant_number(v.contact) : "");
  }
  /// The variants of height classifier `base` the training folds choose
  /// among; empty when its scales are fixed (height: one tilt scale;
  /// height_contact: one tilt and one contact scale) or `base` is no height
  /// classifier.
  std::vector<HeightVariant> height_variants(const std::string& base) const {
    std::vector<HeightVariant> out;
    if (base == "height") {
      if (tilt_scales.size() > 1)
        for (double s : tilt_scales) out.push_back({base, s, 0});
    } else if (base == "height_contact") {
      if (tilt_scales.size() * contact_scales.size() > 1)
        for (double s : tilt_scales)
          for (double c : contact_scales) out.push_back({base, s, c});
    }
    return out;
  }
  /// The height variant named `label` (height_variant_name), if any.
  std::optional<HeightVariant> find_height_variant(const std::string& label) const {
    for (const char* base : {"height", "height_contact"})
      for (const auto& v : height_variants(base))
        if (height_variant_name(v) == label) return v;
    return std::nullopt;
  }
  /// Are the scales of some height classifier chosen on the training folds?
  bool height_is_auto() const { return tilt_scales.size() > 1 || contact_scales.size() > 1; }
  /// The scales of height classifier `base` as the reports print them:
  /// "tilt scale 0.01 m/rad" for height, "tilt scale 0.005 or 0.01 m/rad,
  /// contact scale 1 m/m; 2 variants chosen on the training folds" for
  /// height_contact with a list.
  std::string height_summary(const std::string& base) const {
    auto values = [](const std::vector<double>& list) {
      std::string out;
      for (std::size_t i = 0; i < list.size(); ++i) out += (i ? " or " : "") + format_value(list[i]);
      return out;
    };
    std::string out = "tilt scale " + values(tilt_scales) + " m/rad";
    if (base == "height_contact") out += ", contact scale " + values(contact_scales) + " m/m";
    const auto n = height_variants(base).size();
    if (n > 0) out += "; " + std::to_string(n) + " variants chosen on the training folds";
    return out;
  }

  /// The trimmed fraction of classifier `name` (or of a trim variant: the
  /// choice it was named after, exactly as given; its name holds the
  /// percentage to 6 digits only).
  double trim_of(const std::string& name) const {
    std::string base;
    double f = 1;
    if (split_trim_variant(name, base, f)) {
      for (double choice : trim_choices)
        if (trim_variant(base, choice) == name) return choice;
      return f;
    }
    const auto it = trim_by_name.find(name);
    return it == trim_by_name.end() ? trim : it->second;
  }

  /// Is classifier `name`'s fraction chosen on the training folds?
  bool trim_is_auto(const std::string& name) const {
    if (!is_registration_classifier(name) || trim_by_name.count(name)) return false;
    return trim_auto || trim_auto_by_name.count(name) > 0;
  }

  /// "patch" trimmed to 0.5: "patch-trim50" (0.333: "patch-trim33_3").
  static std::string trim_variant(const std::string& base, double fraction) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", 100 * fraction);
    std::string pct = buf;
    std::replace(pct.begin(), pct.end(), '.', '_');
    return base + "-trim" + pct;
  }
  /// The inverse of trim_variant(); false for any other name.
  static bool split_trim_variant(const std::string& name, std::string& base, double& fraction) {
    const auto at = name.rfind("-trim");
    if (at == std::string::npos || at + 5 >= name.size()) return false;
    std::string pct = name.substr(at + 5);
    std::replace(pct.begin(), pct.end(), '_', '.');
    char* end = nullptr;
    const double v = std::strtod(pct.c_str(), &end);
    if (end != pct.c_str() + pct.size() || !(v > 0 && v <= 100)) return false;
    base = name.substr(0, at);
    fraction = v / 100;
    return true;
  }

  /// Classifier `name`'s variants, one per trim choice.
  std::vector<std::string> trim_variants(const std::string& name) const {
    std::vector<std::string> out;
    for (double f : trim_choices) out.push_back(trim_variant(name, f));
    return out;
  }

  /// The variants the training folds choose among for classifier `name`
  /// (its trim, occupancy's settings or a height classifier's scales);
  /// empty when it has fixed settings.
  std::vector<std::string> chosen_variants(const std::string& name) const {
    if (trim_is_auto(name)) return trim_variants(name);
    if (name == "occupancy" && occupancy_is_auto()) return occupancy_variant_names();
    std::vector<std::string> heights;
    for (const auto& v : height_variants(name)) heights.push_back(height_variant_name(v));
    return heights;
  }

  /// UsageError naming --trim and the classifier when --trim NAME=F or
  /// NAME=auto names a classifier no method in `needed` uses: it was
  /// dropped without a word (`--methods bow --trim icp=0.5` ran plain bow).
  void check_trim_names(const std::vector<std::string>& needed) const {
    std::vector<std::string> named;
    for (const auto& [name, f] : trim_by_name) named.push_back(name);
    named.insert(named.end(), trim_auto_by_name.begin(), trim_auto_by_name.end());
    for (const auto& name : named)
      if (std::find(needed.begin(), needed.end(), name) == needed.end())
        throw UsageError("--trim names '" + name + "', which no method uses (they use: " + Options::join(needed, ", ") +
                         ")");
  }

  /// The classifiers that read option `name`, for an option only some of
  /// them read; empty for the others (the descriptor, the codebook, the
  /// contact threshold, --trim: checked by check_trim_names).
  static std::vector<std::string> option_readers(const std::string& name) {
    if (name == "label-scale") return {"iclap", "iclap_patch"};
    if (name == "descriptor-scale") return {"iclapn"};
    if (name == "tilt-scale") return {"height", "height_contact"};
    if (name == "contact-scale") return {"height_contact"};
    if (name == "patch-points" || name == "patch-voxel") return {"patch", "iclap_patch"};
    if (name.rfind("occupancy-", 0) == 0 || name.rfind("placement-", 0) == 0) return {"occupancy"};
    if (name == "transform" || name == "scalar" || name == "search" || name == "max-iterations" ||
        name == "relative-tolerance")
      return registration_classifiers();
    return {};
  }

  /// UsageError naming the first option given in `o` that only classifiers
  /// outside `needed` (the methods' classifiers) read: `--methods bow
  /// --label-scale 0.01` ran bow and dropped the scale without a word, so a
  /// typo in --methods passed for an experiment on the option.
  static void check_options_used(const Options& o, const std::vector<std::string>& needed) {
    for (const auto& name : value_options()) {
      if (!o.has(name)) continue;
      const auto readers = option_readers(name);
      if (readers.empty() || std::any_of(readers.begin(), readers.end(), [&](const std::string& r) {
            return std::find(needed.begin(), needed.end(), r) != needed.end();
          }))
        continue;
      std::string list = readers.front();
      for (std::size_t i = 1; i < readers.size(); ++i) list += (i + 1 == readers.size() ? " and " : ", ") + readers[i];
      throw UsageError("--" + name + " sets only " + list +
                       (readers.size() == 1 ? ", which no method uses" : ", none of which a method uses") +
                       " (they use: " + Options::join(needed, ", ") + ")");
    }
  }

  /// The classifiers to build for `needed` (the methods' own names): each
  /// one whose settings are chosen on the training folds becomes its
  /// variants.
  std::vector<std::string> expand_choices(const std::vector<std::string>& needed) const {
    std::vector<std::string> out;
    for (const auto& n : needed) {
      const auto variants = chosen_variants(n);
      if (variants.empty()) out.push_back(n);
      out.insert(out.end(), variants.begin(), variants.end());
    }
    return out;
  }
  /// `methods` with every classifier whose settings are chosen on the
  /// training folds replaced by its variants (Method::alternatives).
  std::vector<Method> expand_choices(std::vector<Method> methods, const std::vector<std::string>& needed) const {
    for (auto& m : methods)
      for (const auto& n : needed) {
        const auto variants = chosen_variants(n);
        if (!variants.empty()) m = with_variants(m, n, variants);
      }
    return methods;
  }

  /// The ICP settings of the registration classifiers among `names` as the
  /// reports print them: "at most 50 iterations, relative tolerance 1e-06;
  /// every pair" or "...; trimmed: patch 50%, iclap_patch 70%".
  std::string icp_summary(const std::vector<std::string>& names) const {
    char buf[160];
    std::snprintf(buf, sizeof buf, "at most %d iterations, relative tolerance %g; ", max_iterations, relative_tolerance);
    std::string out = buf, trimmed;
    std::string choices;
    for (double f : trim_choices) {
      std::snprintf(buf, sizeof buf, "%s%g%%", choices.empty() ? "" : "/", 100 * f);
      choices += buf;
    }
    for (const auto& n : names)
      if (trim_is_auto(n)) {
        trimmed += (trimmed.empty() ? "" : ", ") + n + " " + choices + " chosen on the training folds";
      } else if (is_registration_classifier(n) && trim_of(n) < 1) {
        std::snprintf(buf, sizeof buf, "%s%s %g%%", trimmed.empty() ? "" : ", ", n.c_str(), 100 * trim_of(n));
        trimmed += buf;
      }
    return out + (trimmed.empty() ? "every pair" : "trimmed: " + trimmed);
  }

  /// The option names `parse` reads (value options).
  static std::set<std::string> value_options() {
    return {"descriptor", "transform", "scalar", "search", "k", "label-scale", "descriptor-scale",
            "tilt-scale", "contact-scale", "max-iterations", "relative-tolerance", "trim", "trim-choices", "contact-threshold", "patch-points",
            "patch-voxel", "occupancy-voxel", "occupancy-truncation", "occupancy-free-radius", "occupancy-conflict", "occupancy-unknown",
            "occupancy-back",
            "placement-shift", "placement-yaw-deg", "placement-shift-step", "placement-yaw-step-deg"};
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
           "  --tilt-scale S          metres per radian of pad tilt for height and height_contact\n"
           "                          (default 0.01)\n"
           "  --contact-scale S       metres per metre of contact-patch extent for height_contact\n"
           "                          (default 1: a millimetre of patch size counts as a\n"
           "                          millimetre of height)\n"
           "                          (each scale option: > 0 and <= 1e6; --tilt-scale and\n"
           "                          --contact-scale take lists, e.g. 0.005,0.01: every value is a\n"
           "                          variant of height and every combination one of\n"
           "                          height_contact, chosen on the training folds like the\n"
           "                          weights; evaluate only)\n"
           "  --scalar float|double   ICP arithmetic (default float)\n"
           "  --search auto|kdtree|brute  closest-point search: auto (default) scans small\n"
           "                          references by brute force and builds kd-trees for the\n"
           "                          others; the answers are the same, only the time differs\n"
           "  --max-iterations N      ICP iteration cap (default 50)\n"
           "  --relative-tolerance R  ICP relative-change stop (default 1e-6; 0: none); with\n"
           "                          --scalar float at most 3.4e38, and not so small that it\n"
           "                          becomes 0\n"
           "  --trim F|NAME=F,...     trimmed ICP: the distance and the motion use the closest\n"
           "                          fraction F of the pairs, in (0, 1]; F alone for every\n"
           "                          registration classifier, NAME=F for one (e.g. patch=0.5);\n"
           "                          F = auto: chosen among --trim-choices on the training folds\n"
           "                          (evaluate only); default 1: all pairs, the paper's\n"
           "  --trim-choices LIST     fractions --trim auto chooses from (default 1,0.7,0.5,0.3;\n"
           "                          distinct in their percentages' first 6 digits, which name\n"
           "                          the variants: 0.5 is patch-trim50)\n"
           "  --contact-threshold P   a frame is a touch when a taxel exceeds P raw units\n"
           "  --patch-points N        contact points per test touch for patch, iclap_patch (default 8)\n"
           "  --patch-voxel V         reference voxel for patch, iclap_patch, metres, in [0, 1]\n"
           "                          (default 0.002): a reference's contact points averaged per\n"
           "                          V cube; 0 keeps every point\n"
           "  --occupancy-voxel M     lattice spacing of occupancy's distance fields, metres, in\n"
           "                          [0.00025, 0.1] (default 0.001; memory grows up to as 1/M^3)\n"
           "  --occupancy-truncation M  largest distance occupancy charges a contact point,\n"
           "                          metres, in (0, 1] and at most 64 voxels (default 0.003)\n"
           "  --occupancy-free-radius M  how close felt and unfelt evidence must be to\n"
           "                          contradict, metres, > 0 and <= the truncation (default 0.002)\n"
           "  --occupancy-conflict G  cost of a contradiction in units of the truncation squared,\n"
           "                          in [0, 1e6] (default 0.3; 0 ignores where the pad felt nothing)\n"
           "  --occupancy-unknown U   cost of a contact point where no training pad ever was, in\n"
           "                          units of the truncation squared, in [0, 1] (default 1: as a miss)\n"
           "  --occupancy-back M      the slab behind the pad, M metres deep, counts as free: the\n"
           "                          pad's body was there (default 0: not used; at most 16 free\n"
           "                          radii; 0.006 tried: see README)\n"
           "                          The five options above take lists (e.g. 0.002,0.003): every\n"
           "                          combination is a variant, chosen on the training folds like\n"
           "                          the weights (evaluate only; at most 256 combinations)\n"
           "  --placement-shift M     occupancy searches the object's placement within M metres,\n"
           "                          in [0, 1] (default 0.01: the simulator's re-placement)\n"
           "  --placement-yaw-deg D   ... and within +-D degrees about the vertical, in [0, 180]\n"
           "                          (default 10)\n"
           "  --placement-shift-step M  shift lattice spacing, metres, in (0, 1] (default 0.004)\n"
           "  --placement-yaw-step-deg D  turn step, degrees, in (0, 180] (default 5); the grid\n"
           "                          may hold at most 1e5 placements\n";
  }
  /// The largest value of a scale option (--label-scale, --descriptor-scale,
  /// --tilt-scale, --contact-scale), metres per unit: 1e6, a thousand
  /// kilometres per word step, radian or metre of patch, 1e6 to 1e9 times
  /// the defaults. A scale multiplies a quantity that a sane dataset keeps
  /// small: a word index below k <= 100000, a tilt <= pi rad, a contact-patch
  /// extent of a pad of centimetres, a descriptor value (Tactile-SIFT <= 1,
  /// raw pressures of a 12- to 16-bit sensor <= 65535). Times 1e6 they stay
  /// below about 1e11, four orders of magnitude inside the float ICP's
  /// largest_coordinate (1.8e15) and squarable in double by the height
  /// classifiers; beyond it (1e20 gave a label axis of 1e21 m) the
  /// registration failed deep inside a fold, naming an internal matrix.
  static constexpr double kLargestScale = 1e6;

  /// The value of scale option `name` (or `fallback`): in (0, kLargestScale],
  /// UsageError naming the option and the value otherwise.
  static double scale_option(const Options& o, const std::string& name, double fallback) {
    const double v = o.number(name, fallback);
    check_scale(name, v);
    return v;
  }
  /// The values of scale option `name` (comma-separated; `fallback` when
  /// absent), each checked as scale_option checks one; a value listed twice
  /// is an error.
  static std::vector<double> scale_list(const Options& o, const std::string& name, double fallback) {
    return number_list(o, name, fallback, [&](const std::string&, double v) { check_scale(name, v); });
  }
  /// UsageError naming scale option `name` and `v` unless v is in
  /// (0, kLargestScale].
  static void check_scale(const std::string& name, double v) {
    if (!(v > 0 && v <= kLargestScale))
      throw UsageError("--" + name + " must be > 0 and <= " + format_value(kLargestScale) + ", got " +
                       format_value(v) +
                       (v > 0 ? " (metres per unit: a larger scale overflows the squared distances)" : ""));
  }

  void parse(const Options& o) {
    descriptor = o.choice("descriptor", {"sift", "raw", "moments"}, descriptor);
    transform = o.choice("transform", {"full", "spatial", "planar", "translation"}, transform);
    scalar = o.choice("scalar", {"float", "double"}, scalar);
    search = o.choice("search", {"auto", "kdtree", "brute"}, search);
    k = static_cast<Index>(o.integer("k", k, 1, 100000));
    label_scale = scale_option(o, "label-scale", label_scale);
    descriptor_scale = scale_option(o, "descriptor-scale", descriptor_scale);
    tilt_scales = scale_list(o, "tilt-scale", tilt_scale);
    contact_scales = scale_list(o, "contact-scale", contact_scale);
    tilt_scale = tilt_scales.front();
    contact_scale = contact_scales.front();
    if (tilt_scales.size() * contact_scales.size() > kMaxHeightVariants)
      throw UsageError("--tilt-scale and --contact-scale list " + std::to_string(tilt_scales.size()) + " x " +
                       std::to_string(contact_scales.size()) + " = " +
                       std::to_string(tilt_scales.size() * contact_scales.size()) + " combinations; at most " +
                       std::to_string(kMaxHeightVariants) + " (each is a classifier of its own)");
    max_iterations = static_cast<int>(o.integer("max-iterations", max_iterations, 0, 100000));
    relative_tolerance = o.number("relative-tolerance", relative_tolerance, 0.0);
    if (o.has("trim")) parse_trim(o.string("trim"));
    if (o.has("trim-choices")) {
      trim_choices = bounded_list(o, "trim-choices", 1, 0, true, 1);
      // Every choice is a classifier variant named by its percentage to 6
      // digits (trim_variant: the names in the results), so two choices
      // closer than that would be one name.
      for (std::size_t i = 0; i < trim_choices.size(); ++i)
        for (std::size_t j = 0; j < i; ++j)
          if (trim_variant("", trim_choices[i]) == trim_variant("", trim_choices[j]))
            throw UsageError("--trim-choices: " + format_exact(trim_choices[j]) + " and " +
                             format_exact(trim_choices[i]) +
                             " are the same percentage to 6 digits, which names a choice's variant");
      if (!trim_auto && trim_auto_by_name.empty())
        throw UsageError("--trim-choices needs --trim auto or --trim NAME=auto");
    }
    contact_threshold = o.number("contact-threshold", contact_threshold, 0.0);
    patch_points = static_cast<Index>(o.integer("patch-points", patch_points, 1, 84 * 100));
    patch_voxel = o.number("patch-voxel", patch_voxel, 0.0, 1.0);
    // The float ICP holds it as a float: refused here, naming the option,
    // rather than as inf in the middle of the run or as 0 (no relative stop).
    if (scalar == "float" && o.has("relative-tolerance"))
      check_float_value("relative-tolerance", o.string("relative-tolerance"), relative_tolerance);
    // The float ICP weighs the label and descriptor axes by the scales as
    // floats: the classifier's own check (detail::axis_weight), made here so
    // that the error names the option before the run rather than in it.
    if (scalar == "float")
      for (const auto& [name, v] : {std::pair<const char*, double>{"label-scale", label_scale},
                                    std::pair<const char*, double>{"descriptor-scale", descriptor_scale}}) {
        try {
          iclap::detail::axis_weight<float>(v, name);
        } catch (const InvalidArgument& e) {
          throw UsageError(std::string("--") + name + " " + e.reason() + " (--scalar double)");
        }
      }
    parse_occupancy(o);
  }

  /// The value of option `name` (or `fallback`) within [min, max], `min`
  /// itself excluded when `open_min`; UsageError naming the option, the
  /// range (in `unit`, e.g. "metres"; empty for a pure number) and the
  /// value as given otherwise (so that 180.0000001 does not read as 180).
  static double bounded_option(const Options& o, const std::string& name, double fallback, double min, bool open_min,
                               double max, const std::string& unit = "") {
    const double v = o.number(name, fallback);
    check_bounds(name, o.has(name) ? o.string(name) : format_value(v), v, min, open_min, max, unit);
    return v;
  }
  /// UsageError naming option `name` and its value `given` unless `v` is
  /// within [min, max] (`min` excluded when `open_min`).
  static void check_bounds(const std::string& name, const std::string& given, double v, double min, bool open_min,
                           double max, const std::string& unit) {
    if (!((open_min ? v > min : v >= min) && v <= max))
      throw UsageError("--" + name + " must be " + (open_min ? "> " : ">= ") + format_value(min) + " and <= " +
                       format_value(max) + (unit.empty() ? "" : " " + unit) + ", got " + given);
  }

  /// Radians from degrees (180 gives pi exactly, which
  /// PlanarPlacements::max_yaw allows).
  static double radians(double degrees) { return degrees / 180 * 3.14159265358979323846; }
  static double degrees(double radians) { return radians / 3.14159265358979323846 * 180; }

  /// The occupancy options. Each is bounded on its own first, in the units
  /// the user gives. The voxel's lower bound, 0.25 mm (a fourteenth of the
  /// WTS taxel pitch), is where a finer lattice stops paying: the fields'
  /// interpolation error (at most 3/4 voxel^2, 0.05 mm^2 there) is already
  /// far below the truncation^2 (9 mm^2 by default), while their memory
  /// grows up to as 1/voxel^3 (`iclap evaluate` of the 4 objects of
  /// tests/fixtures/live: 10 MB at 1 mm, 43 MB at 0.25 mm, 335 MB at 0.1 mm,
  /// so gigabytes for 20 objects of 85 frames per exploration) and
  /// the box a field can index shrinks as voxel^3 (0.8 m across at 0.25 mm,
  /// 0.3 m at 0.1 mm: TruncatedDistanceField::kMaxIndexBlocks), which would
  /// refuse a large object in the middle of a run. The other upper bounds
  /// (1 m, a conflict of 1e6 truncations squared) lie far beyond use and
  /// keep the sums finite. The combinations (truncation at most 64 voxels,
  /// free radius at most the truncation, at most 1e5 placements) are the
  /// library's: OccupancyClassifier::validate decides them here, before any
  /// run, and its error is given back naming the options and their values.
  void parse_occupancy(const Options& o) {
    occupancy_voxel = bounded_option(o, "occupancy-voxel", occupancy_voxel, 2.5e-4, false, 0.1, "metres");
    const auto truncations = bounded_list(o, "occupancy-truncation", occupancy_truncation, 0, true, 1, "metres");
    const auto free_radii = bounded_list(o, "occupancy-free-radius", occupancy_free_radius, 0, true, 1, "metres");
    const auto conflicts = bounded_list(o, "occupancy-conflict", occupancy_conflict, 0, false, 1e6);
    const auto unknowns = bounded_list(o, "occupancy-unknown", occupancy_unknown, 0, false, 1);
    const auto backs = bounded_list(o, "occupancy-back", occupancy_back, 0, false, 1, "metres");
    placement_shift = bounded_option(o, "placement-shift", placement_shift, 0, false, 1, "metres");
    placement_shift_step = bounded_option(o, "placement-shift-step", placement_shift_step, 0, true, 1, "metres");
    if (o.has("placement-yaw-deg"))
      placement_yaw = radians(bounded_option(o, "placement-yaw-deg", 0, 0, false, 180, "degrees"));
    if (o.has("placement-yaw-step-deg"))
      placement_yaw_step = radians(bounded_option(o, "placement-yaw-step-deg", 0, 0, true, 180, "degrees"));

    const std::size_t combinations =
        truncations.size() * free_radii.size() * conflicts.size() * unknowns.size() * backs.size();
    if (combinations > kMaxOccupancyVariants)
      throw UsageError("--occupancy-truncation, -free-radius, -conflict, -unknown and -back list " +
                       std::to_string(truncations.size()) + " x " + std::to_string(free_radii.size()) + " x " +
                       std::to_string(conflicts.size()) + " x " + std::to_string(unknowns.size()) + " x " +
                       std::to_string(backs.size()) + " = " + std::to_string(combinations) + " combinations; at most " +
                       std::to_string(kMaxOccupancyVariants) + " (each is a classifier of its own)");
    occupancy_variants.clear();
    for (double t : truncations)
      for (double r : free_radii)
        for (double c : conflicts)
          for (double u : unknowns)
            for (double b : backs) occupancy_variants.push_back({t, r, c, u, b});
    for (const auto& v : occupancy_variants) check_occupancy(o, v);
    const OccupancyVariant& first = occupancy_variants.front();
    occupancy_truncation = first.truncation;
    occupancy_free_radius = first.free_radius;
    occupancy_conflict = first.conflict;
    occupancy_unknown = first.unknown;
    occupancy_back = first.back;
    if (occupancy_variants.size() == 1) occupancy_variants.clear();
  }

  /// The values of option `name` (comma-separated; `fallback` when absent),
  /// each bounded as bounded_option bounds one; a value listed twice is an
  /// error.
  static std::vector<double> bounded_list(const Options& o, const std::string& name, double fallback, double min,
                                          bool open_min, double max, const std::string& unit = "") {
    return number_list(o, name, fallback, [&](const std::string& item, double v) {
      check_bounds(name, item, v, min, open_min, max, unit);
    });
  }
  /// The values of option `name` (comma-separated; `fallback` when absent),
  /// each parsed as a number and given to `check(item as written, value)`,
  /// which throws for a value out of range; a value listed twice is an
  /// error. What bounded_list and scale_list share.
  template <typename Check>
  static std::vector<double> number_list(const Options& o, const std::string& name, double fallback, Check&& check) {
    if (!o.has(name)) return {fallback};
    std::vector<double> out;
    for (const auto& item : Options::split(o.string(name), ',')) {
      const double v = Options::parse_number(item, "--" + name, -std::numeric_limits<double>::infinity(),
                                             std::numeric_limits<double>::infinity());
      check(item, v);
      if (std::find(out.begin(), out.end(), v) != out.end()) throw UsageError("--" + name + " lists " + item + " twice");
      out.push_back(v);
    }
    return out;
  }

  /// OccupancyClassifier::validate on the occupancy settings with `v`'s;
  /// its error given back naming the options and their values.
  void check_occupancy(const Options& o, const OccupancyVariant& v) const {
    OccupancyClassifier probe;
    configure_occupancy(probe, &v);
    try {
      probe.validate();
    } catch (const InvalidArgument& e) {
      // The option (and its value as given, or the value of its list) behind
      // each setting the library names; the first is the one at fault, the
      // others what it is measured against.
      auto given = [&](const std::string& name, double value) {
        const bool as_given = o.has(name) && o.string(name).find(',') == std::string::npos;
        return "--" + name + " " + (as_given ? o.string(name) : format_value(value));
      };
      const std::string voxel = given("occupancy-voxel", occupancy_voxel);
      const std::string truncation = given("occupancy-truncation", v.truncation);
      const std::string free_radius = given("occupancy-free-radius", v.free_radius);
      const std::string conflict = given("occupancy-conflict", v.conflict);
      const std::string unknown = given("occupancy-unknown", v.unknown);
      const std::string back = given("occupancy-back", v.back);
      const std::string grid = given("placement-shift", placement_shift) + ", " +
                               given("placement-shift-step", placement_shift_step) + ", " +
                               given("placement-yaw-deg", degrees(placement_yaw)) + " and " +
                               given("placement-yaw-step-deg", degrees(placement_yaw_step));
      const std::string& a = e.argument();
      if (a == "voxel") throw UsageError(voxel + ": " + e.reason());
      if (a == "truncation") throw UsageError(truncation + " with " + voxel + ": " + e.reason());
      if (a == "free_radius") throw UsageError(free_radius + " with " + truncation + ": " + e.reason());
      if (a == "conflict_weight") throw UsageError(conflict + ": " + e.reason());
      if (a == "unknown_cost") throw UsageError(unknown + ": " + e.reason());
      if (a == "back_depth") throw UsageError(back + " with " + free_radius + ": " + e.reason());
      if (a == "placements") throw UsageError(grid + ": " + e.reason());
      // A setting the bounds above already keep in range (e.g.
      // "placements.max_yaw", in radians): every option, and the library's
      // own words.
      throw UsageError(voxel + ", " + truncation + ", " + free_radius + ", " + conflict + ", " + unknown + ", " + back +
                       ", " + grid + ": " + e.what());
    }
  }

  /// A default OccupancyClassifier, whose settings the occupancy options
  /// start from.
  static const OccupancyClassifier& occupancy_defaults() {
    static const OccupancyClassifier defaults;
    return defaults;
  }

  /// Sets `c` as the occupancy options ask, with the settings of `variant`
  /// if given (the classifier's settings only; its name is left as it is).
  void configure_occupancy(OccupancyClassifier& c, const OccupancyVariant* variant = nullptr) const {
    c.voxel = occupancy_voxel;
    c.truncation = variant ? variant->truncation : occupancy_truncation;
    c.free_radius = variant ? variant->free_radius : occupancy_free_radius;
    c.conflict_weight = variant ? variant->conflict : occupancy_conflict;
    c.unknown_cost = variant ? variant->unknown : occupancy_unknown;
    c.back_depth = variant ? variant->back : occupancy_back;
    c.placements.max_shift = placement_shift;
    c.placements.shift_step = placement_shift_step;
    c.placements.max_yaw = placement_yaw;
    c.placements.yaw_step = placement_yaw_step;
  }

  /// The occupancy settings as the reports print them: "voxel 0.001 m,
  /// truncation 0.003 m, free radius 0.002 m, conflict 0.3, unknown 1;
  /// placements within 0.01 m and 10 deg in steps of 0.004 m and 5 deg
  /// (105)", the last the number of placements searched; a setting chosen
  /// on the training folds reads "truncation 0.002 or 0.003 m", a slab
  /// behind the pad adds ", back 0.006 m" (nothing without one), and the
  /// line ends with the number of variants. The options must be valid
  /// (parse checked them).
  std::string occupancy_summary() const {
    OccupancyClassifier c;
    configure_occupancy(c);
    auto values = [&](double first, double OccupancyVariant::*member) {
      std::vector<double> seen{first};
      for (const auto& v : occupancy_variants)
        if (std::find(seen.begin(), seen.end(), v.*member) == seen.end()) seen.push_back(v.*member);
      std::string out;
      for (std::size_t i = 0; i < seen.size(); ++i) out += (i ? " or " : "") + format_value(seen[i]);
      return out;
    };
    std::string out = "voxel " + format_value(occupancy_voxel) + " m, truncation " +
                      values(occupancy_truncation, &OccupancyVariant::truncation) + " m, free radius " +
                      values(occupancy_free_radius, &OccupancyVariant::free_radius) + " m, conflict " +
                      values(occupancy_conflict, &OccupancyVariant::conflict) + ", unknown " +
                      values(occupancy_unknown, &OccupancyVariant::unknown);
    // The slab behind the pad, when one is used (the default line stays as
    // it was before the option).
    const bool any_back =
        occupancy_back > 0 || std::any_of(occupancy_variants.begin(), occupancy_variants.end(),
                                          [](const OccupancyVariant& v) { return v.back > 0; });
    if (any_back) out += ", back " + values(occupancy_back, &OccupancyVariant::back) + " m";
    char buf[160];
    std::snprintf(buf, sizeof buf, "; placements within %g m and %g deg in steps of %g m and %g deg (%ld)",
                  placement_shift, degrees(placement_yaw), placement_shift_step, degrees(placement_yaw_step),
                  static_cast<long>(c.placements.grid().cols()));
    out += buf;
    if (occupancy_is_auto())
      out += "; " + std::to_string(occupancy_variants.size()) + " variants chosen on the training folds";
    return out;
  }

  /// "--trim": "F" for every registration classifier, "NAME=F" for one;
  /// comma-separated, each name at most once.
  void parse_trim(const std::string& value) {
    bool all_given = false;
    std::set<std::string> named;
    // Each item gives the fraction of every classifier, or of one name, at
    // most once (as a number or as auto).
    auto once = [&](const std::string& name) {
      if (name.empty()) {
        if (all_given) throw UsageError("--trim gives the fraction of every classifier twice");
        all_given = true;
      } else if (!named.insert(name).second) {
        throw UsageError("--trim names '" + name + "' twice");
      }
    };
    for (const auto& item : Options::split(value, ',')) {
      const auto eq = item.find('=');
      const std::string name = eq == std::string::npos ? "" : item.substr(0, eq);
      const std::string text = eq == std::string::npos ? item : item.substr(eq + 1);
      if (!name.empty() && !is_registration_classifier(name))
        throw UsageError("--trim " + item + ": '" + name + "' is not a registration classifier (" +
                         Options::join(registration_classifiers(), ", ") + ")");
      if (text == "auto") {
        once(name);
        if (name.empty()) trim_auto = true;
        else trim_auto_by_name.insert(name);
        continue;
      }
      const double f = Options::parse_number(text, "--trim " + item, -std::numeric_limits<double>::infinity(),
                                             std::numeric_limits<double>::infinity());
      if (!(f > 0 && f <= 1)) throw UsageError("--trim " + item + ": the fraction must be in (0, 1]");
      once(name);
      if (name.empty()) trim = f;
      else trim_by_name.emplace(name, f);
    }
  }
};

/// The classifiers named in `names` ("bow", "height", "height_contact", "occupancy", "icp", "iclap",
/// "iclapn", "patch", "iclap_patch"),
/// configured by `options`. Throws UsageError for an unknown name.
std::vector<std::unique_ptr<Classifier>> make_classifiers(const RecognitionOptions& options,
                                                          const std::vector<std::string>& names);

/// Every classifier name the commands know, in the order they are built.
inline const std::vector<std::string>& known_classifiers() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = {"bow", "height", "height_contact", "occupancy"};
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

/// Does classifier `name` read every touch's pad normal (height,
/// height_contact), rather than only the contact points of oriented frames?
inline bool is_height_classifier(const std::string& name) { return name == "height" || name == "height_contact"; }

/// The height classifier `label` names, configured by `o`: "height" or
/// "height_contact" with the options' (first) scales, or a variant of one
/// (RecognitionOptions::height_variant_name) with its scales and its name as
/// its label; null for any other label.
inline std::unique_ptr<HeightClassifier> make_height_classifier(const RecognitionOptions& o, const std::string& label) {
  auto c = std::make_unique<HeightClassifier>();
  if (is_height_classifier(label)) {
    c->tilt_scale = o.tilt_scale;
    if (label == "height_contact") c->contact_scale = o.contact_scale;
  } else if (const auto v = o.find_height_variant(label)) {
    c->tilt_scale = v->tilt;
    if (v->base == "height_contact") c->contact_scale = v->contact;
    c->label = label;
  } else {
    return nullptr;
  }
  return c;
}

/// The classifiers among `needed` that read the pad orientation: the height
/// classifiers (the pad normals, and height_contact the contact points), the
/// patch classifiers (the contact points) and occupancy (the contact and the
/// free points).
inline std::vector<std::string> orientation_classifiers(const std::vector<std::string>& needed) {
  std::vector<std::string> out;
  for (const auto& c : needed)
    if (is_height_classifier(c) || c == "patch" || c == "iclap_patch" || c == "occupancy") out.push_back(c);
  return out;
}

/// Throws InvalidArgument naming `origin` when a classifier among `needed`
/// needs the pad orientation that the touches of `table` lack. The height
/// and occupancy classifiers need it on every contact frame, the patch
/// classifiers on some, or on every one with `every_frame` (live sessions
/// carry it on every touch or none).
inline void check_orientation(const std::vector<std::string>& needed, const TouchTable& table,
                              const std::string& origin, bool every_frame = false) {
  for (const auto& c : orientation_classifiers(needed)) {
    const bool every = every_frame || is_height_classifier(c) || c == "occupancy";
    if (!(every ? table.touches.has_normals() : table.touches.has_contacts()))
      throw InvalidArgument(origin, "the " + c + " classifier needs the pad orientation (columns qw, qx, qy, qz) of " +
                                        (every ? "every contact frame" : "the contact frames"));
  }
}

/// The largest position coordinate (metres) the ICP of `scalar` ("float" or
/// "double") takes: the library's largest_coordinate, which the classifiers
/// enforce too (this check comes first so that its message names the row).
inline double largest_position(const std::string& scalar) {
  return scalar == "double" ? largest_coordinate<double>() : largest_coordinate<float>();
}

/// Empty when the classifiers among `needed` take `position`, otherwise why
/// not (a coordinate beyond largest_position: a unit error, or 1e300 m that
/// a float cloud would hold as inf). The ICP of `ro.scalar` bounds it when a
/// registration classifier is among them; the others compute in double.
inline std::string position_problem(const Eigen::Vector3d& position, const RecognitionOptions& ro,
                                    const std::vector<std::string>& needed) {
  const bool icp = std::any_of(needed.begin(), needed.end(), is_registration_classifier);
  const std::string scalar = icp ? ro.scalar : "double";
  const double limit = largest_position(scalar);
  for (Index r = 0; r < 3; ++r)
    if (!(std::abs(position(r)) <= limit))
      return "position coordinate " + format_value(position(r)) + " m is beyond the " +
             (icp ? scalar + " ICP's" : std::string("classifiers'")) + " range (|v| <= " + format_value(limit) +
             " m); check the unit of x, y, z" + (scalar == "float" ? ", or use --scalar double" : "");
  return {};
}

/// Does a classifier among `needed` read the touches' positions (every one
/// but bow)?
inline bool reads_positions(const std::vector<std::string>& needed) {
  return !std::all_of(needed.begin(), needed.end(), [](const std::string& c) { return c == "bow"; });
}

/// Throws InvalidArgument naming `origin` when reads_positions(needed) and
/// a touch's position has a position_problem: the message names the touch
/// by object, exploration and frame, the row of the dataset. (The reader
/// accepts any finite number; 1e300 m became inf in a float cloud and failed
/// deep inside a fold naming an internal matrix.) Contact points lie within
/// the pad's half-diagonal of their touch's position, far inside the margin.
///
/// With occupancy among `needed`, the contact and free points of every
/// touch must also lie within the range of its distance fields
/// (TruncatedDistanceField::kMaxCoordinateVoxels voxels of
/// --occupancy-voxel: 1e5 m at 1 mm), which the fields would otherwise
/// refuse in the middle of the run. With a patch classifier, the points a
/// reference averages per --patch-voxel cube must lie within
/// ContactEmbedding::kMaxCells voxels of the origin (a UsageError naming
/// --patch-voxel otherwise).
inline void check_positions(const std::vector<std::string>& needed, const TouchTable& table,
                            const RecognitionOptions& ro, const std::string& origin) {
  if (!reads_positions(needed)) return;
  auto touch = [&](Index i) {
    const auto t = static_cast<std::size_t>(i);
    return "object '" + table.objects[static_cast<std::size_t>(table.object[t])] + "' exploration " +
           std::to_string(table.exploration[t]) + " frame " + std::to_string(table.frame[t]) + ": ";
  };
  for (Index i = 0; i < table.size(); ++i) {
    const std::string problem = position_problem(table.touches.positions.col(i), ro, needed);
    if (!problem.empty()) throw InvalidArgument(origin, touch(i) + problem);
  }
  // The patch classifiers average a reference's points per --patch-voxel
  // cube (ContactEmbedding::cell_of, which refuses a point too many voxels
  // from the origin in the middle of the run, naming its
  // "reference_voxel"): the points it indexes are a touch's contact points,
  // or its position when it has none.
  const bool patch = std::find(needed.begin(), needed.end(), "patch") != needed.end() ||
                     std::find(needed.begin(), needed.end(), "iclap_patch") != needed.end();
  if (patch && ro.patch_voxel > 0) {
    const TouchSet& s = table.touches;
    auto check_cell = [&](Index i, double coordinate) {
      try {
        (void)ContactEmbedding<false>::cell_of(coordinate, ro.patch_voxel);
      } catch (const InvalidArgument& e) {
        throw UsageError("--patch-voxel " + format_value(ro.patch_voxel) + ": " + origin + ": " + touch(i) + e.reason());
      }
    };
    for (Index i = 0; i < table.size(); ++i) {
      const Index m = s.contacts_of(i);
      for (Index r = 0; r < 3; ++r) {
        if (m == 0) check_cell(i, s.positions(r, i));
        for (Index j = 0; j < m; ++j)
          check_cell(i, s.contact_points(r, s.contact_offsets[static_cast<std::size_t>(i)] + j));
      }
    }
  }
  if (std::find(needed.begin(), needed.end(), "occupancy") == needed.end()) return;
  const double limit = TruncatedDistanceField::kMaxCoordinateVoxels * ro.occupancy_voxel;
  const TouchSet& s = table.touches;
  auto check = [&](const Eigen::Matrix3Xd& points, const std::vector<Index>& offsets, const char* kind) {
    for (Index i = 0; i + 1 < static_cast<Index>(offsets.size()); ++i)
      for (Index c = offsets[static_cast<std::size_t>(i)]; c < offsets[static_cast<std::size_t>(i) + 1]; ++c)
        for (Index r = 0; r < 3; ++r)
          if (!(std::abs(points(r, c)) <= limit))
            throw InvalidArgument(origin, touch(i) + "a " + kind + " point's coordinate " + format_value(points(r, c)) +
                                              " m is beyond the occupancy classifier's range (|v| <= " +
                                              format_value(limit) + " m at --occupancy-voxel " +
                                              format_value(ro.occupancy_voxel) + "); check the unit of x, y, z");
  };
  check(s.contact_points, s.contact_offsets, "contact");
  check(s.free_points, s.free_offsets, "free");
}

/// Runs `f` and returns what it returns, with the library's argument names
/// in its InvalidArgument errors turned into what the user gave: "table"
/// (what the dataset's explorations do not allow, e.g. too few of an object
/// for cross validation) becomes `dataset`, the file (or origin) the table
/// was made from, as does "dataset" (e.g. no contact frame), and
/// "settings.k" (a codebook larger than the training touches) becomes
/// "--k". Any other InvalidArgument (a matrix the touches of the dataset
/// were turned into, e.g. "points" of a reference cloud or
/// "objects[0].contact_points") is about the data too: it is named by
/// `dataset`, with the library's argument kept after it as a detail
/// ("FILE: objects[0].contact_points: non-finite value ..."). The options
/// that could also be at fault (the scales) are bounded up front.
/// Other exceptions pass through.
template <typename F>
auto naming_inputs(const std::string& dataset, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const InvalidArgument& e) {
    if (e.argument() == dataset) throw;  // named already (nested calls)
    if (e.argument() == "table" || e.argument() == "dataset") throw InvalidArgument(dataset, e.reason());
    if (e.argument() == "settings.k") throw InvalidArgument("--k", e.reason() + " of the training touches from " + dataset);
    throw InvalidArgument(dataset, e.what());
  }
}

/// The touches of `dataset` described by the chosen descriptor. Throws
/// InvalidArgument naming "dataset" (naming_inputs turns it into the file)
/// for an implausible taxel pitch (taxel_pitch_of).
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
