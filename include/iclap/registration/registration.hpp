// SPDX-License-Identifier: MIT
#pragma once

/// N-D (labeled) ICP: reference clouds, transform models, rejection,
/// termination and the registration itself.
#include "iclap/registration/icp.hpp"
#include "iclap/registration/models/full_rigid.hpp"
#include "iclap/registration/models/planar.hpp"
#include "iclap/registration/models/spatial_rigid.hpp"
#include "iclap/registration/models/translation.hpp"
#include "iclap/registration/reference_cloud.hpp"
#include "iclap/registration/rejector.hpp"
#include "iclap/registration/result.hpp"
#include "iclap/registration/termination.hpp"
#include "iclap/registration/transform.hpp"
#include "iclap/search/search.hpp"
