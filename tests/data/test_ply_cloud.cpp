// SPDX-License-Identifier: MIT
// Labeled point cloud export as PLY.

#include <doctest/doctest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "iclap/core/random.hpp"
#include "iclap/data/ply_cloud.hpp"
#include "iclap/mesh/ply.hpp"
#include "../support/temporaries.hpp"

namespace {

namespace fs = std::filesystem;

using iclap::test::slurp;

using iclap::test::TempDir;

}  // namespace

TEST_CASE("labeled cloud ply: ascii content") {
  Eigen::Matrix3Xd p(3, 3);
  p << 0.1, -1.5, 1e-7,  //
      0, 2, 3,           //
      1.0 / 3.0, 4, 5;
  const std::vector<int> labels = {0, 7, -1};
  const TempDir dir("ply_ascii");
  const std::string path = dir.file("ascii.ply");
  iclap::write_labeled_cloud_ply(path, p, labels, {iclap::PlyEncoding::ascii, {"object pliers_1"}});
  const std::string text = slurp(path);
  const auto c0 = iclap::label_colour(0), c7 = iclap::label_colour(7);
  const std::string expected =
      "ply\nformat ascii 1.0\ncomment written by iclap (labeled point cloud)\n"
      "comment object pliers_1\nelement vertex 3\nproperty double x\nproperty double y\n"
      "property double z\nproperty int label\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nend_header\n"
      "0.1 0 0.3333333333333333 0 " +
      std::to_string(c0[0]) + " " + std::to_string(c0[1]) + " " + std::to_string(c0[2]) +
      "\n-1.5 2 4 7 " + std::to_string(c7[0]) + " " + std::to_string(c7[1]) + " " +
      std::to_string(c7[2]) + "\n1e-07 3 5 -1 128 128 128\n";
  CHECK(text == expected);
  // Neighbouring labels are told apart by colour.
  for (int l = 0; l < 50; ++l) CHECK(iclap::label_colour(l) != iclap::label_colour(l + 1));
}

TEST_CASE("labeled cloud ply: binary little endian layout") {
  Eigen::Matrix3Xf p(3, 2);
  p << 1, 2, 3, 4, 5, 6;
  Eigen::VectorXi labels(2);
  labels << 3, 258;
  const TempDir dir("ply_binary");
  const std::string path = dir.file("binary.ply");
  iclap::write_labeled_cloud_ply(path, p, labels, {iclap::PlyEncoding::binary_little_endian, {}});
  const std::string data = slurp(path);
  const auto body_at = data.find("end_header\n");
  REQUIRE(body_at != std::string::npos);
  CHECK(data.find("format binary_little_endian 1.0\n") != std::string::npos);
  CHECK(data.find("property float x\n") != std::string::npos);
  const std::string body = data.substr(body_at + 11);
  REQUIRE(body.size() == 2 * (3 * 4 + 4 + 3));
  auto le32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int b = 3; b >= 0; --b) v = (v << 8) | static_cast<unsigned char>(body[at + static_cast<std::size_t>(b)]);
    return v;
  };
  auto f32 = [&](std::size_t at) {
    const std::uint32_t bits = le32(at);
    float f = 0;
    std::memcpy(&f, &bits, 4);
    return f;
  };
  CHECK(f32(0) == 1.0f);
  CHECK(f32(4) == 3.0f);
  CHECK(f32(8) == 5.0f);
  CHECK(le32(12) == 3u);
  CHECK(f32(19 + 4) == 4.0f);
  CHECK(le32(19 + 12) == 258u);
  const auto c = iclap::label_colour(258);
  CHECK(static_cast<unsigned char>(body[19 + 16]) == c[0]);
  CHECK(static_cast<unsigned char>(body[19 + 18]) == c[2]);
}

TEST_CASE("labeled cloud ply: bad input is rejected and writes nothing") {
  const TempDir dir("ply_bad");
  const std::string path = dir.file("bad.ply");
  Eigen::Matrix3Xd p = Eigen::Matrix3Xd::Zero(3, 2);
  CHECK_THROWS_AS(iclap::write_labeled_cloud_ply(path, p, std::vector<int>{1}), iclap::DimensionMismatch);
  Eigen::MatrixXd p4 = Eigen::MatrixXd::Zero(4, 2);
  CHECK_THROWS_AS(iclap::write_labeled_cloud_ply(path, p4, std::vector<int>{1, 2}), iclap::DimensionMismatch);
  p(2, 1) = std::numeric_limits<double>::quiet_NaN();
  try {
    iclap::write_labeled_cloud_ply(path, p, std::vector<int>{1, 2});
    FAIL("accepted");
  } catch (const iclap::NonFiniteValue& e) {
    CHECK(e.row() == 2);
    CHECK(e.column() == 1);
  }
  p(2, 1) = 0;
  CHECK_THROWS_AS(iclap::write_labeled_cloud_ply(path, p, std::vector<long long>{1, 1LL << 40}),
                  iclap::InvalidArgument);
  CHECK_FALSE(fs::exists(path));
  CHECK_FALSE(iclap::test::temporary_left_beside(path));
}

TEST_CASE("labeled cloud ply: binary refuses a finite coordinate beyond float32, ascii keeps it") {
  // 1e39 is a finite double but inf as float32: the binary file would hold
  // inf where the caller gave a number. Refused before anything is written.
  const TempDir dir("ply_beyond_float");
  const std::string path = dir.file("beyond_float.ply");
  Eigen::Matrix3Xd p = Eigen::Matrix3Xd::Zero(3, 3);
  p(1, 2) = -1e39;
  const std::vector<int> labels = {0, 1, 2};
  try {
    iclap::write_labeled_cloud_ply(path, p, labels, {iclap::PlyEncoding::binary_little_endian, {}});
    FAIL("accepted");
  } catch (const iclap::InvalidArgument& e) {
    const std::string what = e.what();
    CHECK(what.find("point 2") != std::string::npos);
    CHECK(what.find("-1e+39") != std::string::npos);
    CHECK(what.find("float32") != std::string::npos);
  }
  CHECK_FALSE(fs::exists(path));
  CHECK_FALSE(iclap::test::temporary_left_beside(path));
  // The largest float is still written, exactly.
  p(1, 2) = -static_cast<double>(std::numeric_limits<float>::max());
  iclap::write_labeled_cloud_ply(path, p, labels, {iclap::PlyEncoding::binary_little_endian, {}});
  const auto back = iclap::read_ply(path);
  REQUIRE(back.vertices.cols() == 3);
  CHECK(back.vertices(1, 2) == p(1, 2));
  // ASCII writes doubles: 1e39 is kept as is.
  p(1, 2) = -1e39;
  iclap::write_labeled_cloud_ply(path, p, labels, {iclap::PlyEncoding::ascii, {}});
  CHECK(iclap::read_ply(path).vertices(1, 2) == -1e39);
}

TEST_CASE("labeled cloud ply: reads back with a PLY reader (ascii exact, binary float)") {
  iclap::Rng rng(5);
  Eigen::Matrix3Xd p(3, 200);
  std::vector<int> labels(200);
  for (int i = 0; i < 200; ++i) {
    p.col(i) = Eigen::Vector3d(rng.normal(0, 0.1), rng.normal(0, 0.1), rng.uniform(0, 0.05));
    labels[static_cast<std::size_t>(i)] = static_cast<int>(rng.below(50));
  }
  for (auto enc : {iclap::PlyEncoding::ascii, iclap::PlyEncoding::binary_little_endian}) {
    const TempDir dir("ply_readback");
    const std::string path = dir.file("readback.ply");
    iclap::write_labeled_cloud_ply(path, p, labels, {enc, {}});
    const auto back = iclap::read_ply(path);
    REQUIRE(back.vertices.cols() == 200);
    CHECK(back.triangles.cols() == 0);
    if (enc == iclap::PlyEncoding::ascii) CHECK(back.vertices == p);
    else CHECK(back.vertices.isApprox(p.cast<float>().cast<double>(), 0));
    const auto& l = back.vertex_properties.at("label");
    const auto& red = back.vertex_properties.at("red");
    for (std::size_t i = 0; i < 200; ++i) {
      CHECK(l[i] == labels[i]);
      CHECK(red[i] == iclap::label_colour(labels[i])[0]);
    }
  }
}

// ---------------------------------------------------------------------------
// Audit (session 50): defects found from a user's side, skipped until fixed.

TEST_CASE("labeled cloud ply: an unsigned label beyond int32 is refused, not written as -1") {
  // ply_cloud.hpp cast each label to long long before the int32 range
  // check, so a std::uint64_t / std::size_t label SIZE_MAX (a "no word"
  // sentinel, say) became -1: accepted and written as label -1, grey,
  // though the function promises InvalidArgument for a label outside int32.
  // Labels are now compared in their own type.
  const TempDir dir("ply_unsigned");
  const std::string path = dir.file("unsigned.ply");
  const Eigen::Matrix3Xd p = Eigen::Matrix3Xd::Zero(3, 2);
  try {
    iclap::write_labeled_cloud_ply(path, p, std::vector<std::uint64_t>{1, ~std::uint64_t(0)});
    FAIL("accepted");
  } catch (const iclap::InvalidArgument& e) {
    // The label as given, not as -1.
    CHECK(std::string(e.what()) == "labels: label 18446744073709551615 of point 1 does not fit a PLY int");
  }
  CHECK_FALSE(fs::exists(path));
  // 2^32 was refused already (the cast kept its value).
  CHECK_THROWS_AS(iclap::write_labeled_cloud_ply(path, p, std::vector<std::uint64_t>{1, std::uint64_t(1) << 32}),
                  iclap::InvalidArgument);
  // The edge in an unsigned type: INT32_MAX + 1 refused, INT32_MAX written.
  const std::uint32_t int32_max = static_cast<std::uint32_t>(std::numeric_limits<std::int32_t>::max());
  CHECK_THROWS_AS(iclap::write_labeled_cloud_ply(path, p, std::vector<std::uint32_t>{0, int32_max + 1u}),
                  iclap::InvalidArgument);
  CHECK_FALSE(fs::exists(path));
  iclap::write_labeled_cloud_ply(path, p, std::vector<std::uint32_t>{0, int32_max});
  CHECK(slurp(path).find("\n0 0 0 2147483647 ") != std::string::npos);
  // Narrow types take their whole range.
  iclap::write_labeled_cloud_ply(path, p, std::vector<std::uint8_t>{0, 255});
  CHECK(slurp(path).find("\n0 0 0 255 ") != std::string::npos);
  iclap::write_labeled_cloud_ply(path, p, std::vector<std::int8_t>{0, -128});
  CHECK(slurp(path).find("\n0 0 0 -128 ") != std::string::npos);
}
