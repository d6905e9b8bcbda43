// SPDX-License-Identifier: MIT
#pragma once

// Minimal SVG charts for the `iclap` tools: lines (rate against touches or
// weight) and scatter (accuracy against time), with axes, grid and legend.
// No dependency; the output opens in any browser.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace iclap::cli {

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;
  bool dashed = false;
  bool markers_only = false;   ///< scatter instead of a line
  bool highlight = false;      ///< drawn thicker (e.g. a Pareto front)
  std::vector<std::string> point_labels;  ///< optional label per point
};

struct Plot {
  std::string title, x_label, y_label;
  std::vector<PlotSeries> series;
  double y_min = 0, y_max = 1;        ///< fixed y range
  bool y_percent = true;              ///< tick labels as percentages
  bool x_log = false;                 ///< logarithmic x axis
  bool y_auto = false;                ///< fit the y range to the data instead
  bool x_integer = false;             ///< x ticks at whole numbers only (e.g. touch counts)
};

namespace detail {

inline std::string escape_xml(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

inline std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

/// About `target` ticks over [lo, hi] at 1, 2, 2.5 or 5 times a power of
/// ten; with `integer`, whole-number steps only (at least 1). Each tick is a
/// whole multiple of the step (not a running sum, which drifts), and the
/// zero tick is +0 (ceil of a small negative ratio gives -0, printed "-0").
inline std::vector<double> nice_ticks(double lo, double hi, int target, bool integer = false) {
  const double span = hi - lo;
  if (!(span > 0)) return {lo};
  const double raw = span / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = integer ? std::max(1.0, 10 * mag) : 10 * mag;
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    const double candidate = m * mag;
    if (integer && (candidate < 1 || std::floor(candidate) != candidate)) continue;
    if (candidate >= raw) {
      step = candidate;
      break;
    }
  }
  std::vector<double> t;
  for (double k = std::ceil(lo / step);; k += 1) {
    const double v = k * step;
    if (v > hi + 1e-9 * span) break;
    t.push_back(k == 0 ? 0.0 : v);
  }
  return t;
}

/// The fewest decimals (at most 9) that write every multiple of `step`
/// exactly: 0 for a step of 5, 1 for 2.5, 2 for 0.25.
inline int step_decimals(double step) {
  int d = 0;
  for (double scaled = std::abs(step); d < 9; ++d, scaled *= 10)
    if (std::abs(scaled - std::round(scaled)) <= 1e-6 * std::max(1.0, scaled)) break;
  return d;
}

/// Ticks of a log axis over [10^lo, 10^hi]: the powers of ten; where fewer
/// than two of them fall inside, 1, 2 and 5 times them; then 1, 2, ..., 9
/// times them; and where still fewer than two fall inside (the data within
/// 1.5..1.6), the axis widens to the two such ticks around it.
inline std::vector<double> log_ticks(double& lo, double& hi) {
  const std::vector<std::vector<double>> mantissas = {{1}, {1, 2, 5}, {1, 2, 3, 4, 5, 6, 7, 8, 9}};
  std::vector<double> t;
  for (const auto& ms : mantissas) {
    t.clear();
    for (double e = std::floor(lo); e <= std::ceil(hi); e += 1)
      for (double m : ms) {
        const double l = e + std::log10(m);
        if (l >= lo - 1e-9 && l <= hi + 1e-9) t.push_back(m * std::pow(10.0, e));
      }
    if (t.size() >= 2) return t;
  }
  // m * 10^e at or below 10^lo, and the next such tick at or above 10^hi.
  const double e0 = std::floor(lo), e1 = std::floor(hi);
  const double below = std::max(1.0, std::floor(std::pow(10.0, lo - e0) * (1 + 1e-9))) * std::pow(10.0, e0);
  double above = std::ceil(std::pow(10.0, hi - e1) * (1 - 1e-9)) * std::pow(10.0, e1);
  if (above <= below * (1 + 1e-9)) above = below + std::pow(10.0, e1);
  lo = std::log10(below);
  hi = std::log10(above);
  return {below, above};
}

/// Box of a placed point label (SVG user units; y grows downwards) and the
/// text's anchor point and side.
struct LabelBox {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;  ///< extent
  double x = 0, y = 0;                    ///< text anchor point (baseline)
  bool anchor_end = false;                ///< text to the left of the point (text-anchor="end")
  bool leader = false;                    ///< placed away from its point: draw a line to it
};

/// A conservative width of `text` in a sans-serif font of size `font`
/// (wider than most glyphs, so the boxes err on the side of not touching).
inline double label_width(const std::string& text, double font) { return 0.6 * font * static_cast<double>(text.size()); }

inline bool overlaps(const LabelBox& a, const LabelBox& b) {
  return a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1;
}

/// Places labels next to their points (px, py) inside the plot area
/// [left, right] x [top, bottom], in order: right of the point, or left of
/// it where the text would cross the right edge; at the first vertical
/// offset (just above the point, just below, then further away alternately,
/// up to the height of the area) where the box stays inside the area and
/// overlaps no label placed before, trying at each offset first that side
/// and then the other side of the point, where the text fits. A label
/// placed more than a line away from its point gets `leader` set (draw a
/// line to it). A label with no free place at all keeps the place just
/// above its point.
inline std::vector<LabelBox> place_labels(const std::vector<double>& px, const std::vector<double>& py,
                                          const std::vector<std::string>& text, double font, double left,
                                          double right, double top, double bottom) {
  std::vector<LabelBox> placed;
  const double gap = 5, line = font + 2;
  const int reach = static_cast<int>(std::ceil((bottom - top) / line));
  for (std::size_t i = 0; i < text.size(); ++i) {
    const double w = label_width(text[i], font);
    const bool fits_right = px[i] + gap + w <= right, fits_left = px[i] - gap - w >= left;
    const bool prefer_end = !fits_right && fits_left;
    auto at = [&](bool anchor_end, double baseline) {
      LabelBox c;
      c.anchor_end = anchor_end;
      c.x = anchor_end ? px[i] - gap : px[i] + gap;
      c.x0 = anchor_end ? c.x - w : c.x;
      c.x1 = anchor_end ? c.x : c.x + w;
      c.y = baseline;
      c.y0 = baseline - font;
      c.y1 = baseline + 2;
      return c;
    };
    // The first free box, in the order above; none: the place just above.
    auto first_free = [&]() -> LabelBox {
      for (int k = 0; k < reach; ++k) {
        const double offsets[2] = {py[i] - gap - k * line, py[i] + gap + font + k * line};
        for (const bool anchor_end : {prefer_end, !prefer_end}) {
          if (anchor_end != prefer_end && !(anchor_end ? fits_left : fits_right)) continue;
          for (double baseline : offsets) {
            LabelBox c = at(anchor_end, baseline);
            if (c.y0 < top || c.y1 > bottom) continue;
            if (std::none_of(placed.begin(), placed.end(), [&](const LabelBox& o) { return overlaps(c, o); })) {
              c.leader = k > 0;
              return c;
            }
          }
        }
      }
      return at(prefer_end, py[i] - gap);
    };
    placed.push_back(first_free());
  }
  return placed;
}

/// The number of marker shapes that `marker` draws.
inline constexpr std::size_t kMarkerShapes = 5;

/// A marker of `color` centred on (x, y), of about the area of a circle of
/// radius `r`: by `shape` (modulo kMarkerShapes) a circle, a square, a
/// triangle, a diamond or a downward triangle; filled, or `hollow` (white
/// inside a `color` outline).
inline std::string marker(std::size_t shape, double x, double y, double r, const std::string& color,
                          bool hollow = false) {
  auto point = [](double px, double py) { return fmt("%.1f", px) + "," + fmt("%.1f", py); };
  const std::string paint =
      hollow ? "fill=\"white\" stroke=\"" + color + "\" stroke-width=\"1.5\"" : "fill=\"" + color + "\"";
  switch (shape % kMarkerShapes) {
    case 1: {
      const double h = 0.9 * r;
      return "<rect x=\"" + fmt("%.1f", x - h) + "\" y=\"" + fmt("%.1f", y - h) + "\" width=\"" + fmt("%.1f", 2 * h) +
             "\" height=\"" + fmt("%.1f", 2 * h) + "\" " + paint + "/>\n";
    }
    case 2:
    case 4: {  // equilateral, about its centre, pointing up (2) or down (4)
      const double R = (shape % kMarkerShapes == 2 ? 1.5 : -1.5) * r, half = 0.866 * 1.5 * r;
      return "<polygon points=\"" + point(x, y - R) + " " + point(x + half, y + 0.5 * R) + " " +
             point(x - half, y + 0.5 * R) + "\" " + paint + "/>\n";
    }
    case 3: {
      const double d = 1.25 * r;
      return "<polygon points=\"" + point(x, y - d) + " " + point(x + d, y) + " " + point(x, y + d) + " " +
             point(x - d, y) + "\" " + paint + "/>\n";
    }
    default:
      return "<circle cx=\"" + fmt("%.1f", x) + "\" cy=\"" + fmt("%.1f", y) + "\" r=\"" + fmt("%g", r) + "\" " + paint +
             "/>\n";
  }
}

}  // namespace detail

/// Renders `p` as a standalone SVG document.
inline std::string render_svg(const Plot& p) {
  using detail::escape_xml;
  using detail::fmt;
  const double H = 440, left = 70, right = 200, top = 40, bottom = 55;
  const double pw = 760 - left - right, ph = H - top - bottom;
  // The legend, right of the plot: rows 18 units apart from top + 10, as
  // many as fit in the drawing (22); more series wrap into further columns
  // of equal length (read down, then across), each as wide as its longest
  // name and at least `right`, and the drawing widens to hold them.
  const std::size_t n_series = p.series.size();
  const std::size_t max_rows = static_cast<std::size_t>((H - top - 18) / 18) + 1;
  const std::size_t n_columns = std::max<std::size_t>(1, (n_series + max_rows - 1) / max_rows);
  const std::size_t rows = std::max<std::size_t>(1, (n_series + n_columns - 1) / n_columns);
  std::vector<double> column_x = {left + pw};  // left edges, then the drawing's right edge
  for (std::size_t c = 0; c < n_columns; ++c) {
    double width = right;
    for (std::size_t k = c * rows; k < std::min(n_series, (c + 1) * rows); ++k)
      width = std::max(width, std::ceil(50 + detail::label_width(p.series[k].name, 12)));
    column_x.push_back(column_x.back() + width);
  }
  const double W = column_x.back();
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = p.y_min, y1 = p.y_max;
  if (p.y_auto) {
    y0 = std::numeric_limits<double>::infinity();
    y1 = -y0;
  }
  for (const auto& s : p.series)
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const double xv = p.x_log ? std::log10(s.x[i]) : s.x[i];
      x0 = std::min(x0, xv);
      x1 = std::max(x1, xv);
      if (p.y_auto) {
        y0 = std::min(y0, s.y[i]);
        y1 = std::max(y1, s.y[i]);
      }
    }
  if (!std::isfinite(x0)) x0 = 0, x1 = 1;
  if (x1 <= x0) x1 = x0 + 1;
  if (p.y_auto) {
    if (!std::isfinite(y0)) y0 = 0, y1 = 1;
    // At least 4 points of a rate axis (kept within [0, 1] when the data
    // are) or 4% of the values, so that equal values (every setting at 100%)
    // still get distinct ticks around them.
    double min_span = p.y_percent ? 0.04 : 0.04 * std::max(std::abs(y0), std::abs(y1));
    if (!(min_span > 0)) min_span = 1;
    if (y1 - y0 < min_span) {
      const double mid = 0.5 * (y0 + y1);
      y0 = mid - 0.5 * min_span;
      y1 = mid + 0.5 * min_span;
      if (p.y_percent && mid >= 0 && mid <= 1) {
        if (y0 < 0) y0 = 0, y1 = min_span;
        if (y1 > 1) y0 = 1 - min_span, y1 = 1;
      }
    }
    const double pad = 0.05 * (y1 - y0);
    y0 -= pad;
    y1 += pad;
  }
  // A log axis within one decade may widen to the ticks around its data.
  const std::vector<double> xt = p.x_log ? detail::log_ticks(x0, x1) : detail::nice_ticks(x0, x1, 8, p.x_integer);
  auto X = [&](double v) { return left + ((p.x_log ? std::log10(v) : v) - x0) / (x1 - x0) * pw; };
  auto Y = [&](double v) { return top + (1 - (v - y0) / (y1 - y0)) * ph; };
  static const char* colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b",
                                 "#e377c2", "#7f7f7f", "#bcbd22", "#17becf", "#393b79", "#637939"};
  const std::size_t n_colors = sizeof colors / sizeof *colors;
  // Each round of the colours (series k and k + 12 share a colour;
  // fig_all_methods.svg has 19 methods) has its own line pattern, {plain,
  // dashed}, of 3, and its own marker (a scatter's, a line's points) of 5
  // shapes, filled and then hollow: no two series share colour and marker
  // up to 10 rounds (120 series), nor colour, line pattern and marker up to
  // 30 rounds (360 lines); beyond, the styles repeat.
  static const char* dashes[][2] = {{"", "6,4"}, {"2,3", "8,3,2,3"}, {"12,4", "12,3,2,3,2,3"}};
  auto dash_of = [&](std::size_t k, bool dashed) -> std::string {
    const char* d = dashes[(k / n_colors) % (sizeof dashes / sizeof *dashes)][dashed ? 1 : 0];
    return *d ? std::string(" stroke-dasharray=\"") + d + "\"" : std::string();
  };
  // With more series than colours, a line's legend entry shows its marker too.
  const bool legend_markers = n_series > n_colors;
  std::string s;
  s += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + fmt("%.0f", W) + "\" height=\"" + fmt("%.0f", H) +
       "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s += "<text x=\"" + fmt("%.1f", left + pw / 2) + "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">" +
       escape_xml(p.title) + "</text>\n";
  // Grid and ticks.
  const std::vector<double> yt = detail::nice_ticks(y0, y1, 5);
  // Percentages with as many decimals as the step needs (57.5%, 60.25%).
  const int y_decimals = yt.size() > 1 ? detail::step_decimals(100 * (yt[1] - yt[0])) : 0;
  auto percent = [&](double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f%%", y_decimals, 100 * v);
    return std::string(buf);
  };
  for (double t : yt) {
    s += "<line x1=\"" + fmt("%.1f", left) + "\" x2=\"" + fmt("%.1f", left + pw) + "\" y1=\"" + fmt("%.1f", Y(t)) +
         "\" y2=\"" + fmt("%.1f", Y(t)) + "\" stroke=\"#ddd\"/>\n";
    s += "<text x=\"" + fmt("%.1f", left - 6) + "\" y=\"" + fmt("%.1f", Y(t) + 4) + "\" text-anchor=\"end\">" +
         (p.y_percent ? percent(t) : fmt("%g", t)) + "</text>\n";
  }
  for (double t : xt) {
    s += "<line x1=\"" + fmt("%.1f", X(t)) + "\" x2=\"" + fmt("%.1f", X(t)) + "\" y1=\"" + fmt("%.1f", top) +
         "\" y2=\"" + fmt("%.1f", top + ph) + "\" stroke=\"#eee\"/>\n";
    s += "<text x=\"" + fmt("%.1f", X(t)) + "\" y=\"" + fmt("%.1f", top + ph + 16) + "\" text-anchor=\"middle\">" +
         fmt("%g", t) + "</text>\n";
  }
  s += "<rect x=\"" + fmt("%.1f", left) + "\" y=\"" + fmt("%.1f", top) + "\" width=\"" + fmt("%.1f", pw) +
       "\" height=\"" + fmt("%.1f", ph) + "\" fill=\"none\" stroke=\"#333\"/>\n";
  s += "<text x=\"" + fmt("%.1f", left + pw / 2) + "\" y=\"" + fmt("%.1f", H - 12) + "\" text-anchor=\"middle\">" +
       escape_xml(p.x_label) + "</text>\n";
  s += "<text transform=\"translate(16," + fmt("%.1f", top + ph / 2) + ") rotate(-90)\" text-anchor=\"middle\">" +
       escape_xml(p.y_label) + "</text>\n";
  // Series and legend; then every series' point labels, placed together so
  // that no two overlap.
  std::vector<double> label_x, label_y;
  std::vector<std::string> labels;
  for (std::size_t k = 0; k < p.series.size(); ++k) {
    const auto& ser = p.series[k];
    const std::string c = colors[k % n_colors], dash = dash_of(k, ser.dashed);
    const std::size_t round = k / n_colors, shape = round % detail::kMarkerShapes;
    const bool hollow = (round / detail::kMarkerShapes) % 2 == 1;
    if (!ser.markers_only && ser.x.size() > 1) {
      std::string pts;
      for (std::size_t i = 0; i < ser.x.size(); ++i) pts += fmt("%.1f", X(ser.x[i])) + "," + fmt("%.1f", Y(ser.y[i])) + " ";
      s += "<polyline fill=\"none\" stroke=\"" + c + "\" stroke-width=\"" + (ser.highlight ? "3" : "1.8") + "\"" +
           dash + " points=\"" + pts + "\"/>\n";
    }
    for (std::size_t i = 0; i < ser.x.size(); ++i) {
      s += detail::marker(shape, X(ser.x[i]), Y(ser.y[i]), ser.markers_only ? 4 : 2.5, c, hollow);
      if (i < ser.point_labels.size() && !ser.point_labels[i].empty()) {
        label_x.push_back(X(ser.x[i]));
        label_y.push_back(Y(ser.y[i]));
        labels.push_back(ser.point_labels[i]);
      }
    }
    const double lx = column_x[k / rows], ly = top + 10 + 18 * static_cast<double>(k % rows);
    if (ser.markers_only) {
      s += detail::marker(shape, lx + 24, ly, 4, c, hollow);
    } else {
      s += "<line x1=\"" + fmt("%.1f", lx + 12) + "\" x2=\"" + fmt("%.1f", lx + 36) + "\" y1=\"" +
           fmt("%.1f", ly) + "\" y2=\"" + fmt("%.1f", ly) + "\" stroke=\"" + c + "\" stroke-width=\"2.5\"" + dash +
           "/>\n";
      if (legend_markers) s += detail::marker(shape, lx + 24, ly, 3, c, hollow);
    }
    s += "<text x=\"" + fmt("%.1f", lx + 42) + "\" y=\"" + fmt("%.1f", ly + 4) + "\">" + escape_xml(ser.name) +
         "</text>\n";
  }
  const std::vector<detail::LabelBox> boxes =
      detail::place_labels(label_x, label_y, labels, 9, left, left + pw, top, top + ph);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const detail::LabelBox& b = boxes[i];
    if (b.leader)  // from the point to the middle of the box's near edge
      s += "<line x1=\"" + fmt("%.1f", label_x[i]) + "\" y1=\"" + fmt("%.1f", label_y[i]) + "\" x2=\"" +
           fmt("%.1f", b.anchor_end ? b.x1 : b.x0) + "\" y2=\"" + fmt("%.1f", 0.5 * (b.y0 + b.y1)) +
           "\" stroke=\"#999\" stroke-width=\"0.6\"/>\n";
    s += "<text x=\"" + fmt("%.1f", b.x) + "\" y=\"" + fmt("%.1f", b.y) + "\"" +
         (b.anchor_end ? " text-anchor=\"end\"" : "") + " font-size=\"9\" fill=\"#444\">" + escape_xml(labels[i]) +
         "</text>\n";
  }
  s += "</svg>\n";
  return s;
}

}  // namespace iclap::cli
