// SPDX-License-Identifier: MIT
//
// `iclap register MODEL TEST`: N-D ICP of two point files.

#include <cmath>
#include <cstdio>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "cli.hpp"
#include "iclap/core/check.hpp"
#include "iclap/io/point_file.hpp"
#include "iclap/registration/registration.hpp"

namespace {

using iclap::cli::Options;
using iclap::cli::UsageError;

const char* const kUsage =
    "usage: iclap register MODEL TEST [options]\n"
    "\n"
    "Registers TEST onto MODEL with the N-D (labeled) ICP and prints T_model_test\n"
    "(maps TEST coordinates into the MODEL frame), the RMSE, the iterations and the\n"
    "stop reason. Point files: one point per line, numbers separated by whitespace\n"
    "or commas, an optional header line (a first line without any number in it),\n"
    "'#' comments; the dimension is the column count and must be equal in both\n"
    "files (e.g. x,y,z,label for iCLAP). A coordinate (times its --weights) must be\n"
    "within 1.8e15 with --scalar float, 1.3e150 in double.\n"
    "\n"
    "options:\n"
    "  --transform full|spatial|planar|translation   motion model (default full:\n"
    "                       all coordinates, the paper's iCLAP; spatial: x,y,z only;\n"
    "                       planar: rotation about z + x,y shift; translation: x,y,z shift)\n"
    "  --scalar float|double   arithmetic precision (default double)\n"
    "  --search auto|kdtree|brute  closest-point search: auto (default) scans clouds of\n"
    "                       up to 2048 coordinates by brute force and builds a kd-tree\n"
    "                       for larger ones; the result is the same, only the time differs\n"
    "  --max-iterations N      iteration cap (default 50)\n"
    "  --tolerance E           stop when the error E <= E (default 0: exact fit only; a\n"
    "                       negative E: never)\n"
    "  --relative-tolerance R  stop when the relative change of E < R (default 1e-6; 0:\n"
    "                       never; with --scalar float at most 3.4e38 and not so small\n"
    "                       that it becomes 0)\n"
    "  --weights w1,w2,...     per-axis scale of the metric, one per column (default 1)\n"
    "  --max-distance D        drop pairs farther apart than D (default: none)\n"
    "  --trim F                keep the closest fraction F of the pairs (default 1)\n"
    "  --align-centroids       start with the test centroid on the model centroid\n"
    "  --json                  print one JSON object instead of text";

struct Request {
  Eigen::MatrixXd model, test;
  std::string model_path, test_path;
  std::vector<std::size_t> model_lines, test_lines;  // line of each point in its file
  std::string transform, scalar, search;
  int max_iterations = 50;
  double tolerance = 0, relative_tolerance = 1e-6, max_distance = 0, trim = 1;
  bool has_max_distance = false, align_centroids = false, json = false;
  std::vector<double> weights;
};

void print_number(double v, bool is_float) { std::printf(is_float ? "%.9g" : "%.17g", v); }

template <typename Matrix>
void print_json_matrix(const Matrix& m, bool is_float) {
  std::printf("[");
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    std::printf("%s[", r ? "," : "");
    for (Eigen::Index c = 0; c < m.cols(); ++c) {
      if (c) std::printf(",");
      print_number(static_cast<double>(m(r, c)), is_float);
    }
    std::printf("]");
  }
  std::printf("]");
}

template <typename Scalar, int Dim, typename Model>
int run_typed(const Request& q) {
  using namespace iclap;
  const Eigen::Index d = q.model.rows();
  Point<Scalar, Dim> w = Point<Scalar, Dim>::Ones(d);
  for (Eigen::Index k = 0; k < d && !q.weights.empty(); ++k) w(k) = static_cast<Scalar>(q.weights[static_cast<std::size_t>(k)]);
  typename AdaptiveSearch<Scalar, Dim>::Settings search;
  cli::apply_search_choice(q.search, search);
  const ReferenceCloud<Scalar, Dim> reference(q.model.cast<Scalar>(), w, search);
  Icp<Scalar, Dim, Model> icp;
  icp.termination.max_iterations = q.max_iterations;
  icp.termination.absolute_tolerance = static_cast<Scalar>(q.tolerance);
  icp.termination.relative_tolerance = static_cast<Scalar>(q.relative_tolerance);
  if (q.has_max_distance) icp.rejection.max_distance = static_cast<Scalar>(q.max_distance);
  icp.rejection.trim_fraction = static_cast<Scalar>(q.trim);
  icp.centroid_alignment = q.align_centroids;
  const Cloud<Scalar, Dim> test = q.test.cast<Scalar>();
  const auto r = icp.align(reference, test);

  const bool is_float = std::is_same_v<Scalar, float>;
  const auto H = r.T_model_test.matrix();
  if (q.json) {
    std::printf("{\"dimension\":%ld,\"model_points\":%ld,\"test_points\":%ld,\"scalar\":\"%s\","
                "\"transform_model\":\"%s\",\"search\":\"%s\",\"T_model_test\":",
                static_cast<long>(d), static_cast<long>(q.model.cols()), static_cast<long>(q.test.cols()),
                q.scalar.c_str(), q.transform.c_str(), q.search.c_str());
    print_json_matrix(H, is_float);
    std::printf(",\"R\":");
    print_json_matrix(r.T_model_test.R, is_float);
    std::printf(",\"t\":");
    print_json_matrix(r.T_model_test.t.transpose(), is_float);
    std::printf(",\"error\":");
    if (r.pairs > 0) print_number(static_cast<double>(r.error), is_float); else std::printf("null");
    std::printf(",\"rmse\":");
    if (r.pairs > 0) print_number(static_cast<double>(r.rmse), is_float); else std::printf("null");
    std::printf(",\"iterations\":%d,\"converged\":%s,\"stop_reason\":\"%s\",\"pairs\":%ld,\"degenerate\":%s}\n",
                r.iterations, r.converged ? "true" : "false", to_string(r.stop_reason), static_cast<long>(r.pairs),
                r.degenerate ? "true" : "false");
  } else {
    std::printf("model: %s (%ld points)\ntest:  %s (%ld points)\ndimension: %ld, transform: %s, scalar: %s, search: %s\n",
                q.model_path.c_str(), static_cast<long>(q.model.cols()), q.test_path.c_str(),
                static_cast<long>(q.test.cols()), static_cast<long>(d), q.transform.c_str(), q.scalar.c_str(),
                q.search.c_str());
    std::printf("T_model_test (homogeneous, maps test into the model frame):\n");
    for (Eigen::Index i = 0; i < H.rows(); ++i) {
      std::printf(" ");
      for (Eigen::Index j = 0; j < H.cols(); ++j) std::printf(" % .9f", static_cast<double>(H(i, j)));
      std::printf("\n");
    }
    // No pair (all beyond --max-distance): no error to print; the library's
    // infinity would read as a number (the JSON gives null).
    if (r.pairs > 0)
      std::printf("rmse: %.9g\nerror (sum of squared distances): %.9g\n", static_cast<double>(r.rmse),
                  static_cast<double>(r.error));
    else
      std::printf("rmse: none (no pairs)\nerror (sum of squared distances): none (no pairs)\n");
    std::printf("pairs: %ld\niterations: %d\n", static_cast<long>(r.pairs), r.iterations);
    std::printf("converged: %s\nstop reason: %s\n", r.converged ? "yes" : "no", to_string(r.stop_reason));
    if (r.degenerate)
      std::printf("degenerate: yes (the matched points do not determine every moved direction)\n");
    else
      std::printf("degenerate: no\n");
  }
  return iclap::cli::kExitOk;
}

/// Refuses, naming the file, the line and the value, a coordinate whose
/// weighted magnitude is beyond what a registration in `Scalar` takes
/// (largest_coordinate: 1.8e15 in float, 1.3e150 in double, where squared
/// distances would overflow; in float this also covers a finite double
/// such as 1e39 that the cast would turn into inf). Checked before the
/// registration so the message names the file, not an internal argument.
template <typename Scalar>
void check_point_range(const Eigen::MatrixXd& points, const std::vector<std::size_t>& lines, const std::string& path,
                       const std::vector<double>& weights) {
  const auto [k, j] = iclap::find_beyond_range<Scalar>(points, weights.empty() ? nullptr : weights.data());
  if (k < 0) return;
  const double v = points(k, j);
  const double w = weights.empty() ? 1.0 : weights[static_cast<std::size_t>(k)];
  std::string why = "value " + iclap::format_value(v) + " in column " + std::to_string(k + 1);
  if (w != 1.0) why += " (times its weight " + iclap::format_value(w) + ")";
  why += std::string(" is beyond what a registration in ") + (std::is_same_v<Scalar, float> ? "float" : "double") +
         " takes (|value| <= " + iclap::format_value(iclap::largest_coordinate<Scalar>()) +
         "): squared distances would overflow; rescale the points" + (w != 1.0 ? " or the weights" : "") +
         (std::is_same_v<Scalar, float> ? " or use --scalar double" : "");
  throw iclap::ParseError(path, lines[static_cast<std::size_t>(j)], why);
}

template <typename Scalar, typename Model>
int with_dim(const Request& q) {
  // 3-D (the kinesthetic case) gets a compile-time dimension; any other
  // dimension, 4-D iCLAP points included, runs with Eigen::Dynamic.
  if (q.model.rows() == 3) return run_typed<Scalar, 3, Model>(q);
  return run_typed<Scalar, Eigen::Dynamic, Model>(q);
}

template <typename Scalar>
int with_model(const Request& q) {
  if (q.transform == "spatial") return with_dim<Scalar, iclap::SpatialRigid>(q);
  if (q.transform == "planar") return with_dim<Scalar, iclap::Planar>(q);
  if (q.transform == "translation") return with_dim<Scalar, iclap::Translation>(q);
  return with_dim<Scalar, iclap::FullRigid>(q);
}

int run_register(const iclap::cli::Args& args) {
  const Options opt(args,
                    {"transform", "scalar", "search", "max-iterations", "tolerance", "relative-tolerance", "weights",
                     "max-distance", "trim"},
                    {"json", "align-centroids"});
  opt.expect_positional(2, 2, "MODEL and TEST point files");
  Request q;
  q.model_path = opt.positional()[0];
  q.test_path = opt.positional()[1];
  q.transform = opt.choice("transform", {"full", "spatial", "planar", "translation"}, "full");
  q.scalar = opt.choice("scalar", {"float", "double"}, "double");
  q.search = opt.choice("search", {"auto", "kdtree", "brute"}, "auto");
  q.max_iterations = static_cast<int>(opt.integer("max-iterations", 50, 0, 1000000));
  q.tolerance = opt.number("tolerance", 0.0);
  q.relative_tolerance = opt.number("relative-tolerance", 1e-6, 0.0);
  // A float ICP holds it as a float: too small a value would become 0 (no
  // relative stop), too large one inf.
  if (q.scalar == "float" && opt.has("relative-tolerance"))
    iclap::cli::check_float_value("relative-tolerance", opt.string("relative-tolerance"), q.relative_tolerance);
  q.has_max_distance = opt.has("max-distance");
  q.max_distance = opt.number("max-distance", 0.0);
  if (q.has_max_distance && !(q.max_distance > 0)) throw UsageError("--max-distance must be > 0");
  q.trim = opt.number("trim", 1.0);
  if (!(q.trim > 0 && q.trim <= 1)) throw UsageError("--trim must be in (0, 1]");
  q.weights = opt.numbers("weights");
  q.align_centroids = opt.flag("align-centroids");
  q.json = opt.flag("json");

  q.model = iclap::read_point_file(q.model_path, &q.model_lines);
  q.test = iclap::read_point_file(q.test_path, &q.test_lines);
  if (q.test.rows() != q.model.rows())
    throw UsageError("TEST has " + std::to_string(q.test.rows()) + " columns, MODEL has " +
                     std::to_string(q.model.rows()) + ": the dimensions must be equal");
  if (!q.weights.empty()) {
    if (static_cast<Eigen::Index>(q.weights.size()) != q.model.rows())
      throw UsageError("--weights has " + std::to_string(q.weights.size()) + " values, the points have " +
                       std::to_string(q.model.rows()) + " coordinates");
    for (double w : q.weights)
      if (!(w > 0)) throw UsageError("--weights: every weight must be > 0, got " + iclap::format_exact(w));
  }
  const bool is_float = q.scalar == "float";
  for (const auto* f : {&q.model, &q.test}) {
    const bool model = f == &q.model;
    const auto& lines = model ? q.model_lines : q.test_lines;
    const auto& path = model ? q.model_path : q.test_path;
    if (is_float) check_point_range<float>(*f, lines, path, q.weights);
    else check_point_range<double>(*f, lines, path, q.weights);
  }
  try {
    return is_float ? with_model<float>(q) : with_model<double>(q);
  } catch (const iclap::InvalidArgument& e) {
    // The library names its arguments: "points" is the MODEL cloud (e.g.
    // its spread from the centroid is too large even though every value is
    // in range), "test" the TEST cloud, "weights" the option.
    if (e.argument() == "points") throw iclap::InvalidArgument(q.model_path, e.reason());
    if (e.argument() == "weights") throw UsageError("--weights: " + e.reason());
    // "test" is the TEST cloud. (Its "point I has no finite squared
    // distance" cannot happen here: check_point_range keeps every weighted
    // coordinate, and so every difference, far below what squares to
    // infinity.)
    if (e.argument() == "test") throw iclap::InvalidArgument(q.test_path, e.reason());
    // Settings the options gave, refused in the chosen scalar type (e.g. a
    // float --max-distance whose square underflows, or a --tolerance that
    // becomes +inf as a float): named by their option.
    static const std::pair<const char*, const char*> kOptions[] = {
        {"rejection.max_distance", "--max-distance"},
        {"rejection.trim_fraction", "--trim"},
        {"termination.absolute_tolerance", "--tolerance"},
        {"termination.relative_tolerance", "--relative-tolerance"},
        {"termination.max_iterations", "--max-iterations"}};
    for (const auto& [setting, option] : kOptions)
      if (e.argument() == setting) throw UsageError(std::string(option) + ": " + e.reason());
    throw;
  }
}

}  // namespace

ICLAP_COMMAND("register", "ICP-register two point files (N-D, labeled or not)", kUsage, run_register);
