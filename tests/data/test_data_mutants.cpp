// SPDX-License-Identifier: MIT
// Dataset CSV and PLY export: cases a mutation-testing pass found unpinned
// (each fails with a one-site change of the library that weakens a check or
// an error message, and passes as the library is).

#include <doctest/doctest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "iclap/data/data.hpp"
#include "data_test_util.hpp"
#include "../support/errors.hpp"
#include "../support/file_size_limit.hpp"
#include "../support/temporaries.hpp"

namespace {

using iclap::Dataset;
using iclap::Frame;
using iclap::test::TempDir;
using iclap::test::writer_refusal;

using iclap::test::slurp;
using iclap::test::spit;

// A valid 3x2 dataset of `n` frames, with times and orientations as asked.
Dataset small_dataset(std::size_t n, bool time, bool orientation) {
  Dataset ds;
  ds.rows = 3;
  ds.cols = 2;
  for (std::size_t i = 0; i < n; ++i) {
    Frame f;
    f.object = i % 2 == 0 ? "pliers_1" : "wooden_cuboid_1";
    f.exploration = static_cast<std::int64_t>(i / 4);
    f.frame = static_cast<std::int64_t>(i);
    f.position = {0.001 * static_cast<double>(i), 0.25, -0.125};
    if (time) f.time = 0.01 * static_cast<double>(i);
    if (orientation) f.orientation = Eigen::Quaterniond(1, 0, 0, 0);
    f.pressures.resize(3, 2);
    for (Eigen::Index r = 0; r < 3; ++r)
      for (Eigen::Index c = 0; c < 2; ++c) f.pressures(r, c) = static_cast<double>(10 * r + c + static_cast<Eigen::Index>(i));
    ds.frames.push_back(f);
  }
  return ds;
}

// The ParseError reading `text` throws, as "LINE: reason", or "(no error)".
std::string reader_refusal(const std::string& text) {
  std::istringstream in(text);
  try {
    (void)iclap::read_dataset_csv(in, "mem.csv");
  } catch (const iclap::ParseError& e) {
    CHECK(e.file() == "mem.csv");
    return std::to_string(e.line()) + ": " + e.reason();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("dataset csv writer: every frame is checked, the last one too, against the first frame's columns") {
  const Dataset ds = small_dataset(6, true, false);
  REQUIRE(writer_refusal(ds) == "(no error)");
  // The last frame is validated like the others: a bad row there would be
  // written, and the file would not read back.
  Dataset d = ds;
  d.frames.back().object = "a,b";
  CHECK(writer_refusal(d) == "dataset.frames[5].object: 'a,b' contains a comma");
  d = ds;
  d.frames.back().pressures(2, 1) = -1;
  CHECK(writer_refusal(d) == "dataset.frames[5].pressures: taxel p2_1 is -1, pressures must be finite and >= 0");
  // The first frame decides the `t` column: the last frame without a time is
  // the one named (not the first, as if the last decided).
  d = ds;
  d.frames.back().time.reset();
  CHECK(writer_refusal(d) == "dataset.frames[5].time: is missing, the file has a t column");
  d = small_dataset(6, false, false);
  d.frames.back().time = 1.0;
  CHECK(writer_refusal(d) == "dataset.frames[5].time: is set, the file has no t column");
}

TEST_CASE("dataset csv writer and appender: a pressure grid of the wrong width is refused, naming the taxel by row and column") {
  const Dataset ds = small_dataset(4, false, false);
  Dataset d = ds;
  // Same number of rows, one column more: only the file's 3x2 taxels would
  // be written, the third column lost without a word.
  d.frames[2].pressures.conservativeResize(3, 3);
  d.frames[2].pressures.col(2).setConstant(7);
  CHECK(writer_refusal(d) == "dataset.frames[2].pressures: is 3x3, the file's taxel grid is 3x2");
  d = ds;
  d.frames[1].pressures.conservativeResize(3, 1);
  CHECK(writer_refusal(d) == "dataset.frames[1].pressures: is 3x1, the file's taxel grid is 3x2");
  // Row 2, column 0 is p2_0, not p0_2 (a name no column of this file has).
  d = ds;
  d.frames[3].pressures(2, 0) = std::numeric_limits<double>::infinity();
  CHECK(writer_refusal(d) == "dataset.frames[3].pressures: taxel p2_0 is inf, pressures must be finite and >= 0");

  TempDir dir("data_mutants_grid");
  const std::string path = dir.file("log.csv");
  iclap::DatasetCsvAppender app(path, 3, 2, false, false);
  const std::string before = slurp(path);
  Frame f = ds.frames[0];
  f.pressures.conservativeResize(3, 3);
  f.pressures.col(2).setConstant(7);
  CHECK(iclap::test::what_of([&] { app.append(f); }) == "frame.pressures: is 3x3, the file's taxel grid is 3x2");
  CHECK(slurp(path) == before);
  CHECK(app.rows_in_file() == 0);
}

TEST_CASE("dataset csv: the quaternion norm tolerance is 1e-3, in the reader and the writer") {
  const std::string hq = "object,exploration,frame,x,y,z,qw,qx,qy,qz,p0_0\n";
  // Within 1e-3 of a unit norm (values written with 4 significant digits).
  CHECK(reader_refusal(hq + "a,0,0,0,0,0,1.0009,0,0,0,5\n") == "(no error)");
  CHECK(reader_refusal(hq + "a,0,0,0,0,0,0,0,0.9992,0,5\n") == "(no error)");
  // Just outside it: a scaled quaternion, refused.
  CHECK(reader_refusal(hq + "a,0,0,0,0,0,1.002,0,0,0,5\n") ==
        "2: columns qw,qx,qy,qz: the quaternion has norm 1.002; the pad orientation must be a unit quaternion "
        "(norm 1 +- 0.001)");
  CHECK(reader_refusal(hq + "a,0,0,0,0,0,0,0.995,0,0,5\n").rfind("2: columns qw,qx,qy,qz: the quaternion has norm 0.995;", 0) ==
        0);
  Dataset d = small_dataset(3, false, true);
  d.frames[1].orientation = Eigen::Quaterniond(1.005, 0, 0, 0);
  CHECK(iclap::test::argument_of([&] {
          std::ostringstream out;
          iclap::write_dataset_csv(out, d);
        }) == "dataset.frames[1].orientation");
  d.frames[1].orientation = Eigen::Quaterniond(1.0005, 0, 0, 0);
  CHECK(writer_refusal(d) == "(no error)");
}

TEST_CASE("dataset csv reader: three of the four quaternion columns are refused, not ignored") {
  // With qz missing the reader would otherwise drop qw, qx and qy as if the
  // file had no orientation at all.
  CHECK(reader_refusal("# c\nobject,exploration,frame,x,y,z,qw,qx,qy,p0_0\na,0,0,0,0,0,1,0,0,5\n") ==
        "2: quaternion has only some of its components: qw, qx, qy present, qz missing (give all four of "
        "qw,qx,qy,qz or none)");
  CHECK(reader_refusal("object,exploration,frame,x,y,z,qx,qy,qz,p0_0\n") ==
        "1: quaternion has only some of its components: qx, qy, qz present, qw missing (give all four of "
        "qw,qx,qy,qz or none)");
}

TEST_CASE("dataset csv appender: a header with a duplicate column is refused, the file unchanged") {
  TempDir dir("data_mutants_dup");
  const std::string path = dir.file("dup.csv");
  const std::string text = "# c\nobject,exploration,frame,x,y,z,p0_0,p0_1,p0_1\n";
  spit(path, text);
  try {
    iclap::DatasetCsvAppender app(path, 1, 2, false, false);
    FAIL("accepted");
  } catch (const iclap::ParseError& e) {
    CHECK(e.file() == path);
    CHECK(e.line() == 2);
    CHECK(e.reason() ==
          "header does not match the recorder's columns (1x2 taxels, t no, quaternion no): duplicate 'p0_1'");
  }
  CHECK(slurp(path) == text);
}

TEST_CASE("dataset csv appender: a failed write after reopening keeps every earlier row") {
  TempDir dir("data_mutants_reopen_full");
  const std::string path = dir.file("log.csv");
  const Dataset ds = small_dataset(40, true, false);
  {
    iclap::DatasetCsvAppender app(path, ds.rows, ds.cols, true, false, {"first session"});
    for (std::size_t i = 0; i < 10; ++i) app.append(ds.frames[i]);
  }
  const std::string first_session = slurp(path);
  std::size_t written = 10;
  {
    // Reopened: the cut-back point after a failed write is the end of the
    // existing file plus the rows appended since, not a count from zero.
    iclap::DatasetCsvAppender app(path, ds.rows, ds.cols, true, false);
    REQUIRE(app.rows_in_file() == 10);
    bool failed = false;
    {
      iclap::test::FileSizeLimit limit(first_session.size() + 150);  // room for a row or two
      REQUIRE(limit.ok());
      for (std::size_t i = 10; i < ds.frames.size(); ++i) {
        try {
          app.append(ds.frames[i]);
          ++written;
        } catch (const iclap::WriteError&) {
          failed = true;
          break;
        }
      }
    }
    REQUIRE(failed);
    // Closed after the failure, and saying why.
    CHECK(iclap::test::what_of<iclap::WriteError>([&] { app.append(ds.frames[0]); }) ==
          path + ": an earlier write failed; the appender is closed");
  }
  REQUIRE(written > 10);
  REQUIRE(written < ds.frames.size());
  const std::string text = slurp(path);
  CHECK(text.compare(0, first_session.size(), first_session) == 0);
  const Dataset back = iclap::read_dataset_csv(path);
  REQUIRE(back.frames.size() == written);
  for (std::size_t i = 0; i < written; ++i) {
    CAPTURE(i);
    CHECK(back.frames[i].frame == ds.frames[i].frame);
    CHECK(back.frames[i].pressures == ds.frames[i].pressures);
  }
}

TEST_CASE("labeled cloud ply: a label below the int32 range is refused too, and nothing written") {
  const TempDir dir("data_mutants_ply");
  const std::string path = dir.file("labels.ply");
  const Eigen::Matrix3Xd p = Eigen::Matrix3Xd::Zero(3, 3);
  const std::vector<long long> labels = {0, -(1LL << 40), 1};
  CHECK(iclap::test::what_of([&] { iclap::write_labeled_cloud_ply(path, p, labels); }) ==
        "labels: label -1099511627776 of point 1 does not fit a PLY int");
  const std::vector<long long> edge = {0, std::numeric_limits<std::int32_t>::min() - 1LL, 1};
  CHECK(iclap::test::argument_of([&] { iclap::write_labeled_cloud_ply(path, p, edge); }) == "labels");
  CHECK_FALSE(std::filesystem::exists(path));
  CHECK_FALSE(iclap::test::temporary_left_beside(path));
  // The smallest int32 label is written.
  const std::vector<long long> lowest = {0, std::numeric_limits<std::int32_t>::min(), 1};
  iclap::write_labeled_cloud_ply(path, p, lowest);
  CHECK(slurp(path).find("\n0 0 0 -2147483648 128 128 128\n") != std::string::npos);
}

TEST_CASE("dataset csv writer: names the reader would not take back, and non-finite times and heights, are refused") {
  const Dataset ds = small_dataset(4, true, false);
  Dataset d = ds;
  // A carriage return alone is a line break to the reader.
  d.frames[1].object = "pli\rers";
  CHECK(writer_refusal(d) == "dataset.frames[1].object: 'pli\\x0ders' contains a line break");
  // A row starting with '#' would read as a comment after the header.
  d = ds;
  d.frames[2].object = "#3";
  CHECK(writer_refusal(d) == "dataset.frames[2].object: '#3' starts with '#'");
  // Every coordinate is checked, z too; and the time.
  d = ds;
  d.frames[3].position.z() = std::numeric_limits<double>::quiet_NaN();
  CHECK(writer_refusal(d) == "dataset.frames[3].position: is not finite");
  d = ds;
  d.frames[1].time = std::numeric_limits<double>::infinity();
  CHECK(writer_refusal(d) == "dataset.frames[1].time: is not finite");
  // A comment with a lone carriage return would not read back as written.
  d = ds;
  d.comments = {"fine", "half\rline"};
  CHECK(writer_refusal(d) == "dataset.comments[1]: contains a line break");
  TempDir dir("data_mutants_comment");
  CHECK(iclap::test::argument_of([&] { iclap::DatasetCsvAppender app(dir.file("c.csv"), 1, 1, false, false, {"a\rb"}); }) ==
        "comments[0]");
  CHECK_FALSE(std::filesystem::exists(dir.file("c.csv")));
}

TEST_CASE("dataset csv reader: a '#' name after blanks, a lone BOM, a 10-digit taxel index, a directory") {
  // Trimmed, the name starts with '#': refused like the writer refuses it.
  CHECK(reader_refusal("object,exploration,frame,x,y,z,p0_0\n  #3,0,0,0,0,0,1\n") ==
        "2: column 'object': name '#3' starts with '#'");
  // A byte-order mark and nothing else is an empty file, not a header.
  CHECK(reader_refusal("\xEF\xBB\xBF") == "0: no header row (the file has no columns)");
  // Taxel indices have at most 9 digits: p1000000000_0 is an unknown column
  // (warned about), not row 10^9 of a grid with a hole.
  std::istringstream in("object,exploration,frame,x,y,z,p0_0,p1000000000_0\na,0,0,0,0,0,1,2\n");
  std::vector<iclap::DatasetWarning> warnings;
  const Dataset ds = iclap::read_dataset_csv(in, "mem.csv", [&](const iclap::DatasetWarning& w) { warnings.push_back(w); });
  CHECK(ds.rows == 1);
  CHECK(ds.cols == 1);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings[0].to_string() == "mem.csv:1: warning: ignoring unknown column 'p1000000000_0'");
  // A directory is named as one (not a bare read failure).
  TempDir dir("data_mutants_dir");
  CHECK(iclap::test::what_of<iclap::IoError>([&] { (void)iclap::read_dataset_csv(dir.path.string()); }) ==
        dir.path.string() + ": is a directory, not a dataset file");
}

TEST_CASE("dataset csv appender: blank lines are no rows; a long list of missing columns is counted") {
  TempDir dir("data_mutants_appender_misc");
  const std::string path = dir.file("blank.csv");
  spit(path, "object,exploration,frame,x,y,z,p0_0\n\na,0,0,0,0,0,1\n  \nb,0,1,0,0,0,2\n\n");
  {
    iclap::DatasetCsvAppender app(path, 1, 1, false, false);
    CHECK(app.rows_in_file() == 2);
  }
  // Six taxel columns missing: five named, then "and 1 more".
  try {
    iclap::DatasetCsvAppender app(path, 1, 7, false, false);
    FAIL("accepted");
  } catch (const iclap::ParseError& e) {
    CHECK(e.line() == 1);
    CHECK(e.reason() ==
          "header does not match the recorder's columns (1x7 taxels, t no, quaternion no): missing 'p0_1', 'p0_2', "
          "'p0_3', 'p0_4', 'p0_5' and 1 more");
  }
}

TEST_CASE("labeled cloud ply: a comment with a lone carriage return is refused") {
  const TempDir dir("data_mutants_ply_comment");
  const std::string path = dir.file("c.ply");
  const Eigen::Matrix3Xd p = Eigen::Matrix3Xd::Zero(3, 1);
  iclap::LabeledCloudPlyOptions options;
  options.comments = {"half\rline"};
  CHECK(iclap::test::what_of([&] { iclap::write_labeled_cloud_ply(path, p, std::vector<int>{0}, options); }) ==
        "options.comments: a comment contains a line break");
  CHECK_FALSE(std::filesystem::exists(path));
}
