// SPDX-License-Identifier: MIT
// The recognition options of the example programs (examples/iclap/
// recognition_setup.hpp): the defaults the usage text gives, the bounds of
// each option (a bad value refused naming the option and the value as
// given), --trim, and lists of the height classifiers' and occupancy's
// settings, which become variants that the training folds choose among
// (each a classifier with its own settings and name).

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "recognition_setup.hpp"
#include "../support/errors.hpp"

namespace {

using iclap::cli::Args;
using iclap::cli::Options;
using iclap::OccupancyClassifier;
using iclap::cli::RecognitionOptions;

RecognitionOptions parsed(const Args& args) {
  const Options o(args, RecognitionOptions::value_options());
  RecognitionOptions ro;
  ro.parse(o);
  return ro;
}

std::string usage_error(const Args& args) {
  return iclap::test::what_of<iclap::cli::UsageError>([&] { parsed(args); });
}

// Four touches of two objects: heights, tilts and contact patches that
// differ, so that every scale moves the distances.
iclap::TouchSet touches(double z0, double spread) {
  iclap::TouchSet s;
  s.positions.resize(3, 2);
  s.positions << 0.01, 0.02, 0.0, 0.01, z0, z0 + 0.004;
  s.normals.resize(3, 2);
  const double a = 0.3 + spread;
  s.normals << 0, std::sin(a), 0, 0, -1, -std::cos(a);
  s.contact_points.resize(3, 6);
  s.contact_points << 0, 0.003, 0.006, 0, 0.002 * spread + 0.001, 0.01,  //
      0, 0, 0.001, 0, 0.002, 0.001,                                     //
      z0, z0, z0, z0 + 0.004, z0 + 0.004, z0 + 0.004;
  s.contact_offsets = {0, 3, 6};
  return s;
}

}  // namespace

TEST_CASE("without lists the height classifiers have fixed scales and no variants") {
  const RecognitionOptions ro = parsed({"--tilt-scale", "0.02", "--contact-scale", "0.5"});
  CHECK_FALSE(ro.height_is_auto());
  CHECK(ro.chosen_variants("height").empty());
  CHECK(ro.chosen_variants("height_contact").empty());
  CHECK(ro.tilt_scale == 0.02);
  CHECK(ro.contact_scale == 0.5);
  auto h = iclap::cli::make_height_classifier(ro, "height_contact");
  REQUIRE(h);
  CHECK(h->tilt_scale == 0.02);
  CHECK(h->contact_scale == 0.5);
  CHECK(h->name() == "height_contact");
  auto plain = iclap::cli::make_height_classifier(ro, "height");
  REQUIRE(plain);
  CHECK(plain->contact_scale == 0);
  CHECK(plain->name() == "height");
  CHECK(ro.height_summary("height_contact") == "tilt scale 0.02 m/rad, contact scale 0.5 m/m");
  CHECK_FALSE(iclap::cli::make_height_classifier(ro, "occupancy"));
  CHECK_FALSE(iclap::cli::make_height_classifier(ro, "height_contact-s0_02-c0_5"));
}

TEST_CASE("lists of scales make one variant per value (height) and per combination (height_contact)") {
  const RecognitionOptions ro = parsed({"--tilt-scale", "0.005,0.02", "--contact-scale", "0.5,1e6"});
  CHECK(ro.height_is_auto());
  CHECK(ro.chosen_variants("height") == std::vector<std::string>{"height-s0_005", "height-s0_02"});
  const std::vector<std::string> contact{"height_contact-s0_005-c0_5", "height_contact-s0_005-c1e06",
                                         "height_contact-s0_02-c0_5", "height_contact-s0_02-c1e06"};
  CHECK(ro.chosen_variants("height_contact") == contact);
  CHECK(ro.chosen_variants("occupancy").empty());
  CHECK(ro.height_summary("height") == "tilt scale 0.005 or 0.02 m/rad; 2 variants chosen on the training folds");
  CHECK(ro.height_summary("height_contact") ==
        "tilt scale 0.005 or 0.02 m/rad, contact scale 0.5 or 1e+06 m/m; 4 variants chosen on the training folds");
  // The base names keep the first values.
  CHECK(ro.tilt_scale == 0.005);
  CHECK(ro.contact_scale == 0.5);

  // Each variant is a HeightClassifier with its scales and its name, whose
  // distances are those of a classifier given the same scales directly.
  const std::vector<iclap::TouchSet> objects{touches(0.01, 0.0), touches(0.013, 1.0)};
  const iclap::TouchSet test = touches(0.011, 0.5);
  const double tilts[] = {0.005, 0.005, 0.02, 0.02}, contacts[] = {0.5, 1e6, 0.5, 1e6};
  std::vector<Eigen::VectorXd> seen;
  for (std::size_t i = 0; i < contact.size(); ++i) {
    CAPTURE(contact[i]);
    auto v = iclap::cli::make_height_classifier(ro, contact[i]);
    REQUIRE(v);
    CHECK(v->name() == contact[i]);
    CHECK(v->tilt_scale == tilts[i]);
    CHECK(v->contact_scale == contacts[i]);
    iclap::HeightClassifier direct;
    direct.tilt_scale = tilts[i];
    direct.contact_scale = contacts[i];
    v->fit(objects, 0);
    direct.fit(objects, 0);
    Eigen::VectorXd a(2), b(2);
    v->distances(test, a);
    direct.distances(test, b);
    CHECK(a == b);
    seen.push_back(a);
  }
  // ... and the scales matter here: no two variants give the same distances.
  for (std::size_t i = 0; i < seen.size(); ++i)
    for (std::size_t j = i + 1; j < seen.size(); ++j) CHECK(seen[i] != seen[j]);
  auto t = iclap::cli::make_height_classifier(ro, "height-s0_02");
  REQUIRE(t);
  CHECK(t->tilt_scale == 0.02);
  CHECK(t->contact_scale == 0);
  // A name of a value not listed is no variant.
  CHECK_FALSE(iclap::cli::make_height_classifier(ro, "height-s0_01"));
}

TEST_CASE("a fused method becomes one candidate per variant of each listed classifier") {
  const RecognitionOptions ro = parsed({"--contact-scale", "0.5,1,2", "--occupancy-truncation", "0.002,0.003"});
  const std::vector<iclap::Method> methods{iclap::parse_method("occupancy+height_contact")};
  const auto expanded = ro.expand_choices(methods, {"height_contact", "occupancy"});
  REQUIRE(expanded.size() == 1);
  CHECK(expanded[0].candidates().size() == 6);
  const auto built = ro.expand_choices(std::vector<std::string>{"height", "height_contact", "occupancy"});
  // height has one tilt scale: no variants; height_contact three, occupancy two.
  CHECK(built.size() == 1 + 3 + 2);
  CHECK(std::count(built.begin(), built.end(), "height") == 1);
  CHECK(std::count(built.begin(), built.end(), "height_contact-s0_01-c2") == 1);
}

TEST_CASE("bad lists of scales are refused, naming the option and the value") {
  CHECK(usage_error({"--tilt-scale", "0.01,0"}) == "--tilt-scale must be > 0 and <= 1e+06, got 0");
  CHECK(usage_error({"--contact-scale", "1,2e6"}) ==
        "--contact-scale must be > 0 and <= 1e+06, got 2e+06 (metres per unit: a larger scale overflows the squared "
        "distances)");
  CHECK(usage_error({"--contact-scale", "1,1.0"}) == "--contact-scale lists 1.0 twice");
  CHECK(usage_error({"--tilt-scale", "0.01,abc"}) == "--tilt-scale: 'abc' is not a number");
  std::string many;
  for (int i = 1; i <= 17; ++i) many += (i > 1 ? "," : "") + std::to_string(i);
  CHECK(usage_error({"--tilt-scale", many, "--contact-scale", many}) ==
        "--tilt-scale and --contact-scale list 17 x 17 = 289 combinations; at most 256 (each is a classifier of its "
        "own)");
}

TEST_CASE("without options the settings are the defaults the usage text gives") {
  const RecognitionOptions ro = parsed({});
  CHECK(ro.descriptor == "sift");
  CHECK(ro.transform == "planar");
  CHECK(ro.scalar == "float");
  CHECK(ro.search == "auto");
  CHECK(ro.k == 50);
  CHECK(ro.label_scale == 0.001);
  CHECK(ro.descriptor_scale == 0.01);
  CHECK(ro.tilt_scales == std::vector<double>{0.01});
  CHECK(ro.contact_scales == std::vector<double>{1});
  CHECK(ro.max_iterations == 50);
  CHECK(ro.relative_tolerance == 1e-6);
  CHECK(ro.trim == 1);
  CHECK_FALSE(ro.trim_auto);
  CHECK(ro.trim_choices == std::vector<double>{1, 0.7, 0.5, 0.3});
  CHECK(ro.patch_points == 8);
  CHECK(ro.patch_voxel == 0.002);
  CHECK(ro.occupancy_voxel == 0.001);
  CHECK(ro.occupancy_truncation == 0.003);
  CHECK(ro.occupancy_free_radius == 0.002);
  CHECK(ro.occupancy_conflict == 0.3);
  CHECK(ro.occupancy_unknown == 1);
  CHECK(ro.occupancy_back == 0);
  CHECK(ro.occupancy_variants.empty());
  CHECK(ro.placement_shift == 0.01);
  CHECK(ro.placement_shift_step == 0.004);
  CHECK(ro.placement_yaw == doctest::Approx(10 * std::acos(-1.0) / 180));
  CHECK(ro.placement_yaw_step == doctest::Approx(5 * std::acos(-1.0) / 180));
  // The occupancy settings are the library's defaults (the values above
  // are the usage text's: a change of the library's shows there).
  OccupancyClassifier configured, library;
  ro.configure_occupancy(configured);
  CHECK(configured.voxel == library.voxel);
  CHECK(configured.truncation == library.truncation);
  CHECK(configured.free_radius == library.free_radius);
  CHECK(configured.conflict_weight == library.conflict_weight);
  CHECK(configured.unknown_cost == library.unknown_cost);
  CHECK(configured.back_depth == library.back_depth);
  CHECK(configured.placements.max_shift == library.placements.max_shift);
  CHECK(configured.placements.shift_step == library.placements.shift_step);
  CHECK(configured.placements.max_yaw == library.placements.max_yaw);
  CHECK(configured.placements.yaw_step == library.placements.yaw_step);
}

TEST_CASE("options at their bounds are accepted; beyond them refused, naming the option and the value as given") {
  const RecognitionOptions ro = parsed({"--k", "1", "--relative-tolerance", "0", "--placement-yaw-deg", "180",
                                        "--placement-shift", "0", "--occupancy-voxel", "0.00025"});
  CHECK(ro.k == 1);
  CHECK(ro.relative_tolerance == 0);
  CHECK(ro.placement_yaw == std::acos(-1.0));
  CHECK(ro.placement_shift == 0);
  CHECK(ro.occupancy_voxel == 0.00025);
  CHECK(parsed({"--k", "100000"}).k == 100000);
  CHECK(usage_error({"--k", "0"}) == "--k: 0 is outside [1, 100000]");
  CHECK(usage_error({"--relative-tolerance", "-1"}) == "--relative-tolerance: -1 is below 0");
  CHECK(usage_error({"--contact-threshold", "-1"}) == "--contact-threshold: -1 is below 0");
  CHECK(parsed({"--contact-threshold", "0"}).contact_threshold == 0);
  CHECK(usage_error({"--patch-points", "0"}) == "--patch-points: 0 is outside [1, 8400]");
  CHECK(parsed({"--patch-points", "1"}).patch_points == 1);
  // The value as given, so that a value just beyond the bound does not read
  // as the bound.
  CHECK(usage_error({"--placement-yaw-deg", "180.0000001"}) ==
        "--placement-yaw-deg must be >= 0 and <= 180 degrees, got 180.0000001");
  CHECK(usage_error({"--placement-shift-step", "0"}) == "--placement-shift-step must be > 0 and <= 1 metres, got 0");
  CHECK(usage_error({"--occupancy-unknown", "0.5,1.50"}) == "--occupancy-unknown must be >= 0 and <= 1, got 1.50");
  CHECK(usage_error({"--occupancy-conflict", "0.3,"}) == "--occupancy-conflict: '' is not a number");
}

TEST_CASE("--trim: one fraction in (0, 1] for every registration classifier or per name, each given once") {
  const RecognitionOptions ro = parsed({"--trim", "patch=0.5,icp=auto", "--trim-choices", "0.5,1"});
  CHECK(ro.trim_of("patch") == 0.5);
  CHECK(ro.trim_of("iclap") == 1);
  CHECK(ro.trim_is_auto("icp"));
  CHECK_FALSE(ro.trim_is_auto("patch"));
  CHECK(ro.trim_choices == std::vector<double>{0.5, 1});
  CHECK(parsed({"--trim", "1"}).trim == 1);
  CHECK(usage_error({"--trim", "0"}) == "--trim 0: the fraction must be in (0, 1]");
  CHECK(usage_error({"--trim", "patch=0"}) == "--trim patch=0: the fraction must be in (0, 1]");
  CHECK(usage_error({"--trim", "patch=abc"}) == "--trim patch=abc: 'abc' is not a number");
  CHECK(usage_error({"--trim", "patch=0.5,patch=0.7"}) == "--trim names 'patch' twice");
  CHECK(usage_error({"--trim", "0.5,0.7"}) == "--trim gives the fraction of every classifier twice");
  CHECK(usage_error({"--trim", "bow=0.5"}) ==
        "--trim bow=0.5: 'bow' is not a registration classifier (icp, iclap, iclapn, patch, iclap_patch)");
  CHECK(usage_error({"--trim", "auto", "--trim-choices", "1,0"}) == "--trim-choices must be > 0 and <= 1, got 0");
  CHECK(usage_error({"--trim-choices", "0.5"}) == "--trim-choices needs --trim auto or --trim NAME=auto");
}

TEST_CASE("lists of settings: up to 256 combinations are variants; a combination the library refuses names its options") {
  const RecognitionOptions occupancy = parsed({"--occupancy-truncation", "0.002,0.003,0.004,0.005",
                                               "--occupancy-free-radius", "0.0005,0.001,0.0015,0.002",
                                               "--occupancy-conflict", "0,0.1,0.3,1", "--occupancy-unknown",
                                               "0,0.25,0.5,0.75"});
  CHECK(occupancy.occupancy_variants.size() == 256);
  std::string sixteen;
  for (int i = 1; i <= 16; ++i) sixteen += (i > 1 ? "," : "") + std::to_string(i);
  CHECK(parsed({"--tilt-scale", sixteen, "--contact-scale", sixteen}).chosen_variants("height_contact").size() == 256);
  // The free radius beyond the truncation: both options with their values,
  // as given or, from a list, the value of the combination refused.
  CHECK(usage_error({"--occupancy-truncation", "0.002", "--occupancy-free-radius", "0.0025"}).rfind(
            "--occupancy-free-radius 0.0025 with --occupancy-truncation 0.002: must be > 0 and at most truncation", 0) ==
        0);
  CHECK(usage_error({"--occupancy-truncation", "0.003,0.001"})
            .rfind("--occupancy-free-radius 0.002 with --occupancy-truncation 0.001: must be > 0 and at most truncation",
                   0) == 0);
}

// Found by the session-50 audit: --trim-choices that differ only past the
// 6th significant digit were accepted as distinct, but trim_variant() names
// a variant with %g of the percentage, so both became "icp-trim33_3333":
// `iclap evaluate FILE --trim auto --trim-choices 0.3333331,0.3333332` then
// failed after reading FILE, naming the dataset ("FILE: classifiers: two
// classifiers are named 'icp-trim33_3333'"), not the option; and a
// variant's fraction, read back from its name by trim_of(), was the rounded
// 0.333333, not the fraction given. Either the choices are refused naming
// --trim-choices, or every choice is a variant of its own with the fraction
// given; and a choice the name rounds is applied as given.
TEST_CASE("--trim-choices: every choice is a variant of its own, with the fraction given") {
  const Args args = {"--trim", "auto", "--trim-choices", "0.3333331,0.3333332"};
  const std::string refused = usage_error(args);
  if (refused != "(no error)") {
    CHECK(refused.rfind("--trim-choices", 0) == 0);
  } else {
    const RecognitionOptions ro = parsed(args);
    const std::vector<std::string> variants = ro.trim_variants("icp");
    REQUIRE(variants.size() == 2);
    CHECK(variants[0] != variants[1]);
    CHECK(ro.trim_of(variants[0]) == 0.3333331);
    CHECK(ro.trim_of(variants[1]) == 0.3333332);
  }
  // One such choice: its variant's name rounds it (names stay as in the
  // results files), the fraction applied does not.
  const RecognitionOptions one = parsed({"--trim", "auto", "--trim-choices", "0.3333331,0.5"});
  const std::vector<std::string> variants = one.trim_variants("icp");
  REQUIRE(variants.size() == 2);
  CHECK(variants[0] == "icp-trim33_3333");
  CHECK(variants[1] == "icp-trim50");
  CHECK(one.trim_of(variants[0]) == 0.3333331);
  CHECK(one.trim_of(variants[1]) == 0.5);
}

// Found by the session-50 audit: the float ICP (the default --scalar) holds
// --relative-tolerance as a float, so 1e300 became inf (refused in the
// middle of the run, naming the dataset) and 1e-50 became 0 (no relative
// stop at all). Both are refused naming the option; 0 (no relative stop) and
// a float subnormal (a value still) pass, and so does either in double.
TEST_CASE("--relative-tolerance: a value that float would make inf or 0 is refused with --scalar float") {
  CHECK(usage_error({"--relative-tolerance", "1e300"}).rfind("--relative-tolerance: 1e300 is beyond the range of --scalar float", 0) == 0);
  CHECK(usage_error({"--relative-tolerance", "1e-50"}).rfind("--relative-tolerance: 1e-50 is too small for --scalar float", 0) == 0);
  CHECK(parsed({"--relative-tolerance", "0"}).relative_tolerance == 0);
  CHECK(parsed({"--relative-tolerance", "1e-40"}).relative_tolerance == 1e-40);
  CHECK(parsed({"--relative-tolerance", "3e38"}).relative_tolerance == 3e38);
  CHECK(parsed({"--scalar", "double", "--relative-tolerance", "1e300"}).relative_tolerance == 1e300);
  CHECK(parsed({"--scalar", "double", "--relative-tolerance", "1e-50"}).relative_tolerance == 1e-50);
}

// An option only some classifiers read, given with methods that use none of
// them, was dropped without a word: `--methods bow --label-scale 0.01` ran
// bow as if the scale had not been given.
TEST_CASE("an option only classifiers outside the methods read is refused, naming the option and its readers") {
  auto error = [](const Args& args, const std::vector<std::string>& needed) {
    const Options o(args, RecognitionOptions::value_options());
    return iclap::test::what_of<iclap::cli::UsageError>(
        [&] { RecognitionOptions::check_options_used(o, needed); });
  };
  auto accepted = [](const Args& args, const std::vector<std::string>& needed) {
    const Options o(args, RecognitionOptions::value_options());
    RecognitionOptions::check_options_used(o, needed);
    return true;
  };
  CHECK(error({"--label-scale", "0.01"}, {"bow", "icp"}) ==
        "--label-scale sets only iclap and iclap_patch, none of which a method uses (they use: bow, icp)");
  CHECK(error({"--descriptor-scale", "0.1"}, {"iclap"}) ==
        "--descriptor-scale sets only iclapn, which no method uses (they use: iclap)");
  CHECK(error({"--contact-scale", "0.5"}, {"height"}) ==
        "--contact-scale sets only height_contact, which no method uses (they use: height)");
  CHECK(error({"--patch-voxel", "0.002"}, {"icp"}) ==
        "--patch-voxel sets only patch and iclap_patch, none of which a method uses (they use: icp)");
  CHECK(error({"--placement-shift", "0.02"}, {"height_contact"}) ==
        "--placement-shift sets only occupancy, which no method uses (they use: height_contact)");
  CHECK(error({"--occupancy-back", "0.006"}, {"bow"}) ==
        "--occupancy-back sets only occupancy, which no method uses (they use: bow)");
  CHECK(error({"--scalar", "double"}, {"bow", "height", "occupancy"}) ==
        "--scalar sets only icp, iclap, iclapn, patch and iclap_patch, none of which a method uses (they use: bow, "
        "height, occupancy)");
  CHECK(error({"--max-iterations", "5"}, {"occupancy"}).rfind("--max-iterations sets only icp, ", 0) == 0);
  // Any one reader among the methods is enough; options every classifier
  // or the codebook reads are never refused.
  CHECK(accepted({"--label-scale", "0.01"}, {"bow", "iclap_patch"}));
  CHECK(accepted({"--tilt-scale", "0.02", "--contact-scale", "0.5"}, {"height_contact"}));
  CHECK(accepted({"--transform", "full", "--search", "brute", "--relative-tolerance", "0"}, {"iclapn"}));
  CHECK(accepted({"--occupancy-voxel", "0.002", "--placement-yaw-deg", "5"}, {"occupancy"}));
  CHECK(accepted({"--k", "10", "--descriptor", "raw", "--contact-threshold", "3"}, {"icp"}));
}
