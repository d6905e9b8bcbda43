// SPDX-License-Identifier: MIT
#pragma once

#include <cmath>
#include <string>

#include "iclap/core/error.hpp"
#include "iclap/tactile/tactile_image.hpp"

namespace iclap {

/// Decides whether a tactile frame is a touch (a contact with the object)
/// or an idle frame of the sensor.
///
/// A frame *passes* (is a contact) when at least `min_taxels` taxels read
/// strictly more than `threshold`. With the default `min_taxels = 1` this is
/// "the largest taxel is above the threshold", the rule of the dataset format
/// (docs: a frame whose every taxel is at or below the threshold is no
/// contact). Raising `min_taxels` rejects single-taxel spikes of electrical
/// noise. Both settings are public; `validate()` checks them, `operator()`
/// does so too. Stateless apart from the settings: const calls are
/// thread-safe. O(rows * cols) per frame.
struct ContactDetector {
  /// Raw sensor units (WTS: 0..4095). 0 counts any positive reading.
  double threshold = 0.0;
  /// How many taxels must exceed `threshold`; at least 1.
  Index min_taxels = 1;

  /// Throws InvalidArgument naming "threshold" (not finite or negative) or
  /// "min_taxels" (< 1).
  void validate() const {
    if (!std::isfinite(threshold) || threshold < 0.0)
      throw InvalidArgument("threshold", "must be finite and >= 0, got " + format_exact(threshold));
    if (min_taxels < 1)
      throw InvalidArgument("min_taxels", "must be at least 1, got " + std::to_string(min_taxels));
  }

  /// True when `image` is a contact frame (see the class comment).
  bool operator()(const TactileImage& image) const {
    validate();
    return image.count_above(threshold) >= min_taxels;
  }
};

/// Shorthand for the default rule: true when the largest taxel of `image` is
/// strictly above `threshold` (raw units). Throws InvalidArgument for a
/// negative or non-finite threshold.
inline bool is_contact(const TactileImage& image, double threshold = 0.0) {
  return ContactDetector{threshold, 1}(image);
}

}  // namespace iclap
