// SPDX-License-Identifier: MIT
// Every public class template of the registration, the search and the
// recognition classifiers, explicitly instantiated for float and double,
// fixed and run-time dimensions and each transform model: every member
// function compiles, not only those the other tests call (as Sophus does).
// The tactile templates are instantiated in tests/tactile.

#include <doctest/doctest.h>

#include <type_traits>

#include "iclap/recognition/registration_classifier.hpp"
#include "iclap/registration/registration.hpp"
#include "iclap/search/adaptive.hpp"
#include "iclap/search/brute_force.hpp"
#include "iclap/search/kdtree.hpp"

namespace iclap {

// Search structures.
template class KdTreeSearch<float, 3>;
template class KdTreeSearch<double, 4>;
template class KdTreeSearch<float, Eigen::Dynamic>;
template class KdTreeSearch<double, Eigen::Dynamic>;
template class BruteForceSearch<float, 2>;
template class BruteForceSearch<double, 3>;
template class BruteForceSearch<float, Eigen::Dynamic>;
template class BruteForceSearch<double, Eigen::Dynamic>;
template class AdaptiveSearch<float, 4>;
template class AdaptiveSearch<double, 3>;
template class AdaptiveSearch<double, Eigen::Dynamic>;

// The registration's parts.
template struct RigidTransform<float, 2>;
template struct RigidTransform<double, 3>;
template struct RigidTransform<float, 4>;
template struct RigidTransform<double, Eigen::Dynamic>;
template struct RegistrationResult<float, 3>;
template struct RegistrationResult<double, Eigen::Dynamic>;
template struct IcpWorkspace<float, 4>;
template struct IcpWorkspace<double, Eigen::Dynamic>;
template struct DistanceRejector<float>;
template struct DistanceRejector<double>;
template struct PaperTermination<float>;
template struct PaperTermination<double>;
template class ReferenceCloud<float, 3>;
template class ReferenceCloud<double, 4>;
template class ReferenceCloud<float, 4, KdTreeSearch<float, 4>>;
template class ReferenceCloud<double, 3, BruteForceSearch<double, 3>>;
template class ReferenceCloud<double, Eigen::Dynamic>;

// ICP with every transform model, fixed and run-time dimension.
template class Icp<float, 4, FullRigid>;
template class Icp<double, 3, FullRigid>;
template class Icp<double, Eigen::Dynamic, FullRigid>;
template class Icp<float, 4, SpatialRigid>;
template class Icp<double, Eigen::Dynamic, SpatialRigid>;
template class Icp<float, 3, Planar>;
template class Icp<double, 2, Planar>;
template class Icp<double, Eigen::Dynamic, Planar>;
template class Icp<float, 3, Translation>;
template class Icp<double, Eigen::Dynamic, Translation>;
template class Icp<float, 4, FullRigid>::Registration<AdaptiveSearch<float, 4>>;
template class Icp<double, 3, Planar>::Registration<KdTreeSearch<double, 3>>;
template class Icp<double, Eigen::Dynamic, SpatialRigid>::Registration<BruteForceSearch<double, Eigen::Dynamic>>;

// The recognition classifiers built on them (the paper's and beyond).
template class RegistrationClassifier<PositionEmbedding, float, 3, Planar>;
template class RegistrationClassifier<PositionEmbedding, double, 3, FullRigid, KdTreeSearch<double, 3>>;
template class RegistrationClassifier<LabeledEmbedding, float, 4, SpatialRigid>;
template class RegistrationClassifier<LabeledEmbedding, double, 4, Translation, BruteForceSearch<double, 4>>;
template class RegistrationClassifier<ContactEmbedding<false>, double, 3, Planar>;
template class RegistrationClassifier<ContactEmbedding<true>, float, 4, Planar>;
template class RegistrationClassifier<DescriptorEmbedding, float, Eigen::Dynamic, Planar>;
template class RegistrationClassifier<DescriptorEmbedding, double, 3 + 72, SpatialRigid>;

}  // namespace iclap

TEST_CASE("the aliases name the instantiated classifiers") {
  // The explicit instantiations above are what this file checks (it fails to
  // compile otherwise); here, that the public aliases are those types.
  CHECK(std::is_same_v<iclap::IcpClassifier<>, iclap::RegistrationClassifier<iclap::PositionEmbedding, float, 3>>);
  CHECK(std::is_same_v<iclap::IclapClassifier<float, iclap::SpatialRigid>,
                       iclap::RegistrationClassifier<iclap::LabeledEmbedding, float, 4, iclap::SpatialRigid>>);
  CHECK(std::is_same_v<iclap::PatchClassifier<double>,
                       iclap::RegistrationClassifier<iclap::ContactEmbedding<false>, double, 3>>);
  CHECK(std::is_same_v<iclap::IclapNClassifier<72, double, iclap::SpatialRigid>,
                       iclap::RegistrationClassifier<iclap::DescriptorEmbedding, double, 75, iclap::SpatialRigid>>);
  CHECK(std::is_same_v<iclap::IclapNClassifier<>,
                       iclap::RegistrationClassifier<iclap::DescriptorEmbedding, float, Eigen::Dynamic>>);
}
