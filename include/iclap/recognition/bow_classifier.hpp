// SPDX-License-Identifier: MIT
#pragma once

#include <string>
#include <vector>

#include "iclap/core/error.hpp"
#include "iclap/recognition/classifier.hpp"
#include "iclap/tactile/bag_of_words.hpp"

namespace iclap {

/// Tactile-only recognition (paper, Section IV, "Tactile based object
/// recognition"): each object is the normalised histogram of the words of
/// its training touches, h^class; a test touch set is h^test; the distance is
/// the histogram intersection E_BoW = 1 - sum_i min(h^test_i, h^class_i).
class BowClassifier final : public Classifier {
 public:
  std::string name() const override { return "bow"; }

  /// Throws EmptyInput naming "objects[j].words" for an object without words.
  void fit(const std::vector<TouchSet>& objects, Index vocabulary) override {
    if (objects.empty()) throw EmptyInput("objects", "no object to recognise");
    if (vocabulary < 1)
      throw InvalidArgument("vocabulary", "must be at least 1 word, got " + std::to_string(vocabulary));
    Eigen::MatrixXd h(vocabulary, static_cast<Index>(objects.size()));
    for (std::size_t j = 0; j < objects.size(); ++j) {
      if (objects[j].words.size() == 0) throw EmptyInput("objects[" + std::to_string(j) + "].words");
      h.col(static_cast<Index>(j)) = word_histogram(objects[j].words, vocabulary);
    }
    histograms_ = std::move(h);
  }

  void distances(const TouchSet& test, Eigen::Ref<Eigen::VectorXd> out) const override {
    if (test.words.size() == 0) throw EmptyInput("test.words", "the BoW classifier needs the test touches' words");
    check_dimension(out.size(), objects(), "out");
    const WordHistogram h = word_histogram(test.words, histograms_.rows());
    for (Index j = 0; j < histograms_.cols(); ++j) out(j) = histogram_intersection_distance(h, histograms_.col(j));
  }

  Index objects() const override { return histograms_.cols(); }

  /// The objects' histograms, one column per object.
  const Eigen::MatrixXd& histograms() const noexcept { return histograms_; }

 private:
  Eigen::MatrixXd histograms_;
};

}  // namespace iclap
