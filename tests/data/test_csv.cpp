// SPDX-License-Identifier: MIT
// Dataset CSV: exact round trip, every malformed case of the format spec,
// CRLF/BOM, warnings, the streaming appender, summary helpers.

#include <doctest/doctest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "iclap/core/random.hpp"
#include "iclap/data/data.hpp"
#include "data_test_util.hpp"
#include "../support/file_size_limit.hpp"
#include "../support/temporaries.hpp"

namespace {

namespace fs = std::filesystem;
using iclap::Dataset;
using iclap::DatasetWarning;
using iclap::Frame;
using iclap::test::TempDir;
using iclap::test::writer_refusal;

std::string fixture(const std::string& name) { return std::string(ICLAP_TEST_FIXTURES) + "/data/" + name; }

using iclap::test::slurp;
using iclap::test::spit;
using iclap::test::appended_frame;

Dataset read_text(const std::string& text, std::vector<DatasetWarning>* warnings = nullptr) {
  std::istringstream in(text);
  return iclap::read_dataset_csv(in, "mem.csv", [&](const DatasetWarning& w) {
    if (warnings) warnings->push_back(w);
  });
}

// Values chosen to break any formatting that is not shortest-round-trip.
Dataset awkward_dataset(bool time, bool orientation) {
  Dataset ds;
  ds.rows = 3;
  ds.cols = 2;
  ds.comments = {"sensor: test rows=3 cols=2", "", " leading space kept", "a # inside, commas too"};
  iclap::Rng rng(42);
  const double specials[] = {0.1, 1.0 / 3.0, 5e-324, 1e-300, 1.7976931348623157e308,
                             -0.0, 123456789.125, 4095, 2.2250738585072014e-308};
  for (int i = 0; i < 40; ++i) {
    Frame f;
    f.object = i % 3 == 0 ? "pliers_1" : (i % 3 == 1 ? "fixed wrench (2)" : "ÄÖ_utf8");
    f.exploration = i % 2 == 0 ? i / 7 : (std::int64_t(1) << 62) + i;
    f.frame = i % 5 == 0 ? -i : i;
    f.position = {rng.normal(0, 0.1), specials[i % 9] * (i % 2 ? -1 : 1), rng.uniform() * 1e-9};
    if (time) f.time = i * 0.2;
    if (orientation) {
      Eigen::Quaterniond q(rng.normal(), rng.normal(), rng.normal(), rng.normal());
      q.normalize();
      f.orientation = q;
    }
    f.pressures.resize(3, 2);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 2; ++c)
        f.pressures(r, c) = (r + c + i) % 4 == 0 ? std::abs(specials[(r * 2 + c + i) % 9])
                                                 : std::floor(rng.uniform(0, 4096));
    ds.frames.push_back(f);
  }
  return ds;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void check_identical(const Dataset& a, const Dataset& b) {
  REQUIRE(a.rows == b.rows);
  REQUIRE(a.cols == b.cols);
  CHECK(a.comments == b.comments);
  REQUIRE(a.frames.size() == b.frames.size());
  for (std::size_t i = 0; i < a.frames.size(); ++i) {
    const Frame& x = a.frames[i];
    const Frame& y = b.frames[i];
    CAPTURE(i);
    CHECK(x.object == y.object);
    CHECK(x.exploration == y.exploration);
    CHECK(x.frame == y.frame);
    for (int k = 0; k < 3; ++k) CHECK(same_bits(x.position[k], y.position[k]));
    REQUIRE(x.time.has_value() == y.time.has_value());
    if (x.time) CHECK(same_bits(*x.time, *y.time));
    REQUIRE(x.orientation.has_value() == y.orientation.has_value());
    if (x.orientation)
      for (int k = 0; k < 4; ++k) CHECK(same_bits(x.orientation->coeffs()[k], y.orientation->coeffs()[k]));
    REQUIRE(x.pressures.rows() == y.pressures.rows());
    REQUIRE(x.pressures.cols() == y.pressures.cols());
    for (Eigen::Index k = 0; k < x.pressures.size(); ++k)
      CHECK(same_bits(x.pressures.data()[k], y.pressures.data()[k]));
  }
}

// Expects a ParseError at `line` whose reason contains `reason_part`, and no
// warnings delivered.
void check_rejected(const std::string& text, std::size_t line, const std::string& reason_part) {
  std::vector<DatasetWarning> warnings;
  bool thrown = false;
  try {
    read_text(text, &warnings);
  } catch (const iclap::ParseError& e) {
    thrown = true;
    CHECK(e.file() == "mem.csv");
    CHECK(e.line() == line);
    CHECK_MESSAGE(e.reason().find(reason_part) != std::string::npos, e.what());
    CHECK(std::string(e.what()).rfind("mem.csv:" + std::to_string(line) + ": ", 0) == 0);
  }
  CHECK_MESSAGE(thrown, "not rejected: " << text);
  CHECK(warnings.empty());
}

const char* kHeader = "object,exploration,frame,x,y,z,p0_0,p0_1,p1_0,p1_1\n";

}  // namespace

TEST_CASE("dataset csv: write then read is exact, bytes deterministic") {
  for (bool time : {false, true})
    for (bool orientation : {false, true}) {
      CAPTURE(time);
      CAPTURE(orientation);
      const Dataset ds = awkward_dataset(time, orientation);
      std::ostringstream a, b;
      iclap::write_dataset_csv(a, ds);
      iclap::write_dataset_csv(b, ds);
      CHECK(a.str() == b.str());
      const Dataset back = read_text(a.str());
      check_identical(ds, back);
      std::ostringstream again;
      iclap::write_dataset_csv(again, back);
      CHECK(again.str() == a.str());
    }
}

TEST_CASE("dataset csv: writer header order and number text") {
  Dataset ds;
  ds.rows = 1;
  ds.cols = 2;
  Frame f;
  f.object = "a";
  f.exploration = 3;
  f.frame = 7;
  f.position = {0.1, -0.0, 1e-5};
  f.time = 1.4;
  f.orientation = Eigen::Quaterniond(1, 0, 0, 0);
  f.pressures.resize(1, 2);
  f.pressures << 0, 4095;
  ds.frames.push_back(f);
  ds.comments = {"c"};
  std::ostringstream out;
  iclap::write_dataset_csv(out, ds);
  CHECK(out.str() ==
        "# c\nobject,exploration,frame,t,x,y,z,qw,qx,qy,qz,p0_0,p0_1\n"
        "a,3,7,1.4,0.1,-0,1e-05,1,0,0,0,0,4095\n");
}

TEST_CASE("dataset csv: file round trip goes through an atomic write") {
  TempDir dir("data_file");
  const Dataset ds = awkward_dataset(true, true);
  const std::string path = dir.file("out.csv");
  iclap::write_dataset_csv(path, ds);
  CHECK_FALSE(iclap::test::temporary_left_beside(path));
  check_identical(ds, iclap::read_dataset_csv(path));

  // An invalid dataset writes nothing and leaves the old file as it was.
  const std::string before = slurp(path);
  Dataset bad = ds;
  bad.frames[17].object = "a,b";
  CHECK_THROWS_AS(iclap::write_dataset_csv(path, bad), iclap::InvalidArgument);
  CHECK(slurp(path) == before);
  CHECK_FALSE(iclap::test::temporary_left_beside(path));
}

TEST_CASE("dataset csv: writer rejects invalid datasets naming the field") {
  Dataset ds = awkward_dataset(true, false);
  auto rejects = [](const Dataset& d, const std::string& argument) {
    const std::string r = writer_refusal(d);
    CHECK_MESSAGE(r.rfind(argument + ": ", 0) == 0, r);
  };
  Dataset d = ds;
  d.frames[3].object = "quote\"d";
  rejects(d, "dataset.frames[3].object");
  d = ds;
  d.frames[4].pressures(1, 1) = -1;
  rejects(d, "dataset.frames[4].pressures");
  d = ds;
  d.frames[5].pressures(0, 0) = std::numeric_limits<double>::quiet_NaN();
  rejects(d, "dataset.frames[5].pressures");
  Dataset oriented = awkward_dataset(true, true);
  oriented.frames[6].orientation->coeffs() *= 1.01;
  rejects(oriented, "dataset.frames[6].orientation");
  d = ds;
  d.frames[6].pressures.resize(2, 2);
  rejects(d, "dataset.frames[6].pressures");
  d = ds;
  d.frames[7].time.reset();
  rejects(d, "dataset.frames[7].time");
  d = ds;
  d.frames[8].position.y() = std::numeric_limits<double>::infinity();
  rejects(d, "dataset.frames[8].position");
  d = ds;
  d.comments.push_back("two\nlines");
  rejects(d, "dataset.comments[4]");
  d = ds;
  d.cols = 0;
  rejects(d, "dataset.rows/cols");
  // What the reader refuses, the writer does not write: a name that is not
  // UTF-8, two frames with the same object, exploration and frame index.
  d = ds;
  d.frames[2].object = "h\xe4mmer";
  rejects(d, "dataset.frames[2].object");
  d = ds;
  d.frames[9].object = d.frames[1].object;
  d.frames[9].exploration = d.frames[1].exploration;
  d.frames[9].frame = d.frames[1].frame;
  rejects(d, "dataset.frames[9]");
  CHECK(writer_refusal(d).find("is also dataset.frames[1] (one row per frame)") != std::string::npos);
}

TEST_CASE("dataset csv: names with outer white space, orientations not fitting the file are refused naming the frame") {
  // The reader trims the fields, so a name with white space at either end
  // would not read back as written. Inside, a space or a tab is kept.
  const Dataset plain = awkward_dataset(false, false);
  // (The message shows a tab escaped, as \x09.)
  const std::pair<std::string, std::string> outer[] = {
      {" pliers", "' pliers'"}, {"pliers ", "'pliers '"}, {"\tpliers", "'\\x09pliers'"},
      {"pliers\t", "'pliers\\x09'"}, {" ", "' '"}};
  for (const auto& o : outer) {
    CAPTURE(o.second);
    Dataset d = plain;
    d.frames[9].object = o.first;
    CHECK(writer_refusal(d) == "dataset.frames[9].object: " + o.second + " has leading or trailing white space");
  }
  Dataset inner = plain;
  inner.frames[9].object = "wooden cuboid\t1";
  CHECK(writer_refusal(inner) == "(no error)");

  // The file has quaternion columns when the first frame has an orientation;
  // a later frame without one, or a frame with one in a file without them, or
  // a non-finite one, is refused naming that frame.
  const Dataset oriented = awkward_dataset(true, true);
  Dataset d = oriented;
  d.frames[11].orientation.reset();
  CHECK(writer_refusal(d) == "dataset.frames[11].orientation: is missing, the file has qw,qx,qy,qz columns");
  d = plain;
  d.frames[12].orientation = Eigen::Quaterniond(1, 0, 0, 0);
  CHECK(writer_refusal(d) == "dataset.frames[12].orientation: is set, the file has no quaternion columns");
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()})
    for (int k = 0; k < 4; ++k) {
      CAPTURE(bad);
      CAPTURE(k);
      d = oriented;
      d.frames[13].orientation->coeffs()[k] = bad;
      CHECK(writer_refusal(d) == "dataset.frames[13].orientation: is not finite");
    }

  // The appender checks each frame against its file's columns the same way,
  // naming the argument "frame", and writes nothing.
  TempDir dir("data_orientation");
  const std::string with_q = dir.file("with_q.csv"), without_q = dir.file("without_q.csv");
  iclap::DatasetCsvAppender app_q(with_q, oriented.rows, oriented.cols, true, true);
  iclap::DatasetCsvAppender app(without_q, plain.rows, plain.cols, false, false);
  app_q.append(oriented.frames[0]);
  app.append(plain.frames[0]);
  const std::string before_q = slurp(with_q), before = slurp(without_q);
  Frame f = oriented.frames[1];
  f.orientation.reset();
  CHECK_THROWS_WITH_AS(app_q.append(f), "frame.orientation: is missing, the file has qw,qx,qy,qz columns",
                       iclap::InvalidArgument);
  f = oriented.frames[1];
  f.orientation->coeffs()[2] = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH_AS(app_q.append(f), "frame.orientation: is not finite", iclap::InvalidArgument);
  f = plain.frames[1];
  f.orientation = Eigen::Quaterniond(0, 1, 0, 0);
  CHECK_THROWS_WITH_AS(app.append(f), "frame.orientation: is set, the file has no quaternion columns",
                       iclap::InvalidArgument);
  f = plain.frames[1];
  f.object = "pliers_1 ";
  CHECK_THROWS_WITH_AS(app.append(f), "frame.object: 'pliers_1 ' has leading or trailing white space",
                       iclap::InvalidArgument);
  CHECK(slurp(with_q) == before_q);
  CHECK(slurp(without_q) == before);
  CHECK(app_q.rows_in_file() == 1);
  CHECK(app.rows_in_file() == 1);
}

TEST_CASE("dataset csv: reader accepts comments, any column order, CRLF and a BOM") {
  const std::string text =
      "# first\n#second\n\n"
      "p1_1,z,p0_0,frame,y,object,t,x,exploration,p1_0,p0_1\n"
      "4,0.3,1,5,0.2,obj,0.5,0.1,2,3,2\n";
  const Dataset a = read_text(text);
  REQUIRE(a.frames.size() == 1);
  CHECK(a.comments == std::vector<std::string>{"first", "second"});
  CHECK(a.rows == 2);
  CHECK(a.cols == 2);
  const Frame& f = a.frames[0];
  CHECK(f.object == "obj");
  CHECK(f.exploration == 2);
  CHECK(f.frame == 5);
  CHECK(f.position == Eigen::Vector3d(0.1, 0.2, 0.3));
  REQUIRE(f.time.has_value());
  CHECK(*f.time == 0.5);
  CHECK_FALSE(f.orientation.has_value());
  CHECK(f.pressures(0, 0) == 1);
  CHECK(f.pressures(0, 1) == 2);
  CHECK(f.pressures(1, 0) == 3);
  CHECK(f.pressures(1, 1) == 4);

  // Same content with CRLF and a byte-order mark.
  std::string crlf = "\xEF\xBB\xBF";
  for (char ch : text) {
    if (ch == '\n') crlf += '\r';
    crlf += ch;
  }
  check_identical(a, read_text(crlf));
  // Without a final line break too.
  check_identical(a, read_text(text.substr(0, text.size() - 1)));
}

TEST_CASE("dataset csv: unknown columns are ignored with a warning that names them") {
  std::vector<DatasetWarning> warnings;
  const Dataset ds = read_text(
      "# c\nobject,note,exploration,frame,x,y,z,p0_0,,P0_1,p00_1\n"
      "a,hello,0,0,1,2,3,7,x,y,z\n",
      &warnings);
  REQUIRE(ds.frames.size() == 1);
  CHECK(ds.cols == 1);
  CHECK(ds.frames[0].pressures(0, 0) == 7);
  REQUIRE(warnings.size() == 4);
  CHECK(warnings[0].line == 2);
  CHECK(warnings[0].message == "ignoring unknown column 'note'");
  CHECK(warnings[0].to_string() == "mem.csv:2: warning: ignoring unknown column 'note'");
  CHECK(warnings[1].message == "ignoring unnamed column 9");
  CHECK(warnings[2].message == "ignoring unknown column 'P0_1'");
  CHECK(warnings[3].message == "ignoring unknown column 'p00_1'");
}

TEST_CASE("dataset csv: every malformed case of the spec is rejected with its line") {
  const std::string h = kHeader;
  const std::string ok = "a,0,0,0.1,0.2,0.3,1,2,3,4\n";
  // Missing required columns (header on line 2, after one comment).
  for (const std::string col : {"object", "exploration", "frame", "x", "y", "z"}) {
    std::string header = "object,exploration,frame,x,y,z,p0_0";
    const auto at = header.find(col + ",");
    header.erase(at, col.size() + 1);
    check_rejected("# c\n" + header + "\n", 2, "missing required column '" + col + "'");
  }
  check_rejected("object,exploration,frame,x,y,z\n" + ok, 1, "taxel columns");
  // A hole in the taxel grid.
  check_rejected("object,exploration,frame,x,y,z,p0_0,p0_1,p1_1\n", 1, "missing column 'p1_0'");
  check_rejected("object,exploration,frame,x,y,z,p2_0\n", 1, "has a hole");
  // Wrong number of fields.
  check_rejected(h + ok + "a,0,1,0.1,0.2,0.3,1,2,3\n", 3, "expected 10 fields");
  check_rejected(h + "a,0,1,0.1,0.2,0.3,1,2,3,4,5\n", 2, "got 11");
  // Values that are not finite numbers.
  for (const std::string v : {"abc", "nan", "inf", "-inf", "", "1.5.2", "0x10", "1e999", "+-1", "1 2"}) {
    CAPTURE(v);
    check_rejected(h + ok + "a,0,1,0.1,0.2,0.3,1,2,3,4\n" + "a,0,2," + v + ",0.2,0.3,1,2,3,4\n", 4,
                   "is not a finite number");
    check_rejected(h + "a,0,0,0.1,0.2,0.3,1,2," + v + ",4\n", 2, "column 'p1_0'");
  }
  // A control byte in a field is shown escaped: a raw NUL cut the message short.
  {
    using namespace std::string_literals;
    check_rejected(h + "a,0,0,0\0" "1,0.2,0.3,1,2,3,4\n"s, 2, "column 'x': '0\\x001' is not a finite number");
    check_rejected(h + "a,0,0,0.1,0.2,0.3,1,2,\x1b[31m,4\n", 2, "'\\x1b[31m' is not a finite number");
  }
  // Negative pressure.
  check_rejected(h + ok + "a,0,0,0.1,0.2,0.3,1,-2,3,4\n", 3, "negative pressure -2");
  // Non-integer exploration or frame.
  for (const std::string v : {"1.5", "1e3", "x", "", "9223372036854775808"}) {
    CAPTURE(v);
    check_rejected(h + "a," + v + ",0,0.1,0.2,0.3,1,2,3,4\n", 2, "column 'exploration'");
    check_rejected(h + ok + "a,0," + v + ",0.1,0.2,0.3,1,2,3,4\n", 3, "is not an integer");
  }
  // A quaternion with only some of its components.
  check_rejected("object,exploration,frame,x,y,z,qw,qx,p0_0\n", 1,
                 "quaternion has only some of its components: qw, qx present, qy, qz missing");
  check_rejected("object,exploration,frame,x,y,z,qz,p0_0\n", 1, "quaternion");
  // Also rejected: empty quaternion fields, duplicate columns, comments after
  // the header, names with quotes, no header at all.
  check_rejected("object,exploration,frame,x,y,z,qw,qx,qy,qz,p0_0\na,0,0,1,2,3,1,0,,0,5\n", 2,
                 "column 'qy'");
  check_rejected("object,exploration,frame,x,y,z,x,p0_0\n", 1, "duplicate column 'x'");
  check_rejected("object,exploration,frame,x,y,z,p0_0,p0_0\n", 1, "duplicate column 'p0_0'");
  check_rejected(h + ok + "# late\n", 3, "comment line after the header");
  check_rejected(h + "\"a\",0,0,0.1,0.2,0.3,1,2,3,4\n", 2, "contains a quote");
  {
    using namespace std::string_literals;
    check_rejected(h + "pli\0ers,0,0,0.1,0.2,0.3,1,2,3,4\n"s, 2, "name 'pli\\x00ers' contains a control character");
    check_rejected(h + "a\x1b[2Jb,0,0,0.1,0.2,0.3,1,2,3,4\n", 2, "contains a control character");
  }
  CHECK(read_text(h + "tab\tname,0,0,0.1,0.2,0.3,1,2,3,4\n").frames.at(0).object == "tab\tname");
  check_rejected("# only a comment\n", 1, "no header row");
  // A comment the writer could not write back (a lone carriage return).
  check_rejected("# fine\n# half\rline\n" + h, 2, "carriage return");
  // Line breaks are \n or \r\n; a stray carriage return in the header or a
  // row would end up inside its last field (a column 'p0_1\r' lost to the
  // unknown-column warning), and a file with \r line breaks is one line.
  std::string crcr = h;
  crcr.insert(crcr.size() - 1, "\r\r");
  check_rejected(crcr + ok, 1, "carriage return inside the line");
  std::string row_cr = ok;
  row_cr.insert(row_cr.size() - 1, "\r\r");
  check_rejected(h + row_cr, 2, "carriage return inside the line");
  std::string cr_only = h + ok;
  std::replace(cr_only.begin(), cr_only.end(), '\n', '\r');
  check_rejected(cr_only, 1, "carriage return inside the line");
  check_rejected(h + "a,0,0,0.1,0.2,1e-400,1,2,3,4\n", 2, "column 'z'");
  // The pad orientation is a unit quaternion (spec); 4 significant digits
  // are enough, a zero or scaled quaternion is refused.
  const std::string hq = "object,exploration,frame,x,y,z,qw,qx,qy,qz,p0_0\n";
  CHECK(read_text(hq + "a,0,0,0,0,0,0.7071,0.7071,0,0,5\n").frames.size() == 1);
  check_rejected(hq + "a,0,0,0,0,0,1,0,0,0,5\na,0,1,0,0,0,0,0,0,0,5\n", 3,
                 "columns qw,qx,qy,qz: the quaternion has norm 0; the pad orientation must be a unit quaternion");
  check_rejected(hq + "a,0,0,0,0,0,2,0,0,0,5\n", 2, "has norm 2;");
  check_rejected("", 0, "no header row");
  // One row per frame: a second row of the same object, exploration and
  // frame names the first's line; the same frame index of another
  // exploration or object, and frames out of order, are fine.
  check_rejected(h + ok + "a,0,1,0.1,0.2,0.3,1,2,3,4\n" + ok, 4,
                 "frame 0 of exploration 0 of object 'a' is already on line 2 (one row per frame)");
  CHECK(read_text(h + ok + "a,1,0,0.1,0.2,0.3,1,2,3,4\nb,0,0,0.1,0.2,0.3,1,2,3,4\n").frames.size() == 3);
  CHECK(read_text(h + "a,0,5,0.1,0.2,0.3,1,2,3,4\n" + ok).frames.at(1).frame == 0);
  // Object names are UTF-8 text (the spec): a Latin-1 name or a cut
  // character is refused with the byte; any well-formed name is taken.
  check_rejected(h + "h\xe4mmer,0,0,0.1,0.2,0.3,1,2,3,4\n", 2,
                 "is not UTF-8: byte 0xE4 at offset 1 starts no well-formed character");
  check_rejected(h + ok + "pliers\xc3,0,0,0.1,0.2,0.3,1,2,3,4\n", 3, "is not UTF-8: byte 0xC3 at offset 6");
  check_rejected(h + "\xed\xa0\x80,0,0,0.1,0.2,0.3,1,2,3,4\n", 2, "is not UTF-8: byte 0xED at offset 0");
  CHECK(read_text(h + "h\xc3\xa4mmer,0,0,0.1,0.2,0.3,1,2,3,4\n").frames.at(0).object == "h\xc3\xa4mmer");
}

TEST_CASE("dataset csv: fixtures and summary helpers") {
  std::vector<DatasetWarning> warnings;
  const Dataset ds = iclap::read_dataset_csv(fixture("small.csv"),
                                             [&](const DatasetWarning& w) { warnings.push_back(w); });
  CHECK(warnings.empty());
  CHECK(ds.rows == 2);
  CHECK(ds.cols == 3);
  CHECK(ds.frames.size() == 7);
  CHECK(iclap::object_names(ds) == std::vector<std::string>{"pliers_1", "wooden_cuboid_1"});
  CHECK(iclap::explorations_of(ds, "pliers_1") == std::vector<std::int64_t>{0, 1});
  CHECK(iclap::explorations_of(ds, "wooden_cuboid_1") == std::vector<std::int64_t>{0});
  CHECK(iclap::explorations_of(ds, "nothing").empty());
  // Contacts: frame maxima are 0, 4095, 0, 15, 0, 310, 305.
  CHECK(iclap::contact_frame_count(ds) == 3);
  CHECK(iclap::contact_frame_count(ds, 10.0) == 4);
  CHECK(iclap::contact_frame_count(ds, 0.0) == 4);
  CHECK(iclap::contact_frame_count(ds, 4095.0) == 0);
  const auto summary = iclap::summarize(ds);
  REQUIRE(summary.size() == 2);
  CHECK(summary[0].name == "pliers_1");
  CHECK(summary[0].frames == 4);
  CHECK(summary[0].contact_frames == 1);
  CHECK(summary[1].explorations.size() == 1);
  CHECK(summary[1].contact_frames == 2);

  try {
    iclap::read_dataset_csv(fixture("bad_negative_pressure.csv"));
    FAIL("accepted");
  } catch (const iclap::ParseError& e) {
    CHECK(e.line() == 4);
    CHECK(e.file() == fixture("bad_negative_pressure.csv"));
  }
  CHECK_THROWS_AS(iclap::read_dataset_csv(fixture("does_not_exist.csv")), iclap::IoError);
  CHECK_THROWS_AS(iclap::read_dataset_csv(std::string(ICLAP_TEST_FIXTURES)), iclap::IoError);
  CHECK_THROWS_AS(iclap::DatasetCsvAppender(std::string(ICLAP_TEST_FIXTURES), 1, 1, false, false), iclap::IoError);
}

TEST_CASE("dataset csv appender: create, append, reopen, mismatched header, complete rows") {
  TempDir dir("data_appender");
  const std::string path = dir.file("log.csv");
  const Dataset ds = awkward_dataset(true, true);
  const iclap::DatasetColumns columns{ds.rows, ds.cols, true, true};
  {
    iclap::DatasetCsvAppender app(path, ds.rows, ds.cols, true, true, ds.comments);
    CHECK(app.rows_in_file() == 0);
    for (std::size_t i = 0; i < 25; ++i) {
      app.append(ds.frames[i]);
      // After every append the file is complete rows only and reads back.
      const std::string text = slurp(path);
      REQUIRE(text.back() == '\n');
      CHECK(iclap::read_dataset_csv(path).frames.size() == i + 1);
    }
    CHECK(app.rows_in_file() == 25);
    // An invalid frame writes nothing.
    Frame bad = ds.frames[0];
    bad.time.reset();
    const std::string before = slurp(path);
    CHECK_THROWS_AS(app.append(bad), iclap::InvalidArgument);
    bad = ds.frames[0];
    bad.pressures(0, 0) = -1;
    CHECK_THROWS_AS(app.append(bad), iclap::InvalidArgument);
    // The pressure as it is: std::to_string showed -1e-9 as -0.000000.
    bad.pressures(0, 0) = -1e-9;
    CHECK_THROWS_WITH_AS(app.append(bad), doctest::Contains("taxel p0_0 is -1e-09, pressures must be"),
                         iclap::InvalidArgument);
    CHECK(slurp(path) == before);
    // A moved-from appender refuses to append (it wrote through a null FILE).
    iclap::DatasetCsvAppender moved(std::move(app));
    CHECK_THROWS_WITH_AS(app.append(ds.frames[0]), doctest::Contains("moved from"), iclap::WriteError);  // NOLINT(bugprone-use-after-move)
    CHECK(slurp(path) == before);
  }
  {
    // Reopen and append: the comments are not repeated.
    iclap::DatasetCsvAppender app(path, columns, {"ignored on reopen"});
    CHECK(app.rows_in_file() == 25);
    CHECK(app.recovered_bytes() == 0);
    for (std::size_t i = 25; i < ds.frames.size(); ++i) app.append(ds.frames[i]);
    app.sync();
  }
  check_identical(ds, iclap::read_dataset_csv(path));
  // The appender writes exactly what the writer writes.
  std::ostringstream whole;
  iclap::write_dataset_csv(whole, ds);
  CHECK(slurp(path) == whole.str());

  // A partial last row (crash mid-write) is cut off on reopen.
  {
    std::ofstream(path, std::ios::binary | std::ios::app) << "pliers_1,0,0,0.1,0.2";
    iclap::DatasetCsvAppender app(path, columns);
    CHECK(app.recovered_bytes() == std::string("pliers_1,0,0,0.1,0.2").size());
    CHECK(app.rows_in_file() == ds.frames.size());
  }
  CHECK(slurp(path) == whole.str());

  // Mismatched header: rejected with file and header line, file untouched.
  const std::string before = slurp(path);
  try {
    iclap::DatasetCsvAppender app(path, ds.rows, ds.cols, false, true);
    FAIL("accepted");
  } catch (const iclap::ParseError& e) {
    CHECK(e.file() == path);
    CHECK(e.line() == ds.comments.size() + 1);
    CHECK_MESSAGE(e.reason().find("unexpected 't'") != std::string::npos, e.what());
  }
  try {
    iclap::DatasetCsvAppender app(path, ds.rows + 1, ds.cols, true, true);
    FAIL("accepted");
  } catch (const iclap::ParseError& e) {
    CHECK_MESSAGE(e.reason().find("missing 'p3_0'") != std::string::npos, e.what());
  }
  CHECK(slurp(path) == before);

  // A mismatched header is refused before a partial last row is cut off:
  // a file the appender refuses is not changed at all.
  std::ofstream(path, std::ios::binary | std::ios::app) << "pliers_1,0,0,0.1";
  const std::string with_partial = slurp(path);
  CHECK_THROWS_AS(iclap::DatasetCsvAppender(path, ds.rows, ds.cols, false, true), iclap::ParseError);
  CHECK(slurp(path) == with_partial);
  {
    iclap::DatasetCsvAppender app(path, columns);
    CHECK(app.recovered_bytes() == std::string("pliers_1,0,0,0.1").size());
  }
  CHECK(slurp(path) == before);

  // A last line with every field but no line break may be a whole row (or
  // one cut in its last number): refused, naming the line, file unchanged.
  const std::string whole_row = whole.str().substr(whole.str().rfind('\n', whole.str().size() - 2) + 1);
  const std::string unterminated = before + whole_row.substr(0, whole_row.size() - 1);
  spit(path, unterminated);
  try {
    iclap::DatasetCsvAppender app(path, columns);
    FAIL("accepted");
  } catch (const iclap::ParseError& e) {
    CHECK(e.file() == path);
    CHECK(e.line() == ds.comments.size() + 1 + ds.frames.size() + 1);
    CHECK_MESSAGE(e.reason().find("but no line break") != std::string::npos, e.what());
  }
  CHECK(slurp(path) == unterminated);
  spit(path, before);
}

TEST_CASE("dataset csv appender: a failed write leaves complete rows only") {
  TempDir dir("data_appender_full");
  const std::string path = dir.file("log.csv");
  const Dataset ds = awkward_dataset(true, true);
  std::size_t written = 0;
  {
    iclap::DatasetCsvAppender app(path, ds.rows, ds.cols, true, true, ds.comments);
    const auto size = std::filesystem::file_size(path);
    iclap::test::FileSizeLimit limit(size + 150);  // room for a row or two
    REQUIRE(limit.ok());
    bool failed = false;
    for (const auto& f : ds.frames) {
      try {
        app.append(f);
        ++written;
      } catch (const iclap::WriteError& e) {
        CHECK_MESSAGE(std::string(e.what()).find("cut back to its last complete row") != std::string::npos, e.what());
        failed = true;
        break;
      }
    }
    REQUIRE(failed);
    CHECK_THROWS_AS(app.append(ds.frames[0]), iclap::WriteError);  // closed
  }
  REQUIRE(written < ds.frames.size());
  const std::string text = slurp(path);
  CHECK(text.back() == '\n');
  CHECK(iclap::read_dataset_csv(path).frames.size() == written);
}

TEST_CASE("dataset csv appender: foreign column order and an empty file") {
  TempDir dir("data_appender2");
  const std::string path = dir.file("foreign.csv");
  spit(path, "\xEF\xBB\xBF# exported\r\nz,y,x,p0_1,p0_0,frame,exploration,object\r\n0.3,0.2,0.1,2,1,0,0,a\r\n");
  const Frame f = appended_frame();
  {
    iclap::DatasetCsvAppender app(path, 1, 2, false, false);
    CHECK(app.rows_in_file() == 1);
    app.append(f);
  }
  const Dataset ds = iclap::read_dataset_csv(path);
  REQUIRE(ds.frames.size() == 2);
  CHECK(ds.frames[1].object == "b");
  CHECK(ds.frames[1].exploration == 4);
  CHECK(ds.frames[1].position == Eigen::Vector3d(1, 2, 3));
  CHECK(ds.frames[1].pressures(0, 1) == 6);
  const std::string text = slurp(path);
  const std::string tail = "\r\n3,2,1,6,5,1,4,b\n";
  CHECK(text.compare(text.size() - tail.size(), tail.size(), tail) == 0);

  const std::string empty = dir.file("empty.csv");
  spit(empty, "");
  {
    iclap::DatasetCsvAppender app(empty, 1, 2, false, false, {"hello"});
    app.append(f);
  }
  CHECK(slurp(empty) == "# hello\nobject,exploration,frame,x,y,z,p0_0,p0_1\nb,4,1,1,2,3,5,6\n");

  // A file of comments only cannot be appended to.
  const std::string headless = dir.file("headless.csv");
  spit(headless, "# a\n# b\n");
  CHECK_THROWS_AS(iclap::DatasetCsvAppender(headless, 1, 2, false, false), iclap::ParseError);
}

TEST_CASE("dataset csv appender: an existing file that ends with its header, without a line break, gets one first") {
  TempDir dir("data_appender_header_only");
  const std::string path = dir.file("header.csv");
  spit(path, "# c\nobject,exploration,frame,x,y,z,p0_0,p0_1");
  const Frame f = appended_frame();
  {
    iclap::DatasetCsvAppender app(path, 1, 2, false, false);
    CHECK(app.rows_in_file() == 0);
    CHECK(app.recovered_bytes() == 0);
    app.append(f);
  }
  // Not "...,p0_1b,4,1,...": the row on a line of its own.
  CHECK(slurp(path) == "# c\nobject,exploration,frame,x,y,z,p0_0,p0_1\nb,4,1,1,2,3,5,6\n");
  CHECK(iclap::read_dataset_csv(path).frames.size() == 1);
}

TEST_CASE("dataset csv appender: a second row of a frame is refused, naming the line of the first, in the file or appended since") {
  // The reader allows one row per (object, exploration, frame); an appender
  // that wrote a second one would leave a file nothing can read.
  TempDir dir("data_appender_duplicate");
  const Frame f = appended_frame();
  // The message for frame F of exploration E of object O (by default those
  // of `f`) already on line `line` of `path`.
  const auto refusal = [](const std::string& path, std::size_t line, int frame = 1, int exploration = 4,
                          const std::string& object = "b") {
    return "frame: frame " + std::to_string(frame) + " of exploration " + std::to_string(exploration) +
           " of object '" + object + "' is already in " + path + ", line " + std::to_string(line) +
           " (one row per frame)";
  };

  // Appended since: two comments and the header, so the row is line 4.
  const std::string path = dir.file("log.csv");
  {
    iclap::DatasetCsvAppender app(path, 1, 2, false, false, {"one", "two"});
    app.append(f);
    const std::string before = slurp(path);
    CHECK_THROWS_WITH_AS(app.append(f), refusal(path, 4).c_str(), iclap::InvalidArgument);
    CHECK(slurp(path) == before);
    CHECK(app.rows_in_file() == 1);
    // Another frame, exploration or object is another row.
    Frame g = f;
    g.frame = 2;
    app.append(g);
    g.exploration = 5;
    app.append(g);
    g.object = "c";
    app.append(g);
    CHECK_THROWS_WITH_AS(app.append(g), refusal(path, 7, 2, 5, "c").c_str(), iclap::InvalidArgument);
    // The index goes with a move.
    iclap::DatasetCsvAppender moved(std::move(app));
    CHECK_THROWS_WITH_AS(moved.append(f), refusal(path, 4).c_str(), iclap::InvalidArgument);
    CHECK(moved.rows_in_file() == 4);
    g.frame = 1;
    moved.append(g);  // line 8
    CHECK_THROWS_WITH_AS(moved.append(g), refusal(path, 8, 1, 5, "c").c_str(), iclap::InvalidArgument);
  }
  CHECK(iclap::read_dataset_csv(path).frames.size() == 5);

  // In the file: its rows are indexed on opening, by the line the reader
  // would name (BOM, CRLF, comments and blank lines counted; any column
  // order; an integer written as the reader reads it, '+4' and '04' are 4).
  const std::string foreign = dir.file("foreign.csv");
  spit(foreign,
       "\xEF\xBB\xBF# exported\r\nz,y,x,p0_1,p0_0,frame,exploration,object\r\n\r\n0.3,0.2,0.1,2,1,0,4,b\r\n"
       "0.3,0.2,0.1,2,1, +1 ,04, b \r\n");
  {
    iclap::DatasetCsvAppender app(foreign, 1, 2, false, false);
    CHECK(app.rows_in_file() == 2);
    CHECK_THROWS_WITH_AS(app.append(f), refusal(foreign, 5).c_str(), iclap::InvalidArgument);
    Frame g = f;
    g.frame = 0;
    CHECK_THROWS_WITH_AS(app.append(g), refusal(foreign, 4, 0, 4, "b").c_str(), iclap::InvalidArgument);
    g.frame = 2;
    app.append(g);  // line 6
    g.frame = 3;
    app.append(g);  // line 7
    g.frame = 2;
    CHECK_THROWS_WITH_AS(app.append(g), refusal(foreign, 6, 2, 4, "b").c_str(), iclap::InvalidArgument);
  }
  CHECK(iclap::read_dataset_csv(foreign).frames.size() == 4);

  // A partial last row cut off on opening is not a row: the next row takes
  // its line, and its frame is free.
  const std::string cut = dir.file("cut.csv");
  spit(cut, "object,exploration,frame,x,y,z,p0_0,p0_1\nb,4,0,1,2,3,5,6\nb,4,1,1,2");
  {
    iclap::DatasetCsvAppender app(cut, 1, 2, false, false);
    CHECK(app.recovered_bytes() == 9);
    app.append(f);  // frame 1, on line 3
    CHECK_THROWS_WITH_AS(app.append(f), refusal(cut, 3).c_str(), iclap::InvalidArgument);
  }
  CHECK(slurp(cut) == "object,exploration,frame,x,y,z,p0_0,p0_1\nb,4,0,1,2,3,5,6\nb,4,1,1,2,3,5,6\n");

  // A file that ends with its header, without a line break: the first row
  // is line 2.
  const std::string header_only = dir.file("header.csv");
  spit(header_only, "object,exploration,frame,x,y,z,p0_0,p0_1");
  {
    iclap::DatasetCsvAppender app(header_only, 1, 2, false, false);
    app.append(f);
    CHECK_THROWS_WITH_AS(app.append(f), refusal(header_only, 2).c_str(), iclap::InvalidArgument);
  }

  // A row whose frame the reader refuses anyway (not an integer) is counted
  // and not indexed: the appender neither fails on it nor guesses its frame.
  const std::string broken = dir.file("broken.csv");
  spit(broken, "object,exploration,frame,x,y,z,p0_0,p0_1\nb,4,one,1,2,3,5,6\nb,4\n");
  {
    iclap::DatasetCsvAppender app(broken, 1, 2, false, false);
    CHECK(app.rows_in_file() == 2);
    app.append(f);
    CHECK_THROWS_WITH_AS(app.append(f), refusal(broken, 4).c_str(), iclap::InvalidArgument);
  }
}

// ---------------------------------------------------------------------------
// Audit (session 50): defects found from a user's side, skipped until fixed.

TEST_CASE("dataset csv: a stream that failed to open is an IoError, not a file without a header") {
  // csv_reader.hpp read_dataset_csv(std::istream&, name) checked only
  // in.bad(): an std::ifstream that could not open the file (failbit only)
  // read as an empty text and gave ParseError "NAME:0: no header row (the
  // file has no columns)", sending the user to look for a header in a file
  // that does not exist. A stream failed on entry is now an IoError naming
  // the file, as the path overload reports a file it cannot open.
  const TempDir dir("csv_failed_stream");
  const std::string path = dir.file("missing.csv");
  std::ifstream in(path, std::ios::binary);
  REQUIRE_FALSE(in.is_open());
  try {
    (void)iclap::read_dataset_csv(in, path);
    FAIL("accepted");
  } catch (const iclap::IoError& e) {
    CHECK(e.path() == path);
    CHECK(std::string(e.what()).rfind(path + ": cannot open for reading", 0) == 0);
  }
  // The path overload says the same (with the system's reason).
  try {
    (void)iclap::read_dataset_csv(path);
    FAIL("accepted");
  } catch (const iclap::IoError& e) {
    CHECK(std::string(e.what()).rfind(path + ": cannot open for reading", 0) == 0);
  }
  // An open empty file is a file without a header, as before; so is a
  // stream already at its end (eofbit only: not failed).
  spit(dir.file("empty.csv"), "");
  std::ifstream empty(dir.file("empty.csv"), std::ios::binary);
  CHECK_THROWS_AS(iclap::read_dataset_csv(empty, "empty.csv"), iclap::ParseError);
  std::istringstream at_end("");
  at_end.setstate(std::ios::eofbit);
  CHECK_THROWS_AS(iclap::read_dataset_csv(at_end, "end.csv"), iclap::ParseError);
}
