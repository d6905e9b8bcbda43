// SPDX-License-Identifier: MIT
#pragma once

#include <cstddef>
#include <functional>

namespace iclap {

/// Progress of a long computation: called with (done, total) units of work,
/// `done` non-decreasing, from the calling thread or, for parallel work, from
/// any worker thread (so implementations must be thread-safe). The library
/// never prints; tools pass a callback that does. An empty function is a
/// valid "no progress wanted".
using ProgressCallback = std::function<void(std::size_t done, std::size_t total)>;

}  // namespace iclap
