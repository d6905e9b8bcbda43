// SPDX-License-Identifier: MIT
// A user's program: 4-D labeled ICP with the installed iclap package, on
// the library's matrices and on the user's own touch records.
#include <cmath>
#include <cstdio>
#include <vector>

#include <iclap/iclap.hpp>

// The user's own record of a touch: where the pad was and which word it felt.
struct Touch {
  double x, y, z;
  int word;
};

// How iclap reads a std::vector<Touch>: as 4-D points (x, y, z, word).
template <>
struct iclap::PointCloudTraits<std::vector<Touch>> {
  static iclap::Index size(const std::vector<Touch>& c) { return static_cast<iclap::Index>(c.size()); }
  static iclap::Index dimension(const std::vector<Touch>&) { return 4; }
  static double coordinate(const std::vector<Touch>& c, iclap::Index i, iclap::Index k) {
    const Touch& t = c[static_cast<std::size_t>(i)];
    return k == 0 ? t.x : k == 1 ? t.y : k == 2 ? t.z : static_cast<double>(t.word);
  }
};

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

  // The same test as the user's records, registered without building a matrix.
  std::vector<Touch> touches;
  for (int i = 0; i < 20; ++i) touches.push_back({test(0, i), test(1, i), test(2, i), static_cast<int>(test(3, i))});
  const auto own = icp.align(reference, touches);
  const bool same = own.T_model_test.matrix() == result.T_model_test.matrix() && own.iterations == result.iterations;

  std::printf("iclap %s consumer: %s (t_x = %.6f m, rmse %.3g, %d iterations; own point type: %s)\n",
              ICLAP_VERSION_STRING, ok && same ? "ok" : "FAILED", result.T_model_test.t.x(),
              static_cast<double>(result.rmse), result.iterations, same ? "same result" : "DIFFERENT");
  return ok && same ? 0 : 1;
}
