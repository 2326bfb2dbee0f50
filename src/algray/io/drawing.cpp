// The drawing kit's bitmap font, raster canvas, SVG writer and rasteriser.
#include "algray/io/drawing.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace algray::draw {

namespace {

constexpr Rgb8 kBackground{255, 255, 255};

std::string hex(Rgb8 c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", c.r, c.g, c.b);
  return buf;
}

// ---------------------------------------------------------------------------------------------
// The font. Each sheet row is one pixel row of every glyph in `chars`, 5 columns per glyph and one space
// between glyphs, so that glyphs can be drawn and checked by eye in the source.

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

}  // namespace

std::array<float, 3> unit(Rgb8 c) { return {c.r / 255.0f, c.g / 255.0f, c.b / 255.0f}; }

int text_width(std::size_t chars, int scale) {
  return chars == 0 ? 0 : (static_cast<int>(chars) * kAdvance - 1) * scale;
}

// ---------------------------------------------------------------------------------------------
// Raster canvas

Canvas::Canvas(int width, int height, Rgb8 background)
    : width_(width), height_(height), rgb_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3) {
  const auto c = unit(background);
  for (std::size_t i = 0; i < rgb_.size(); ++i) rgb_[i] = c[i % 3];
}

void Canvas::set(int x, int y, const std::array<float, 3>& srgb) {
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
  float* p = &rgb_[index(x, y)];
  for (int c = 0; c < 3; ++c) p[c] = srgb[static_cast<std::size_t>(c)];
}

void Canvas::blend(int x, int y, Rgb8 colour, double alpha, const std::optional<Box>& clip) {
  if (x < 0 || y < 0 || x >= width_ || y >= height_ || !(alpha > 0)) return;
  if (clip && (x + 0.5 < clip->x0 || x + 0.5 > clip->x1 || y + 0.5 < clip->y0 || y + 0.5 > clip->y1)) return;
  const auto a = static_cast<float>(std::min(alpha, 1.0));
  const auto c = unit(colour);
  float* p = &rgb_[index(x, y)];
  for (std::size_t k = 0; k < 3; ++k) p[k] = p[k] * (1 - a) + c[k] * a;
}

void Canvas::text(double x, double y_center, const std::string& s, int scale, Anchor anchor, Rgb8 colour) {
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

FrameImage Canvas::to_frame() const {
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

std::size_t Canvas::index(int x, int y) const {
  return (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) * 3;
}

namespace {

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

}  // namespace

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

FrameImage rasterise(const Drawing& d) {
  Canvas canvas(d.width, d.height, kBackground);
  Coverage coverage(d.width, d.height);
  Rasteriser r{canvas, coverage, d.clip};
  for (const Shape& s : d.shapes) std::visit(r, s);
  return canvas.to_frame();
}

// ---------------------------------------------------------------------------------------------
// Label text

std::string format(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

double nice_step(double raw) {
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / mag;
  return (norm <= 1 ? 1 : norm <= 2 ? 2 : norm <= 5 ? 5 : 10) * mag;
}

}  // namespace algray::draw
