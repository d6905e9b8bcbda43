// SPDX-License-Identifier: MIT
// A user's program: 4-D labeled ICP with the installed iclap package.
#include <cmath>
#include <cstdio>

#include <iclap/iclap.hpp>

int main() {
  // Twenty touches of an object: (x, y, z, word label).
  iclap::Cloud<double, 4> model(4, 20);
  for (int i = 0; i < 20; ++i)
    model.col(i) << 0.01 * i, 0.004 * (i % 5), 0.002 * (i % 3), static_cast<double>(i % 4);
  // The same touches after the object moved 5 mm along x.
  iclap::Cloud<double, 4> test = model;
  test.row(0).array() -= 0.005;

  const iclap::ReferenceCloud<double, 4> reference(model, Eigen::Vector4d(1, 1, 1, 0.01));
  iclap::Icp<double, 4, iclap::SpatialRigid> icp;
  icp.termination.max_iterations = 30;
  const auto result = icp.align(reference, test);
  const bool ok = result.converged && std::abs(result.T_model_test.t.x() - 0.005) < 1e-9 && result.rmse < 1e-9;
  std::printf("iclap %s consumer: %s (t_x = %.6f m, rmse %.3g, %d iterations)\n", ICLAP_VERSION_STRING,
              ok ? "ok" : "FAILED", result.T_model_test.t.x(), static_cast<double>(result.rmse), result.iterations);
  return ok ? 0 : 1;
}
