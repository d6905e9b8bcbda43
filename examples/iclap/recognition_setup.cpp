// SPDX-License-Identifier: MIT
#include "recognition_setup.hpp"

#include "iclap/tactile/moments.hpp"
#include "iclap/tactile/raw_pressures.hpp"
#include "iclap/tactile/tactile_sift.hpp"

namespace iclap::cli {

template <typename Scalar>
std::vector<std::unique_ptr<Classifier>> make_classifiers_for(const RecognitionOptions& o,
                                                              const std::vector<std::string>& names);
extern template std::vector<std::unique_ptr<Classifier>> make_classifiers_for<float>(const RecognitionOptions&,
                                                                                     const std::vector<std::string>&);
extern template std::vector<std::unique_ptr<Classifier>> make_classifiers_for<double>(const RecognitionOptions&,
                                                                                      const std::vector<std::string>&);

std::vector<std::unique_ptr<Classifier>> make_classifiers(const RecognitionOptions& options,
                                                          const std::vector<std::string>& names) {
  return options.scalar == "double" ? make_classifiers_for<double>(options, names)
                                    : make_classifiers_for<float>(options, names);
}

TouchTable make_touch_table(const Dataset& dataset, const RecognitionOptions& options, const ProgressCallback& progress) {
  if (options.descriptor == "raw")
    return iclap::make_touch_table(dataset, RawPressures<float>{}, options.contact_threshold, progress);
  if (options.descriptor == "moments")
    return iclap::make_touch_table(dataset, MomentsDescriptor<float>{}, options.contact_threshold, progress);
  return iclap::make_touch_table(dataset, TactileSift<float>{}, options.contact_threshold, progress);
}

}  // namespace iclap::cli
