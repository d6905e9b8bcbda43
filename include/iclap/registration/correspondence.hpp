// SPDX-License-Identifier: MIT
#pragma once

#include "iclap/core/types.hpp"

namespace iclap {

/// A matched pair: test point `test`, its closest model point `model`, and
/// their squared (weighted) distance under the current transform.
template <typename Scalar>
struct Correspondence {
  Index test = 0;
  Index model = 0;
  Scalar squared_distance = 0;
};

}  // namespace iclap
