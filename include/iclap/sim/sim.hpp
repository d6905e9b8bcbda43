// SPDX-License-Identifier: MIT
#pragma once

/// \file
/// Umbrella header of the rig simulator: sensor model, objects (built-in and
/// from mesh files), exploration and whole datasets.

#include "iclap/sim/builtin_objects.hpp"
#include "iclap/sim/exploration.hpp"
#include "iclap/sim/objects.hpp"
#include "iclap/sim/sensor.hpp"
#include "iclap/sim/simulator.hpp"
