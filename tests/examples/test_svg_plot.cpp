// SPDX-License-Identifier: MIT
// The SVG charts of the example programs (examples/iclap/svg_plot.hpp):
// point labels placed without overlaps inside the plot area.

#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "svg_plot.hpp"

namespace {

std::size_t count(const std::string& s, const std::string& needle) {
  std::size_t n = 0;
  for (std::size_t at = s.find(needle); at != std::string::npos; at = s.find(needle, at + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("point labels: crowded points get separate boxes inside the plot area") {
  using iclap::cli::detail::LabelBox;
  using iclap::cli::detail::overlaps;
  using iclap::cli::detail::place_labels;
  const double left = 70, right = 560, top = 40, bottom = 385, font = 9;
  // The trade study's accurate end: three points a few pixels apart at the
  // right edge, one near the top edge, one at the left edge.
  const std::vector<double> px = {540, 542, 530, 75, 300};
  const std::vector<double> py = {60, 66, 70, 45, 380};
  const std::vector<std::string> text = {"height+patch ICP 50%", "height*patch ICP 50%",
                                         "lower bound, trimmed patch ICP 50%", "height and tilt, 1 cm/rad", "x"};
  const std::vector<LabelBox> boxes = place_labels(px, py, text, font, left, right, top, bottom);
  REQUIRE(boxes.size() == text.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    CAPTURE(i);
    CHECK(boxes[i].x0 >= left);
    CHECK(boxes[i].x1 <= right);
    CHECK(boxes[i].y0 >= top);
    CHECK(boxes[i].y1 <= bottom);
    CHECK(boxes[i].x1 - boxes[i].x0 == doctest::Approx(iclap::cli::detail::label_width(text[i], font)));
    for (std::size_t j = 0; j < i; ++j) {
      CAPTURE(j);
      CHECK_FALSE(overlaps(boxes[i], boxes[j]));
    }
  }
  // Points at the right edge label to their left, the others to their right.
  CHECK(boxes[0].anchor_end);
  CHECK(boxes[1].anchor_end);
  CHECK(boxes[2].anchor_end);
  CHECK_FALSE(boxes[3].anchor_end);
  CHECK_FALSE(boxes[4].anchor_end);
  CHECK(boxes[0].x == doctest::Approx(px[0] - 5));
  CHECK(boxes[3].x == doctest::Approx(px[3] + 5));
  // The first label takes the place just above its point; the one at the
  // bottom edge goes above its point too (below would leave the area).
  CHECK(boxes[0].y == doctest::Approx(py[0] - 5));
  CHECK(boxes[4].y1 <= py[4]);
}

TEST_CASE("point labels: a crowd beyond six lines still gets separate boxes, the far ones with leader lines") {
  using iclap::cli::detail::LabelBox;
  using iclap::cli::detail::overlaps;
  using iclap::cli::detail::place_labels;
  // Thirty labels on one point (the trade study's fused rows end up a few
  // pixels apart at the top of the front): more than the 24 places within
  // six lines above and below, on both sides.
  const double left = 0, right = 600, top = 0, bottom = 400, font = 9;
  const std::vector<double> px(30, 300.0), py(30, 200.0);
  std::vector<std::string> text;
  for (int i = 0; i < 30; ++i) text.push_back("setting number " + std::to_string(i));
  const std::vector<LabelBox> boxes = place_labels(px, py, text, font, left, right, top, bottom);
  REQUIRE(boxes.size() == text.size());
  int leaders = 0;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    CAPTURE(i);
    CHECK(boxes[i].y0 >= top);
    CHECK(boxes[i].y1 <= bottom);
    for (std::size_t j = 0; j < i; ++j) {
      CAPTURE(j);
      CHECK_FALSE(overlaps(boxes[i], boxes[j]));
    }
    // A label without a leader is at most a line from its point.
    if (!boxes[i].leader) CHECK(std::abs(boxes[i].y - py[i]) <= 5 + font + 1e-9);
    leaders += boxes[i].leader ? 1 : 0;
  }
  // The first four take the places just above and below the point, on
  // both sides; the rest are further away and say so.
  CHECK(leaders == 26);
  CHECK_FALSE(boxes[0].anchor_end);
  CHECK(boxes[2].anchor_end);

  // Rendered: one leader line per label placed away from its point.
  iclap::cli::Plot p;
  iclap::cli::PlotSeries crowd;
  crowd.name = "crowd";
  crowd.markers_only = true;
  for (int i = 0; i < 30; ++i) {
    crowd.x.push_back(1.0);
    crowd.y.push_back(0.5);
    crowd.point_labels.push_back(text[static_cast<std::size_t>(i)]);
  }
  iclap::cli::PlotSeries range;
  range.name = "range";
  range.x = {0.0, 2.0};
  range.y = {0.0, 1.0};
  p.series = {crowd, range};
  const std::string svg = iclap::cli::render_svg(p);
  CHECK(count(svg, "stroke=\"#999\" stroke-width=\"0.6\"") == 26);
  CHECK(count(svg, ">setting number ") == 30);
}

TEST_CASE("point labels: a label with no free place keeps the place above its point") {
  using iclap::cli::detail::overlaps;
  using iclap::cli::detail::place_labels;
  // An area 20 units high that starts 10 units left of the point: the first
  // label fits above its point, the second (same point) fits neither above,
  // below, nor further away, and not on the left side either.
  const auto boxes = place_labels({100, 100}, {15, 15}, {"first", "second"}, 9, 90, 400, 0, 20);
  REQUIRE(boxes.size() == 2);
  CHECK(boxes[0].y == doctest::Approx(10));
  CHECK(boxes[1].y == doctest::Approx(10));
  CHECK(overlaps(boxes[0], boxes[1]));
  CHECK_FALSE(boxes[1].leader);
  // With room on the left, the second label goes there instead.
  const auto wider = place_labels({100, 100}, {15, 15}, {"first", "second"}, 9, 0, 400, 0, 20);
  CHECK_FALSE(overlaps(wider[0], wider[1]));
  CHECK(wider[1].anchor_end);
  CHECK(wider[1].y == doctest::Approx(10));
}

TEST_CASE("render_svg: scatter labels and legend") {
  iclap::cli::Plot p;
  p.title = "t";
  p.x_log = true;
  p.y_auto = true;
  iclap::cli::PlotSeries all, front;
  all.name = "settings";
  all.markers_only = true;
  all.x = {0.025, 4.4, 6.2, 6.3};
  all.y = {0.587, 0.595, 0.632, 0.643};
  all.point_labels = {"fast", "", "a <b> & c", "right edge"};
  front.name = "front";
  front.highlight = true;
  front.x = all.x;
  front.y = all.y;
  p.series = {all, front};
  const std::string svg = iclap::cli::render_svg(p);
  CHECK(svg.rfind("<svg ", 0) == 0);
  CHECK(svg.find("</svg>\n") == svg.size() - 7);
  // Three labels (the empty one is not drawn), escaped; the rightmost point's
  // label ends at the point.
  CHECK(count(svg, "font-size=\"9\"") == 3);
  CHECK(svg.find("a &lt;b&gt; &amp; c") != std::string::npos);
  CHECK(svg.find("text-anchor=\"end\" font-size=\"9\" fill=\"#444\">right edge<") != std::string::npos);
  CHECK(svg.find(">fast<") != std::string::npos);
  // The legend shows the scatter as a marker and the front as a line.
  CHECK(count(svg, "<polyline") == 1);
  CHECK(count(svg, "stroke-width=\"2.5\"") == 1);
  CHECK(count(svg, "<circle") == 2 * all.x.size() + 1);
}

TEST_CASE("axis ticks: whole numbers on request (touch counts)") {
  using iclap::cli::detail::nice_ticks;
  // 1..20 touches: the free choice is steps of 2.5, whole numbers give 5.
  CHECK(nice_ticks(1, 20, 8) == std::vector<double>{2.5, 5, 7.5, 10, 12.5, 15, 17.5, 20});
  CHECK(nice_ticks(1, 20, 8, true) == std::vector<double>{5, 10, 15, 20});
  // A short range never gets fractional ticks: steps of at least 1.
  CHECK(nice_ticks(1, 3, 8, true) == std::vector<double>{1, 2, 3});
  CHECK(nice_ticks(0, 100, 4, true) == std::vector<double>{0, 25, 50, 75, 100});
}
