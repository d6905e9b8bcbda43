// SPDX-License-Identifier: MIT
// Reproducers for the SVG charts of `iclap evaluate --out DIR` and the
// benchmark study programs (examples/iclap/svg_plot.hpp) with many series:
// telling the series apart, and the legend's place. Each case failed
// before its fix.

#include <doctest/doctest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "svg_plot.hpp"

namespace {

using iclap::cli::Plot;
using iclap::cli::PlotSeries;
using iclap::cli::render_svg;

// `n` series named s0, s1, ..., all through the same three points, so that
// only their style tells them apart; every `dashed_every`-th is dashed.
Plot many_series(int n, bool markers_only, int dashed_every = 0) {
  Plot p;
  p.title = "many";
  p.x_integer = true;
  for (int k = 0; k < n; ++k) {
    PlotSeries s;
    s.name = "s" + std::to_string(k);
    s.markers_only = markers_only;
    s.dashed = dashed_every > 0 && k % dashed_every == 0;
    s.x = {1, 2, 3};
    s.y = {0.2, 0.5, 0.8};
    p.series.push_back(s);
  }
  return p;
}

struct Element {
  std::string tag;
  std::map<std::string, std::string> attr;
};

// The shapes (circle, rect, polygon, polyline, line) in `text`, in order.
std::vector<Element> elements(const std::string& text) {
  std::vector<Element> out;
  const std::regex re("<(circle|rect|polygon|polyline|line) ([^>]*)/>"), attr_re("([a-z][a-z0-9-]*)=\"([^\"]*)\"");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator(); ++it) {
    Element e;
    e.tag = (*it)[1];
    const std::string attrs = (*it)[2];
    for (auto a = std::sregex_iterator(attrs.begin(), attrs.end(), attr_re); a != std::sregex_iterator(); ++a)
      e.attr[(*a)[1]] = (*a)[2];
    out.push_back(e);
  }
  return out;
}

std::vector<double> numbers(const std::string& list) {
  std::vector<double> v;
  const std::regex re("-?[0-9.]+");
  for (auto it = std::sregex_iterator(list.begin(), list.end(), re); it != std::sregex_iterator(); ++it)
    v.push_back(std::strtod(it->str().c_str(), nullptr));
  return v;
}

// The leftmost x and the topmost and bottommost y of a shape.
struct Extent {
  double x0, y0, y1;
};
Extent extent(const Element& e) {
  auto num = [&](const char* key) { return e.attr.count(key) ? std::strtod(e.attr.at(key).c_str(), nullptr) : 0.0; };
  if (e.tag == "circle") return {num("cx") - num("r"), num("cy") - num("r"), num("cy") + num("r")};
  if (e.tag == "rect") return {num("x"), num("y"), num("y") + num("height")};
  if (e.tag == "line") return {std::min(num("x1"), num("x2")), std::min(num("y1"), num("y2")), std::max(num("y1"), num("y2"))};
  const std::vector<double> v = numbers(e.attr.at("points"));
  Extent r{v.at(0), v.at(1), v.at(1)};
  for (std::size_t i = 0; i + 1 < v.size(); i += 2) {
    r.x0 = std::min(r.x0, v[i]);
    r.y0 = std::min(r.y0, v[i + 1]);
    r.y1 = std::max(r.y1, v[i + 1]);
  }
  return r;
}

// A shape's style without its place: the tag and the attributes other than
// coordinates; a polygon's corners relative to its first.
std::string style(const Element& e) {
  static const std::set<std::string> place = {"cx", "cy", "x", "y", "x1", "x2", "y1", "y2", "points"};
  std::string s = e.tag;
  for (const auto& kv : e.attr)
    if (!place.count(kv.first)) s += " " + kv.first + "=" + kv.second;
  if (e.tag == "polygon") {
    const std::vector<double> v = numbers(e.attr.at("points"));
    char buf[64];
    for (std::size_t i = 2; i + 1 < v.size(); i += 2) {
      std::snprintf(buf, sizeof buf, " %.1f,%.1f", v[i] - v[0], v[i + 1] - v[1]);
      s += buf;
    }
  }
  return s;
}

struct Legend {
  std::string name;
  double x, y;  ///< text anchor (baseline, start)
};

struct Chart {
  double width = 0, height = 0, plot_right = 0;
  std::vector<Legend> legend;
  // Per series: the styles of its shapes in the plot area and in the legend.
  std::vector<std::string> data_style, legend_style;
  std::vector<Element> all;
};

// Parses a chart of many_series: the legend's texts, and between one and
// the next the shapes that render_svg writes for the next series.
Chart parse(const std::string& svg) {
  Chart c;
  std::smatch m;
  REQUIRE(std::regex_search(svg, m, std::regex("<svg [^>]*width=\"([0-9.]+)\" height=\"([0-9.]+)\"")));
  c.width = std::strtod(m[1].str().c_str(), nullptr);
  c.height = std::strtod(m[2].str().c_str(), nullptr);
  REQUIRE(std::regex_search(svg, m, std::regex("<rect x=\"([0-9.]+)\" y=\"[0-9.]+\" width=\"([0-9.]+)\" [^>]*stroke=\"#333\"/>")));
  c.plot_right = std::strtod(m[1].str().c_str(), nullptr) + std::strtod(m[2].str().c_str(), nullptr);
  c.all = elements(svg);
  // The series start after the y axis label.
  std::size_t from = svg.find("</text>", svg.find("rotate(-90)"));
  REQUIRE(from != std::string::npos);
  const std::regex legend_re("<text x=\"([0-9.]+)\" y=\"([0-9.]+)\">(s[0-9]+[^<]*)</text>");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), legend_re); it != std::sregex_iterator(); ++it) {
    c.legend.push_back({(*it)[3], std::strtod((*it)[1].str().c_str(), nullptr), std::strtod((*it)[2].str().c_str(), nullptr)});
    const std::size_t at = static_cast<std::size_t>(it->position(0));
    std::set<std::string> data;
    std::vector<std::string> legend;
    for (const Element& e : elements(svg.substr(from, at - from))) {
      if (extent(e).x0 >= c.plot_right)
        legend.push_back(style(e));
      else
        data.insert(style(e));
    }
    std::string d, l;
    for (const auto& s : data) d += s + "; ";
    for (const auto& s : legend) l += s + "; ";
    c.data_style.push_back(d);
    c.legend_style.push_back(l);
    from = at + static_cast<std::size_t>(it->length(0));
  }
  return c;
}

// Checks that no two series of `c` look the same, in the plot or in the legend.
void check_distinct(const Chart& c) {
  for (const std::vector<std::string>* styles : {&c.data_style, &c.legend_style})
    for (std::size_t i = 0; i < styles->size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if ((*styles)[i] == (*styles)[j]) {
          const std::string a = c.legend[j].name, b = c.legend[i].name, same = (*styles)[i];
          CAPTURE(a);
          CAPTURE(b);
          CAPTURE(same);
          FAIL_CHECK("two series look the same");
        }
}

}  // namespace

// Input: 24 markers-only series (a scatter per setting).
// Was: series k and k + 12 were the same filled circle of one colour, in
// the plot and in the legend (only lines got a dash pattern per round of
// the 12 colours).
// Now: each round of the colours has its own marker shape (circle, square,
// triangle, diamond, downward triangle), in the legend too; a chart of up
// to 12 series keeps its filled circles.
TEST_CASE("render_svg: markers-only series beyond 12 colours have their own marker shape") {
  const Chart c = parse(render_svg(many_series(24, true)));
  REQUIRE(c.legend.size() == 24);
  check_distinct(c);
  // The legend shows the marker of the plot.
  for (std::size_t k = 0; k < c.legend.size(); ++k) {
    CAPTURE(k);
    CHECK(c.legend_style[k] == c.data_style[k]);
  }
  const std::string twelve = render_svg(many_series(12, true));
  CHECK(twelve.find("<polygon") == std::string::npos);
  CHECK(twelve.find("<rect x=") == twelve.rfind("<rect x="));  // the plot's frame only
}

// Input: charts of 23 to 130 series (`iclap evaluate --methods all` with
// more methods; a weight sweep of fine steps), and one of two series with
// a name of 40 characters.
// Was: the legend, one column of 18-pixel rows from y = 50, ran off the
// bottom of the 440-pixel drawing from the 23rd series on; a long name ran
// off its right edge.
// Now: the legend wraps into as many columns as it needs, each as wide as
// its longest name, and the drawing widens to hold them; up to 22 series
// keep the single column and the drawing's size.
TEST_CASE("render_svg: the legend of many series stays inside the drawing") {
  for (const int n : {1, 12, 22, 23, 30, 45, 60, 130}) {
    for (const bool markers : {false, true}) {
      CAPTURE(n);
      CAPTURE(markers);
      const Chart c = parse(render_svg(many_series(n, markers)));
      REQUIRE(c.legend.size() == static_cast<std::size_t>(n));
      if (n <= 22) {
        CHECK(c.width == 760);
        CHECK(c.height == 440);
      }
      int outside = 0;
      for (const Legend& l : c.legend)
        if (l.y + 4 > c.height || l.y - 12 < 0 || l.x + iclap::cli::detail::label_width(l.name, 12) > c.width) ++outside;
      CHECK(outside == 0);
      for (const Element& e : c.all) {
        const Extent x = extent(e);
        if (e.tag == "rect" && e.attr.at("width") == "100%") continue;
        CHECK(x.y1 <= c.height);
        CHECK(x.x0 >= 0);
      }
      // No two entries on one line of one column.
      std::set<std::pair<double, double>> places;
      for (const Legend& l : c.legend) places.insert({l.x, l.y});
      CHECK(places.size() == c.legend.size());
    }
  }
  Plot p = many_series(2, false);
  p.series[1].name = "s1 height_contact+patch*bow+occupancy-a";
  const Chart c = parse(render_svg(p));
  REQUIRE(c.legend.size() == 2);
  for (const Legend& l : c.legend) {
    const std::string name = l.name;
    CAPTURE(name);
    CHECK(l.x + iclap::cli::detail::label_width(l.name, 12) <= c.width);
  }
}

// Input: 120 lines, every third dashed (and 120 markers-only series).
// Was: three dash patterns (plain and dashed), one per round of the 12
// colours: series k and k + 36 were the same line, in the legend too.
// Now: colour, dash pattern (3 rounds) and marker (5 shapes, filled then
// hollow: 10 rounds) change together, and with more than 12 series a
// line's legend entry shows its marker: 120 markers-only series and 360
// lines differ; beyond, the styles repeat (nothing throws).
TEST_CASE("render_svg: many series, no two with the same colour, dash pattern and marker") {
  for (const bool markers : {false, true}) {
    CAPTURE(markers);
    const Chart c = parse(render_svg(many_series(120, markers, 3)));
    REQUIRE(c.legend.size() == 120);
    check_distinct(c);
  }
  const Chart lines = parse(render_svg(many_series(360, false, 5)));
  REQUIRE(lines.legend.size() == 360);
  check_distinct(lines);
  // Beyond: the styles repeat, the chart is still drawn.
  const Chart beyond = parse(render_svg(many_series(400, true)));
  REQUIRE(beyond.legend.size() == 400);
  CHECK(beyond.data_style[0] == beyond.data_style[120]);
}
