// A small 2-D drawing kit: sRGB colours, a bitmap font, a raster canvas, and shapes written as SVG or rasterised.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "algray/io/image_io.h"

namespace algray {

// sRGB bytes as a PNG reader sees them; the SVG uses the same colours.
struct Rgb8 {
  std::uint8_t r = 0, g = 0, b = 0;
};

// Nested so that the kit's short names (Box, Canvas, unit, format) cannot clash with the rest of algray, nor
// be found by argument-dependent lookup on Rgb8.
namespace draw {

// Colours travel as sRGB bytes because that is how both SVG and a PNG viewer speak.
inline constexpr Rgb8 kInk{34, 34, 40};
std::array<float, 3> unit(Rgb8 c);  // 0..1, still sRGB-encoded

// The built-in font: 5x7 glyphs of capitals, digits and the punctuation that labels use, one blank column
// between glyphs, each pixel drawn as scale x scale.
inline constexpr int kGlyphW = 5, kGlyphH = 7, kAdvance = 6;
int text_width(std::size_t chars, int scale);

enum class Anchor { Start, Middle, End };

struct Box {
  double x0, y0, x1, y1;
};

// Pixels hold sRGB-encoded values and blending happens there, as SVG renderers do, so that a rasterised
// drawing looks like its SVG; the conversion to linear happens once, in to_frame().
class Canvas {
 public:
  Canvas(int width, int height, Rgb8 background);

  int width() const { return width_; }
  int height() const { return height_; }

  // Both ignore pixels outside the canvas, so callers may draw past its edges.
  void set(int x, int y, const std::array<float, 3>& srgb);
  void blend(int x, int y, Rgb8 colour, double alpha, const std::optional<Box>& clip = std::nullopt);
  // Text centred vertically on y_center. The font has no lower case, so letters show as capitals and
  // anything else it lacks (each UTF-8 sequence included) as '?'.
  void text(double x, double y_center, const std::string& s, int scale, Anchor anchor, Rgb8 colour);

  FrameImage to_frame() const;

 private:
  std::size_t index(int x, int y) const;

  int width_, height_;
  std::vector<float> rgb_;
};

// Display list: a picture is laid out once into these shapes, then written as SVG or rasterised, so that the
// two forms cannot drift apart.

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
  // The one clip region, which shapes with clip = true stay inside. The SVG names it "plot-area", the name
  // it had when probe plots were its only user, kept so that the SVG bytes stay as they were.
  Box clip{};
  std::string title;
  std::vector<Shape> shapes;
};

// A standalone SVG 1.1 document on a white background.
std::string to_svg(const Drawing& d);
// The same picture on a white background, as linear RGBA.
FrameImage rasterise(const Drawing& d);

// Label text for axes and colour bars.
std::string format(const char* fmt, double v);  // one printf conversion of v
// A 1, 2 or 5 times a power of ten at least `raw`: tick spacings a reader can count along in their head.
double nice_step(double raw);

}  // namespace draw
}  // namespace algray
