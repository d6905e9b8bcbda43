// SPDX-License-Identifier: MIT
#pragma once

// Builds a PoseSource from a command-line spec such as `fixed:0,0,0.1`.
// Includes OpenHaptics only when ICLAP_HAVE_OPENHAPTICS is defined.

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/data/csv_reader.hpp"
#include "iclap/rig/pose_source.hpp"
#ifdef ICLAP_HAVE_OPENHAPTICS
#include "iclap/rig/openhaptics_pose.hpp"
#endif

namespace iclap::rig {

/// Whether this build can read the Omni arm (OpenHaptics found at configure time).
inline constexpr bool kHaveOpenHaptics =
#ifdef ICLAP_HAVE_OPENHAPTICS
    true;
#else
    false;
#endif

/// The accepted pose specs, for usage texts, one per line, each line
/// starting with `indent`.
inline std::string pose_spec_help(const std::string& indent = "  ") {
  std::string out;
  for (const char* line : {"fixed:X,Y,Z              the same position (metres) for every frame",
                           "fixed:X,Y,Z,QW,QX,QY,QZ  ... with a unit quaternion orientation (norm 1 +- 0.001)",
                           "replay:FILE.csv          the poses of a dataset CSV in file order; the run ends with them",
                           "omni[:DEVICE]            the Phantom Omni / Touch arm via OpenHaptics (if built with it)"})
    out += (out.empty() ? "" : "\n") + indent + line;
  return out;
}

/// Parses a pose spec (see pose_spec_help()). A fixed orientation is
/// normalised when its norm is within kQuaternionNormTolerance of 1 (as the
/// dataset reader's are: 0.7071,0.7071,0,0 is accepted). Throws
/// InvalidArgument naming `argument` and the spec for a malformed spec or a
/// quaternion further from unit norm; the dataset reader's ParseError or
/// IoError for a bad replay file; TransportError if the arm cannot start.
inline std::unique_ptr<PoseSource> make_pose_source(const std::string& spec, const std::string& argument = "pose") {
  const auto colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const std::string rest = colon == std::string::npos ? std::string() : spec.substr(colon + 1);
  if (kind == "fixed") {
    std::vector<double> v;
    std::size_t start = 0;
    for (;;) {
      const std::size_t comma = rest.find(',', start);
      const std::string item = rest.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      // from_chars, not strtod: the same in every locale (a program that
      // set a decimal comma read "0.1" as 0 and stopped), no hex.
      double x = 0;
      if (!detail::parse_double(detail::trim_ascii(item), x) || !std::isfinite(x))
        throw InvalidArgument(argument, quote_text(spec, 80) + ": " + quote_text(item, 40) + " is not a finite number");
      v.push_back(x);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (v.size() != 3 && v.size() != 7)
      throw InvalidArgument(argument, quote_text(spec, 80) + " needs 3 numbers (x,y,z) or 7 (x,y,z,qw,qx,qy,qz), got " +
                                          std::to_string(v.size()));
    Pose p;
    p.position = Eigen::Vector3d(v[0], v[1], v[2]);
    if (v.size() == 7) {
      // As the dataset reader: a quaternion typed with 4 digits is unit
      // only within kQuaternionNormTolerance; FixedPoseSource wants 1e-6.
      const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
      const std::string problem = quaternion_problem(q);
      if (!problem.empty())
        throw InvalidArgument(argument, quote_text(spec, 80) + ": the orientation quaternion " + problem);
      p.orientation = q.normalized();
    }
    try {
      return std::make_unique<FixedPoseSource>(p);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(argument, quote_text(spec, 80) + ": " + e.reason());
    }
  }
  if (kind == "replay") {
    if (rest.empty()) throw InvalidArgument(argument, quote_text(spec, 80) + " needs a file: replay:FILE.csv");
    const Dataset d = read_dataset_csv(rest);
    return std::make_unique<ReplayPoseSource>(ReplayPoseSource::from_dataset(d, rest));
  }
  if (kind == "omni") {
#ifdef ICLAP_HAVE_OPENHAPTICS
    return std::make_unique<OpenHapticsPoseSource>(rest);
#else
    throw InvalidArgument(argument, quote_text(spec, 80) +
                                        ": this build has no OpenHaptics support (install OpenHaptics and "
                                        "reconfigure; CMake looks for HD/hd.h)");
#endif
  }
  throw InvalidArgument(argument, quote_text(spec, 80) + " is not a pose source; use one of:\n" + pose_spec_help());
}

}  // namespace iclap::rig
