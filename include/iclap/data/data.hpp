// SPDX-License-Identifier: MIT
#pragma once

/// \file
/// Umbrella header of the data layer: the in-memory dataset, the dataset CSV
/// reader, writer and streaming appender, and the labeled point cloud export.

#include "iclap/data/csv_appender.hpp"
#include "iclap/data/csv_common.hpp"
#include "iclap/data/csv_reader.hpp"
#include "iclap/data/csv_writer.hpp"
#include "iclap/data/dataset.hpp"
#include "iclap/data/ply_cloud.hpp"
