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

  /// Throws EmptyInput naming "objects[j].words" for an object without
  /// words, InvalidArgument naming it for a word id outside the vocabulary,
  /// and DimensionMismatch naming "objects[j].words (touches)" for words
  /// that are not one per touch (TouchSet::validate_layout), as the
  /// registration classifiers and the pool path refuse them.
  void fit(const std::vector<TouchSet>& objects, Index vocabulary) override {
    if (objects.empty()) throw EmptyInput("objects", "no object to recognise");
    if (vocabulary < 1)
      throw InvalidArgument("vocabulary", "must be at least 1 word, got " + std::to_string(vocabulary));
    Eigen::MatrixXd h(vocabulary, static_cast<Index>(objects.size()));
    for (std::size_t j = 0; j < objects.size(); ++j) {
      objects[j].validate_layout("objects[" + std::to_string(j) + "]");
      if (objects[j].words.size() == 0) throw EmptyInput("objects[" + std::to_string(j) + "].words");
      h.col(static_cast<Index>(j)) = histogram_of(objects[j].words, vocabulary, "objects[" + std::to_string(j) + "].words");
    }
    histograms_ = std::move(h);
  }

  /// Throws as fit does, naming "test" (words not one per touch counted
  /// ids that belong to no touch).
  void distances(const TouchSet& test, Eigen::Ref<Eigen::VectorXd> out) const override {
    test.validate_layout("test");
    if (test.words.size() == 0) throw EmptyInput("test.words", "the BoW classifier needs the test touches' words");
    check_dimension(out.size(), objects(), "out");
    const WordHistogram h = histogram_of(test.words, histograms_.rows(), "test.words");
    for (Index j = 0; j < histograms_.cols(); ++j) out(j) = histogram_intersection_distance(h, histograms_.col(j));
  }

  Index objects() const override { return histograms_.cols(); }

  /// The objects' histograms, one column per object.
  const Eigen::MatrixXd& histograms() const noexcept { return histograms_; }

 private:
  /// word_histogram, with a word id outside the vocabulary named as
  /// `argument` (which object's words, or the test's).
  static WordHistogram histogram_of(const WordIds& words, Index vocabulary, const std::string& argument) {
    return rename_argument("words", argument, [&] { return word_histogram(words, vocabulary); });
  }

  Eigen::MatrixXd histograms_;
};

}  // namespace iclap
