// SPDX-License-Identifier: MIT
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "iclap/core/types.hpp"
#include "iclap/recognition/touch_set.hpp"

namespace iclap {

/// A recognition pipeline that measures how far a set of test touches is
/// from every known object (smaller: more alike). Runtime-polymorphic so that
/// a recogniser can hold any mix of them, chosen on the command line.
///
/// Contract: `fit` builds the references once per training set (one touch
/// set per object, in object order; kd-trees included) and may be called
/// again to replace them; `distances` is const, thread-safe, and writes one
/// finite, non-negative, unnormalised distance per object.
class Classifier {
 public:
  virtual ~Classifier() = default;
  /// Stable name used by fusion expressions and results files.
  virtual std::string name() const = 0;
  /// `vocabulary` is the number of words of the codebook that produced the
  /// touches' word ids.
  virtual void fit(const std::vector<TouchSet>& objects, Index vocabulary) = 0;
  virtual void distances(const TouchSet& test, Eigen::Ref<Eigen::VectorXd> out) const = 0;
  /// Number of objects of the last fit (0 before).
  virtual Index objects() const = 0;
};

}  // namespace iclap
