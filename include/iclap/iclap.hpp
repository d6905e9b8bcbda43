// SPDX-License-Identifier: MIT
#pragma once

/// The whole core library (needs only Eigen and nanoflann). Rig support
/// (serial, hidapi) is opt-in through its own headers under iclap/rig/.
#include "iclap/core/error.hpp"
#include "iclap/core/point_cloud.hpp"
#include "iclap/core/random.hpp"
#include "iclap/core/version.hpp"
#include "iclap/registration/registration.hpp"
#include "iclap/tactile/tactile.hpp"
