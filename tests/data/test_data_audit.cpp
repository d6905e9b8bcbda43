// SPDX-License-Identifier: MIT
// Reproducers from helper-55b's audit (session 55) of the dataset and file
// I/O headers (include/iclap/data, include/iclap/io). Each case failed on
// the code it was written against and was fixed in the same session; it
// states the behaviour the contract promises, and its comment says what
// happened before ("Now").

#include <doctest/doctest.h>

#include <sys/stat.h>
#include <sys/types.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "iclap/data/data.hpp"
#include "iclap/data/overlap.hpp"
#include "iclap/io/atomic_file.hpp"
#include "../support/errors.hpp"
#include "../support/temporaries.hpp"

namespace {

using iclap::Dataset;
using iclap::Frame;
using iclap::test::slurp;
using iclap::test::spit;
using iclap::test::TempDir;

Frame frame_with(double p0, double p1, std::int64_t exploration) {
  Frame f;
  f.object = "a";
  f.exploration = exploration;
  f.frame = 0;
  f.position = {0, 0, 0};
  f.pressures.resize(1, 2);
  f.pressures << p0, p1;
  return f;
}

std::string octal(unsigned mode) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0%o", mode);
  return buf;
}

}  // namespace

// Input: an in-memory Frame (e.g. from a simulator or a user's converter)
// whose taxels are {NaN, 30} or {30, NaN}, threshold 20.
// Now: the answer depends on where the NaN sits: is_contact({NaN, 30}) is
// false, is_contact({30, NaN}) is true (Eigen's maxCoeff returns the first
// coefficient when the comparison with NaN fails: NaN, or 30). The same
// silent, order-dependent answer goes into contact_frame_count, summarize and
// exploration_overlap (a NaN taxel makes a touch vanish or count). No error
// is raised anywhere, although the threshold and the contact positions are
// checked for NaN.
// Should: a NaN (or infinite) pressure is refused, e.g. NonFiniteValue or
// InvalidArgument naming the frame's pressures, as exploration_overlap does
// for frames[i].position; at the very least the answer must not depend on
// the taxel order.
// Cause: include/iclap/data/dataset.hpp:74 (detail::is_contact_unchecked:
// `f.pressures.maxCoeff() > threshold` on unchecked pressures), used by
// is_contact (:85), contact_frame_count (:94), summarize (:170) and
// include/iclap/data/overlap.hpp:73.
TEST_CASE("audit: a NaN taxel pressure is refused, not counted as contact or not by its position") {
  const Frame nan_first = frame_with(std::nan(""), 30, 0);
  const Frame nan_last = frame_with(30, std::nan(""), 1);
  CHECK_THROWS_AS(iclap::is_contact(nan_first, 20), iclap::Error);
  CHECK_THROWS_AS(iclap::is_contact(nan_last, 20), iclap::Error);

  Dataset ds;
  ds.rows = 1;
  ds.cols = 2;
  ds.frames = {nan_first, nan_last};
  CHECK_THROWS_AS(iclap::contact_frame_count(ds, 20), iclap::Error);
  CHECK_THROWS_AS(iclap::summarize(ds, 20), iclap::Error);
  CHECK_THROWS_AS(iclap::exploration_overlap(ds, 0.01, 20), iclap::Error);
  // The fix names the frame and the taxel, and refuses infinities too.
  using iclap::test::what_of;
  CHECK(what_of<iclap::NonFiniteValue>([&] { (void)iclap::is_contact(nan_first, 20); }) ==
        "frame.pressures: non-finite value nan at row 0, column 0");
  CHECK(what_of<iclap::NonFiniteValue>([&] { (void)iclap::contact_frame_count(ds, 20); }) ==
        "frames[0].pressures: non-finite value nan at row 0, column 0");
  ds.frames[0] = frame_with(0, 0, 0);
  CHECK(what_of<iclap::NonFiniteValue>([&] { (void)iclap::summarize(ds, 20); }) ==
        "frames[1].pressures: non-finite value nan at row 0, column 1");
  CHECK(what_of<iclap::NonFiniteValue>([&] { (void)iclap::exploration_overlap(ds, 0.01, 20); }) ==
        "frames[1].pressures: non-finite value nan at row 0, column 1");
  ds.frames[1] = frame_with(30, std::numeric_limits<double>::infinity(), 1);
  CHECK(what_of<iclap::NonFiniteValue>([&] { (void)iclap::contact_frame_count(ds, 20); }) ==
        "frames[1].pressures: non-finite value inf at row 0, column 1");
  ds.frames[1] = frame_with(30, 0, 1);
  CHECK(iclap::contact_frame_count(ds, 20) == 1);
}

// Input: an existing file whose last row was cut (crash, power loss) right
// after its last comma: "...\na,0,1,1,2,3,4," (no line break), header of 8
// columns.
// Now: DatasetCsvAppender's constructor throws ParseError
// "t.csv:3: the last row has 8 fields (the header has 8) but no line break:
// a whole row or one cut inside its last value; end it with a line break or
// remove it before appending". The recorder cannot resume, and following the
// advice "end it with a line break" makes the whole file unreadable (an
// empty value is refused by the reader).
// Should: a last line whose last field is empty can only be a row cut after
// its last separator (an empty value is never a valid row, so there is
// nothing to guess): it is a partial row like any with fewer fields, cut off
// and reported by recovered_bytes(), as the class comment and the README
// ("cuts off a partial last row left by a crash") promise.
// Cause: include/iclap/data/csv_appender.hpp:207 (the refusal tests only
// `fields.size() >= header_fields.size()`, not whether the last field is
// empty).
TEST_CASE("audit: appender cuts off a last row torn right after its last comma") {
  TempDir dir("audit_h55b_torn_comma");
  const std::string path = dir.file("t.csv");
  const std::string complete = "object,exploration,frame,x,y,z,p0_0,p0_1\na,0,0,1,2,3,4,5\n";
  const std::string torn = "a,0,1,1,2,3,4,";
  spit(path, complete + torn);
  Frame f = frame_with(4, 5, 0);
  f.frame = 1;
  f.position = {1, 2, 3};
  try {
    iclap::DatasetCsvAppender app(path, 1, 2, false, false);
    CHECK(app.recovered_bytes() == torn.size());
    CHECK(app.rows_in_file() == 1);
    app.append(f);
  } catch (const iclap::Error& e) {
    FAIL_CHECK("appender refused a torn row: " << std::string(e.what()));
  }
  CHECK(slurp(path) == complete + "a,0,1,1,2,3,4,5\n");
}

// Input: an existing file with mode 0600 (private data) replaced through
// AtomicFileWriter (write_dataset_csv(path, ds), write_labeled_cloud_ply and
// every other atomic writer), umask 022.
// Now: the temporary file PATH.partial-PID-N that receives the whole new
// content is created with mode 0644 (0666 & ~umask) and only gets the
// target's 0600 at commit(): during the whole write (and forever, if the
// process is killed before commit) any local user can read the content the
// owner keeps private, or open the temporary and keep reading it after the
// chmod. The doc promises "a 0600 file stays 0600".
// Should: the temporary never grants more than the target it replaces, e.g.
// created with mode 0600 (or the target's bits) from the start, with the
// final chmod as now.
// Cause: include/iclap/io/atomic_file.hpp:186 (`::open(temp, O_WRONLY |
// O_CREAT | O_EXCL, 0666)`), the permissions only copied at :135 in commit().
TEST_CASE("audit: the temporary file of an atomic write is not more readable than the file it replaces") {
  struct UmaskGuard {
    mode_t old = ::umask(022);
    ~UmaskGuard() { ::umask(old); }
  } umask_guard;
  {
    TempDir dir("audit_h55b_mode");
    const std::string path = dir.file("secret.csv");
    spit(path, "old\n");
    REQUIRE(::chmod(path.c_str(), 0600) == 0);
    iclap::AtomicFileWriter w(path);
    struct stat st {};
    REQUIRE(::stat(w.temporary_path().c_str(), &st) == 0);
    CHECK_MESSAGE((st.st_mode & 077) == 0, "temporary mode " << octal(st.st_mode & 0777));
    w.stream() << "secret\n";
    w.commit();
    REQUIRE(::stat(path.c_str(), &st) == 0);
    CHECK((st.st_mode & 0777) == 0600);
  }
}
