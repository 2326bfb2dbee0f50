// The heat map of solver work per pixel: its scale, colour ramp and layout on a drawing-kit canvas.
#include "algray/io/heatmap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "algray/io/drawing.h"

namespace algray {
using namespace draw;

namespace {

// Neutral, and darker than the work ramp's middle but lighter than its start, so it reads as "no data"
// rather than as "little work".
constexpr Rgb8 kOutOfExtent{70, 70, 70};
constexpr Rgb8 kPanel{246, 246, 246};

// Dark indigo through crimson and amber to pale yellow, with CIE lightness rising steadily along the ramp
// (CIE L* of the anchors: 4, 18, 31, 46, 61, 80, 96), so that brighter always means more work, also in greyscale.
constexpr std::array<Rgb8, 7> kWorkRamp = {{
    {14, 8, 40},
    {62, 20, 104},
    {130, 30, 110},
    {200, 52, 82},
    {236, 112, 46},
    {246, 190, 60},
    {252, 246, 190},
}};

// sRGB of ramp position u in [0, 1], interpolated between anchors in sRGB, which is closer to perceptual
// spacing than linear light.
std::array<float, 3> work_colour(double u) {
  const double x = std::clamp(u, 0.0, 1.0) * static_cast<double>(kWorkRamp.size() - 1);
  const auto i = std::min(static_cast<std::size_t>(x), kWorkRamp.size() - 2);
  const auto f = static_cast<float>(x - static_cast<double>(i));
  const auto a = unit(kWorkRamp[i]), b = unit(kWorkRamp[i + 1]);
  return {a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f, a[2] + (b[2] - a[2]) * f};
}

double ramp_position(double v, const HeatmapScale& s) {
  if (s.max <= s.min) return 0.5;
  if (s.logarithmic) return (std::log1p(v) - std::log1p(s.min)) / (std::log1p(s.max) - std::log1p(s.min));
  return (v - s.min) / (s.max - s.min);
}

// Greedy word wrap at `columns` characters; a word longer than a line is cut.
std::vector<std::string> wrap(const std::string& text, std::size_t columns) {
  std::vector<std::string> lines;
  std::string line, word;
  auto place = [&] {
    while (word.size() > columns) {
      if (!line.empty()) lines.push_back(line), line.clear();
      lines.push_back(word.substr(0, columns));
      word.erase(0, columns);
    }
    if (word.empty()) return;
    if (!line.empty() && line.size() + 1 + word.size() > columns) lines.push_back(line), line.clear();
    line += (line.empty() ? "" : " ") + word;
    word.clear();
  };
  for (char c : text) {
    if (c == ' ' || c == '\n' || c == '\t')
      place();
    else
      word += c;
  }
  place();
  if (!line.empty()) lines.push_back(line);
  return lines;
}

void check_heatmap_input(int width, int height, const std::vector<std::uint32_t>& work,
                         const std::vector<std::uint8_t>& in_extent) {
  if (width < 0 || height < 0)
    throw OutputError("invalid heat map size " + std::to_string(width) + "x" + std::to_string(height));
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (work.size() != n)
    throw OutputError("heat map work holds " + std::to_string(work.size()) + " values, expected " + std::to_string(n));
  if (!in_extent.empty() && in_extent.size() != n)
    throw OutputError("heat map extent mask holds " + std::to_string(in_extent.size()) + " values, expected " +
                      std::to_string(n));
}

// Layout: the map at the origin, the bar to its right with the scale's name above it, the caption below.
constexpr int kScale = 2, kBarWidth = 20, kGap = 16, kBarTop = 38, kMinBody = 220, kLine = 20;

struct HeatmapLayout {
  int body;  // the height of the map and bar, above the caption
  int bar_x, bar_top, bar_bottom;
  double bar_h;

  HeatmapLayout(int width, int height)
      : body(std::max(height, kMinBody)),
        bar_x(width + kGap),
        bar_top(kBarTop),
        bar_bottom(body - 12),
        bar_h(bar_bottom - bar_top) {}
};

struct Tick {
  double value;
  std::string label;
};

// The scale's ends, and round values between them where their labels keep clear of each other.
std::vector<Tick> bar_ticks(const HeatmapScale& scale, const HeatmapLayout& layout) {
  std::vector<Tick> ticks;
  auto label = [](double v) { return format("%.0f", v); };
  if (scale.pixels == 0) return ticks;
  ticks.push_back({scale.min, label(scale.min)});
  if (!(scale.max > scale.min)) return ticks;
  std::vector<double> inner;
  if (scale.logarithmic) {
    for (double p = 1; p < scale.max; p *= 10)
      if (p > scale.min) inner.push_back(p);
  } else {
    const double step = std::max(1.0, nice_step((scale.max - scale.min) / 5));
    for (double v = std::ceil(scale.min / step) * step; v < scale.max; v += step)
      if (v > scale.min) inner.push_back(v);
  }
  auto y_of = [&](double v) { return layout.bar_bottom - ramp_position(v, scale) * layout.bar_h; };
  const int text_h = kGlyphH * kScale;
  const double y_max = y_of(scale.max);
  double last_y = y_of(scale.min);
  for (double v : inner) {
    const double y = y_of(v);
    if (last_y - y >= text_h + 4 && y - y_max >= text_h + 4) {
      ticks.push_back({v, label(v)});
      last_y = y;
    }
  }
  ticks.push_back({scale.max, label(scale.max)});
  return ticks;
}

void paint_map(Canvas& canvas, int width, int height, const std::vector<std::uint32_t>& work,
               const std::vector<std::uint8_t>& in_extent, const HeatmapScale& scale) {
  const auto grey = unit(kOutOfExtent);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
      const bool inside = in_extent.empty() || in_extent[i];
      canvas.set(x, y, inside ? work_colour(ramp_position(work[i], scale)) : grey);
    }
}

// The bar: bright at the top like "more"; a single colour when every pixel did the same work.
void paint_bar(Canvas& canvas, const HeatmapScale& scale, const HeatmapLayout& layout, const std::string& kind,
               const std::vector<Tick>& ticks) {
  const int bar_x = layout.bar_x, bar_top = layout.bar_top, bar_bottom = layout.bar_bottom;
  for (int y = bar_top; y < bar_bottom; ++y) {
    const bool single = scale.pixels > 0 && scale.max == scale.min;
    const double u = single ? 0.5 : 1.0 - (y - bar_top + 0.5) / layout.bar_h;
    for (int x = bar_x; x < bar_x + kBarWidth; ++x) canvas.set(x, y, work_colour(u));
  }
  canvas.text(bar_x, kBarTop / 2.0, kind, kScale, Anchor::Start, kInk);
  for (const Tick& t : ticks) {
    const double y = scale.max > scale.min ? bar_bottom - ramp_position(t.value, scale) * layout.bar_h
                                           : (bar_top + bar_bottom) / 2.0;
    const int yi = std::clamp(static_cast<int>(std::lround(y)), bar_top, bar_bottom - 1);
    for (int x = bar_x + kBarWidth; x < bar_x + kBarWidth + 6; ++x) canvas.blend(x, yi, kInk, 1);
    canvas.text(bar_x + kBarWidth + 10, yi, t.label, kScale, Anchor::Start, kInk);
  }
}

}  // namespace

HeatmapScale heatmap_scale(const std::vector<std::uint32_t>& work, const std::vector<std::uint8_t>& in_extent) {
  HeatmapScale s;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t i = 0; i < work.size(); ++i) {
    if (!in_extent.empty() && (i >= in_extent.size() || !in_extent[i])) continue;
    lo = std::min(lo, static_cast<double>(work[i]));
    hi = std::max(hi, static_cast<double>(work[i]));
    ++s.pixels;
  }
  if (s.pixels == 0) return s;
  s.min = lo;
  s.max = hi;
  s.logarithmic = (1 + hi) / (1 + lo) > 50;
  return s;
}

FrameImage work_heatmap(int width, int height, const std::vector<std::uint32_t>& work,
                        const std::vector<std::uint8_t>& in_extent, const std::string& caption) {
  check_heatmap_input(width, height, work, in_extent);
  const HeatmapScale scale = heatmap_scale(work, in_extent);
  const HeatmapLayout layout(width, height);
  const std::vector<Tick> ticks = bar_ticks(scale, layout);
  std::size_t widest = 0;
  for (const Tick& t : ticks) widest = std::max(widest, t.label.size());
  const std::string kind = scale.pixels == 0 ? "no data" : scale.logarithmic ? "log scale" : "linear scale";
  const int bar_x = layout.bar_x;
  const int panel_right =
      std::max(bar_x + kBarWidth + 10 + text_width(widest, kScale), bar_x + text_width(kind.size(), kScale)) + 12;

  const int canvas_w = std::max(panel_right, 240);
  const auto columns = static_cast<std::size_t>(std::max(10, (canvas_w - 16) / (kAdvance * kScale)));
  std::string full_caption = caption.empty() ? "solver work" : caption;
  full_caption += scale.pixels == 0 ? " (no pixel in the extent)"
                                    : " (" + kind + ", " + std::to_string(scale.pixels) + " pixels in the extent)";
  const std::vector<std::string> lines = wrap(full_caption, columns);
  const int canvas_h = layout.body + 8 + static_cast<int>(lines.size()) * kLine + 6;

  Canvas canvas(canvas_w, canvas_h, kPanel);
  paint_map(canvas, width, height, work, in_extent, scale);
  paint_bar(canvas, scale, layout, kind, ticks);
  for (std::size_t i = 0; i < lines.size(); ++i)
    canvas.text(8, layout.body + 8 + (static_cast<double>(i) + 0.5) * kLine, lines[i], kScale, Anchor::Start, kInk);
  return canvas.to_frame();
}

}  // namespace algray
