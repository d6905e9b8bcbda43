// SPDX-License-Identifier: MIT
#include "classifier_factory.hpp"

template std::vector<std::unique_ptr<iclap::Classifier>> iclap::cli::make_classifiers_for<float>(
    const RecognitionOptions&, const std::vector<std::string>&);
