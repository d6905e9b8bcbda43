// SPDX-License-Identifier: MIT
// Reproducers of session 58's audit of DatasetCsvAppender (what `iclap
// record` appends through): files left by a creation cut short. Each case
// failed on the code it was written against; its comment says what happened
// before ("Was").

#include <doctest/doctest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "iclap/data/data.hpp"
#include "../support/temporaries.hpp"
#include "data_test_util.hpp"

namespace {

using iclap::Frame;
using iclap::test::slurp;
using iclap::test::spit;
using iclap::test::TempDir;

const std::string kBom = "\xEF\xBB\xBF";
const std::string kHeader = "object,exploration,frame,x,y,z,p0_0,p0_1";  // of a 1x2 grid, no t, no quaternion

using iclap::test::appended_frame;

// The ParseError a 1x2 appender with `comments` throws on `path` ("(none)"
// if it opens), and checks that the file is unchanged.
std::string refusal(const std::string& path, const std::vector<std::string>& comments = {}) {
  const std::string before = slurp(path);
  std::string what = "(none)";
  try {
    iclap::DatasetCsvAppender app(path, 1, 2, false, false, comments);
  } catch (const iclap::ParseError& e) {
    what = e.what();
  }
  CHECK(slurp(path) == before);
  return what;
}

}  // namespace

// Input: a file holding only a UTF-8 byte-order mark (an editor's "new
// file"), which the reader skips.
// Was: ParseError "FILE:0: existing file has no header row; cannot append to
// it", while an empty file is accepted as new.
// Now: treated as an empty file: comments and header are written after the
// BOM, and the reader reads the result.
TEST_CASE("audit: appender treats a file holding only a BOM as an empty one") {
  TempDir dir("audit_h58c_bom");
  const std::string path = dir.file("bom.csv");
  spit(path, kBom);
  try {
    iclap::DatasetCsvAppender app(path, 1, 2, false, false, {"hello"});
    CHECK(app.rows_in_file() == 0);
    CHECK(app.recovered_bytes() == 0);
    CHECK(!app.header_completed());
    app.append(appended_frame());
  } catch (const iclap::Error& e) {
    FAIL_CHECK("appender refused a BOM-only file: " << std::string(e.what()));
  }
  CHECK(slurp(path) == kBom + "# hello\n" + kHeader + "\nb,4,1,1,2,3,5,6\n");
  const iclap::Dataset ds = iclap::read_dataset_csv(path);
  CHECK(ds.frames.size() == 1);
  REQUIRE(ds.comments.size() == 1);
  CHECK(ds.comments[0] == "hello");
}

// Input: files left by a run killed while it wrote the comments and header
// of a new file: the file ends inside them, no line break, no row.
// Was: ParseError "header does not match the recorder's columns (...):
// missing 'y', ...", or "no header row" when cut inside a comment; the user
// was sent to look for a wrong column.
// Now: the beginning of the header line this appender writes (whatever the
// comments before it), or of its comments and header, is completed (the
// rest is appended, nothing is cut) and header_completed() says so.
TEST_CASE("audit: appender completes a header cut short at creation") {
  TempDir dir("audit_h58c_torn");
  const Frame f = appended_frame();
  const std::string row = "b,4,1,1,2,3,5,6\n";
  struct Case {
    std::string text;                   // the file as the killed run left it
    std::vector<std::string> comments;  // this run's
    std::string completed;              // the file after this run's one row
  };
  const Case cases[] = {
      {"object,exploration,fr", {}, kHeader + "\n" + row},
      {"object,exploration,frame,x,y,z,p0_0,", {"not written"}, kHeader + "\n" + row},
      {"o", {}, kHeader + "\n" + row},
      // Comments of another run before the header: kept as they are.
      {"# an earlier run\r\n\r\nobject,explo", {"this run"}, "# an earlier run\r\n\r\nobject,explo" +
                                                                  kHeader.substr(12) + "\n" + row},
      // Cut inside this run's own comments, or between them.
      {"# one\n# tw", {"one", "two"}, "# one\n# two\n" + kHeader + "\n" + row},
      {"# one\n", {"one", "two"}, "# one\n# two\n" + kHeader + "\n" + row},
      {"# on", {"one"}, "# one\n" + kHeader + "\n" + row},
      {kBom + "obj", {"c"}, kBom + kHeader + "\n" + row},
      {kBom + "# on", {"one"}, kBom + "# one\n" + kHeader + "\n" + row},
  };
  int n = 0;
  for (const Case& c : cases) {
    const std::string path = dir.file("torn" + std::to_string(n++) + ".csv");
    const std::string text = c.text;
    CAPTURE(text);
    spit(path, c.text);
    try {
      iclap::DatasetCsvAppender app(path, 1, 2, false, false, c.comments);
      CHECK(app.rows_in_file() == 0);
      CHECK(app.recovered_bytes() == 0);
      CHECK(app.header_completed());
      app.append(f);
      // The row is on the line the reader gives it.
      const std::string line =
          ", line " + std::to_string(std::count(c.completed.begin(), c.completed.end(), '\n')) + " (one row per frame)";
      CHECK_THROWS_WITH_AS(app.append(f), doctest::Contains(line.c_str()), iclap::InvalidArgument);
    } catch (const iclap::Error& e) {
      FAIL_CHECK("appender refused a torn header: " << std::string(e.what()));
    }
    CHECK(slurp(path) == c.completed);
    CHECK(iclap::read_dataset_csv(path).frames.size() == 1);
  }

  // A complete header without its line break is not "completed" (it gets
  // its line break, as before).
  const std::string whole = dir.file("whole.csv");
  spit(whole, kHeader);
  {
    iclap::DatasetCsvAppender app(whole, 1, 2, false, false);
    CHECK(!app.header_completed());
  }
  CHECK(slurp(whole) == kHeader + "\n");
}

// Input: a file that ends inside a header or a comment line that is not the
// beginning of what this appender writes (another grid, other comments).
// Was: "header does not match the recorder's columns" / "no header row",
// not saying that the file is cut short.
// Now: still refused, file unchanged, and the message names the line and
// says that it has no line break and may be cut short.
TEST_CASE("audit: appender refuses a cut-short header it cannot complete, saying so") {
  TempDir dir("audit_h58c_torn_refused");
  const std::string other = dir.file("other.csv");
  spit(other, "# c\nobject,exploration,frame,t,x,y,z,qw,q");  // a run with t and a quaternion
  const std::string what = refusal(other);
  CHECK(what.find(other + ":2: header does not match the recorder's columns") == 0);
  CHECK_MESSAGE(what.find("no line break") != std::string::npos, what);
  CHECK_MESSAGE(what.find("cut short") != std::string::npos, what);

  const std::string comment = dir.file("comment.csv");
  spit(comment, "# sensor: WTS rows=1 cols=2 pitch_m=0.005");
  const std::string what2 = refusal(comment, {"sensor: WTS rows=1 cols=2 pitch_m=0.0034 (other)"});
  CHECK(what2.find(comment + ":1: existing file has no header row") == 0);
  CHECK_MESSAGE(what2.find("no line break") != std::string::npos, what2);
  CHECK_MESSAGE(what2.find("cut short") != std::string::npos, what2);

  // A complete header of other columns, comments only (ended), or a blank
  // last line: as before.
  spit(other, "object,exploration,frame,x,y,z,p0_0\n");
  CHECK(refusal(other).find(other + ":1: header does not match the recorder's columns (1x2 taxels, t no, "
                                    "quaternion no): missing 'p0_1'") == 0);
  CHECK(refusal(other).find("cut short") == std::string::npos);
  spit(comment, "# a\n# b\n");
  CHECK(refusal(comment) == comment + ":2: existing file has no header row; cannot append to it");
  spit(comment, "# a\n  ");
  CHECK(refusal(comment) == comment + ":2: existing file has no header row; cannot append to it");
}
