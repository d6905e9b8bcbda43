// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <string>
#include <system_error>
#include <vector>

#include "iclap/core/check.hpp"
#include "iclap/core/error.hpp"
#include "iclap/core/progress.hpp"
#include "iclap/data/dataset.hpp"
#include "iclap/recognition/touch_set.hpp"
#include "iclap/tactile/descriptor.hpp"
#include "iclap/tactile/tactile_image.hpp"

namespace iclap {

/// Every touch (contact frame) of a dataset, described once: positions and
/// descriptor features in `touches` (words are per codebook, so left empty),
/// with the object, exploration and frame each touch came from.
struct TouchTable {
  /// Object names in order of first appearance in the dataset.
  std::vector<std::string> objects;
  TouchSet touches;
  std::vector<Index> object;               ///< object index of each touch
  std::vector<std::int64_t> exploration;   ///< exploration id of each touch
  std::vector<std::int64_t> frame;         ///< frame index of each touch
  /// Frames of the dataset that were not contacts (kept in the file, dropped here).
  std::size_t idle_frames = 0;

  Index size() const noexcept { return touches.size(); }

  /// Throws DimensionMismatch naming `argument`.object / .exploration /
  /// .frame when one of them does not hold one entry per touch, and
  /// InvalidArgument naming `argument`.object for an object index outside
  /// [0, objects.size()) (a table built by hand; make_touch_table's are
  /// consistent), and what TouchSet::validate throws for the touches
  /// (naming `argument`.touches: parts that disagree in length, such as
  /// fewer feature columns than touches, or a value that is not finite).
  void validate(const std::string& argument = "table") const {
    if (size() > 0) touches.validate(argument + ".touches");
    check_dimension(static_cast<Index>(object.size()), size(), argument + ".object (touches)");
    check_dimension(static_cast<Index>(exploration.size()), size(), argument + ".exploration (touches)");
    check_dimension(static_cast<Index>(frame.size()), size(), argument + ".frame (touches)");
    for (std::size_t i = 0; i < object.size(); ++i)
      if (object[i] < 0 || object[i] >= static_cast<Index>(objects.size()))
        throw InvalidArgument(argument + ".object", "touch " + std::to_string(i) + " has object index " +
                                                        std::to_string(object[i]) + ", outside [0, " +
                                                        std::to_string(objects.size()) + ") (the object names)");
  }

  /// The touches at `rows` (indices into this table, in that order) as a
  /// table of their own, e.g. to drop explorations or objects' touches. The
  /// object list is kept whole, so object indices stay valid; idle_frames is
  /// 0. Throws InvalidArgument naming "rows" for an index outside [0, size()),
  /// and what validate("table") throws.
  TouchTable select(const std::vector<Index>& rows) const {
    validate("table");
    for (std::size_t k = 0; k < rows.size(); ++k)
      if (rows[k] < 0 || rows[k] >= size())
        throw InvalidArgument("rows", "index " + std::to_string(rows[k]) + " at position " + std::to_string(k) +
                                          " is outside the table's " + std::to_string(size()) + " touches");
    TouchTable out;
    out.objects = objects;
    out.touches = select_touches(touches, rows);
    for (const Index i : rows) {
      const auto r = static_cast<std::size_t>(i);
      out.object.push_back(object[r]);
      out.exploration.push_back(exploration[r]);
      out.frame.push_back(frame[r]);
    }
    return out;
  }

  /// Sorted exploration ids of object `o`.
  std::vector<std::int64_t> explorations_of(Index o) const {
    std::vector<std::int64_t> ids;
    for (std::size_t i = 0; i < object.size(); ++i)
      if (object[i] == o) ids.push_back(exploration[i]);
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    return ids;
  }
};

/// The largest taxel pitch a dataset comment may give, metres: 1 m, some
/// hundred times a real pad's (the WTS 0614-34A's is 3.4 mm).
constexpr double kLargestTaxelPitch = 1.0;

namespace detail {
/// Whether `pitch` is a taxel pitch: in (0, kLargestTaxelPitch] metres.
inline bool pitch_in_range(double pitch) noexcept {
  return std::isfinite(pitch) && pitch > 0 && pitch <= kLargestTaxelPitch;
}
}  // namespace detail

/// The taxel pitch of a dataset, metres: the `pitch_m=` value of a comment
/// such as "sensor: WTS 0614-34A rows=14 cols=6 pitch_m=0.0034" (what the
/// recorder and the simulator write), otherwise `fallback` (the WTS 0614-34A's
/// 3.4 mm). Throws InvalidArgument naming "dataset" and quoting the comment
/// when its `pitch_m=` is not a number or is outside (0, kLargestTaxelPitch]:
/// a pitch of 1e308 m placed contact points at infinity, and a pitch of 0 or
/// "abc" was silently replaced by the fallback.
inline double taxel_pitch_of(const Dataset& dataset, double fallback = 0.0034) {
  for (const auto& c : dataset.comments) {
    const auto at = c.find("pitch_m=");
    if (at == std::string::npos) continue;
    // from_chars, not strtod: the same in every locale (strtod read
    // "0.0034" as 0 where the decimal separator is a comma).
    double v = 0;
    const auto read = std::from_chars(c.data() + at + 8, c.data() + c.size(), v);
    if (read.ec == std::errc() && detail::pitch_in_range(v)) return v;
    throw InvalidArgument("dataset", "the pitch_m= of comment " + quote_text(c, 120) +
                                         (read.ec == std::errc::invalid_argument ? std::string(" is not a number")
                                          : read.ec == std::errc::result_out_of_range
                                              ? std::string(" is beyond the range of a double")
                                              : " gives a taxel pitch of " + format_value(v) + " m, outside (0, " +
                                                    format_value(kLargestTaxelPitch) +
                                                    "] m (a pad's taxels are millimetres apart)"));
  }
  return fallback;
}

namespace detail {

/// Throws InvalidArgument naming `orientation_argument` (a string, or a
/// callable returning one, called only then) when `frame` has an
/// orientation that is not a unit quaternion (as the dataset reader): a
/// zero quaternion turned like the identity.
template <typename Name>
void check_frame_orientation(const Frame& frame, const Name& orientation_argument) {
  if (!frame.orientation) return;
  const std::string problem = quaternion_problem(*frame.orientation);
  if (!problem.empty()) throw InvalidArgument(argument_name(orientation_argument), problem);
}

/// Throws InvalidArgument naming `threshold_argument` unless `threshold` is
/// finite and >= 0 (as make_touch_table), "pitch" unless `pitch` is in
/// (0, kLargestTaxelPitch] metres (as taxel_pitch_of), and
/// "frame.orientation" as check_frame_orientation: a NaN threshold made
/// every taxel free and a pitch of 0 put every taxel at the pad centre.
inline void check_taxel_placement(const Frame& frame, double threshold, const char* threshold_argument,
                                  double pitch) {
  check_non_negative(threshold, threshold_argument);
  if (!pitch_in_range(pitch))
    throw InvalidArgument("pitch", "must be in (0, " + format_value(kLargestTaxelPitch) +
                                       "] m (a pad's taxels are millimetres apart), got " + format_value(pitch));
  check_frame_orientation(frame, "frame.orientation");
}

/// The world positions of the taxels of `frame` that were pressed (pressure
/// above `threshold`; `pressed`) or not (`!pressed`), appended to `out`:
/// see append_contact_points, which checks what this takes as checked
/// (check_taxel_placement). Returns the number appended.
inline Index place_taxels(const Frame& frame, double threshold, double pitch, bool pressed,
                          std::vector<Eigen::Vector3d>& out) {
  if (!frame.orientation) return 0;
  const Eigen::Matrix3d R = frame.orientation->normalized().toRotationMatrix();
  const double r0 = 0.5 * static_cast<double>(frame.pressures.rows() - 1);
  const double c0 = 0.5 * static_cast<double>(frame.pressures.cols() - 1);
  Index n = 0;
  for (Index r = 0; r < frame.pressures.rows(); ++r)
    for (Index c = 0; c < frame.pressures.cols(); ++c)
      if ((frame.pressures(r, c) > threshold) == pressed) {
        out.push_back(frame.position +
                      R * Eigen::Vector3d((static_cast<double>(r) - r0) * pitch, (static_cast<double>(c) - c0) * pitch, 0.0));
        ++n;
      }
  return n;
}

}  // namespace detail

/// The world positions of the pressed taxels of `frame` (pressure above
/// `threshold`), appended to `out`: taxel (r, c) sits at ((r - (rows-1)/2)
/// pitch, (c - (cols-1)/2) pitch, 0) in the pad frame, whose x axis runs
/// along the rows, y along the columns and z into the object; the frame's
/// orientation (qw..qz) turns the pad frame into the world. Nothing is
/// appended for a frame without orientation. Returns the number appended.
/// Throws InvalidArgument naming "threshold" unless it is finite and >= 0,
/// "pitch" unless it is in (0, kLargestTaxelPitch] metres, and
/// "frame.orientation" for an orientation that is not a unit quaternion.
inline Index append_contact_points(const Frame& frame, double threshold, double pitch, std::vector<Eigen::Vector3d>& out) {
  detail::check_taxel_placement(frame, threshold, "threshold", pitch);
  return detail::place_taxels(frame, threshold, pitch, true, out);
}

/// The world positions of the other taxels of `frame` (pressure at or below
/// `threshold`: where the pad was and the object was not), placed as by
/// append_contact_points and appended to `out`. Nothing is appended for a
/// frame without orientation. Returns the number appended. Throws as
/// append_contact_points.
inline Index append_free_points(const Frame& frame, double threshold, double pitch, std::vector<Eigen::Vector3d>& out) {
  detail::check_taxel_placement(frame, threshold, "threshold", pitch);
  return detail::place_taxels(frame, threshold, pitch, false, out);
}

/// Builds the touch table of `dataset`: keeps the frames whose largest taxel
/// is above `contact_threshold` (raw units) and runs `descriptor` on each;
/// for frames with an orientation, also their contact and free points
/// (`append_contact_points`, `append_free_points`, pitch from
/// `taxel_pitch_of`); when every
/// contact frame has an orientation, the pad normals (`TouchSet::normals`).
/// Throws InvalidArgument naming "contact_threshold" unless it is finite
/// and >= 0, NonFiniteValue naming "dataset.frames[I].pressures" for a
/// frame with a NaN or infinite pressure (a hand-built dataset's; the
/// reader refuses one), EmptyInput naming "dataset" when no frame is a contact, what
/// taxel_pitch_of throws when a contact frame has an orientation, and
/// InvalidArgument naming "dataset.frames[I].orientation" for a contact
/// frame's orientation that is not a unit quaternion (a hand-built
/// dataset's; the reader refuses one). What the
/// descriptor returns is checked as extract_features checks it, naming the
/// frame (`dataset.frames[I]`): its InvalidArgument (or derived error)
/// about "image" names the frame instead; an empty feature is EmptyInput, a length that
/// differs from the first frame's DimensionMismatch, a finite value beyond
/// float's range (features are kept in float) InvalidArgument, and a NaN or
/// infinity NonFiniteValue naming "features" (row: coordinate, column: touch).
/// `progress` gets (frames done, frames).
template <typename Descriptor>
TouchTable make_touch_table(const Dataset& dataset, const Descriptor& descriptor,
                            double contact_threshold = kDefaultContactThreshold,
                            const ProgressCallback& progress = {}) {
  ICLAP_CHECK_DESCRIPTOR(Descriptor);
  check_non_negative(contact_threshold, "contact_threshold");
  TouchTable t;
  std::map<std::string, Index> index;
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < dataset.frames.size(); ++i) {
    const Frame& f = dataset.frames[i];
    if (!index.count(f.object)) {
      index[f.object] = static_cast<Index>(t.objects.size());
      t.objects.push_back(f.object);
    }
    if (detail::is_contact_unchecked(f, contact_threshold,
                                     [i] { return "dataset.frames[" + std::to_string(i) + "].pressures"; }))
      kept.push_back(i);
    else ++t.idle_frames;
  }
  if (kept.empty())
    throw EmptyInput("dataset", "has no contact frame (no taxel above " + format_value(contact_threshold) + ")");
  const auto n = static_cast<Index>(kept.size());
  std::vector<Eigen::Vector3d> contacts, free;
  std::vector<Index> offsets{0}, free_offsets{0};
  bool oriented = true, any_oriented = false;
  for (const std::size_t i : kept) {
    oriented = oriented && dataset.frames[i].orientation.has_value();
    any_oriented = any_oriented || dataset.frames[i].orientation.has_value();
  }
  // Only the contact points of oriented frames use the pitch.
  const double pitch = any_oriented ? taxel_pitch_of(dataset) : 0.0034;
  t.touches.positions.resize(3, n);
  if (oriented) t.touches.normals.resize(3, n);
  t.object.resize(kept.size());
  t.exploration.resize(kept.size());
  t.frame.resize(kept.size());
  for (Index j = 0; j < n; ++j) {
    const Frame& f = dataset.frames[kept[static_cast<std::size_t>(j)]];
    const auto ju = static_cast<std::size_t>(j);
    const auto frame_name = [i = kept[ju]] { return "dataset.frames[" + std::to_string(i) + "]"; };
    // The threshold and pitch are checked above, once (taxel_pitch_of
    // returns a pitch in range); a hand-built dataset's orientation here.
    detail::check_frame_orientation(f, [&] { return frame_name() + ".orientation"; });
    t.touches.positions.col(j) = f.position;
    if (oriented) t.touches.normals.col(j) = f.orientation->normalized() * Eigen::Vector3d::UnitZ();
    t.object[ju] = index[f.object];
    t.exploration[ju] = f.exploration;
    t.frame[ju] = f.frame;
    // As extract_features: the descriptor's own complaint about its "image"
    // names the frame.
    const auto feature =
        rename_argument("image", frame_name, [&] { return descriptor.compute(TactileImage(f.pressures)); });
    if (j == 0) {
      // As extract_features: an empty feature breaks the Descriptor concept,
      // and 0 x n features would read as "no features" until the codebook.
      if (feature.size() == 0) throw EmptyInput("features", "descriptor returned an empty feature for " + frame_name());
      t.touches.features.resize(feature.size(), n);
    }
    // (A descriptor's length follows the image size, which a hand-built
    // dataset may vary: a shorter feature was cut, a longer one read past.)
    check_dimension(feature.size(), t.touches.features.rows(), "features of " + frame_name());
    t.touches.features.col(j) = feature.template cast<float>();
    // A finite value the cast to float made infinite is a range error, not
    // the descriptor's NaN or infinity (checked below for the whole table).
    for (Index k = 0; k < feature.size(); ++k)
      if (std::isfinite(static_cast<double>(feature(k))) && !std::isfinite(t.touches.features(k, j)))
        throw InvalidArgument("features of " + frame_name(),
                              "coordinate " + std::to_string(k) + " is " + format_value(static_cast<double>(feature(k))) +
                                  ", beyond the range of float, in which a touch table keeps features");
    offsets.push_back(offsets.back() + detail::place_taxels(f, contact_threshold, pitch, true, contacts));
    free_offsets.push_back(free_offsets.back() + detail::place_taxels(f, contact_threshold, pitch, false, free));
    if (progress && (j % 256 == 0 || j + 1 == n)) progress(static_cast<std::size_t>(j + 1), kept.size());
  }
  check_finite(t.touches.features, "features");
  if (!contacts.empty()) {
    t.touches.contact_points.resize(3, static_cast<Index>(contacts.size()));
    for (std::size_t k = 0; k < contacts.size(); ++k) t.touches.contact_points.col(static_cast<Index>(k)) = contacts[k];
    t.touches.contact_offsets = std::move(offsets);
  }
  if (any_oriented) {
    t.touches.free_points.resize(3, static_cast<Index>(free.size()));
    for (std::size_t k = 0; k < free.size(); ++k) t.touches.free_points.col(static_cast<Index>(k)) = free[k];
    t.touches.free_offsets = std::move(free_offsets);
  }
  return t;
}

}  // namespace iclap
