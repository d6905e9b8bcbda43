// SPDX-License-Identifier: MIT
// Reproducers from the session-57 audit (helper h57c) of the outputs of
// `iclap evaluate` and the benchmark helpers: the SVG charts
// (examples/iclap/svg_plot.hpp) and the --touches list
// (examples/iclap/touch_counts.hpp). Each case failed before its fix.

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <regex>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "svg_plot.hpp"
#include "touch_counts.hpp"

namespace {

using iclap::cli::Plot;
using iclap::cli::PlotSeries;
using iclap::cli::render_svg;

// The y-axis tick labels of a rendered chart, top to bottom as written
// (render_svg writes them bottom to top: "<text x=... text-anchor="end">L</text>").
std::vector<std::string> y_tick_labels(const std::string& svg) {
  std::vector<std::string> out;
  const std::regex re("<text x=\"[^\"]*\" y=\"[^\"]*\" text-anchor=\"end\">([^<]*)</text>");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), re); it != std::sregex_iterator(); ++it)
    out.push_back((*it)[1]);
  return out;
}

// The x-axis tick labels: the numeric "text-anchor="middle"" texts (the
// title and the axis label are not numbers).
std::vector<std::string> x_tick_labels(const std::string& svg) {
  std::vector<std::string> out;
  const std::regex re("<text x=\"[^\"]*\" y=\"[^\"]*\" text-anchor=\"middle\">([-+0-9.e]+)</text>");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), re); it != std::sregex_iterator(); ++it)
    out.push_back((*it)[1]);
  return out;
}

// The trade study's chart (benchmarks/trade_study.cpp): accuracy against
// time, log x, y fitted to the data, y labels as percentages.
Plot trade_study_plot(const std::vector<double>& ms, const std::vector<double>& rate) {
  Plot p;
  p.title = "iCLAP recognition: accuracy against time per recognition";
  p.x_log = true;
  p.y_auto = true;
  PlotSeries all;
  all.name = "settings";
  all.markers_only = true;
  all.x = ms;
  all.y = rate;
  p.series = {all};
  return p;
}

}  // namespace

// Input: `iclap evaluate --touches 5,1,3`.
// Was: the counts kept that order, so every line of the fig_*.svg charts
// zigzagged 5 -> 1 -> 3 and the three-term weight figure (meant at the
// largest count) was drawn at 3 touches.
// Now: parse_touches returns the counts in increasing order.
TEST_CASE("--touches out of order: the figures need the counts in increasing order") {
  std::vector<int> t;
  bool refused = false;
  try {
    t = iclap::cli::parse_touches("5,1,3");
  } catch (const iclap::cli::UsageError& e) {
    refused = std::string(e.what()).find("--touches") != std::string::npos;
  }
  if (!refused) {
    CHECK(t == std::vector<int>{1, 3, 5});
    CHECK(std::is_sorted(t.begin(), t.end()));
  }
}

// Input: a y_auto percentage chart (trade_study.svg) with rates 0.55..0.65,
// or 0.60..0.61.
// Was: ticks at 2.5% (0.25%) steps labelled "%.0f%%": "55% 58% 60% 63% 65%",
// "60% 60% 60% 61% 61%".
// Now: as many decimals as the step needs: "55.0% 57.5% ..."; a fixed
// range 0.60..0.61 reads "60.00% 60.25% ..." (fitted, that range is now
// widened to 4 points: "59% 60% 61% 62%").
TEST_CASE("render_svg: percentage tick labels keep the tick's value") {
  for (const auto& range : std::vector<std::pair<double, double>>{{0.55, 0.65}, {0.60, 0.61}}) {
    // Named copies: clang refuses structured bindings in CAPTURE's lambda.
    const double lo = range.first, hi = range.second;
    CAPTURE(lo);
    CAPTURE(hi);
    const std::vector<std::string> labels = y_tick_labels(render_svg(trade_study_plot({0.03, 6}, {lo, hi})));
    REQUIRE(labels.size() >= 3);
    std::vector<double> v;
    for (const auto& l : labels) {
      REQUIRE(!l.empty());
      REQUIRE(l.back() == '%');
      v.push_back(std::strtod(l.c_str(), nullptr));
    }
    CAPTURE(labels);
    CHECK(std::set<std::string>(labels.begin(), labels.end()).size() == labels.size());
    for (std::size_t i = 2; i < v.size(); ++i) CHECK(v[i] - v[i - 1] == doctest::Approx(v[1] - v[0]));
  }
  Plot fixed = trade_study_plot({0.03, 6}, {0.60, 0.61});
  fixed.y_auto = false;
  fixed.y_min = 0.60;
  fixed.y_max = 0.61;
  CHECK(y_tick_labels(render_svg(fixed)) == std::vector<std::string>{"60.00%", "60.25%", "60.50%", "60.75%", "61.00%"});
}

// Input: a y_auto percentage chart whose points all have one rate (every
// setting of a trade study at 100%, or at 60%).
// Was: the axis spanned 1e-10 and its five ticks all read "100%" ("60%").
// Now: the fitted range spans at least 4 points (96%..100%, 58%..62%).
TEST_CASE("render_svg: y_auto with every value equal still gives distinct tick labels") {
  for (const double rate : {1.0, 0.6}) {
    CAPTURE(rate);
    const std::vector<std::string> labels =
        y_tick_labels(render_svg(trade_study_plot({0.03, 1, 6}, {rate, rate, rate})));
    CAPTURE(labels);
    REQUIRE(labels.size() >= 2);
    CHECK(std::set<std::string>(labels.begin(), labels.end()).size() == labels.size());
  }
}

// Input: an x_log chart with x within one decade: 1.5..6 ms, or 12..80 ms.
// Was: no x tick at all (only powers of ten inside the range were ticks).
// Now: 2 and 5 times the powers of ten are added ("2 5", "20 50"); then
// 1..9 times them, and failing that the axis widens to the two around.
TEST_CASE("render_svg: a log x axis within one decade still has tick labels") {
  for (const auto& range : std::vector<std::pair<double, double>>{{1.5, 6.0}, {12.0, 80.0}}) {
    const double lo = range.first, hi = range.second;  // not bindings: see above
    CAPTURE(lo);
    CAPTURE(hi);
    const std::vector<std::string> labels = x_tick_labels(render_svg(trade_study_plot({lo, hi}, {0.5, 0.6})));
    CAPTURE(labels);
    CHECK(labels.size() >= 2);
  }
  // Between two ticks of 1..9 x 10^k: the axis widens to them.
  CHECK(x_tick_labels(render_svg(trade_study_plot({1.5, 1.6}, {0.5, 0.6}))) == std::vector<std::string>{"1", "2"});
  CHECK(x_tick_labels(render_svg(trade_study_plot({12, 18}, {0.5, 0.6}))) == std::vector<std::string>{"10", "20"});
}

// Input: a chart of 19 line series (fig_all_methods.svg of `iclap evaluate
// --methods all`).
// Was: colours cycled through 12 entries and nothing else changed, so
// series k and k + 12 were identical lines, in the legend too.
// Now: each round of the colours has its own dash pattern.
TEST_CASE("render_svg: more than 12 series are still distinguishable") {
  Plot p;
  p.x_integer = true;
  for (int k = 0; k < 19; ++k) {
    PlotSeries s;
    s.name = "method" + std::to_string(k);
    s.x = {1, 2, 3};
    s.y = {0.1 + 0.02 * k, 0.2 + 0.02 * k, 0.3 + 0.02 * k};
    p.series.push_back(s);
  }
  const std::string svg = render_svg(p);
  // The style of each line: everything but its points.
  std::vector<std::string> styles;
  const std::regex re("<polyline ([^>]*) points=\"[^\"]*\"/>");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), re); it != std::sregex_iterator(); ++it)
    styles.push_back((*it)[1]);
  REQUIRE(styles.size() == 19);
  for (std::size_t i = 0; i < styles.size(); ++i)
    for (std::size_t j = 0; j < i; ++j) {
      CAPTURE(i);
      CAPTURE(j);
      CAPTURE(styles[i]);
      CHECK(styles[i] != styles[j]);
    }
  // The legend's lines likewise.
  std::vector<std::string> legend;
  const std::regex legend_re(
      "<line x1=\"[^\"]*\" x2=\"[^\"]*\" y1=\"[^\"]*\" y2=\"[^\"]*\" (stroke=\"#[^\"]*\" stroke-width=\"2.5\"[^/]*)/>");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), legend_re); it != std::sregex_iterator(); ++it)
    legend.push_back((*it)[1]);
  REQUIRE(legend.size() == 19);
  CHECK(std::set<std::string>(legend.begin(), legend.end()).size() == 19);
}

// Input: a y_auto percentage chart with rates {0, 0.8}.
// Was: the lowest tick read "-0%" (ceil(-0.05 / 0.25) * 0.25 is -0.0).
// Now: "0%"; nice_ticks returns +0 for the zero tick.
TEST_CASE("render_svg: the zero tick is not labelled -0%") {
  const std::vector<std::string> labels = y_tick_labels(render_svg(trade_study_plot({0.03, 6}, {0.0, 0.8})));
  CAPTURE(labels);
  REQUIRE(!labels.empty());
  for (const auto& l : labels) CHECK(l.rfind("-0", 0) != 0);
}
