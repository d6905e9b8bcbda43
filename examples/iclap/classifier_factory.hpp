// SPDX-License-Identifier: MIT
#pragma once

// The heavy part of recognition_setup: every classifier type the options can
// ask for. Instantiated once per scalar type in its own translation unit
// (classifiers_float.cpp, classifiers_double.cpp) so they compile in parallel.

#include <memory>
#include <string>
#include <vector>

#include "iclap/recognition/bow_classifier.hpp"
#include "iclap/recognition/occupancy_classifier.hpp"
#include "iclap/recognition/registration_classifier.hpp"
#include "recognition_setup.hpp"

namespace iclap::cli {

/// The ICP settings and the name of registration classifier `c`: `label` is
/// the classifier's name (a trim variant such as "patch-trim50", or the
/// base name), and sets its trimmed fraction.
template <typename C>
void configure(C& c, const RecognitionOptions& o, const std::string& label) {
  using Scalar = typename C::IcpType::Transform::Vector::Scalar;
  c.label = label;
  c.icp.termination.max_iterations = o.max_iterations;
  c.icp.termination.relative_tolerance = static_cast<Scalar>(o.relative_tolerance);
  c.icp.rejection.trim_fraction = static_cast<Scalar>(o.trim_of(label));
  apply_search_choice(o.search, c.search_settings);
}

/// `name` is the base classifier ("patch"), `label` its name in the
/// recogniser (see configure).
template <typename Scalar, typename Model, template <typename, int> class Search>
std::unique_ptr<Classifier> make_registration_classifier(const std::string& name, const std::string& label,
                                                         const RecognitionOptions& o) {
  if (name == "icp") {
    auto c = std::make_unique<IcpClassifier<Scalar, Model, Search<Scalar, 3>>>();
    configure(*c, o, label);
    return c;
  }
  if (name == "iclap") {
    auto c = std::make_unique<IclapClassifier<Scalar, Model, Search<Scalar, 4>>>();
    configure(*c, o, label);
    c->embedding.label_scale = o.label_scale;
    return c;
  }
  if (name == "patch") {
    auto c = std::make_unique<PatchClassifier<Scalar, Model, Search<Scalar, 3>>>();
    configure(*c, o, label);
    c->embedding.test_points_per_touch = o.patch_points;
    c->embedding.reference_voxel = o.patch_voxel;
    return c;
  }
  if (name == "iclap_patch") {
    auto c = std::make_unique<IclapPatchClassifier<Scalar, Model, Search<Scalar, 4>>>();
    configure(*c, o, label);
    c->embedding.label_scale = o.label_scale;
    c->embedding.test_points_per_touch = o.patch_points;
    c->embedding.reference_voxel = o.patch_voxel;
    return c;
  }
  auto c = std::make_unique<IclapNClassifier<Eigen::Dynamic, Scalar, Model, Search<Scalar, Eigen::Dynamic>>>();
  configure(*c, o, label);
  c->embedding.descriptor_scale = o.descriptor_scale;
  return c;
}

template <typename Scalar, template <typename, int> class Search>
std::unique_ptr<Classifier> make_with_search(const std::string& name, const std::string& label,
                                             const RecognitionOptions& o) {
  if (o.transform == "full") return make_registration_classifier<Scalar, FullRigid, Search>(name, label, o);
  if (o.transform == "spatial") return make_registration_classifier<Scalar, SpatialRigid, Search>(name, label, o);
  if (o.transform == "translation") return make_registration_classifier<Scalar, Translation, Search>(name, label, o);
  return make_registration_classifier<Scalar, Planar, Search>(name, label, o);
}

template <typename Scalar>
std::vector<std::unique_ptr<Classifier>> make_classifiers_for(const RecognitionOptions& o,
                                                              const std::vector<std::string>& names) {
  std::vector<std::unique_ptr<Classifier>> out;
  for (const auto& label : names) {
    std::string name = label;
    double trim = 1;
    RecognitionOptions::split_trim_variant(label, name, trim);
    if (name == "bow" && name == label) {
      out.push_back(std::make_unique<BowClassifier>());
    } else if (auto h = make_height_classifier(o, label)) {
      out.push_back(std::move(h));
    } else if (name == "occupancy" && name == label) {
      auto c = std::make_unique<OccupancyClassifier>();
      o.configure_occupancy(*c);
      out.push_back(std::move(c));
    } else if (const auto* v = o.find_occupancy_variant(label)) {
      auto c = std::make_unique<OccupancyClassifier>();
      o.configure_occupancy(*c, v);
      c->label = label;
      out.push_back(std::move(c));
    } else if (is_registration_classifier(name)) {
      out.push_back(make_with_search<Scalar, AdaptiveSearch>(name, label, o));
    } else {
      throw UsageError("unknown classifier '" + name + "' (known: " + Options::join(known_classifiers(), ", ") + ")");
    }
  }
  return out;
}

}  // namespace iclap::cli
