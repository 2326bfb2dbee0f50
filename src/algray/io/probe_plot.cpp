// The probe plot: its vertical scale, its layout into the drawing kit's display list, and its files.
#include "algray/io/probe_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

namespace algray {
namespace fs = std::filesystem;
using namespace draw;

namespace {

// The plot's own colours; its ink and white paper are the drawing kit's.
constexpr Rgb8 kGrid{226, 228, 232};
constexpr Rgb8 kZeroLine{0, 0, 0};
constexpr Rgb8 kCurve{28, 64, 160};
constexpr Rgb8 kIsolationEnd{224, 118, 0};
constexpr Rgb8 kRoot{204, 16, 48};
constexpr Rgb8 kReferenceRoot{0, 150, 90};
constexpr Rgb8 kInterval{250, 206, 80};
constexpr double kIntervalOpacity = 0.4;

// ---------------------------------------------------------------------------------------------
// Number formatting for labels

// 10^k as a reader would write it: plain for small exponents, 1e-12 style otherwise.
std::string power_of_ten_label(int k, bool negative) {
  std::string s;
  // std::string("1") rather than "1": from "1" + a string, GCC 12 at -O3 warns of an overlapping copy that
  // cannot happen (-Wrestrict, a false positive).
  if (k >= 0 && k <= 4)
    s = std::string("1") + std::string(static_cast<std::size_t>(k), '0');
  else if (k < 0 && k >= -3)
    s = "0." + std::string(static_cast<std::size_t>(-k - 1), '0') + "1";
  else
    s = "1e" + std::to_string(k);
  return negative ? "-" + s : s;
}

// Enough digits to tell neighbouring ticks `step` apart, and no more.
std::string tick_label(double v, double step) {
  if (std::abs(v) < step * 1e-9) v = 0;  // no "-0" or 1e-17 from rounding
  const double mag = std::max(std::abs(v), step);
  if (mag >= 1e7 || step < 1e-6) {
    const int digits =
        std::clamp(static_cast<int>(std::floor(std::log10(mag)) - std::floor(std::log10(step))) + 1, 1, 17);
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    return buf;
  }
  const int decimals = std::clamp(static_cast<int>(-std::floor(std::log10(step) + 1e-9)), 0, 12);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// The shortest text that reads back as exactly t: a probe is about the last digits.
std::string t_text(double t) {
  std::string s;
  for (int digits = 6; digits <= 17; ++digits) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.*g", digits, t);
    s = buf;
    if (!std::isfinite(t) || std::strtod(buf, nullptr) == t) break;
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// Probe plot layout

constexpr int kPlotWidth = 900;
constexpr double kLeft = 100, kRightMargin = 40, kTop = 64, kPlotHeight = 300;
constexpr double kLegendGap = 66, kRowHeight = 22, kMinTickGap = 20;
constexpr std::size_t kMaxIntervalRows = 4, kMaxMarkerRows = 12;

double signed_log(double v, double floor) { return std::copysign(std::log10(1 + std::abs(v) / floor), v); }

struct CheckedPlot {
  double t_in, t_out;
};

CheckedPlot check_plot(const ProbePlot& plot) {
  if (plot.t.size() != plot.value.size())
    throw OutputError("probe plot has " + std::to_string(plot.t.size()) + " t samples but " +
                      std::to_string(plot.value.size()) + " values");
  if (!std::isfinite(plot.t_in) || !std::isfinite(plot.t_out) || plot.t_out < plot.t_in)
    throw OutputError("probe plot range [" + t_text(plot.t_in) + ", " + t_text(plot.t_out) + "] is not a finite range");
  CheckedPlot c{plot.t_in, plot.t_out};
  // A zero-length range (a grazing ray) still deserves a picture: open it around its point.
  const double min_span = std::max(std::abs(c.t_in), std::abs(c.t_out)) * 1e-12;
  if (c.t_out - c.t_in <= min_span) {
    const double half = std::max(std::abs(c.t_in) * 1e-6, 1e-9);
    c.t_in -= half;
    c.t_out += half;
  }
  return c;
}

std::size_t legend_rows(const ProbePlot& plot) {
  const std::size_t intervals =
      std::min(plot.intervals.size(), kMaxIntervalRows) + (plot.intervals.size() > kMaxIntervalRows ? 1 : 0);
  const std::size_t markers =
      std::min(plot.markers.size(), kMaxMarkerRows) + (plot.markers.size() > kMaxMarkerRows ? 1 : 0);
  return 1 + intervals + markers;
}

bool in_range(double t, const ProbePlotGeometry& g) { return t >= g.t_in && t <= g.t_out; }

std::string floor_origin(const std::vector<double>& values, double floor) {
  double smallest = std::numeric_limits<double>::infinity();
  for (double v : values)
    if (std::isfinite(v) && v != 0) smallest = std::min(smallest, std::abs(v));
  if (!std::isfinite(smallest)) return "no nonzero P";
  return floor == smallest ? "smallest nonzero |P|" : "1e-12 max |P|";
}

std::vector<double> visible_values(const ProbePlot& plot, const CheckedPlot& range) {
  std::vector<double> values;
  for (std::size_t i = 0; i < plot.t.size(); ++i)
    if (plot.t[i] >= range.t_in && plot.t[i] <= range.t_out) values.push_back(plot.value[i]);
  return values;
}

void add_y_ticks(Drawing& d, const ProbePlotGeometry& g) {
  const double y0 = g.y_of(0);
  const double px_per_unit = (g.bottom - g.top) / (g.y_max - g.y_min);
  // Decades whose position lies in the visible range; one scaled unit is close to one decade above the floor.
  const double reach = std::max(std::abs(g.y_min), std::abs(g.y_max));
  const int k_lo = static_cast<int>(std::floor(std::log10(g.floor))) - 1;
  const int k_hi = static_cast<int>(std::ceil(std::log10(g.floor) + reach)) + 1;
  // Label every step-th decade, the smallest step that keeps labels kMinTickGap apart.
  int step = 500;
  for (int s : {1, 2, 3, 4, 5, 10, 20, 25, 50, 100, 200})
    if (s * px_per_unit >= kMinTickGap) {
      step = s;
      break;
    }

  struct Tick {
    double y;
    std::string label;
  };
  std::vector<Tick> labelled{{y0, "0"}}, candidates, minor;
  for (int k = k_lo; k <= k_hi; ++k) {
    const double v = std::pow(10.0, k);
    for (bool negative : {false, true}) {
      const double s = signed_log(negative ? -v : v, g.floor);
      if (!std::isfinite(s) || s < g.y_min || s > g.y_max) continue;
      Tick t{g.y_of(negative ? -v : v), power_of_ten_label(k, negative)};
      (((k % step) + step) % step == 0 ? candidates : minor).push_back(t);
    }
  }
  // Nearest to zero first, each kept only when clear of those already kept.
  std::sort(candidates.begin(), candidates.end(),
            [&](const Tick& a, const Tick& b) { return std::abs(a.y - y0) < std::abs(b.y - y0); });
  auto clear_of = [](const std::vector<Tick>& kept, double y, double gap) {
    return std::all_of(kept.begin(), kept.end(), [&](const Tick& t) { return std::abs(t.y - y) >= gap; });
  };
  for (const Tick& t : candidates) (clear_of(labelled, t.y, kMinTickGap) ? labelled : minor).push_back(t);
  for (const Tick& t : minor)
    if (clear_of(labelled, t.y, 3)) d.shapes.push_back(LineShape{g.left - 3, t.y, g.left, t.y, kInk, 1});
  for (std::size_t i = 0; i < labelled.size(); ++i) {
    const Tick& t = labelled[i];
    if (i > 0) d.shapes.push_back(LineShape{g.left, t.y, g.right, t.y, kGrid, 1, false, true});  // 0 has its own line
    d.shapes.push_back(LineShape{g.left - 6, t.y, g.left, t.y, kInk, 1});
    d.shapes.push_back(TextShape{g.left - 10, t.y, t.label, 2, 0, Anchor::End});
  }
}

void add_t_ticks(Drawing& d, const ProbePlotGeometry& g) {
  const double span = g.t_out - g.t_in;
  const double width = g.right - g.left;
  double step = nice_step(span / 10);
  // Widen the step until the widest label fits between neighbours.
  for (int attempt = 0; attempt < 20; ++attempt, step = nice_step(step * 1.5)) {
    const double first = std::ceil(g.t_in / step);
    const double last = std::floor(g.t_out / step);
    if (!(last - first < 100)) continue;
    std::vector<std::pair<double, std::string>> ticks;
    std::size_t widest = 0;
    for (double i = first; i <= last; ++i) {
      ticks.emplace_back(i * step, tick_label(i * step, step));
      widest = std::max(widest, ticks.back().second.size());
    }
    const double gap = ticks.size() > 1 ? step / span * width : width;
    if (text_width(widest, 2) + 16 > gap && attempt + 1 < 20) continue;
    for (const auto& [t, label] : ticks) {
      const double x = g.x_of(t);
      const double half = text_width(label.size(), 2) / 2.0;
      if (x - half < 2 || x + half > g.width - 2) continue;  // would be cut at the picture's edge
      d.shapes.push_back(LineShape{x, g.top, x, g.bottom, kGrid, 1, false, true});
      d.shapes.push_back(LineShape{x, g.bottom, x, g.bottom + 6, kInk, 1});
      d.shapes.push_back(TextShape{x, g.bottom + 20, label, 2, 0, Anchor::Middle});
    }
    return;
  }
}

std::string default_label(PlotMarker::Kind kind) {
  switch (kind) {
    case PlotMarker::Kind::IsolationEnd:
      return "isolation end";
    case PlotMarker::Kind::Root:
      return "root";
    case PlotMarker::Kind::ReferenceRoot:
      return "reference root";
  }
  return "marker";
}

// The marker's look, drawn at x on the plot, or as a legend swatch when the line spans only the swatch.
void add_marker_shapes(Drawing& d, PlotMarker::Kind kind, double x, double y_top, double y_bottom, double y_zero,
                       bool clip) {
  switch (kind) {
    case PlotMarker::Kind::IsolationEnd:
      d.shapes.push_back(LineShape{x, y_top, x, y_bottom, kIsolationEnd, 2, true, clip});
      break;
    case PlotMarker::Kind::Root:
      d.shapes.push_back(LineShape{x, y_top, x, y_bottom, kRoot, 2, false, clip});
      d.shapes.push_back(CircleShape{x, y_zero, 4, kRoot, true, 0, clip});
      break;
    case PlotMarker::Kind::ReferenceRoot:
      d.shapes.push_back(CircleShape{x, y_zero, 7, kReferenceRoot, false, 2.5, clip});
      break;
  }
}

void add_headings(Drawing& d, const ProbePlot& plot, const ProbePlotGeometry& g) {
  const double text_room = g.width - 24;
  d.shapes.push_back(TextShape{g.width / 2.0, 20, plot.title, 2, text_room, Anchor::Middle});
  const CheckedPlot range{g.t_in, g.t_out};
  d.shapes.push_back(TextShape{g.left, 44,
                               "y = sign(P) log10(1+|P|/f), f = " + format("%.3g", g.floor) + " (" +
                                   floor_origin(visible_values(plot, range), g.floor) + ")",
                               2, g.right - g.left});
}

// At least 2 px wide, or a tight interval around a root would vanish.
void add_intervals(Drawing& d, const ProbePlot& plot, const ProbePlotGeometry& g) {
  for (const auto& [a, b] : plot.intervals) {
    if (!std::isfinite(a) || !std::isfinite(b) || std::max(a, b) < g.t_in || std::min(a, b) > g.t_out) continue;
    double x0 = g.x_of(std::max(std::min(a, b), g.t_in)), x1 = g.x_of(std::min(std::max(a, b), g.t_out));
    if (x1 - x0 < 2) {
      const double mid = (x0 + x1) / 2;
      x0 = mid - 1;
      x1 = mid + 1;
    }
    d.shapes.push_back(RectShape{{x0, g.top, x1, g.bottom}, kInterval, kIntervalOpacity, true});
  }
}

// The curve, broken at non-finite values.
void add_curve(Drawing& d, const ProbePlot& plot, const ProbePlotGeometry& g) {
  PolylineShape piece{{}, kCurve, 2, true};
  auto flush = [&] {
    if (!piece.points.empty()) d.shapes.push_back(piece);
    piece.points.clear();
  };
  for (std::size_t i = 0; i < plot.t.size(); ++i) {
    if (!std::isfinite(plot.t[i]) || !std::isfinite(plot.value[i])) {
      flush();
      continue;
    }
    piece.points.emplace_back(g.x_of(plot.t[i]), g.y_of(plot.value[i]));
  }
  flush();
}

void add_frame(Drawing& d, const ProbePlotGeometry& g) {
  d.shapes.push_back(RectShape{{g.left, g.top, g.right, g.top + 1}, kInk});
  d.shapes.push_back(RectShape{{g.left, g.bottom - 1, g.right, g.bottom}, kInk});
  d.shapes.push_back(RectShape{{g.left, g.top, g.left + 1, g.bottom}, kInk});
  d.shapes.push_back(RectShape{{g.right - 1, g.top, g.right, g.bottom}, kInk});
  d.shapes.push_back(TextShape{g.right, g.bottom + 42, "t", 2, 0, Anchor::End});
}

// Legend: one row per curve, interval and marker, each with its swatch and its exact t.
void add_legend(Drawing& d, const ProbePlot& plot, const ProbePlotGeometry& g) {
  const double sx0 = g.left, sx1 = g.left + 36, tx = g.left + 48, room = g.width - tx - 12;
  double row = g.bottom + kLegendGap;
  std::size_t visible_samples = 0;
  for (std::size_t i = 0; i < plot.t.size(); ++i)
    visible_samples += in_range(plot.t[i], g) && std::isfinite(plot.value[i]) ? 1 : 0;
  d.shapes.push_back(LineShape{sx0, row, sx1, row, kCurve, 2});
  d.shapes.push_back(TextShape{tx, row,
                               "P*(t), " + std::to_string(visible_samples) +
                                   (visible_samples == 1 ? " sample" : " samples") + " on [" + t_text(plot.t_in) +
                                   ", " + t_text(plot.t_out) + "]",
                               2, room});
  for (std::size_t i = 0; i < plot.intervals.size() && i <= kMaxIntervalRows; ++i) {
    row += kRowHeight;
    if (i == kMaxIntervalRows) {
      d.shapes.push_back(
          TextShape{tx, row, "... and " + std::to_string(plot.intervals.size() - i) + " more intervals", 2, room});
      break;
    }
    d.shapes.push_back(RectShape{{sx0, row - 6, sx1, row + 6}, kInterval, kIntervalOpacity * 2});
    d.shapes.push_back(TextShape{
        tx, row,
        "isolating interval [" + t_text(plot.intervals[i].first) + ", " + t_text(plot.intervals[i].second) + "]", 2,
        room});
  }
  for (std::size_t i = 0; i < plot.markers.size() && i <= kMaxMarkerRows; ++i) {
    row += kRowHeight;
    if (i == kMaxMarkerRows) {
      d.shapes.push_back(
          TextShape{tx, row, "... and " + std::to_string(plot.markers.size() - i) + " more markers", 2, room});
      break;
    }
    const PlotMarker& m = plot.markers[i];
    d.shapes.push_back(LineShape{sx0, row, sx1, row, kZeroLine, 1});  // the zero line that roots sit on
    add_marker_shapes(d, m.kind, (sx0 + sx1) / 2, row - 8, row + 8, row, false);
    const std::string label = m.label.empty() ? default_label(m.kind) : m.label;
    d.shapes.push_back(
        TextShape{tx, row, label + ": t = " + t_text(m.t) + (in_range(m.t, g) ? "" : " (outside the plot)"), 2, room});
  }
}

Drawing draw_probe_plot(const ProbePlot& plot, const ProbePlotGeometry& g) {
  Drawing d;
  d.width = g.width;
  d.height = g.height;
  d.clip = {g.left, g.top, g.right, g.bottom};
  d.title = plot.title;
  add_headings(d, plot, g);
  // Shaded intervals first, so everything else stays visible on top.
  add_intervals(d, plot, g);
  add_y_ticks(d, g);
  add_t_ticks(d, g);
  const double y0 = g.y_of(0);
  d.shapes.push_back(LineShape{g.left, y0, g.right, y0, kZeroLine, 1.5, false, true});
  add_curve(d, plot, g);
  // Markers by kind, so reference roots (open circles) stay visible over the roots found.
  for (auto kind : {PlotMarker::Kind::IsolationEnd, PlotMarker::Kind::Root, PlotMarker::Kind::ReferenceRoot})
    for (const PlotMarker& m : plot.markers)
      if (m.kind == kind && in_range(m.t, g)) add_marker_shapes(d, kind, g.x_of(m.t), g.top, g.bottom, y0, true);
  add_frame(d, g);
  add_legend(d, plot, g);
  return d;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Probe plot, public

double ProbePlotGeometry::x_of(double t) const { return left + (t - t_in) / (t_out - t_in) * (right - left); }

double ProbePlotGeometry::y_of(double value) const {
  return bottom - (signed_log(value, floor) - y_min) / (y_max - y_min) * (bottom - top);
}

double signed_log_floor(const std::vector<double>& values) {
  double largest = 0, smallest = std::numeric_limits<double>::infinity();
  for (double v : values) {
    if (!std::isfinite(v) || v == 0) continue;
    largest = std::max(largest, std::abs(v));
    smallest = std::min(smallest, std::abs(v));
  }
  if (largest == 0) return 1;
  return std::max(smallest, largest * 1e-12);
}

ProbePlotGeometry probe_plot_geometry(const ProbePlot& plot) {
  const CheckedPlot range = check_plot(plot);
  ProbePlotGeometry g;
  g.width = kPlotWidth;
  g.left = kLeft;
  g.right = kPlotWidth - kRightMargin;
  g.top = kTop;
  g.bottom = kTop + kPlotHeight;
  g.height = static_cast<int>(g.bottom + kLegendGap + static_cast<double>(legend_rows(plot) - 1) * kRowHeight + 22);
  g.t_in = range.t_in;
  g.t_out = range.t_out;

  const std::vector<double> values = visible_values(plot, range);
  g.floor = signed_log_floor(values);
  double most_positive = 0, most_negative = 0;
  for (double v : values)
    if (std::isfinite(v)) most_positive = std::max(most_positive, v), most_negative = std::min(most_negative, v);
  // Out to the next power of ten, so that the outermost decade of the data has a labelled tick.
  auto outer_decade = [](double magnitude) {
    const double p = std::pow(10.0, std::ceil(std::log10(magnitude)));
    return std::isfinite(p) ? p : magnitude;
  };
  double hi = most_positive > 0 ? signed_log(outer_decade(most_positive), g.floor) : 0;
  double lo = most_negative < 0 ? -signed_log(outer_decade(-most_negative), g.floor) : 0;
  if (hi - lo <= 0) {
    lo = -1;
    hi = 1;
  }
  const double pad = 0.03 * (hi - lo);
  g.y_min = lo - pad;
  g.y_max = hi + pad;
  return g;
}

std::string probe_plot_svg(const ProbePlot& plot) { return to_svg(draw_probe_plot(plot, probe_plot_geometry(plot))); }

// The PNG form exists because `--plot x.png` is asked for: CI artefact pages, issue trackers and image viewers
// show PNG where SVG often is not.
FrameImage probe_plot_image(const ProbePlot& plot) {
  return rasterise(draw_probe_plot(plot, probe_plot_geometry(plot)));
}

void check_probe_plot_path(const fs::path& path) {
  const std::string ext = lowercase_extension(path);
  if (ext != ".svg" && ext != ".png")
    throw OutputError("unsupported plot extension '" + path.extension().string() + "' in '" + path.string() +
                      "'; use .svg or .png");
}

void write_probe_plot(const fs::path& path, const ProbePlot& plot) {
  // Check the name before drawing, so a wrong name costs nothing and writes nothing.
  check_probe_plot_path(path);
  if (lowercase_extension(path) == ".svg")
    write_text_file(path, probe_plot_svg(plot));
  else
    write_png(path, probe_plot_image(plot));
}

Rgb8 probe_curve_colour() { return kCurve; }

Rgb8 marker_colour(PlotMarker::Kind kind) {
  switch (kind) {
    case PlotMarker::Kind::IsolationEnd:
      return kIsolationEnd;
    case PlotMarker::Kind::Root:
      return kRoot;
    case PlotMarker::Kind::ReferenceRoot:
      return kReferenceRoot;
  }
  return kInk;
}

}  // namespace algray
