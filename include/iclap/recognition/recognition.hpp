// SPDX-License-Identifier: MIT
#pragma once

/// Recognition (paper, Sections III-VI): classifiers that give a distance
/// from a test touch set to every known object (BoW, ICP, iCLAP, iCLAP-N,
/// contact patches, heights and tilts),
/// their normalisation, fusion policies, the paper's named methods, and the
/// cross-validation experiment.
#include "iclap/recognition/bow_classifier.hpp"
#include "iclap/recognition/classifier.hpp"
#include "iclap/recognition/cross_validation.hpp"
#include "iclap/recognition/fusion.hpp"
#include "iclap/recognition/methods.hpp"
#include "iclap/recognition/normalization.hpp"
#include "iclap/recognition/occupancy_classifier.hpp"
#include "iclap/recognition/height_classifier.hpp"
#include "iclap/recognition/recognizer.hpp"
#include "iclap/recognition/registration_classifier.hpp"
#include "iclap/recognition/touch_set.hpp"
#include "iclap/recognition/touch_table.hpp"
