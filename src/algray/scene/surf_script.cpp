// The surf script reader: a tokenizer and interpreter for surf's command language, and the algray scene made from
// the state at the drawing command.
//
// Facts about surf (1.0.6, Debian's surf-alggeo) this file relies on, measured with surf itself
// (bench/surf_compare.py renders the comparison):
// - Screen space is x right, y up, z towards the viewer; the image's shorter side spans -10..10 on the plane z = 0,
//   whatever the clip radius. `perspective = central` puts the eye at (0, 0, spec_z), spec_z 25 by default;
//   the default is parallel projection along -z.
// - The surface is moved by `first`, `second`, `third` (translate, rotate, scale by default): translate moves it by
//   origin_*, scale_* = s shows P(s x), rotate turns it about y, then x, then z. rot_x and rot_z turn points as
//   right-handed rotations do, rot_y the other way; rotate(p, a, yAxis) likewise.
// - The clip region is in screen space: a ball (default) or cube of `radius` about center_*, or with clip = none
//   the slab clip_back <= z <= clip_front.
// - Unary minus binds tighter than ^ (-x^2 is x^2), ^ is left-associative, and / divides integers as reals.
// - Lights are fixed in screen space; their default places are the 3 x 3 grid (-100..100, 100..-100, 100).
// - cut_with_plane draws, on the picture drawn last, the curve where `plane` meets surface number surf_nr
//   (surface_n is the same variable; 1 by default), hidden where another surface is in front. The plane is in the
//   surfaces' own coordinates and moves with them (rot_x = 0.8 shows y = 0 as a tilted ellipse; scale_x = 2 shows
//   x = 1 at 0.5). The curve is curve_width / 400 of the image's shorter side wide (3 by default), in
//   curve_red/green/blue (white by default) shaded like the surface. A plane with no z once moved (seen edge-on)
//   gets no curve at all.
#include "algray/scene/surf_script.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "algray/math/colour.h"
#include "algray/scene/located_text.h"
#include "algray/scene/scene.h"
#include "algray/scene/solver_options.h"
#include "algray/scene/sparse_poly.h"
#include "algray/scene/toml_reader.h"

namespace algray {
namespace {

// Untrusted scripts stop here rather than loop for ever (surf has `if (...) goto`) or expand for minutes. 20,000
// statements hold any animation loop of surf's examples many times over; the endless loop they stop takes 0.05 s in
// Release, 3 s in the fuzzers' ASan build (200,000 took 30 s there, a fuzzing run's whole budget).
constexpr long kMaxStatements = 20000;
constexpr int kSurfaces = 9;
constexpr int kLights = 9;
constexpr std::size_t kMaxCuts = 64;  // cut_with_plane on one picture

struct SurfToken {
  enum Kind { Name, Int, Real, String, Op, End } kind = End;
  std::string text;
  double number = 0;
  int line = 1, column = 1;
};

using Poly = SparsePoly;
using Exponents = SparsePoly::Exponents;

struct Value {
  enum Kind { Int, Real, Polynomial, String } kind = Int;
  double number = 0;  // Int and Real
  Poly poly;
  std::string text;

  static Value of_int(double v) { return {Int, v, {}, {}}; }
  static Value of_real(double v) { return {Real, v, {}, {}}; }
  static Value of_poly(Poly p) { return {Polynomial, 0, std::move(p), {}}; }
  static Value of_string(std::string s) { return {String, 0, {}, std::move(s)}; }
  bool is_number() const { return kind == Int || kind == Real; }
  Poly as_poly() const { return kind == Polynomial ? poly : Poly::constant(number); }
};

const char* kind_name(Value::Kind k) {
  switch (k) {
    case Value::Int:
      return "int";
    case Value::Real:
      return "double";
    case Value::Polynomial:
      return "poly";
    case Value::String:
      return "string";
  }
  return "?";
}

// Names surf reserves that change nothing algray draws: files, dithering, the numeric solver's settings, curves.
const std::set<std::string>& no_effect_names() {
  static const std::set<std::string> names = {
      "filename", "color_file_format", "color_file_colormap", "dither_file_format", "dither_colors", "dither_steps",
      "dithering_method", "serpentine_raster", "random_weights", "weight", "barons", "pattern_size", "enhance_edges",
      "alpha", "background", "tone_scale_adjustment", "gamma", "pixel_size", "print_resolution", "resolution",
      "optimize_colors", "epsilon", "iterations", "root_finder", "curve", "curve_gamma", "do_background",
      "cutsurface1", "cutsurface2", "jpeg_quality", "color_slider"};
  return names;
}

// Commands that change nothing algray draws.
const std::set<std::string>& quiet_commands() {
  static const std::set<std::string> names = {"clear_screen", "clear_pixmap", "set_size", "dither_surface",
                                              "dither_curve", "save_dithered_image", "reset"};
  return names;
}

// The constants of surf's language that the subset reads (choices of perspective, clip, order, axes, lighting).
// surf also takes clip = sphere, and draws it as the ball.
const std::map<std::string, double>& constants() {
  static const std::map<std::string, double> names = {
      {"yes", 1},          {"no", 0},           {"parallel", 0},      {"central", 1},         {"translate", 0},
      {"rotate", 1},       {"scale", 2},        {"ball", 0},          {"sphere", 0},          {"cylinder_xaxis", 1},
      {"cylinder_yaxis", 2}, {"cylinder_zaxis", 3}, {"cube", 4},      {"none", 5},            {"xAxis", 0},
      {"yAxis", 1},        {"zAxis", 2},        {"ambient_light", 1}, {"diffuse_light", 2},   {"reflected_light", 4},
      {"transmitted_light", 8}};
  return names;
}

std::string surface_suffix(int n) { return n == 1 ? "" : std::to_string(n); }

// The reserved variables algray reads, with surf's defaults.
std::map<std::string, Value> reserved_defaults() {
  std::map<std::string, Value> v;
  auto i = [&](const std::string& name, double x) { v[name] = Value::of_int(x); };
  auto d = [&](const std::string& name, double x) { v[name] = Value::of_real(x); };
  i("width", 200);
  i("height", 200);
  i("antialiasing", 1);
  d("antialiasing_threshold", 0.1);
  for (const char* axis : {"x", "y", "z"}) {
    d(std::string("rot_") + axis, 0);
    d(std::string("scale_") + axis, 1);
    d(std::string("origin_") + axis, 0);
    d(std::string("center_") + axis, 0);
  }
  d("spec_z", 25);
  d("stereo_eye", 0);
  i("perspective", 0);
  i("first", 0);
  i("second", 1);
  i("third", 2);
  i("clip", 0);
  d("radius", 10);
  d("clip_front", 10);
  d("clip_back", -10);
  i("illumination", 7);
  // cut_with_plane's plane and the curve it draws (see Script::cut).
  v["plane"] = Value::of_poly({});
  i("surf_nr", 1);
  for (const char* c : {"red", "green", "blue"}) i(std::string("curve_") + c, 255);
  d("curve_width", 3);
  for (const char* c : {"red", "green", "blue"}) i(std::string("background_") + c, 0);
  for (int n = 1; n <= kSurfaces; ++n) {
    const std::string s = surface_suffix(n);
    v["surface" + s] = Value::of_poly({});
    const int outside[3] = {123, 104, 238}, inside[3] = {230, 180, 30};
    const char* channels[3] = {"red", "green", "blue"};
    for (int c = 0; c < 3; ++c) {
      i("surface" + s + "_" + channels[c], outside[c]);
      i("inside" + s + "_" + channels[c], inside[c]);
    }
    i("ambient" + s, 35);
    i("diffuse" + s, 60);
    i("reflected" + s, 60);
    i("transmitted" + s, 60);
    i("smoothness" + s, 13);
    i("transparence" + s, 80);
    i("thickness" + s, 0);
  }
  for (int n = 1; n <= kLights; ++n) {
    const std::string l = "light" + std::to_string(n) + "_";
    d(l + "x", 100.0 * ((n - 1) % 3 - 1));
    d(l + "y", 100.0 * (1 - (n - 1) / 3));
    d(l + "z", 100);
    i(l + "vol", n == 1 ? 50 : 0);
    for (const char* c : {"red", "green", "blue"}) i(l + c, 255);
  }
  return v;
}

// surf spells some names two ways.
std::string canonical_name(const std::string& name) {
  static const std::string volume = "_volume", transparency = "transparency";
  if (name == "surface_n") return "surf_nr";
  if (name.size() > volume.size() && name.compare(name.size() - volume.size(), volume.size(), volume) == 0)
    return name.substr(0, name.size() - volume.size()) + "_vol";
  if (name.compare(0, transparency.size(), transparency) == 0)
    return "transparence" + name.substr(transparency.size());
  return name;
}

// Reserved names surf draws with that algray does not follow: assigning one is a located warning.
bool is_known_unsupported(const std::string& name) {
  static const std::set<std::string> names = {
      "depth_cueing", "depth_value", "depth", "normalize", "normalize_factor", "normalize_brightness",
      "antialiasing_radius", "stereo_z", "stereo_red", "stereo_green", "stereo_blue", "display_numeric",
      "light_settings"};
  return names.count(name) > 0;
}

class Script {
 public:
  Script(const std::string& text, std::string source, std::vector<std::string>& warnings)
      : text_(text, std::move(source)), source_(text_.source()), warnings_(warnings) {
    tokenize(text);
    globals_ = reserved_defaults();
  }

  SurfTranslation run(int width, int height);

 private:
  // A plane section drawn on a picture: the values cut_with_plane read, where it ran.
  struct Cut {
    Poly plane;  // in the script's own coordinates, as the surfaces are
    int surface = 1;
    glm::dvec3 colour;  // 0..255
    double width = 1;
    SurfToken at;
  };
  struct Snapshot {
    std::map<std::string, Value> globals;
    SurfToken at;
    std::vector<Cut> cuts;  // the cut_with_plane runs after this draw_surface, in order
  };

  // --- messages ---
  std::string where(const SurfToken& t) const { return text_.where(t.line, t.column); }
  std::string excerpt(const SurfToken& t) const { return text_.excerpt(t.line, t.column); }
  [[noreturn]] void fail(const SurfToken& t, const std::string& message) const { text_.fail(t.line, t.column, message); }
  void warn(const SurfToken& t, const std::string& message) { warnings_.push_back(where(t) + ": " + message); }
  void warn_once(const SurfToken& t, const std::string& key, const std::string& message) {
    if (warned_.insert(key).second) warn(t, message);
  }

  // --- tokens ---
  void tokenize(const std::string& text) {
    TextCursor cursor(text);
    std::size_t& i = cursor.i;
    const int &line = cursor.line, &column = cursor.column;
    auto advance = [&](std::size_t n) { cursor.advance(n); };
    while (i < text.size()) {
      const char c = text[i];
      if (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v') {
        advance(1);
        continue;
      }
      if (const int comment = cursor.skip_comment()) {
        if (comment < 0) fail(SurfToken{SurfToken::Op, "/*", 0, line, column}, "this comment never ends (no */)");
        continue;
      }
      SurfToken t{SurfToken::Op, "", 0, line, column};
      if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
        std::size_t j = i;
        while (j < text.size() && (std::isalnum(static_cast<unsigned char>(text[j])) || text[j] == '_')) ++j;
        t.kind = SurfToken::Name;
        t.text = text.substr(i, j - i);
        advance(j - i);
      } else if (std::isdigit(static_cast<unsigned char>(c)) ||
                 (c == '.' && i + 1 < text.size() && std::isdigit(static_cast<unsigned char>(text[i + 1])))) {
        bool real = false;
        const std::size_t j = cursor.number_end(&real);
        t.kind = real ? SurfToken::Real : SurfToken::Int;
        t.text = text.substr(i, j - i);
        std::istringstream in(t.text);
        in.imbue(std::locale::classic());
        in >> t.number;
        if (!std::isfinite(t.number) || in.fail()) fail(t, "the number " + t.text + " is too large");
        advance(j - i);
      } else if (c == '"') {
        std::size_t j = i + 1;
        while (j < text.size() && text[j] != '"' && text[j] != '\n') ++j;
        if (j >= text.size() || text[j] != '"') fail(t, "this string never ends (no closing \")");
        t.kind = SurfToken::String;
        t.text = text.substr(i + 1, j - i - 1);
        advance(j + 1 - i);
      } else {
        static const char* two[] = {"==", "!=", "<=", ">=", "&&", "||"};
        for (const char* op : two)
          if (text.compare(i, 2, op) == 0) t.text = op;
        if (t.text.empty()) {
          if (std::string("+-*/%^()=<>;,:!").find(c) == std::string::npos) {
            const unsigned char u = static_cast<unsigned char>(c);
            fail(t, u >= 0x20 && u < 0x7f ? std::string("unexpected character '") + c + "'"
                                           : "unexpected byte " + std::to_string(u) + " (surf scripts are ASCII)");
          }
          t.text = std::string(1, c);
        }
        advance(t.text.size());
      }
      tokens_.push_back(t);
    }
    tokens_.push_back({SurfToken::End, "", 0, line, column});
  }

  const SurfToken& peek(std::size_t ahead = 0) const { return tokens_[std::min(pos_ + ahead, tokens_.size() - 1)]; }
  bool at_op(const char* op, std::size_t ahead = 0) const {
    return peek(ahead).kind == SurfToken::Op && peek(ahead).text == op;
  }
  const SurfToken& next() {
    const SurfToken& t = tokens_[pos_];
    if (pos_ + 1 < tokens_.size()) ++pos_;
    return t;
  }
  void expect(const char* op, const char* what) {
    if (!at_op(op)) fail(peek(), std::string("expected ") + what + ", found " + describe(peek()));
    next();
  }
  static std::string describe(const SurfToken& t) {
    switch (t.kind) {
      case SurfToken::End:
        return "the end of the file";
      case SurfToken::String:
        return "a string";
      default:
        return "'" + t.text + "'";
    }
  }
  void skip_statement() {
    while (peek().kind != SurfToken::End && !at_op(";")) next();
    if (at_op(";")) next();
  }

  // --- expressions ---
  Poly multiply(const Poly& a, const Poly& b, const SurfToken& at) {
    try {
      return algray::multiply(a, b, budget_);
    } catch (const PolyTooLarge& e) {
      fail(at, e.what());
    }
  }
  Poly power(const Poly& p, long e, const SurfToken& at) {
    try {
      return algray::power(p, e, budget_);
    } catch (const PolyTooLarge& error) {
      fail(at, error.what());
    }
  }
  Poly substitute(const Poly& p, const std::array<std::array<double, 4>, 3>& m, const SurfToken& at) {
    try {
      return algray::substitute(p, m, budget_);
    } catch (const PolyTooLarge& e) {
      fail(at, e.what());
    }
  }
  // surf's rotation by `angle` about an axis (0 x, 1 y, 2 z) as the matrix that moves points.
  static std::array<std::array<double, 3>, 3> rotation(std::size_t axis, double angle) {
    if (axis == 1) angle = -angle;  // surf turns about y the other way (see the top of the file)
    const double c = std::cos(angle), s = std::sin(angle);
    const std::size_t a = static_cast<std::size_t>(axis + 1) % 3, b = static_cast<std::size_t>(axis + 2) % 3;
    std::array<std::array<double, 3>, 3> r{};
    r[axis][axis] = 1;
    r[a][a] = c;
    r[a][b] = -s;
    r[b][a] = s;
    r[b][b] = c;
    return r;
  }
  // The surface P turned by `angle`: P(R^-1 x), R^-1 being R's transpose.
  Poly rotated(const Poly& p, int axis, double angle, const SurfToken& at) {
    const auto r = rotation(static_cast<std::size_t>(axis), angle);
    std::array<std::array<double, 4>, 3> m{};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m[i][j] = r[j][i];
    return substitute(p, m, at);
  }

  double real_result(double v, const SurfToken& at) {
    if (!std::isfinite(v)) fail(at, "this gives " + std::string(std::isnan(v) ? "no real number" : "an infinity"));
    return v;
  }
  Value number_result(double v, bool both_int, const SurfToken& at) {
    real_result(v, at);
    return both_int && std::fabs(v) < 9.007e15 ? Value::of_int(v) : Value::of_real(v);
  }

  Value binary(const std::string& op, const Value& a, const Value& b, const SurfToken& at) {
    if (a.kind == Value::String || b.kind == Value::String) {
      if (op == "+" && a.kind == Value::String && b.kind == Value::String) return Value::of_string(a.text + b.text);
      if ((op == "==" || op == "!=") && a.kind == Value::String && b.kind == Value::String)
        return Value::of_int((a.text == b.text) == (op == "=="));
      fail(at, std::string("'") + op + "' does not apply to " + kind_name(a.kind) + " and " + kind_name(b.kind));
    }
    const bool polys = a.kind == Value::Polynomial || b.kind == Value::Polynomial;
    const bool ints = a.kind == Value::Int && b.kind == Value::Int;
    if (op == "+" || op == "-") {
      if (!polys) return number_result(op == "+" ? a.number + b.number : a.number - b.number, ints, at);
      Poly out = a.as_poly();
      for (const auto& [e, c] : b.as_poly().terms) out.add(e, op == "+" ? c : -c);
      return Value::of_poly(std::move(out));
    }
    if (op == "*") {
      if (!polys) return number_result(a.number * b.number, ints, at);
      return Value::of_poly(multiply(a.as_poly(), b.as_poly(), at));
    }
    if (op == "/") {
      if (b.kind == Value::Polynomial) fail(at, "surf divides by numbers only, not by polynomials");
      if (b.number == 0) fail(at, "division by zero");
      if (!polys) return Value::of_real(real_result(a.number / b.number, at));
      Poly out = a.poly;
      for (auto& [e, c] : out.terms) c = real_result(c / b.number, at);
      return Value::of_poly(std::move(out));
    }
    if (op == "%") {
      if (!ints) fail(at, "'%' takes two ints");
      if (b.number == 0) fail(at, "remainder of a division by zero");
      return Value::of_int(std::fmod(a.number, b.number));
    }
    if (op == "^") {
      if (b.kind == Value::Polynomial) fail(at, "an exponent must be a number");
      if (a.kind == Value::Polynomial) {
        if (b.kind != Value::Int || b.number < 0)
          fail(at, "a polynomial's exponent must be a non-negative int");
        return Value::of_poly(power(a.poly, static_cast<long>(std::min(b.number, 1e6)), at));
      }
      return Value::of_real(real_result(std::pow(a.number, b.number), at));
    }
    if (polys) fail(at, std::string("'") + op + "' compares numbers, not polynomials");
    bool r = false;
    if (op == "==") r = a.number == b.number;
    else if (op == "!=") r = a.number != b.number;
    else if (op == "<") r = a.number < b.number;
    else if (op == "<=") r = a.number <= b.number;
    else if (op == ">") r = a.number > b.number;
    else if (op == ">=") r = a.number >= b.number;
    else if (op == "&&") r = a.number != 0 && b.number != 0;
    else if (op == "||") r = a.number != 0 || b.number != 0;
    return Value::of_int(r ? 1 : 0);
  }

  // C's precedence, with ^ above * and unary minus above ^ (as surf reads them).
  Value expression(int depth = 0) {
    if (depth > 200) fail(peek(), "the expression is nested too deeply");
    return binary_level(0, depth);
  }
  Value binary_level(int level, int depth) {
    static const std::vector<std::vector<std::string>> levels = {
        {"||"}, {"&&"}, {"==", "!="}, {"<", "<=", ">", ">="}, {"+", "-"}, {"*", "/", "%"}, {"^"}};
    if (level == static_cast<int>(levels.size())) return unary(depth);
    Value left = binary_level(level + 1, depth);
    for (;;) {
      const SurfToken& t = peek();
      if (t.kind != SurfToken::Op ||
          std::find(levels[level].begin(), levels[level].end(), t.text) == levels[level].end())
        return left;
      const SurfToken op = next();
      const Value right = binary_level(level + 1, depth);
      left = binary(op.text, left, right, op);
    }
  }
  Value unary(int depth) {
    if (depth > 200) fail(peek(), "the expression is nested too deeply");
    if (at_op("-") || at_op("+") || at_op("!")) {
      const SurfToken op = next();
      Value v = unary(depth + 1);
      if (op.text == "+") {
        if (v.kind == Value::String) fail(op, "unary '+' does not apply to a string");
        return v;
      }
      if (op.text == "!") {
        if (!v.is_number()) fail(op, "'!' takes a number");
        return Value::of_int(v.number == 0 ? 1 : 0);
      }
      if (v.kind == Value::String) fail(op, "unary '-' does not apply to a string");
      if (v.kind == Value::Polynomial)
        for (auto& [e, c] : v.poly.terms) c = -c;
      else
        v.number = -v.number;
      return v;
    }
    return primary(depth);
  }
  std::vector<Value> arguments(int depth) {
    std::vector<Value> args;
    expect("(", "'('");
    if (!at_op(")"))
      for (;;) {
        args.push_back(expression(depth + 1));
        if (!at_op(",")) break;
        next();
      }
    expect(")", "')' or ','");
    return args;
  }
  double number_arg(const Value& v, const SurfToken& at, const std::string& function) {
    if (!v.is_number()) fail(at, function + " takes numbers, not a " + kind_name(v.kind));
    return v.number;
  }
  Value call(const SurfToken& name, int depth) {
    const std::vector<Value> args = arguments(depth);
    const std::string& f = name.text;
    auto want = [&](std::size_t n) {
      if (args.size() != n)
        fail(name, f + " takes " + std::to_string(n) + " argument" + (n == 1 ? "" : "s") + ", not " +
                       std::to_string(args.size()));
    };
    static const std::map<std::string, double (*)(double)> maths = {
        {"sqrt", [](double v) { return std::sqrt(v); }}, {"sin", [](double v) { return std::sin(v); }},
        {"cos", [](double v) { return std::cos(v); }},   {"tan", [](double v) { return std::tan(v); }},
        {"arcsin", [](double v) { return std::asin(v); }}, {"arccos", [](double v) { return std::acos(v); }},
        {"arctan", [](double v) { return std::atan(v); }}, {"exp", [](double v) { return std::exp(v); }},
        {"log", [](double v) { return std::log(v); }}};
    if (const auto m = maths.find(f); m != maths.end()) {
      want(1);
      return Value::of_real(real_result(m->second(number_arg(args[0], name, f)), name));
    }
    if (f == "pow") {
      want(2);
      return Value::of_real(real_result(std::pow(number_arg(args[0], name, f), number_arg(args[1], name, f)), name));
    }
    if (f == "rotate") {
      want(3);
      if (args[0].kind == Value::String) fail(name, "rotate turns a polynomial, not a string");
      const double axis = number_arg(args[2], name, "rotate's axis");
      if (axis != 0 && axis != 1 && axis != 2) fail(name, "rotate's axis is xAxis, yAxis or zAxis");
      return Value::of_poly(
          rotated(args[0].as_poly(), static_cast<int>(axis), number_arg(args[1], name, "rotate's angle"), name));
    }
    if (f == "deg" || f == "len") {
      want(1);
      if (args[0].kind == Value::String) fail(name, f + " takes a polynomial");
      const Poly p = args[0].as_poly();
      return Value::of_int(f == "deg" ? std::max(p.degree(), 0) : static_cast<double>(p.terms.size()));
    }
    if (f == "diff") {
      want(2);
      if (args[0].kind == Value::String || args[1].kind != Value::Polynomial || args[1].poly.terms.size() != 1 ||
          args[1].poly.degree() != 1 || args[1].poly.terms.begin()->second != 1)
        fail(name, "diff takes a polynomial and x, y or z");
      const Exponents v = args[1].poly.terms.begin()->first;
      const int axis = v[0] ? 0 : v[1] ? 1 : 2;
      Poly out;
      for (const auto& [e, c] : args[0].as_poly().terms)
        if (e[static_cast<std::size_t>(axis)] > 0) {
          Exponents d = e;
          --d[static_cast<std::size_t>(axis)];
          out.add(d, c * e[static_cast<std::size_t>(axis)]);
        }
      return Value::of_poly(std::move(out));
    }
    if (f == "itostr" || f == "itostrn") {
      want(f == "itostr" ? 1 : 2);
      const double v = number_arg(args.back(), name, f);
      std::string s = std::to_string(static_cast<long long>(std::clamp(v, -1e15, 1e15)));
      if (f == "itostrn") {
        const double width = std::clamp(number_arg(args[0], name, f), 0.0, 64.0);
        while (s.size() < static_cast<std::size_t>(width)) s.insert(0, "0");
      }
      return Value::of_string(s);
    }
    fail(name, "'" + f + "' is not a function surf scripts have that algray reads (sqrt, pow, sin, cos, tan, "
                         "arcsin, arccos, arctan, rotate, deg, len, diff, itostr, itostrn)");
  }
  Value primary(int depth) {
    const SurfToken t = next();
    switch (t.kind) {
      case SurfToken::Int:
        return Value::of_int(t.number);
      case SurfToken::Real:
        return Value::of_real(t.number);
      case SurfToken::String:
        return Value::of_string(t.text);
      case SurfToken::Op:
        if (t.text == "(") {
          Value v = expression(depth + 1);
          expect(")", "')'");
          return v;
        }
        fail(t, "expected a value, found " + describe(t));
      case SurfToken::End:
        fail(t, "expected a value, found the end of the file");
      case SurfToken::Name:
        break;
    }
    if (at_op("(")) return call(t, depth);
    if (t.text == "x" || t.text == "y" || t.text == "z") return Value::of_poly(Poly::variable(t.text[0] - 'x'));
    if (const auto it = locals_.find(t.text); it != locals_.end()) return it->second;
    if (const auto it = globals_.find(canonical_name(t.text)); it != globals_.end()) return it->second;
    if (const auto it = constants().find(t.text); it != constants().end()) return Value::of_int(it->second);
    fail(t, "'" + t.text + "' is not declared (int, double, poly or string NAME first) and is no name algray "
                           "reads from surf scripts");
  }

  // --- statements ---
  Value converted(const Value& v, Value::Kind kind, const SurfToken& at) {
    if (v.kind == kind) return v;
    if (kind == Value::Polynomial && v.is_number()) return Value::of_poly(Poly::constant(v.number));
    if (kind == Value::Real && v.kind == Value::Int) return Value::of_real(v.number);
    if (kind == Value::Real && v.kind == Value::Polynomial && v.poly.degree() <= 0) {
      const auto c = v.poly.terms.find({0, 0, 0});
      return Value::of_real(c == v.poly.terms.end() ? 0 : c->second);
    }
    if (kind == Value::Int && v.kind == Value::Real && v.number == std::trunc(v.number))
      return Value::of_int(v.number);
    fail(at, std::string("a ") + kind_name(kind) + " cannot hold this " + kind_name(v.kind) + " value");
  }
  void declaration(const SurfToken& type) {
    static const std::map<std::string, Value::Kind> types = {{"int", Value::Int},
                                                             {"double", Value::Real},
                                                             {"poly", Value::Polynomial},
                                                             {"polyxyz", Value::Polynomial},
                                                             {"string", Value::String}};
    const SurfToken name = next();
    if (name.kind != SurfToken::Name) fail(name, "expected a name after " + type.text + ", found " + describe(name));
    if (locals_.count(name.text)) fail(name, "'" + name.text + "' is already declared");
    if (globals_.count(canonical_name(name.text)) || constants().count(name.text) || name.text == "x" ||
        name.text == "y" || name.text == "z" || types.count(name.text))
      fail(name, "'" + name.text + "' is a reserved word of surf's language");
    const Value::Kind kind = types.at(type.text);
    Value value = kind == Value::Int         ? Value::of_int(0)
                  : kind == Value::Real      ? Value::of_real(0)
                  : kind == Value::String    ? Value::of_string("")
                                             : Value::of_poly({});
    if (at_op("=")) {
      const SurfToken eq = next();
      value = converted(expression(), kind, eq);
    }
    locals_[name.text] = value;
    expect(";", "';'");
  }
  void assignment(const SurfToken& name) {
    const SurfToken eq = next();  // '='
    const std::string key = canonical_name(name.text);
    if (const auto it = locals_.find(name.text); it != locals_.end()) {
      it->second = converted(expression(), it->second.kind, eq);
    } else if (const auto g = globals_.find(key); g != globals_.end()) {
      g->second = converted(expression(), g->second.kind == Value::Int ? Value::Real : g->second.kind, eq);
      if (g->second.kind == Value::Real && (key.find("_red") != std::string::npos ||
                                            key.find("_green") != std::string::npos ||
                                            key.find("_blue") != std::string::npos))
        g->second.number = std::trunc(g->second.number);
      assigned_at_[key] = name;
      note_assignment(name, key, g->second);
    } else if (no_effect_names().count(key)) {
      skip_statement();
      return;
    } else if (is_known_unsupported(key)) {
      warn_once(name, key, key + " is not part of what algray reads from surf scripts; ignored, so the picture "
                               "may differ from surf's");
      skip_statement();
      return;
    } else {
      warn_once(name, key, "'" + name.text + "' is no variable of this script and no name algray reads from surf "
                           "scripts; the statement is ignored");
      skip_statement();
      return;
    }
    expect(";", "';'");
  }
  // Values algray draws differently: said once, where they are set.
  void note_assignment(const SurfToken& at, const std::string& key, const Value& v) {
    if (key == "clip" && (v.number == 1 || v.number == 2 || v.number == 3))
      fail(at, "clip to a cylinder: algray clips to a ball, a cube or none (the slab between clip_back and "
               "clip_front)");
    if (key == "clip" && !(v.number == 0 || v.number == 4 || v.number == 5))
      fail(at, "clip is ball, cube, none or a cylinder");
    if (key == "stereo_eye" && v.number != 0)
      fail(at, "stereo_eye: surf draws a red/green stereo pair, algray one view; set stereo_eye = 0 for that view");
    if (key.compare(0, 9, "thickness") == 0 && v.number != 0)
      warn_once(at, key, key + ": algray's transparent surfaces have no thickness; ignored");
  }
  void command(const SurfToken& name) {
    expect(";", "';' after the command");
    const std::string& c = name.text;
    if (c == "draw_surface") {
      // A picture is a copy of every reserved value: counted like arithmetic, so that a loop of thousands of
      // draws of large surfaces stops at the budget instead of copying for minutes.
      double terms = 0;
      for (const auto& [key, v] : globals_) terms += 1 + static_cast<double>(v.poly.terms.size());
      budget_.work += terms;
      if (budget_.work > budget_.limit) fail(name, "the script's pictures and arithmetic are too large to follow here");
      last_drawn_ = Snapshot{globals_, name, {}};
      ++draws_;
    } else if (c == "save_color_image") {
      if (last_drawn_ && !first_saved_) first_saved_ = last_drawn_;
      if (last_drawn_) ++saves_;
    } else if (c == "cut_with_plane") {
      cut(name);
    } else if (c == "draw_curve") {
      warn_once(name, c, "draw_curve: algray draws surfaces, not plane curves; ignored");
      curve_at_ = name;
    } else if (c == "cut_with_surface") {
      warn_once(name, c, "cut_with_surface: algray draws no intersection curves; ignored");
    } else if (!quiet_commands().count(c)) {
      warn_once(name, c, "'" + c + "' is no command algray follows in surf scripts; ignored");
    }
  }
  // cut_with_plane: the curve where `plane` meets surface number surf_nr, drawn on the picture draw_surface drew
  // last in the curve's colour and width; written as a [[section]] of that surface (translate()).
  void cut(const SurfToken& at) {
    if (!last_drawn_) {
      warn_once(at, "cut_with_plane", "cut_with_plane before any draw_surface: surf draws the section on the picture "
                                      "drawn last, and there is none yet; ignored");
      return;
    }
    if (last_drawn_->cuts.size() >= kMaxCuts)
      fail(at, "more than " + std::to_string(kMaxCuts) + " cut_with_plane on one picture; algray draws up to " +
                   std::to_string(kMaxCuts));
    Cut k;
    k.at = at;
    k.plane = globals_.at("plane").poly;
    if (k.plane.degree() != 1)
      fail(set_at_now("plane", at), "cut_with_plane needs plane to be linear in x, y and z (plane = z; or plane = "
                                "x+y-1;); it is " + (k.plane.degree() < 1 ? std::string("a constant")
                                                                          : "of degree " +
                                                                                std::to_string(k.plane.degree())));
    const double n = globals_.at("surf_nr").number;
    if (n != std::trunc(n) || n < 1 || n > kSurfaces)
      fail(set_at_now("surf_nr", at), "surf_nr must be a surface's number, 1 to " + std::to_string(kSurfaces));
    k.surface = static_cast<int>(n);
    for (int i = 0; i < 3; ++i) {
      const std::string key = std::string("curve_") + (i == 0 ? "red" : i == 1 ? "green" : "blue");
      k.colour[i] = globals_.at(key).number;
      if (k.colour[i] < 0 || k.colour[i] > 255) fail(set_at_now(key, at), key + " must be between 0 and 255");
    }
    k.width = globals_.at("curve_width").number;
    if (!(k.width > 0 && k.width <= kMaxSectionWidth))
      fail(set_at_now("curve_width", at), "curve_width must be above 0 and at most " +
                                          std::to_string(static_cast<int>(kMaxSectionWidth)) + " (pixels)");
    last_drawn_->cuts.push_back(std::move(k));
  }
  // Where a reserved value was last set, or `otherwise` where it was never set.
  const SurfToken& set_at_now(const std::string& key, const SurfToken& otherwise) const {
    const auto it = assigned_at_.find(key);
    return it != assigned_at_.end() ? it->second : otherwise;
  }
  void if_goto(const SurfToken& at) {
    expect("(", "'(' after if");
    const Value condition = expression();
    expect(")", "')'");
    if (!condition.is_number()) fail(at, "if needs a number (a comparison)");
    const SurfToken go = next();
    if (go.kind != SurfToken::Name || go.text != "goto") fail(go, "surf's if is `if (condition) goto LABEL;`");
    const SurfToken label = next();
    if (label.kind != SurfToken::Name) fail(label, "expected a label after goto");
    const auto target = labels_.find(label.text);
    if (target == labels_.end()) fail(label, "no label '" + label.text + ":' before this goto");
    expect(";", "';'");
    if (condition.number != 0) pos_ = target->second;
  }
  void statement() {
    if (++statements_ > kMaxStatements)
      fail(peek(), "the script runs more than " + std::to_string(kMaxStatements) +
                       " statements (a goto loop that does not end?)");
    const SurfToken t = next();
    if (t.kind == SurfToken::Op && t.text == ";") return;
    if (t.kind != SurfToken::Name) fail(t, "expected a statement, found " + describe(t));
    if (t.text == "int" || t.text == "double" || t.text == "poly" || t.text == "polyxyz" || t.text == "string")
      return declaration(t);
    if (t.text == "if" && at_op("(")) return if_goto(t);
    if (at_op(":")) {
      next();
      labels_.emplace(t.text, pos_);
      return;
    }
    if (at_op("=")) return assignment(t);
    if (at_op(";")) return command(t);
    fail(peek(), "expected '=', ';' or ':' after '" + t.text + "', found " + describe(peek()));
  }

  // --- the scene ---
  double number(const Snapshot& s, const std::string& key) const { return s.globals.at(key).number; }
  const SurfToken& set_at(const Snapshot& s, const std::string& key) const {
    const auto it = assigned_at_.find(key);
    return it != assigned_at_.end() ? it->second : s.at;
  }
  glm::dvec3 colour(const Snapshot& s, const std::string& prefix) const {
    glm::dvec3 c;
    for (int i = 0; i < 3; ++i) {
      const std::string key = prefix + (i == 0 ? "red" : i == 1 ? "green" : "blue");
      const double v = number(s, key);
      if (v < 0 || v > 255) fail(set_at(s, key), key + " must be between 0 and 255");
      c[i] = srgb_to_linear(v / 255);  // surf's colours are display values, algray's linear
    }
    return c;
  }
  double percent(const Snapshot& s, const std::string& key) const {
    const double v = number(s, key);
    if (v < 0 || v > 100) fail(set_at(s, key), key + " must be between 0 and 100");
    return v / 100;
  }
  using Affine = std::array<std::array<double, 4>, 3>;
  // The clip region and the framing: the shorter side spans -10..10 on the plane z = 0.
  struct View {
    glm::dvec3 centre;
    double radius, clip;
    double width, height;  // the script's image size
    double rendered_width, rendered_height;  // the size it is rendered at
    double half_w, half_h;
    bool central;
    double spec_z;
  };
  std::string translate(const Snapshot& s);
  Affine screen_to_script(const Snapshot& s) const;
  Affine undone_position_step(const Snapshot& s, const char* order) const;
  // Writes the surfaces; surface number n (1..9) becomes algray's surface index_of[n], -1 where it is empty.
  void write_surfaces(std::ostringstream& toml, const Snapshot& s, const Affine& inverse,
                      std::array<int, kSurfaces + 1>& index_of);
  void write_sections(std::ostringstream& toml, const Snapshot& s, const Affine& inverse,
                      const std::array<int, kSurfaces + 1>& index_of, const View& v);
  void write_material(std::ostringstream& toml, const Snapshot& s, const std::string& sfx, const char* side,
                      bool transmitted) const;
  View view(const Snapshot& s) const;
  void write_extent(std::ostringstream& toml, const Snapshot& s, const View& v) const;
  void write_camera_and_image(std::ostringstream& toml, const Snapshot& s, const View& v) const;
  void write_lights(std::ostringstream& toml, const Snapshot& s) const;

  LocatedText text_;
  const std::string& source_;
  std::vector<std::string>& warnings_;
  std::vector<SurfToken> tokens_;
  std::size_t pos_ = 0;
  long statements_ = 0;
  PolyBudget budget_;  // the script's polynomial arithmetic, all of it
  std::map<std::string, Value> locals_, globals_;
  std::map<std::string, SurfToken> assigned_at_;
  std::map<std::string, std::size_t> labels_;
  std::set<std::string> warned_;
  // Only the pictures algray may render are kept: a loop may draw thousands.
  std::optional<Snapshot> last_drawn_, first_saved_;
  long draws_ = 0, saves_ = 0;
  std::optional<SurfToken> curve_at_;
  int rendered_width_ = 0, rendered_height_ = 0;  // overrides of width and height, 0 where none
};

// The position settings in their order, undone: a screen point -> the script's own coordinates. The steps apply
// first to last to the surface, so their inverses apply last to first to a screen point:
// inverse = inv(first) o inv(second) o inv(third), which composing in this order builds.
Script::Affine Script::screen_to_script(const Snapshot& s) const {
  Affine inverse{};
  for (int i = 0; i < 3; ++i) inverse[i][i] = 1;
  for (const char* order : {"first", "second", "third"}) {
    const Affine step = undone_position_step(s, order);
    Affine out{};  // inverse o step
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k) out[r][c] += inverse[r][k] * step[k][c];
      out[r][3] = inverse[r][3];
      for (int k = 0; k < 3; ++k) out[r][3] += inverse[r][k] * step[k][3];
    }
    inverse = out;
  }
  return inverse;
}

Script::Affine Script::undone_position_step(const Snapshot& s, const char* order) const {
  const double what = number(s, order);
  Affine step{};
  if (what == 0) {  // translate by origin: p -> p + o, undone by x - o
    for (int i = 0; i < 3; ++i) {
      step[i][i] = 1;
      step[i][3] = -number(s, std::string("origin_") + "xyz"[i]);
    }
  } else if (what == 1) {  // rotate about y, then x, then z: undone by R^T
    auto product = rotation(1, number(s, "rot_y"));
    for (std::size_t axis : {std::size_t{0}, std::size_t{2}}) {
      const auto r = rotation(axis, number(s, axis == 0 ? "rot_x" : "rot_z"));
      std::array<std::array<double, 3>, 3> next{};
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          for (int k = 0; k < 3; ++k) next[i][j] += r[i][k] * product[k][j];
      product = next;
    }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) step[i][j] = product[j][i];
  } else if (what == 2) {  // scale: P(s x)
    for (int i = 0; i < 3; ++i) step[i][i] = number(s, std::string("scale_") + "xyz"[i]);
  } else {
    fail(set_at(s, order), std::string(order) + " is translate, rotate or scale");
  }
  return step;
}

void Script::write_surfaces(std::ostringstream& toml, const Snapshot& s, const Affine& inverse,
                            std::array<int, kSurfaces + 1>& index_of) {
  int surfaces = 0;
  index_of.fill(-1);
  const bool transmitted = (static_cast<long>(number(s, "illumination")) & 8) != 0;
  const std::size_t slash = source_.find_last_of('/');
  for (int n = 1; n <= kSurfaces; ++n) {
    const std::string sfx = surface_suffix(n);
    const Poly& own = s.globals.at("surface" + sfx).poly;
    if (own.terms.empty()) continue;
    const SurfToken& at = set_at(s, "surface" + sfx);
    const Poly p = substitute(own, inverse, at);
    if (p.degree() < 1) fail(at, "surface" + sfx + " is a constant after its position is applied; nothing to draw");
    index_of[static_cast<std::size_t>(n)] = surfaces;
    ++surfaces;
    toml << "\n[[surface]]\nname = " << toml_quoted(source_.substr(slash == std::string::npos ? 0 : slash + 1) +
                                                   (n == 1 ? "" : " surface" + sfx))
         << "\nterms = [";
    const char* sep = "";
    for (const auto& [e, c] : p.terms) {
      if (!std::isfinite(c)) fail(at, "surface" + sfx + "'s coefficients overflow after its position is applied");
      toml << sep << "[" << e[0] << ", " << e[1] << ", " << e[2] << ", " << toml_number(c) << "]";
      sep = ", ";
    }
    toml << "]\n";
    for (const char* side : {"front", "back"}) write_material(toml, s, sfx, side, transmitted);
  }
  if (surfaces == 0) fail(s.at, "no surface is set when draw_surface runs (surface = ...; first)");
  if (surfaces > static_cast<int>(kMaxSurfaces))
    fail(s.at, std::to_string(surfaces) + " surfaces: algray draws up to " + std::to_string(kMaxSurfaces) +
                   " in one scene");
}

// Each cut_with_plane as a [[section]] of its surface. The plane is in the script's own coordinates, as the
// surfaces are, and moves with them: L(inverse x), still linear. surf draws the curve curve_width / 400 of the
// image's shorter side wide, and draws nothing for a plane seen edge-on (no z in screen space): nor does algray.
void Script::write_sections(std::ostringstream& toml, const Snapshot& s, const Affine& inverse,
                            const std::array<int, kSurfaces + 1>& index_of, const View& v) {
  const double pixels_per_width = std::min(v.rendered_width, v.rendered_height) / 400;
  for (const Cut& k : s.cuts) {
    const int index = index_of[static_cast<std::size_t>(k.surface)];
    if (index < 0) {
      warn(k.at, "cut_with_plane cuts surface" + surface_suffix(k.surface) + " (surf_nr = " +
                     std::to_string(k.surface) + "), which is not set when draw_surface runs; nothing is drawn");
      continue;
    }
    const Poly plane = substitute(k.plane, inverse, k.at);
    double abcd[4] = {0, 0, 0, 0};
    for (const auto& [e, c] : plane.terms) {
      if (!std::isfinite(c)) fail(k.at, "the plane's coefficients overflow after the position settings are applied");
      if (e[0] + e[1] + e[2] == 0) abcd[3] += c;
      for (int i = 0; i < 3; ++i)
        if (e[static_cast<std::size_t>(i)] == 1) abcd[i] += c;
    }
    // Scaled to a unit largest normal component, so that its numbers are coordinates the scene reader takes.
    const double largest = std::max({std::fabs(abcd[0]), std::fabs(abcd[1]), std::fabs(abcd[2])});
    if (!(largest > 0))
      fail(k.at, "the plane is no plane after the position settings are applied (a scale of 0?)");
    for (double& c : abcd) c /= largest;
    if (!(std::fabs(abcd[3]) <= 1e15)) {
      warn(k.at, "cut_with_plane: the plane lies too far away to meet what is drawn; nothing is drawn");
      continue;
    }
    if (std::fabs(abcd[2]) <= 1e-12 * std::hypot(abcd[0], abcd[1])) {
      warn(k.at, "cut_with_plane: the plane is seen edge-on (it holds the viewing direction), where surf draws no "
                 "section; nor does algray (--section draws it)");
      continue;
    }
    glm::dvec3 colour;
    for (int i = 0; i < 3; ++i) colour[i] = srgb_to_linear(k.colour[i] / 255);  // display values, as surfaces' are
    toml << "\n[[section]]  # cut_with_plane at " << where(k.at) << "\nplane = [" << toml_number(abcd[0]) << ", "
         << toml_number(abcd[1]) << ", " << toml_number(abcd[2]) << ", " << toml_number(abcd[3])
         << "]\ncolour = " << toml_vector(colour) << "\nsurface = " << index
         << "\nwidth = " << toml_number(std::clamp(k.width * pixels_per_width, 1e-3, kMaxSectionWidth)) << "\n";
  }
}

void Script::write_material(std::ostringstream& toml, const Snapshot& s, const std::string& sfx, const char* side,
                            bool transmitted) const {
  const bool front = side[0] == 'f';
  toml << "\n[surface.material." << side << "]\ncolour = "
       << toml_vector(colour(s, (front ? "surface" : "inside") + sfx + "_")) << "\n";
  toml << "ambient = " << toml_number(percent(s, "ambient" + sfx)) << "\n";
  toml << "diffuse = " << toml_number(percent(s, "diffuse" + sfx)) << "\n";
  toml << "specular = " << toml_number(percent(s, "reflected" + sfx)) << "\n";
  const double smooth = number(s, "smoothness" + sfx);
  if (smooth < 0) fail(set_at(s, "smoothness" + sfx), "smoothness" + sfx + " must not be negative");
  toml << "exponent = " << toml_number(std::clamp(smooth, 1.0, 10000.0)) << "\n";
  toml << "transparency = " << toml_number(transmitted ? percent(s, "transparence" + sfx) : 0.0) << "\n";
}

// Read and checked in this order, which decides what a script with several mistakes is told first.
Script::View Script::view(const Snapshot& s) const {
  View v;
  v.centre = glm::dvec3(number(s, "center_x"), number(s, "center_y"), number(s, "center_z"));
  v.radius = number(s, "radius");
  if (!(v.radius > 0)) fail(set_at(s, "radius"), "radius must be positive");
  v.clip = number(s, "clip");
  v.width = number(s, "width");
  v.height = number(s, "height");
  if (v.width < 1 || v.width > 32768) fail(set_at(s, "width"), "width must be between 1 and 32768");
  if (v.height < 1 || v.height > 32768) fail(set_at(s, "height"), "height must be between 1 and 32768");
  // The framing follows the size the image is rendered at, which --set or --width may change.
  const double fw = rendered_width_ > 0 ? rendered_width_ : v.width;
  const double fh = rendered_height_ > 0 ? rendered_height_ : v.height;
  v.rendered_width = fw;
  v.rendered_height = fh;
  v.half_w = 10 * fw / std::min(fw, fh);
  v.half_h = 10 * fh / std::min(fw, fh);
  v.central = number(s, "perspective") != 0;
  v.spec_z = number(s, "spec_z");
  if (v.central && !(v.spec_z > 0)) fail(set_at(s, "spec_z"), "spec_z must be positive");
  return v;
}

void Script::write_extent(std::ostringstream& toml, const Snapshot& s, const View& v) const {
  if (v.clip == 5) {
    const double front = number(s, "clip_front"), back = number(s, "clip_back");
    if (!(front > back)) fail(set_at(s, "clip_front"), "clip_front must be above clip_back");
    if (v.central && front >= v.spec_z)
      fail(set_at(s, "clip_front"), "clip_front must be below spec_z, where the eye is");
    // Wide enough for the whole view: the frustum widens towards the back.
    const double widen = v.central ? (v.spec_z - back) / v.spec_z : 1.0;
    toml << "\n[extent]  # clip = none: the slab clip_back <= z <= clip_front\ntype = \"box\"\nmin = "
         << toml_vector({-v.half_w * widen * 1.01, -v.half_h * widen * 1.01, back})
         << "\nmax = " << toml_vector({v.half_w * widen * 1.01, v.half_h * widen * 1.01, front}) << "\n";
  } else if (v.clip == 4) {
    toml << "\n[extent]  # clip = cube\ntype = \"box\"\nmin = " << toml_vector(v.centre - glm::dvec3(v.radius))
         << "\nmax = " << toml_vector(v.centre + glm::dvec3(v.radius)) << "\n";
  } else {
    toml << "\n[extent]  # surf's clip ball\ntype = \"sphere\"\ncentre = " << toml_vector(v.centre)
         << "\nradius = " << toml_number(v.radius) << "\n";
  }
}

void Script::write_camera_and_image(std::ostringstream& toml, const Snapshot& s, const View& v) const {
  toml << "\n[camera]\neye = " << toml_vector({0, 0, v.central ? v.spec_z : 1000.0})
       << "\nlook_at = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\n";
  if (v.central)
    toml << "projection = \"perspective\"\nfov_y = "
         << toml_number(2 * std::atan(v.half_h / v.spec_z) * 180 / 3.14159265358979323846) << "\n";
  else
    toml << "projection = \"orthographic\"\nheight = " << toml_number(2 * v.half_h) << "\n";

  const glm::dvec3 background = colour(s, "background_");
  toml << "\n[image]\nwidth = " << static_cast<long>(v.width) << "\nheight = " << static_cast<long>(v.height)
       << "\nbackground = " << toml_vector(background) << "\n";
  const double aa = number(s, "antialiasing");
  if (aa < 1 || aa > 16) fail(set_at(s, "antialiasing"), "antialiasing must be between 1 and 16");
  const double threshold = number(s, "antialiasing_threshold");
  toml << "\n[antialias]\nsamples = " << static_cast<long>(aa) << "\nadaptive = " << (aa > 1 ? "true" : "false")
       << "\nthreshold = " << toml_number(std::clamp(threshold, 0.0, 1.0)) << "\n";
}

// Lights in screen space, without shadows (surf casts none). With none on, surf shows the ambient term alone:
// a light of no intensity keeps algray from adding its headlight.
void Script::write_lights(std::ostringstream& toml, const Snapshot& s) const {
  int lights = 0;
  for (int n = 1; n <= kLights; ++n) {
    const std::string l = "light" + std::to_string(n) + "_";
    const double vol = percent(s, l + "vol");
    if (vol == 0) continue;
    ++lights;
    toml << "\n[[light]]  # light" << n << "\ntype = \"point\"\nposition = "
         << toml_vector({number(s, l + "x"), number(s, l + "y"), number(s, l + "z")})
         << "\ncolour = " << toml_vector(colour(s, l)) << "\nintensity = " << toml_number(vol)
         << "\nshadows = false\n";
  }
  if (lights == 0)
    toml << "\n[[light]]  # no light is on in the script\ntype = \"point\"\nposition = [0.0, 0.0, 100.0]\n"
            "intensity = 0.0\nshadows = false\n";
}

std::string Script::translate(const Snapshot& s) {
  std::ostringstream toml;
  toml << "# Translated from " << source_ << " (surf script)\n";
  const Affine inverse = screen_to_script(s);
  std::array<int, kSurfaces + 1> index_of{};
  write_surfaces(toml, s, inverse, index_of);
  const View v = view(s);
  write_extent(toml, s, v);
  write_camera_and_image(toml, s, v);
  write_lights(toml, s);
  write_sections(toml, s, inverse, index_of, v);
  return toml.str();
}

SurfTranslation Script::run(int width, int height) {
  rendered_width_ = width;
  rendered_height_ = height;
  // A label is known once its statement has run: surf's goto jumps back only.
  while (peek().kind != SurfToken::End) statement();
  if (!last_drawn_) {
    if (curve_at_) fail(*curve_at_, "this script draws plane curves only; algray draws surfaces (draw_surface)");
    fail(peek(), "the script never draws a surface (no draw_surface)");
  }
  const Snapshot& snapshot = first_saved_ ? *first_saved_ : *last_drawn_;
  const long images = std::max(saves_, draws_);
  if (images > 1)
    warn(snapshot.at, "the script draws " + std::to_string(images) + " pictures; algray renders this one, " +
                          (first_saved_ ? "the first it saves" : "the last it draws"));
  return {translate(snapshot), where(snapshot.at), excerpt(snapshot.at)};
}

}  // namespace

SurfTranslation surf_script_to_toml(const std::string& text, const std::string& source,
                                    std::vector<std::string>& warnings, int width, int height) {
  return Script(text, source, warnings).run(width, height);
}

}  // namespace algray
