// Probe plots (one display list drawn as SVG or rasterised for PNG), work heat maps and the small bitmap font.
#include "algray/io/probe_plot.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <stdexcept>
#include <variant>

namespace algray {
namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------------------------
// Colours, as sRGB bytes because that is how both SVG and a PNG viewer speak.

constexpr Rgb8 kBackground{255, 255, 255};
constexpr Rgb8 kInk{34, 34, 40};
constexpr Rgb8 kGrid{226, 228, 232};
constexpr Rgb8 kZeroLine{0, 0, 0};
constexpr Rgb8 kCurve{28, 64, 160};
constexpr Rgb8 kIsolationEnd{224, 118, 0};
constexpr Rgb8 kRoot{204, 16, 48};
constexpr Rgb8 kReferenceRoot{0, 150, 90};
constexpr Rgb8 kInterval{250, 206, 80};
constexpr double kIntervalOpacity = 0.4;

// Neutral, and darker than the work ramp's middle but lighter than its start, so it reads as "no data"
// rather than as "little work".
constexpr Rgb8 kOutOfExtent{70, 70, 70};
constexpr Rgb8 kPanel{246, 246, 246};

std::array<float, 3> unit(Rgb8 c) { return {c.r / 255.0f, c.g / 255.0f, c.b / 255.0f}; }

std::string hex(Rgb8 c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", c.r, c.g, c.b);
  return buf;
}

// ---------------------------------------------------------------------------------------------
// A 5x7 bitmap font of capitals, digits and the punctuation that labels use. Each sheet row is one pixel
// row of every glyph in `chars`, 5 columns per glyph and one space between glyphs.

constexpr int kGlyphW = 5, kGlyphH = 7, kAdvance = 6;

struct FontSheet {
  const char* chars;
  const char* rows[kGlyphH];
};

constexpr FontSheet kFontSheets[] = {
    {"0123456789",
     {".###. ..#.. .###. ##### ...#. ##### ..##. ##### .###. .###.",
      "#...# .##.. #...# ...#. ..##. #.... .#... ....# #...# #...#",
      "#..## ..#.. ....# ..#.. .#.#. ####. #.... ...#. #...# #...#",
      "#.#.# ..#.. ...#. ...#. #..#. ....# ####. ..#.. .###. .####",
      "##..# ..#.. ..#.. ....# ##### ....# #...# .#... #...# ....#",
      "#...# ..#.. .#... #...# ...#. #...# #...# .#... #...# ...#.",
      ".###. .###. ##### .###. ...#. .###. .###. .#... .###. .##.."}},
    {"ABCDEFGHIJKLM",
     {".###. ####. .###. ###.. ##### ##### .###. #...# .###. ..### #...# #.... #...#",
      "#...# #...# #...# #..#. #.... #.... #...# #...# ..#.. ...#. #..#. #.... ##.##",
      "#...# #...# #.... #...# #.... #.... #.... #...# ..#.. ...#. #.#.. #.... #.#.#",
      "##### ####. #.... #...# ####. ####. #.### ##### ..#.. ...#. ##... #.... #.#.#",
      "#...# #...# #.... #...# #.... #.... #...# #...# ..#.. ...#. #.#.. #.... #...#",
      "#...# #...# #...# #..#. #.... #.... #...# #...# ..#.. #..#. #..#. #.... #...#",
      "#...# ####. .###. ###.. ##### #.... .#### #...# .###. .##.. #...# ##### #...#"}},
    {"NOPQRSTUVWXYZ",
     {"#...# .###. ####. .###. ####. .#### ##### #...# #...# #...# #...# #...# #####",
      "#...# #...# #...# #...# #...# #.... ..#.. #...# #...# #...# #...# #...# ....#",
      "##..# #...# #...# #...# #...# #.... ..#.. #...# #...# #...# .#.#. .#.#. ...#.",
      "#.#.# #...# ####. #...# ####. .###. ..#.. #...# #...# #.#.# ..#.. ..#.. ..#..",
      "#..## #...# #.... #.#.# #.#.. ....# ..#.. #...# #...# #.#.# .#.#. ..#.. .#...",
      "#...# #...# #.... #..#. #..#. ....# ..#.. #...# .#.#. #.#.# #...# ..#.. #....",
      "#...# .###. #.... .##.# #...# ####. ..#.. .###. ..#.. .#.#. #...# ..#.. #####"}},
    {" -+.(),=:_[]/?",
     {"..... ..... ..... ..... ...#. .#... ..... ..... ..... ..... .###. .###. ....# .###.",
      "..... ..... ..#.. ..... ..#.. ..#.. ..... ..... .##.. ..... .#... ...#. ....# #...#",
      "..... ..... ..#.. ..... .#... ...#. ..... ##### .##.. ..... .#... ...#. ...#. ....#",
      "..... ##### ##### ..... .#... ...#. ..... ..... ..... ..... .#... ...#. ..#.. ...#.",
      "..... ..... ..#.. ..... .#... ...#. .##.. ##### .##.. ..... .#... ...#. .#... ..#..",
      "..... ..... ..#.. .##.. ..#.. ..#.. ..#.. ..... .##.. ..... .#... ...#. #.... .....",
      "..... ..... ..... .##.. ...#. .#... .#... ..... ..... ##### .###. .###. #.... ..#.."}},
    {"<>*'\"&%#!|^~;",
     {"...#. .#... ..... ..#.. .#.#. .##.. ##..# .#.#. ..#.. ..#.. ..#.. ..... .....",
      "..#.. ..#.. #.#.# ..#.. .#.#. #..#. ##..# .#.#. ..#.. ..#.. .#.#. ..... .##..",
      ".#... ...#. .###. .#... ..... #.#.. ...#. ##### ..#.. ..#.. #...# .#... .##..",
      "#.... ....# ##### ..... ..... .#... ..#.. .#.#. ..#.. ..#.. ..... #.#.# .....",
      ".#... ...#. .###. ..... ..... #.#.# .#... ##### ..#.. ..#.. ..... ...#. .##..",
      "..#.. ..#.. #.#.# ..... ..... #..#. #..## .#.#. ..... ..#.. ..... ..... ..#..",
      "...#. .#... ..... ..... ..... .##.# #..## .#.#. ..#.. ..#.. ..... ..... .#..."}},
};

using Glyph = std::array<std::uint8_t, kGlyphH>;  // bit 4 is the leftmost column

const std::array<std::optional<Glyph>, 128>& font() {
  static const std::array<std::optional<Glyph>, 128> table = [] {
    std::array<std::optional<Glyph>, 128> t{};
    for (const FontSheet& sheet : kFontSheets) {
      const std::string chars = sheet.chars;
      for (std::size_t i = 0; i < chars.size(); ++i) {
        Glyph g{};
        for (int row = 0; row < kGlyphH; ++row) {
          const std::string line = sheet.rows[row];
          if (line.size() != chars.size() * kAdvance - 1) throw std::logic_error("malformed font sheet row");
          for (int col = 0; col < kGlyphW; ++col) {
            if (line[i * kAdvance + static_cast<std::size_t>(col)] == '#')
              g[static_cast<std::size_t>(row)] |= static_cast<std::uint8_t>(1u << (kGlyphW - 1 - col));
          }
        }
        t[static_cast<unsigned char>(chars[i])] = g;
      }
    }
    return t;
  }();
  return table;
}

// What the bitmap font can show of `text`: lower case as capitals, each UTF-8 sequence or unknown byte as '?'.
std::string font_text(const std::string& text) {
  std::string out;
  for (char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if ((c & 0xC0) == 0x80) continue;  // UTF-8 continuation byte: its lead byte already printed '?'
    const char upper = static_cast<char>(std::toupper(c));
    out += c < 128 && font()[static_cast<unsigned char>(upper)] ? upper : '?';
  }
  return out;
}

int text_width(std::size_t chars, int scale) {
  return chars == 0 ? 0 : (static_cast<int>(chars) * kAdvance - 1) * scale;
}

// ---------------------------------------------------------------------------------------------
// Raster canvas. The PNG form exists because `--plot x.png` is asked for: CI artefact pages, issue trackers
// and image viewers show PNG where SVG often is not. It draws the same display list as the SVG, so the two
// cannot drift apart. Pixels hold sRGB-encoded values and blending happens there, as SVG renderers do, so the
// PNG looks like the SVG; the conversion to linear happens once, in to_frame().

enum class Anchor { Start, Middle, End };

struct Box {
  double x0, y0, x1, y1;
};

class Canvas {
 public:
  Canvas(int width, int height, Rgb8 background)
      : width_(width), height_(height), rgb_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3) {
    const auto c = unit(background);
    for (std::size_t i = 0; i < rgb_.size(); ++i) rgb_[i] = c[i % 3];
  }

  int width() const { return width_; }
  int height() const { return height_; }

  void set(int x, int y, const std::array<float, 3>& srgb) {
    if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
    float* p = &rgb_[index(x, y)];
    for (int c = 0; c < 3; ++c) p[c] = srgb[static_cast<std::size_t>(c)];
  }

  void blend(int x, int y, Rgb8 colour, double alpha, const std::optional<Box>& clip = std::nullopt) {
    if (x < 0 || y < 0 || x >= width_ || y >= height_ || !(alpha > 0)) return;
    if (clip && (x + 0.5 < clip->x0 || x + 0.5 > clip->x1 || y + 0.5 < clip->y0 || y + 0.5 > clip->y1)) return;
    const auto a = static_cast<float>(std::min(alpha, 1.0));
    const auto c = unit(colour);
    float* p = &rgb_[index(x, y)];
    for (std::size_t k = 0; k < 3; ++k) p[k] = p[k] * (1 - a) + c[k] * a;
  }

  // Text centred vertically on y_center; capitals only, see font_text.
  void text(double x, double y_center, const std::string& s, int scale, Anchor anchor, Rgb8 colour) {
    const std::string shown = font_text(s);
    const int w = text_width(shown.size(), scale);
    int left = static_cast<int>(std::lround(x));
    if (anchor == Anchor::Middle) left -= w / 2;
    if (anchor == Anchor::End) left -= w;
    const int top = static_cast<int>(std::lround(y_center - kGlyphH * scale / 2.0));
    for (std::size_t i = 0; i < shown.size(); ++i) {
      const Glyph& g = *font()[static_cast<unsigned char>(shown[i])];
      const int gx = left + static_cast<int>(i) * kAdvance * scale;
      for (int row = 0; row < kGlyphH; ++row)
        for (int col = 0; col < kGlyphW; ++col)
          if (g[static_cast<std::size_t>(row)] & (1u << (kGlyphW - 1 - col)))
            for (int dy = 0; dy < scale; ++dy)
              for (int dx = 0; dx < scale; ++dx) blend(gx + col * scale + dx, top + row * scale + dy, colour, 1.0);
    }
  }

  FrameImage to_frame() const {
    FrameImage image;
    image.width = width_;
    image.height = height_;
    const std::size_t n = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
    image.rgba.resize(4 * n);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t c = 0; c < 3; ++c) image.rgba[4 * i + c] = static_cast<float>(srgb_to_linear(rgb_[3 * i + c]));
      image.rgba[4 * i + 3] = 1.0f;
    }
    return image;
  }

 private:
  std::size_t index(int x, int y) const {
    return (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) * 3;
  }

  int width_, height_;
  std::vector<float> rgb_;
};

// Per-pixel coverage of one shape, combined by maximum so that a polyline's joints and a dashed line's pieces
// are blended once and do not darken where they overlap.
class Coverage {
 public:
  Coverage(int width, int height)
      : width_(width), height_(height), a_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {}

  void add(int x, int y, double c) {
    if (x < 0 || y < 0 || x >= width_ || y >= height_ || !(c > 0)) return;
    float& a = a_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)];
    a = std::max(a, static_cast<float>(std::min(c, 1.0)));
    x0_ = std::min(x0_, x), y0_ = std::min(y0_, y), x1_ = std::max(x1_, x), y1_ = std::max(y1_, y);
  }

  // Blends the colour through the coverage (times opacity) and clears it for the next shape.
  void paint(Canvas& canvas, Rgb8 colour, double opacity, const std::optional<Box>& clip) {
    for (int y = y0_; y <= y1_; ++y)
      for (int x = x0_; x <= x1_; ++x) {
        float& a = a_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)];
        canvas.blend(x, y, colour, a * opacity, clip);
        a = 0;
      }
    x0_ = y0_ = std::numeric_limits<int>::max();
    x1_ = y1_ = -1;
  }

  // Anti-aliased by the distance from each pixel centre to the segment: full inside, fading over one pixel.
  void segment(double ax, double ay, double bx, double by, double half_width) {
    const double reach = half_width + 1;
    const int xa = std::max(0, static_cast<int>(std::floor(std::min(ax, bx) - reach)));
    const int xb = std::min(width_ - 1, static_cast<int>(std::ceil(std::max(ax, bx) + reach)));
    const int ya = std::max(0, static_cast<int>(std::floor(std::min(ay, by) - reach)));
    const int yb = std::min(height_ - 1, static_cast<int>(std::ceil(std::max(ay, by) + reach)));
    const double dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
    for (int y = ya; y <= yb; ++y)
      for (int x = xa; x <= xb; ++x) {
        const double px = x + 0.5 - ax, py = y + 0.5 - ay;
        const double s = len2 > 0 ? std::clamp((px * dx + py * dy) / len2, 0.0, 1.0) : 0.0;
        const double d = std::hypot(px - s * dx, py - s * dy);
        add(x, y, half_width + 0.5 - d);
      }
  }

  // filled: a disc of radius r; otherwise a ring of that radius and the given half width.
  void circle(double cx, double cy, double r, bool filled, double half_width) {
    const double reach = r + half_width + 1;
    for (int y = static_cast<int>(std::floor(cy - reach)); y <= static_cast<int>(std::ceil(cy + reach)); ++y)
      for (int x = static_cast<int>(std::floor(cx - reach)); x <= static_cast<int>(std::ceil(cx + reach)); ++x) {
        const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
        add(x, y, filled ? r + 0.5 - d : half_width + 0.5 - std::abs(d - r));
      }
  }

  // Exact area coverage of an axis-aligned rectangle.
  void rect(double rx0, double ry0, double rx1, double ry1) {
    for (int y = static_cast<int>(std::floor(ry0)); y < static_cast<int>(std::ceil(ry1)); ++y)
      for (int x = static_cast<int>(std::floor(rx0)); x < static_cast<int>(std::ceil(rx1)); ++x) {
        const double cx = std::min<double>(x + 1, rx1) - std::max<double>(x, rx0);
        const double cy = std::min<double>(y + 1, ry1) - std::max<double>(y, ry0);
        add(x, y, cx * cy);
      }
  }

 private:
  int width_, height_;
  std::vector<float> a_;
  int x0_ = std::numeric_limits<int>::max(), y0_ = std::numeric_limits<int>::max(), x1_ = -1, y1_ = -1;
};

// ---------------------------------------------------------------------------------------------
// Display list: the probe plot is laid out once into these shapes, then written as SVG or rasterised.

struct RectShape {
  Box box;
  Rgb8 fill;
  double opacity = 1;
  bool clip = false;
};
struct LineShape {
  double x1, y1, x2, y2;
  Rgb8 colour;
  double width = 1;
  bool dashed = false;
  bool clip = false;
};
struct PolylineShape {
  std::vector<std::pair<double, double>> points;
  Rgb8 colour;
  double width = 1;
  bool clip = false;
};
struct CircleShape {
  double cx, cy, r;
  Rgb8 colour;
  bool filled = false;
  double stroke_width = 1;
  bool clip = false;
};
struct TextShape {
  double x, y_center;
  std::string text;
  int scale = 2;         // of the bitmap font in the PNG; the SVG uses a font size of similar height
  double max_width = 0;  // > 0: shrink, then cut, the text to fit
  Anchor anchor = Anchor::Start;
  Rgb8 colour = kInk;
};
using Shape = std::variant<RectShape, LineShape, PolylineShape, CircleShape, TextShape>;

struct Drawing {
  int width = 0, height = 0;
  Box clip{};  // the plot area, which shapes with clip = true stay inside
  std::string title;
  std::vector<Shape> shapes;
};

constexpr double kDashOn = 6, kDashOff = 4;

// SVG font size for a bitmap-font scale: about the same cap height.
double svg_font_size(int scale) { return 6.0 + 5.0 * scale; }

// ---------------------------------------------------------------------------------------------
// SVG writing

// XML 1.0 allows neither most control characters nor malformed UTF-8, so those become '?'; the markup
// characters become entities.
std::string xml_escape(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c >= 0x80) {
      const std::size_t len = (c & 0xE0) == 0xC0 ? 2 : (c & 0xF0) == 0xE0 ? 3 : (c & 0xF8) == 0xF0 ? 4 : 0;
      bool ok = len > 0 && i + len <= s.size();
      for (std::size_t k = 1; ok && k < len; ++k) ok = (static_cast<unsigned char>(s[i + k]) & 0xC0) == 0x80;
      if (ok) {
        out.append(s, i, len);
        i += len;
      } else {
        out += '?';
        ++i;
      }
      continue;
    }
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c < 0x20 && c != '\t' ? '?' : static_cast<char>(c);
    }
    ++i;
  }
  return out;
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

const char* kClipAttribute = " clip-path=\"url(#plot-area)\"";

void svg_shape(std::string& out, const RectShape& r) {
  out += "<rect x=\"" + num(r.box.x0) + "\" y=\"" + num(r.box.y0) + "\" width=\"" + num(r.box.x1 - r.box.x0) +
         "\" height=\"" + num(r.box.y1 - r.box.y0) + "\" fill=\"" + hex(r.fill) + "\"";
  if (r.opacity < 1) out += " fill-opacity=\"" + num(r.opacity) + "\"";
  if (r.clip) out += kClipAttribute;
  out += "/>\n";
}

void svg_shape(std::string& out, const LineShape& l) {
  out += "<line x1=\"" + num(l.x1) + "\" y1=\"" + num(l.y1) + "\" x2=\"" + num(l.x2) + "\" y2=\"" + num(l.y2) +
         "\" stroke=\"" + hex(l.colour) + "\" stroke-width=\"" + num(l.width) + "\"";
  if (l.dashed) out += " stroke-dasharray=\"" + num(kDashOn) + " " + num(kDashOff) + "\"";
  if (l.clip) out += kClipAttribute;
  out += "/>\n";
}

void svg_shape(std::string& out, const PolylineShape& p) {
  out += "<polyline fill=\"none\" stroke=\"" + hex(p.colour) + "\" stroke-width=\"" + num(p.width) +
         "\" stroke-linejoin=\"round\" stroke-linecap=\"round\"";
  if (p.clip) out += kClipAttribute;
  out += " points=\"";
  for (std::size_t i = 0; i < p.points.size(); ++i) {
    if (i) out += ' ';
    out += num(p.points[i].first) + "," + num(p.points[i].second);
  }
  out += "\"/>\n";
}

void svg_shape(std::string& out, const CircleShape& c) {
  out += "<circle cx=\"" + num(c.cx) + "\" cy=\"" + num(c.cy) + "\" r=\"" + num(c.r) + "\" fill=\"" +
         (c.filled ? hex(c.colour) : std::string("none")) + "\"";
  if (!c.filled) out += " stroke=\"" + hex(c.colour) + "\" stroke-width=\"" + num(c.stroke_width) + "\"";
  if (c.clip) out += kClipAttribute;
  out += "/>\n";
}

void svg_shape(std::string& out, const TextShape& t) {
  double size = svg_font_size(t.scale);
  // Monospace glyphs are about 0.6 em wide; shrink long text to fit, but not below legibility.
  const double estimated = 0.6 * size * static_cast<double>(t.text.size());
  if (t.max_width > 0 && estimated > t.max_width) size = std::max(9.0, size * t.max_width / estimated);
  const char* anchor = t.anchor == Anchor::Start ? "start" : t.anchor == Anchor::Middle ? "middle" : "end";
  out += "<text x=\"" + num(t.x) + "\" y=\"" + num(t.y_center + 0.36 * size) + "\" font-size=\"" + num(size) +
         "\" text-anchor=\"" + anchor + "\" fill=\"" + hex(t.colour) + "\">" + xml_escape(t.text) + "</text>\n";
}

std::string to_svg(const Drawing& d) {
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out += "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" + std::to_string(d.width) +
         "\" height=\"" + std::to_string(d.height) + "\" viewBox=\"0 0 " + std::to_string(d.width) + " " +
         std::to_string(d.height) + "\" font-family=\"DejaVu Sans Mono, Menlo, Consolas, monospace\">\n";
  out += "<title>" + xml_escape(d.title) + "</title>\n";
  out += "<defs><clipPath id=\"plot-area\"><rect x=\"" + num(d.clip.x0) + "\" y=\"" + num(d.clip.y0) + "\" width=\"" +
         num(d.clip.x1 - d.clip.x0) + "\" height=\"" + num(d.clip.y1 - d.clip.y0) + "\"/></clipPath></defs>\n";
  out += "<rect width=\"" + std::to_string(d.width) + "\" height=\"" + std::to_string(d.height) + "\" fill=\"" +
         hex(kBackground) + "\"/>\n";
  for (const Shape& s : d.shapes) std::visit([&](const auto& shape) { svg_shape(out, shape); }, s);
  out += "</svg>\n";
  return out;
}

// ---------------------------------------------------------------------------------------------
// Rasterising

struct Rasteriser {
  Canvas& canvas;
  Coverage& coverage;
  Box clip_box;

  std::optional<Box> clip(bool on) const { return on ? std::optional<Box>(clip_box) : std::nullopt; }

  void operator()(const RectShape& r) {
    coverage.rect(r.box.x0, r.box.y0, r.box.x1, r.box.y1);
    coverage.paint(canvas, r.fill, r.opacity, clip(r.clip));
  }
  void operator()(const LineShape& l) {
    const double len = std::hypot(l.x2 - l.x1, l.y2 - l.y1);
    if (!l.dashed || len == 0) {
      coverage.segment(l.x1, l.y1, l.x2, l.y2, l.width / 2);
    } else {
      const double ux = (l.x2 - l.x1) / len, uy = (l.y2 - l.y1) / len;
      for (double s = 0; s < len; s += kDashOn + kDashOff) {
        const double e = std::min(len, s + kDashOn);
        // Butt ends, as in the SVG: pull the round ends of the segment in by the half width.
        const double hw = l.width / 2, s0 = s + std::min(hw, (e - s) / 2), e0 = e - std::min(hw, (e - s) / 2);
        coverage.segment(l.x1 + ux * s0, l.y1 + uy * s0, l.x1 + ux * e0, l.y1 + uy * e0, hw);
      }
    }
    coverage.paint(canvas, l.colour, 1, clip(l.clip));
  }
  void operator()(const PolylineShape& p) {
    for (std::size_t i = 0; i + 1 < p.points.size(); ++i)
      coverage.segment(p.points[i].first, p.points[i].second, p.points[i + 1].first, p.points[i + 1].second,
                       p.width / 2);
    if (p.points.size() == 1)
      coverage.segment(p.points[0].first, p.points[0].second, p.points[0].first, p.points[0].second, p.width / 2);
    coverage.paint(canvas, p.colour, 1, clip(p.clip));
  }
  void operator()(const CircleShape& c) {
    coverage.circle(c.cx, c.cy, c.r, c.filled, c.stroke_width / 2);
    coverage.paint(canvas, c.colour, 1, clip(c.clip));
  }
  void operator()(const TextShape& t) {
    // Smaller font first, then cut with "..." when even that does not fit.
    std::string s = t.text;
    int scale = t.scale;
    const double room = t.max_width > 0 ? t.max_width : std::numeric_limits<double>::infinity();
    while (scale > 1 && text_width(s.size(), scale) > room) --scale;
    if (text_width(s.size(), scale) > room) {
      const auto fit = static_cast<std::size_t>(std::max(0.0, (room / scale + 1) / kAdvance));
      s = fit > 3 ? s.substr(0, fit - 3) + "..." : s.substr(0, fit);
    }
    canvas.text(t.x, t.y_center, s, scale, t.anchor, t.colour);
  }
};

FrameImage rasterise(const Drawing& d) {
  Canvas canvas(d.width, d.height, kBackground);
  Coverage coverage(d.width, d.height);
  Rasteriser r{canvas, coverage, d.clip};
  for (const Shape& s : d.shapes) std::visit(r, s);
  return canvas.to_frame();
}

// ---------------------------------------------------------------------------------------------
// Number formatting for labels

std::string format(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

// 10^k as a reader would write it: plain for small exponents, 1e-12 style otherwise.
std::string power_of_ten_label(int k, bool negative) {
  std::string s;
  if (k >= 0 && k <= 4)
    s = "1" + std::string(static_cast<std::size_t>(k), '0');
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

// A 1, 2 or 5 times a power of ten at least `raw`.
double nice_step(double raw) {
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / mag;
  return (norm <= 1 ? 1 : norm <= 2 ? 2 : norm <= 5 ? 5 : 10) * mag;
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

Drawing draw_probe_plot(const ProbePlot& plot, const ProbePlotGeometry& g) {
  Drawing d;
  d.width = g.width;
  d.height = g.height;
  d.clip = {g.left, g.top, g.right, g.bottom};
  d.title = plot.title;
  const double text_room = g.width - 24;
  d.shapes.push_back(TextShape{g.width / 2.0, 20, plot.title, 2, text_room, Anchor::Middle});
  const CheckedPlot range{g.t_in, g.t_out};
  d.shapes.push_back(TextShape{g.left, 44,
                               "y = sign(P) log10(1+|P|/f), f = " + format("%.3g", g.floor) + " (" +
                                   floor_origin(visible_values(plot, range), g.floor) + ")",
                               2, g.right - g.left});

  // Shaded intervals first, so everything else stays visible on top; at least 2 px wide, or a tight
  // interval around a root would vanish.
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

  add_y_ticks(d, g);
  add_t_ticks(d, g);
  const double y0 = g.y_of(0);
  d.shapes.push_back(LineShape{g.left, y0, g.right, y0, kZeroLine, 1.5, false, true});

  // The curve, broken at non-finite values.
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

  // Markers by kind, so reference roots (open circles) stay visible over the roots found.
  for (auto kind : {PlotMarker::Kind::IsolationEnd, PlotMarker::Kind::Root, PlotMarker::Kind::ReferenceRoot})
    for (const PlotMarker& m : plot.markers)
      if (m.kind == kind && in_range(m.t, g)) add_marker_shapes(d, kind, g.x_of(m.t), g.top, g.bottom, y0, true);

  d.shapes.push_back(RectShape{{g.left, g.top, g.right, g.top + 1}, kInk});
  d.shapes.push_back(RectShape{{g.left, g.bottom - 1, g.right, g.bottom}, kInk});
  d.shapes.push_back(RectShape{{g.left, g.top, g.left + 1, g.bottom}, kInk});
  d.shapes.push_back(RectShape{{g.right - 1, g.top, g.right, g.bottom}, kInk});
  d.shapes.push_back(TextShape{g.right, g.bottom + 42, "t", 2, 0, Anchor::End});

  // Legend: one row per curve, interval and marker, each with its swatch and its exact t.
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

// ---------------------------------------------------------------------------------------------
// Work heat map

namespace {

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
  if (width < 0 || height < 0)
    throw OutputError("invalid heat map size " + std::to_string(width) + "x" + std::to_string(height));
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (work.size() != n)
    throw OutputError("heat map work holds " + std::to_string(work.size()) + " values, expected " + std::to_string(n));
  if (!in_extent.empty() && in_extent.size() != n)
    throw OutputError("heat map extent mask holds " + std::to_string(in_extent.size()) + " values, expected " +
                      std::to_string(n));
  const HeatmapScale scale = heatmap_scale(work, in_extent);

  // Layout: the map at the origin, the bar to its right with the scale's name above it, the caption below.
  constexpr int kScale = 2, kBarWidth = 20, kGap = 16, kBarTop = 38, kMinBody = 220, kLine = 20;
  const int text_h = kGlyphH * kScale;
  const int body = std::max(height, kMinBody);
  const int bar_x = width + kGap, bar_top = kBarTop, bar_bottom = body - 12;
  const double bar_h = bar_bottom - bar_top;

  struct Tick {
    double value;
    std::string label;
  };
  std::vector<Tick> ticks;
  auto label = [](double v) { return format("%.0f", v); };
  if (scale.pixels > 0) {
    ticks.push_back({scale.min, label(scale.min)});
    if (scale.max > scale.min) {
      std::vector<double> inner;
      if (scale.logarithmic) {
        for (double p = 1; p < scale.max; p *= 10)
          if (p > scale.min) inner.push_back(p);
      } else {
        const double step = std::max(1.0, nice_step((scale.max - scale.min) / 5));
        for (double v = std::ceil(scale.min / step) * step; v < scale.max; v += step)
          if (v > scale.min) inner.push_back(v);
      }
      auto y_of = [&](double v) { return bar_bottom - ramp_position(v, scale) * bar_h; };
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
    }
  }
  std::size_t widest = 0;
  for (const Tick& t : ticks) widest = std::max(widest, t.label.size());
  const std::string kind = scale.pixels == 0 ? "no data" : scale.logarithmic ? "log scale" : "linear scale";
  const int panel_right =
      std::max(bar_x + kBarWidth + 10 + text_width(widest, kScale), bar_x + text_width(kind.size(), kScale)) + 12;

  const int canvas_w = std::max(panel_right, 240);
  const auto columns = static_cast<std::size_t>(std::max(10, (canvas_w - 16) / (kAdvance * kScale)));
  std::string full_caption = caption.empty() ? "solver work" : caption;
  full_caption += scale.pixels == 0 ? " (no pixel in the extent)"
                                    : " (" + kind + ", " + std::to_string(scale.pixels) + " pixels in the extent)";
  const std::vector<std::string> lines = wrap(full_caption, columns);
  const int canvas_h = body + 8 + static_cast<int>(lines.size()) * kLine + 6;

  Canvas canvas(canvas_w, canvas_h, kPanel);
  const auto grey = unit(kOutOfExtent);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
      const bool inside = in_extent.empty() || in_extent[i];
      canvas.set(x, y, inside ? work_colour(ramp_position(work[i], scale)) : grey);
    }

  // The bar: bright at the top like "more"; a single colour when every pixel did the same work.
  for (int y = bar_top; y < bar_bottom; ++y) {
    const bool single = scale.pixels > 0 && scale.max == scale.min;
    const double u = single ? 0.5 : 1.0 - (y - bar_top + 0.5) / bar_h;
    for (int x = bar_x; x < bar_x + kBarWidth; ++x) canvas.set(x, y, work_colour(u));
  }
  canvas.text(bar_x, kBarTop / 2.0, kind, kScale, Anchor::Start, kInk);
  for (const Tick& t : ticks) {
    const double y =
        scale.max > scale.min ? bar_bottom - ramp_position(t.value, scale) * bar_h : (bar_top + bar_bottom) / 2.0;
    const int yi = std::clamp(static_cast<int>(std::lround(y)), bar_top, bar_bottom - 1);
    for (int x = bar_x + kBarWidth; x < bar_x + kBarWidth + 6; ++x) canvas.blend(x, yi, kInk, 1);
    canvas.text(bar_x + kBarWidth + 10, yi, t.label, kScale, Anchor::Start, kInk);
  }
  for (std::size_t i = 0; i < lines.size(); ++i)
    canvas.text(8, body + 8 + (static_cast<double>(i) + 0.5) * kLine, lines[i], kScale, Anchor::Start, kInk);
  return canvas.to_frame();
}

}  // namespace algray
