// Tests for the probe plot (SVG well-formedness, PNG pixels where the features must be) and the work heat map.
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "algray/io/drawing.h"
#include "algray/io/heatmap.h"
#include "algray/io/probe_plot.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using algray::FrameImage;
using algray::OutputError;
using algray::PlotMarker;
using algray::ProbePlot;
using algray::Rgb8;

namespace {

using algray::testing::TempDir;

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// ---------------------------------------------------------------------------------------------
// A small XML well-formedness checker: one root element, properly nested and closed tags, quoted and unique
// attributes, and no raw '<' or stray '&' in text or attribute values. Returns what is wrong, or "".

bool name_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == ':' || c == '.';
}

// Checks the entities in text or an attribute value.
std::string check_chars(const std::string& s, bool attribute) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '<') return "raw '<' in " + std::string(attribute ? "attribute" : "text");
    if (s[i] != '&') continue;
    const std::size_t semi = s.find(';', i);
    if (semi == std::string::npos) return "unterminated entity";
    const std::string entity = s.substr(i + 1, semi - i - 1);
    static const std::set<std::string> named = {"amp", "lt", "gt", "quot", "apos"};
    const bool numeric =
        entity.size() > 1 && entity[0] == '#' &&
        std::all_of(entity.begin() + 1, entity.end(), [](char c) { return std::isxdigit(c) || c == 'x'; });
    if (!named.count(entity) && !numeric) return "unknown entity &" + entity + ";";
  }
  return "";
}

std::string xml_problem(const std::string& doc) {
  std::size_t i = 0;
  std::vector<std::string> open;
  bool seen_root = false;
  auto skip_space = [&] {
    while (i < doc.size() && std::isspace(static_cast<unsigned char>(doc[i]))) ++i;
  };
  auto read_name = [&] {
    const std::size_t start = i;
    while (i < doc.size() && name_char(doc[i])) ++i;
    return doc.substr(start, i - start);
  };
  if (doc.compare(0, 5, "<?xml") == 0) {
    i = doc.find("?>");
    if (i == std::string::npos) return "unterminated XML declaration";
    i += 2;
  }
  while (i < doc.size()) {
    if (doc[i] != '<') {
      const std::size_t end = std::min(doc.find('<', i), doc.size());
      const std::string text = doc.substr(i, end - i);
      if (open.empty() && text.find_first_not_of(" \t\r\n") != std::string::npos) return "text outside the root";
      if (std::string p = check_chars(text, false); !p.empty()) return p;
      i = end;
      continue;
    }
    if (doc.compare(i, 4, "<!--") == 0) {
      i = doc.find("-->", i);
      if (i == std::string::npos) return "unterminated comment";
      i += 3;
      continue;
    }
    if (doc.compare(i, 2, "</") == 0) {
      i += 2;
      const std::string name = read_name();
      skip_space();
      if (i >= doc.size() || doc[i] != '>') return "malformed end tag </" + name;
      ++i;
      if (open.empty() || open.back() != name) return "end tag </" + name + "> does not match";
      open.pop_back();
      continue;
    }
    ++i;
    const std::string name = read_name();
    if (name.empty()) return "empty tag name at " + std::to_string(i);
    if (open.empty()) {
      if (seen_root) return "second root element <" + name + ">";
      seen_root = true;
    }
    std::set<std::string> attributes;
    for (;;) {
      const std::size_t before = i;
      skip_space();
      if (i >= doc.size()) return "unterminated tag <" + name;
      if (doc.compare(i, 2, "/>") == 0) {
        i += 2;
        break;
      }
      if (doc[i] == '>') {
        ++i;
        open.push_back(name);
        break;
      }
      if (i == before) return "attributes of <" + name + "> not separated by space";
      const std::string attribute = read_name();
      if (attribute.empty()) return "bad attribute in <" + name + ">";
      if (!attributes.insert(attribute).second) return "duplicate attribute " + attribute;
      skip_space();
      if (i >= doc.size() || doc[i] != '=') return "attribute " + attribute + " without value";
      ++i;
      skip_space();
      if (i >= doc.size() || (doc[i] != '"' && doc[i] != '\'')) return "unquoted attribute " + attribute;
      const char quote = doc[i++];
      const std::size_t end = doc.find(quote, i);
      if (end == std::string::npos) return "unterminated attribute " + attribute;
      if (std::string p = check_chars(doc.substr(i, end - i), true); !p.empty()) return p;
      i = end + 1;
    }
  }
  if (!open.empty()) return "unclosed <" + open.back() + ">";
  if (!seen_root) return "no root element";
  return "";
}

// ---------------------------------------------------------------------------------------------
// PNG read-back through libpng's simplified API, as 8-bit RGB.

struct Png {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;
  Rgb8 at(int x, int y) const {
    const std::size_t i =
        (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 3;
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

bool has_png_signature(const fs::path& p) {
  const std::string bytes = read_all(p);
  return bytes.size() >= 8 && png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) == 0;
}

Png read_png(const fs::path& p) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  REQUIRE(png_image_begin_read_from_file(&image, p.c_str()) != 0);
  image.format = PNG_FORMAT_RGB;
  Png out;
  out.width = static_cast<int>(image.width);
  out.height = static_cast<int>(image.height);
  out.rgb.resize(PNG_IMAGE_SIZE(image));
  REQUIRE(png_image_finish_read(&image, nullptr, out.rgb.data(), 0, nullptr) != 0);
  return out;
}

bool near(Rgb8 a, Rgb8 b, int tolerance = 2) {
  return std::abs(a.r - b.r) <= tolerance && std::abs(a.g - b.g) <= tolerance && std::abs(a.b - b.b) <= tolerance;
}

std::string hex(Rgb8 c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", c.r, c.g, c.b);
  return buf;
}

// ---------------------------------------------------------------------------------------------
// Fixtures

double quadratic(double t) { return (t - 0.3) * (t - 0.7); }

ProbePlot quadratic_plot() {
  ProbePlot p;
  p.title = "(t-0.3)(t-0.7) on [0, 1]";
  for (int i = 0; i <= 400; ++i) {
    p.t.push_back(i / 400.0);
    p.value.push_back(quadratic(i / 400.0));
  }
  p.intervals = {{0.25, 0.35}};
  p.markers = {{PlotMarker::Kind::IsolationEnd, 0.25, "lo"},
               {PlotMarker::Kind::IsolationEnd, 0.35, "hi"},
               {PlotMarker::Kind::Root, 0.3, "root (bernstein+brent)"},
               {PlotMarker::Kind::ReferenceRoot, 0.7, "solver_ref simple"}};
  return p;
}

double luminance(const FrameImage& im, int x, int y) {
  const std::size_t i =
      (static_cast<std::size_t>(y) * static_cast<std::size_t>(im.width) + static_cast<std::size_t>(x)) * 4;
  return 0.2126 * im.rgba[i] + 0.7152 * im.rgba[i + 1] + 0.0722 * im.rgba[i + 2];
}

bool neutral(const FrameImage& im, int x, int y) {
  const std::size_t i =
      (static_cast<std::size_t>(y) * static_cast<std::size_t>(im.width) + static_cast<std::size_t>(x)) * 4;
  return im.rgba[i] == im.rgba[i + 1] && im.rgba[i + 1] == im.rgba[i + 2];
}

}  // namespace

TEST_CASE("the XML checker rejects what it must", "[diagnostic][xml]") {
  CHECK(xml_problem("<?xml version=\"1.0\"?>\n<a x=\"1\"><b/>t &amp; u</a>\n") == "");
  CHECK(xml_problem("<a><b></a></b>") != "");
  CHECK(xml_problem("<a>1 < 2</a>") != "");
  CHECK(xml_problem("<a>Q&A</a>") != "");
  CHECK(xml_problem("<a x=1/>") != "");
  CHECK(xml_problem("<a x=\"1\" x=\"2\"/>") != "");
  CHECK(xml_problem("<a/><b/>") != "");
  CHECK(xml_problem("<a>") != "");
}

TEST_CASE("signed_log_floor: smallest nonzero |v|, but not below 1e-12 of the largest", "[diagnostic][plot]") {
  CHECK(algray::signed_log_floor({0.0, 1e-3, -2.0, 5.0}) == 1e-3);
  CHECK(algray::signed_log_floor({-1e-3, 2.0, 0.0}) == 1e-3);
  CHECK(algray::signed_log_floor({1e-300, -1.0}) == Approx(1e-12));
  CHECK(algray::signed_log_floor({0.0, 0.0}) == 1.0);
  CHECK(algray::signed_log_floor({}) == 1.0);
  CHECK(algray::signed_log_floor({std::nan(""), INFINITY, 4.0}) == 4.0);
}

TEST_CASE("probe plot geometry keeps sign and order over many decades", "[diagnostic][plot]") {
  ProbePlot p;
  p.t_in = 2;
  p.t_out = 3;
  p.t = {2.0, 2.25, 2.5, 2.75, 3.0};
  p.value = {1e300, 1e-200, 0.0, -1e-6, -1e100};
  const auto g = algray::probe_plot_geometry(p);
  CHECK(g.floor == Approx(1e288));
  // Rows grow downwards: positive values above the zero line, negative below, monotone in value.
  CHECK(g.y_of(1e300) < g.y_of(1e295));
  CHECK(g.y_of(1e295) < g.y_of(0));
  CHECK(g.y_of(-1e100) == Approx(g.y_of(0)).margin(1e-9));  // below the floor: squeezed onto the zero line
  CHECK(g.y_of(-1e299) > g.y_of(0));
  CHECK(g.y_of(1e300) >= g.top);
  CHECK(g.y_of(0) <= g.bottom);
  CHECK(g.x_of(2.0) == g.left);
  CHECK(g.x_of(3.0) == g.right);

  const std::string svg = algray::probe_plot_svg(p);
  CHECK(xml_problem(svg) == "");
  CHECK(svg.find("nan") == std::string::npos);
  CHECK(svg.find("inf") == std::string::npos);
  CHECK(svg.find(">1e300</text>") != std::string::npos);
  CHECK(svg.find(">1e295</text>") != std::string::npos);
}

TEST_CASE("probe plot rejects inconsistent input", "[diagnostic][plot]") {
  ProbePlot p = quadratic_plot();
  p.value.pop_back();
  CHECK_THROWS_AS(algray::probe_plot_svg(p), OutputError);
  p = quadratic_plot();
  p.t_in = 2;
  p.t_out = 1;
  CHECK_THROWS_AS(algray::probe_plot_image(p), OutputError);
  p.t_out = NAN;
  CHECK_THROWS_AS(algray::probe_plot_geometry(p), OutputError);
  // A zero-length range is opened up rather than refused.
  p = ProbePlot{};
  p.t_in = p.t_out = 5;
  p.t = {5};
  p.value = {0};
  const auto g = algray::probe_plot_geometry(p);
  CHECK(g.t_in < 5);
  CHECK(g.t_out > 5);
  CHECK(xml_problem(algray::probe_plot_svg(p)) == "");
}

TEST_CASE("probe plot SVG is well-formed and shows curve, markers, ticks and an escaped title", "[diagnostic][svg]") {
  ProbePlot p = quadratic_plot();
  p.title = "pixel <3,4> & \"ray\" 'x'";
  TempDir dir;
  algray::write_probe_plot(dir / "probe.SVG", p);  // the extension in any case
  const std::string svg = read_all(dir / "probe.SVG");

  INFO(svg.substr(0, 400));
  CHECK(xml_problem(svg) == "");
  CHECK(svg.find("<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\"") != std::string::npos);
  CHECK(svg.find("pixel &lt;3,4&gt; &amp; &quot;ray&quot; &apos;x&apos;") != std::string::npos);
  CHECK(svg.find("<3,4>") == std::string::npos);

  // One polyline holding every sample.
  const std::size_t polyline = svg.find("<polyline");
  REQUIRE(polyline != std::string::npos);
  const std::size_t points = svg.find("points=\"", polyline) + 8;
  const std::string list = svg.substr(points, svg.find('"', points) - points);
  CHECK(std::count(list.begin(), list.end(), ',') == 401);
  CHECK(svg.find("<polyline", polyline + 1) == std::string::npos);

  for (const char* label : {"lo: t = 0.25", "hi: t = 0.35", "root (bernstein+brent): t = 0.3",
                            "solver_ref simple: t = 0.7", "isolating interval [0.25, 0.35]"}) {
    INFO(label);
    CHECK(svg.find(std::string(">") + label + "</text>") != std::string::npos);
  }
  // t ticks, and y ticks with their actual values on both sides of zero.
  for (const char* tick :
       {">0</text>", ">0.0</text>", ">0.2</text>", ">0.6</text>", ">1.0</text>", ">0.1</text>", ">-0.01</text>"}) {
    INFO(tick);
    CHECK(svg.find(tick) != std::string::npos);
  }
  CHECK(svg.find("stroke-dasharray") != std::string::npos);
  CHECK(svg.find(hex(algray::marker_colour(PlotMarker::Kind::IsolationEnd))) != std::string::npos);
  CHECK(svg.find(hex(algray::marker_colour(PlotMarker::Kind::Root))) != std::string::npos);
  CHECK(svg.find("fill=\"none\" stroke=\"" + hex(algray::marker_colour(PlotMarker::Kind::ReferenceRoot))) !=
        std::string::npos);
  CHECK(svg.find("fill-opacity") != std::string::npos);  // the shaded interval
}

TEST_CASE("probe plot PNG has the markers and the curve where they belong", "[diagnostic][png]") {
  const ProbePlot p = quadratic_plot();
  const auto g = algray::probe_plot_geometry(p);
  double smallest = INFINITY;
  for (double v : p.value)
    if (v != 0) smallest = std::min(smallest, std::abs(v));
  CHECK(g.floor == smallest);

  TempDir dir;
  algray::write_probe_plot(dir / "probe.png", p);
  REQUIRE(has_png_signature(dir / "probe.png"));
  const Png png = read_png(dir / "probe.png");
  REQUIRE(png.width == g.width);
  REQUIRE(png.height == g.height);
  CHECK(png.width == 900);

  const int top = static_cast<int>(g.top) + 2, bottom = static_cast<int>(g.bottom) - 2;
  // The share of plot rows in the best of the three columns around t that show `colour`.
  auto column_share = [&](double t, Rgb8 colour) {
    const int x0 = static_cast<int>(std::floor(g.x_of(t)));
    double best = 0;
    for (int x = x0 - 1; x <= x0 + 1; ++x) {
      int hits = 0;
      for (int y = top; y <= bottom; ++y) hits += near(png.at(x, y), colour) ? 1 : 0;
      best = std::max(best, hits / double(bottom - top + 1));
    }
    return best;
  };
  const Rgb8 iso = algray::marker_colour(PlotMarker::Kind::IsolationEnd);
  const Rgb8 root = algray::marker_colour(PlotMarker::Kind::Root);
  const Rgb8 ref = algray::marker_colour(PlotMarker::Kind::ReferenceRoot);
  const Rgb8 curve = algray::probe_curve_colour();
  CHECK(column_share(0.3, root) > 0.9);  // solid
  for (double t : {0.25, 0.35}) {        // dashed: about half
    CHECK(column_share(t, iso) > 0.35);
    CHECK(column_share(t, iso) < 0.75);
  }
  CHECK(column_share(0.5, root) == 0);
  CHECK(column_share(0.5, iso) == 0);

  // The reference root is an open circle on the zero line at t = 0.7, and nowhere else in the plot.
  const double rx = g.x_of(0.7), ry = g.y_of(0);
  int ring = 0, elsewhere = 0;
  for (int y = top; y <= bottom; ++y)
    for (int x = static_cast<int>(g.left) + 2; x < static_cast<int>(g.right) - 2; ++x) {
      if (!near(png.at(x, y), ref)) continue;
      (std::hypot(x + 0.5 - rx, y + 0.5 - ry) < 10 ? ring : elsewhere)++;
    }
  CHECK(ring > 20);
  CHECK(elsewhere == 0);
  CHECK_FALSE(near(png.at(static_cast<int>(rx), static_cast<int>(ry) - 2), ref));  // open, not filled

  // The zero line, and the curve above it where P > 0 and below it between the roots.
  const int zero_row = static_cast<int>(std::floor(ry));
  CHECK(near(png.at(static_cast<int>(g.x_of(0.1)), zero_row), Rgb8{0, 0, 0}, 40));
  for (double t : {0.1, 0.5, 0.9}) {
    const int x = static_cast<int>(std::floor(g.x_of(t)));
    std::vector<int> rows;
    for (int y = top; y <= bottom; ++y)
      if (near(png.at(x, y), curve, 12)) rows.push_back(y);
    INFO("t = " << t);
    REQUIRE(!rows.empty());
    const double expected = g.y_of(quadratic(t));
    for (int y : rows) CHECK(std::abs(y + 0.5 - expected) < 3);
    for (int y : rows) CHECK((quadratic(t) > 0 ? y < zero_row - 2 : y > zero_row + 2));
  }
}

TEST_CASE("write_probe_plot refuses unknown extensions and missing directories, leaving nothing", "[diagnostic][io]") {
  TempDir dir;
  const ProbePlot p = quadratic_plot();
  for (const char* name : {"probe.txt", "probe", "probe.svg.bak", "probe.jpg"}) {
    INFO(name);
    CHECK_THROWS_AS(algray::write_probe_plot(dir / name, p), OutputError);
  }
  CHECK_THROWS_AS(algray::write_probe_plot(dir / "missing" / "probe.svg", p), OutputError);
  CHECK_THROWS_AS(algray::write_probe_plot(dir / "missing" / "probe.png", p), OutputError);
  CHECK(dir.entries().empty());
  CHECK_FALSE(fs::exists(dir / "missing"));
}

TEST_CASE("write_text_file replaces the file atomically and byte for byte", "[diagnostic][io]") {
  TempDir dir;
  const std::string text = std::string("{\"a\": 1}\n") + '\0' + "tail";
  algray::write_text_file(dir / "out.json", "old contents that are longer than the new ones");
  algray::write_text_file(dir / "out.json", text);
  CHECK(read_all(dir / "out.json") == text);
  CHECK(dir.entries() == std::vector<fs::path>{"out.json"});
  algray::write_text_file(dir / "empty.json", "");
  CHECK(fs::file_size(dir / "empty.json") == 0);
  CHECK_THROWS_AS(algray::write_text_file(dir / "missing" / "x.json", text), OutputError);
  CHECK_FALSE(fs::exists(dir / "missing"));
}

TEST_CASE("heat map scale: linear unless the work spans more than a factor 50", "[diagnostic][heatmap]") {
  using algray::heatmap_scale;
  CHECK(heatmap_scale({1, 10000}, {}).logarithmic);
  CHECK_FALSE(heatmap_scale({100, 150}, {}).logarithmic);
  CHECK_FALSE(heatmap_scale({0, 49}, {}).logarithmic);  // (1 + 49) / (1 + 0) = 50
  CHECK(heatmap_scale({0, 50}, {}).logarithmic);
  // Only pixels in the extent count.
  const auto s = heatmap_scale({100, 4000000000u, 120}, {1, 0, 1});
  CHECK_FALSE(s.logarithmic);
  CHECK(s.min == 100);
  CHECK(s.max == 120);
  CHECK(s.pixels == 2);
  CHECK(heatmap_scale({5, 6}, {0, 0}).pixels == 0);
  CHECK(heatmap_scale({}, {}).pixels == 0);
}

TEST_CASE("heat map: map at 1:1, more work brighter, grey outside the extent, a bar beside", "[diagnostic][heatmap]") {
  const int w = 48, h = 40;
  for (bool log_data : {false, true}) {
    INFO((log_data ? "log" : "linear"));
    std::vector<std::uint32_t> work(static_cast<std::size_t>(w * h));
    std::vector<std::uint8_t> inside(work.size(), 1);
    for (std::size_t i = 0; i < work.size(); ++i) {
      work[i] = log_data ? static_cast<std::uint32_t>(std::lround(std::pow(1.01, double(i)))) : 1000 + std::uint32_t(i);
      if (i % 7 == 3) inside[i] = 0;
    }
    REQUIRE(algray::heatmap_scale(work, inside).logarithmic == log_data);
    const FrameImage im = algray::work_heatmap(w, h, work, inside, "isolation steps + refinement iterations");
    REQUIRE(im.rgba.size() == 4 * static_cast<std::size_t>(im.width) * static_cast<std::size_t>(im.height));
    CHECK(im.width >= w + 20);
    CHECK(im.height >= h);

    double previous = -1, first = -1, last = -1;
    for (int i = 0; i < w * h; ++i) {
      const int x = i % w, y = i / w;
      if (!inside[static_cast<std::size_t>(i)]) {
        CHECK(neutral(im, x, y));
        CHECK(luminance(im, x, y) > 0.02);
        CHECK(luminance(im, x, y) < 0.15);
        continue;
      }
      CHECK_FALSE(neutral(im, x, y));
      const double l = luminance(im, x, y);
      CHECK(l >= previous);
      previous = l;
      if (first < 0) first = l;
      last = l;
    }
    CHECK(last - first > 0.5);

    // The bar: some column right of the map that gets steadily darker downwards over many rows.
    int longest = 0;
    for (int x = w; x < im.width; ++x) {
      int run = 0;
      for (int y = 1; y < im.height; ++y) {
        run = luminance(im, x, y) < luminance(im, x, y - 1) ? run + 1 : 0;
        longest = std::max(longest, run);
      }
    }
    CHECK(longest > 100);
  }
}

TEST_CASE("heat map log scale lifts the middle decades", "[diagnostic][heatmap]") {
  const std::vector<std::uint32_t> work = {1, 100, 10000};
  const FrameImage im = algray::work_heatmap(3, 1, work, {}, "work");
  const double lo = luminance(im, 0, 0), mid = luminance(im, 1, 0), hi = luminance(im, 2, 0);
  // Linear would put 100 at 1% of the way up the ramp; log puts it half way.
  CHECK(mid > lo + 0.1 * (hi - lo));
  CHECK(mid < hi);
}

TEST_CASE("heat map handles equal, empty and inconsistent input", "[diagnostic][heatmap]") {
  const FrameImage equal = algray::work_heatmap(5, 4, std::vector<std::uint32_t>(20, 7), {}, "");
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 5; ++x) {
      CHECK(luminance(equal, x, y) == luminance(equal, 0, 0));
      CHECK_FALSE(neutral(equal, x, y));
    }

  const FrameImage none = algray::work_heatmap(0, 0, {}, {}, "nothing");
  CHECK(none.width > 0);
  CHECK(none.height > 0);
  const FrameImage outside =
      algray::work_heatmap(4, 3, std::vector<std::uint32_t>(12, 9), std::vector<std::uint8_t>(12, 0), "all missed");
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) CHECK(neutral(outside, x, y));

  CHECK_THROWS_AS(algray::work_heatmap(4, 3, std::vector<std::uint32_t>(11, 0), {}, ""), OutputError);
  CHECK_THROWS_AS(algray::work_heatmap(4, 3, std::vector<std::uint32_t>(12, 0), std::vector<std::uint8_t>(5, 1), ""),
                  OutputError);
  CHECK_THROWS_AS(algray::work_heatmap(-1, 3, {}, {}, ""), OutputError);

  // And it goes through the ordinary PNG writer.
  TempDir dir;
  algray::write_png(dir / "heat.png", equal);
  const Png png = read_png(dir / "heat.png");
  CHECK(png.width == equal.width);
  CHECK(png.height == equal.height);
}
