// SPDX-License-Identifier: MIT
#pragma once

/// The tactile pipeline of iCLAP (paper Section III, first paragraph, and
/// Section IV, "Tactile based object recognition"):
///
///   TactileImage --Descriptor--> feature --Quantizer--> word id
///   words of a touch set --word_histogram--> h --histogram_intersection_distance--> E_BoW
///
/// Descriptors and quantizers are concepts (descriptor.hpp, quantizer.hpp):
/// the shipped ones are TactileSift (the paper's feature), RawPressures and
/// MomentsDescriptor, and KMeansQuantizer (the paper's k-means codebook);
/// user types plug in without registration.
#include "iclap/tactile/bag_of_words.hpp"
#include "iclap/tactile/contact.hpp"
#include "iclap/tactile/descriptor.hpp"
#include "iclap/tactile/kmeans.hpp"
#include "iclap/tactile/moments.hpp"
#include "iclap/tactile/normalization.hpp"
#include "iclap/tactile/quantizer.hpp"
#include "iclap/tactile/raw_pressures.hpp"
#include "iclap/tactile/tactile_image.hpp"
#include "iclap/tactile/tactile_sift.hpp"
#include "iclap/tactile/word_ordering.hpp"
