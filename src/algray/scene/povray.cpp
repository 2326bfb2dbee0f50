// The POV-Ray scene reader: a tokenizer and parser for the part of POV-Ray's scene language that describes
// algebraic surfaces and how they are seen, and the algray scene made from it.
//
// Facts about POV-Ray 3.7 (Debian's povray) this file relies on, checked by rendering with it (bench/pov_compare.py):
// - The world is left-handed: x right, y up, z into the screen, for the default camera. A camera whose right, up
//   and direction form a right-handed set (right = -x, say) shows the mirror image. algray's world is
//   right-handed, so a left-handed scene is read with z negated, which shows the same picture.
// - rotate <a, b, c> turns about x by a, then y by b, then z by c degrees, each by the usual rotation matrix of
//   the numbers (in the left-handed world that is clockwise seen from the axis' tip). matrix <m00, m01, m02, m10,
//   ..., m32> maps a point p to p.x*row0 + p.y*row1 + p.z*row2 + row3.
// - poly { n, <a...> } lists the coefficients of x^i y^j z^k for i from n down to 0, j from n - i down to 0, k from
//   n - i - j down to 0; quartic and cubic are poly 4 and 3; polynomial lists xyz(i, j, k): a terms. Inside is
//   P < 0. torus { R, r } lies around the y axis.
// - The camera: direction <0, 0, 1>, right <1.33, 0, 0>, up and sky <0, 1, 0> by default; angle is the horizontal
//   field of view and sets direction's length to |right| / 2 / tan(angle / 2). The view spans |right| across and
//   |up| down at distance |direction|, whatever the image's size. Without look_at the rays are direction + u right
//   + v up (u, v from -1/2 to 1/2) as written: a direction not normal to right and up (the trough and witch
//   samples' <0, 0.1, 1.5>) is an off-axis view, its image plane still spanned by right and up; look_at makes the
//   three normal to each other.
// - bounded_by alone is no clip: a ray that misses the bound skips the object, one that meets it sees all of the
//   surface along it, inside the bound or not (the hyptorus sample shows its arms beyond its bounding sphere, cut
//   off only along the sphere's outline). That is algray's extent gate (extent.gate), whose far sphere (reach) is
//   set to hold what rays traced here see through the bound (gate_reach). An object with no region at all gets a
//   sphere about what the camera sees.
// - plane { n, d } is the half-space n.x <= d, the side away from n (POV-Ray's documentation: the normal points
//   outside); clipped_by { plane { ... } } keeps the object's part in it. algray cuts every surface of a scene by
//   the same clipping planes ([[clip]]), so an object's planes cut the others too, with a warning.
// - #include "name.inc" reads the file in place; POV-Ray's own includes (colors.inc, shapesq.inc, ...) declare
//   colours, objects and macros with #declare, #macro and #ifndef guards.
//
// Where #include looks, in order: the scene's own directory (when the scene is a file), each directory of the
// ALGRAY_POV_INCLUDE environment variable (':'-separated, like povray's +L), then POV-Ray's include directory
// (/usr/share/povray-3.7/include, Debian's povray-includes). Only names ending in .inc, relative and without '..',
// are looked up, at most kMaxIncludeDepth deep and kMaxIncludes files in all: a scene cannot read other files or
// include itself forever. Inside included files, declarations the reader cannot use (textures, macros, other
// objects) are skipped silently; using one of their names is a located error naming where it was declared.
#include "algray/scene/povray.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <glm/glm.hpp>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>

#include "algray/scene/camera.h"
#include "algray/scene/located_text.h"
#include "algray/scene/ray_roots.h"
#include "algray/scene/scene.h"
#include "algray/scene/sparse_poly.h"
#include "algray/scene/toml_reader.h"

namespace algray {
namespace {

constexpr int kMaxIncludeDepth = 16;         // POV-Ray's own includes nest 3 deep
constexpr int kMaxIncludes = 256;            // files read in all, repeats counted
constexpr std::size_t kMaxTokens = 1 << 22;  // tokens of all files together

struct PovToken {
  enum Kind { Name, Number, String, Directive, Op, End } kind = End;
  std::string text;
  double number = 0;
  int line = 1, column = 1;
  int file = 0;  // index into the reader's files: 0 the scene, then each #include as read
};

using Vec = std::vector<double>;  // a float is one component

struct Clip {
  bool sphere = true;
  glm::dvec3 centre{0}, min{0}, max{0};
  double radius = 0;
  bool bound = false;  // from bounded_by alone: POV-Ray's hint, not a clip (see the top of the file)
};

struct Object {
  SparsePoly poly;          // in the object's own coordinates
  glm::dmat4 transform{1};  // object to world (POV-Ray's coordinates)
  std::vector<std::pair<Clip, glm::dmat4>> clips;  // each with its own object-to-world transform
  // clipped_by { plane { n, d } }: (n, -d), whose n.x - d <= 0 is kept (POV-Ray's inside), in the plane's own
  // coordinates, with its object-to-world transform.
  std::vector<std::pair<glm::dvec4, glm::dmat4>> planes;
  std::optional<Clip> natural;                     // the bound of a sphere or torus, in object coordinates
  std::optional<glm::dvec3> front, back;
  bool inverse = false;
  double ambient = 0.1, diffuse = 0.6, specular = 0, exponent = 40;  // POV-Ray's default finish
  bool finished = false;  // a finish was given
  PovToken at;
  std::string kind;
};

struct Camera {
  bool orthographic = false;
  glm::dvec3 location{0, 0, 0}, direction{0, 0, 1}, right{1.33, 0, 0}, up{0, 1, 0}, sky{0, 1, 0};
  std::optional<glm::dvec3> look_at;
  std::optional<double> angle;
};

struct PovLight {
  glm::dvec3 position{0}, colour{1}, edge_u{0}, edge_v{0};
  int samples = 1;
  bool area = false, shadows = true;
};

class PovReader {
 public:
  PovReader(const std::string& text, std::string source, std::vector<std::string>& warnings, int width, int height)
      : warnings_(warnings), width_(width), height_(height) {
    const std::filesystem::path dir = std::filesystem::path(source).parent_path();
    if (!dir.empty()) include_dirs_.push_back(dir);
    if (const char* extra = std::getenv("ALGRAY_POV_INCLUDE")) {
      std::string list = extra;
      for (std::size_t start = 0; start <= list.size();) {
        const std::size_t end = std::min(list.find(':', start), list.size());
        if (end > start) include_dirs_.emplace_back(list.substr(start, end - start));
        start = end + 1;
      }
    }
    include_dirs_.emplace_back("/usr/share/povray-3.7/include");
    files_.push_back({std::make_unique<LocatedText>(text, std::move(source)), 0});
    tokens_ = tokenize(text, 0);
  }

  PovTranslation run();

 private:
  // --- messages ---
  const LocatedText& text_of(const PovToken& t) const { return *files_[static_cast<std::size_t>(t.file)].text; }
  std::string where(const PovToken& t) const { return text_of(t).where(t.line, t.column); }
  std::string excerpt(const PovToken& t) const { return text_of(t).excerpt(t.line, t.column); }
  [[noreturn]] void fail(const PovToken& t, const std::string& message) const {
    text_of(t).fail(t.line, t.column, message);
  }
  void warn(const PovToken& t, const std::string& message) {
    if (!quiet_) warnings_.push_back(where(t) + ": " + message);
  }

  // --- tokens ---
  std::vector<PovToken> tokenize(const std::string& text, int file) {
    std::vector<PovToken> tokens;
    TextCursor cursor(text);
    std::size_t& i = cursor.i;
    const int &line = cursor.line, &column = cursor.column;
    auto advance = [&](std::size_t n) { cursor.advance(n); };
    while (i < text.size()) {
      const char c = text[i];
      if (std::isspace(static_cast<unsigned char>(c))) {
        advance(1);
        continue;
      }
      PovToken t{PovToken::Op, "", 0, line, column, file};
      if (const int comment = cursor.skip_comment()) {
        if (comment < 0) fail(t, "this comment never ends (no */)");
        continue;
      }
      if (std::isalpha(static_cast<unsigned char>(c)) || c == '_' || (c == '#' && i + 1 < text.size())) {
        std::size_t start = i + (c == '#' ? 1 : 0);
        while (c == '#' && start < text.size() && (text[start] == ' ' || text[start] == '\t')) ++start;  // "#  debug"
        std::size_t j = start;
        while (j < text.size() && (std::isalnum(static_cast<unsigned char>(text[j])) || text[j] == '_')) ++j;
        t.kind = c == '#' ? PovToken::Directive : PovToken::Name;
        t.text = text.substr(start, j - start);
        if (c == '#' && t.text.empty()) fail(t, "expected a directive after '#'");
        advance(j - i);
      } else if (std::isdigit(static_cast<unsigned char>(c)) ||
                 (c == '.' && i + 1 < text.size() && std::isdigit(static_cast<unsigned char>(text[i + 1])))) {
        bool real = false;
        const std::size_t j = cursor.number_end(&real);
        t.kind = PovToken::Number;
        t.text = text.substr(i, j - i);
        std::istringstream in(t.text);
        in.imbue(std::locale::classic());
        in >> t.number;
        if (in.fail() || !std::isfinite(t.number)) fail(t, "the number " + t.text + " is too large");
        advance(j - i);
      } else if (c == '"') {
        std::size_t j = i + 1;
        while (j < text.size() && text[j] != '"' && text[j] != '\n') j += text[j] == '\\' && j + 1 < text.size() ? 2 : 1;
        if (j >= text.size() || text[j] != '"') fail(t, "this string never ends (no closing \")");
        t.kind = PovToken::String;
        t.text = text.substr(i + 1, j - i - 1);
        advance(j + 1 - i);
      } else {
        // ! & | ? are POV-Ray's logic operators, met in its include files; this reader evaluates none of them.
        if (std::string("{}<>,()+-*/:;.=[]!&|?").find(c) == std::string::npos) {
          const unsigned char u = static_cast<unsigned char>(c);
          fail(t, u >= 0x20 && u < 0x7f ? std::string("unexpected character '") + c + "'"
                                         : "unexpected byte " + std::to_string(u) +
                                               " (outside strings, scenes are ASCII)");
        }
        t.text = std::string(1, c);
        advance(1);
      }
      tokens.push_back(t);
      if (tokens.size() > kMaxTokens) fail(t, "more than " + std::to_string(kMaxTokens) + " tokens");
    }
    tokens.push_back({PovToken::End, "", 0, line, column, file});
    return tokens;
  }

  const PovToken& peek(std::size_t ahead = 0) const { return tokens_[std::min(pos_ + ahead, tokens_.size() - 1)]; }
  bool at_op(const char* op, std::size_t ahead = 0) const {
    return peek(ahead).kind == PovToken::Op && peek(ahead).text == op;
  }
  bool at_name(const char* name) const { return peek().kind == PovToken::Name && peek().text == name; }
  const PovToken& next() {
    const PovToken& t = tokens_[pos_];
    if (pos_ + 1 < tokens_.size()) ++pos_;
    return t;
  }
  static std::string describe(const PovToken& t) {
    switch (t.kind) {
      case PovToken::End:
        return "the end of the file";
      case PovToken::String:
        return "a string";
      case PovToken::Directive:
        return "'#" + t.text + "'";
      default:
        return "'" + t.text + "'";
    }
  }
  void expect(const char* op, const char* what) {
    if (!at_op(op)) fail(peek(), std::string("expected ") + what + ", found " + describe(peek()));
    next();
  }
  void optional_comma() {
    if (at_op(",")) next();
  }
  // Skips a { ... } block, the opening brace next.
  void skip_block() {
    const PovToken open = peek();
    expect("{", "'{'");
    int depth = 1;
    while (depth > 0) {
      const PovToken& t = next();
      if (t.kind == PovToken::End) fail(open, "this '{' is never closed");
      if (t.kind == PovToken::Op && t.text == "{") ++depth;
      if (t.kind == PovToken::Op && t.text == "}") --depth;
    }
  }
  // Skips what follows an item this reader does not read: its block, or its values up to the next word or '}'.
  void skip_item() {
    if (at_op("{")) return skip_block();
    while (peek().kind != PovToken::End && !at_op("}") && peek().kind != PovToken::Name && peek().kind != PovToken::Directive) {
      if (at_op("{")) {
        skip_block();
        continue;
      }
      next();
    }
  }

  // --- expressions: floats and vectors ---
  Vec expression(int depth = 0) {
    if (depth > 200) fail(peek(), "the expression is nested too deeply");
    Vec left = term(depth);
    while (at_op("+") || at_op("-")) {
      const PovToken op = next();
      left = combine(left, term(depth), op);
    }
    return left;
  }
  Vec term(int depth) {
    Vec left = unary(depth);
    while (at_op("*") || at_op("/")) {
      const PovToken op = next();
      left = combine(left, unary(depth), op);
    }
    return left;
  }
  Vec unary(int depth) {
    if (depth > 200) fail(peek(), "the expression is nested too deeply");
    if (at_op("-")) {
      next();
      Vec v = unary(depth + 1);
      for (double& c : v) c = -c;
      return v;
    }
    if (at_op("+")) {
      next();
      return unary(depth + 1);
    }
    return postfix(primary(depth), depth);
  }
  Vec postfix(Vec v, int depth) {
    (void)depth;
    while (at_op(".")) {
      const PovToken dot = next();
      const PovToken member = next();
      static const std::map<std::string, std::size_t> members = {{"x", 0},     {"u", 0},     {"red", 0},
                                                                 {"y", 1},     {"v", 1},     {"green", 1},
                                                                 {"z", 2},     {"blue", 2},  {"filter", 3},
                                                                 {"t", 3},     {"transmit", 4}};
      const auto m = members.find(member.text);
      if (m == members.end()) fail(member, "expected x, y, z, red, green, blue, filter or transmit after '.'");
      const Vec w = widen(v, std::max<std::size_t>(3, m->second + 1), dot);
      v = {w[m->second]};
    }
    return v;
  }
  Vec combine(const Vec& a, const Vec& b, const PovToken& op) {
    const std::size_t n = std::max(a.size(), b.size());
    const Vec x = widen(a, n, op), y = widen(b, n, op);
    Vec out(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (op.text == "+") out[i] = x[i] + y[i];
      if (op.text == "-") out[i] = x[i] - y[i];
      if (op.text == "*") out[i] = x[i] * y[i];
      if (op.text == "/") {
        if (y[i] == 0) fail(op, "division by zero");
        out[i] = x[i] / y[i];
      }
      if (!std::isfinite(out[i])) fail(op, "this gives an infinity");
    }
    return out;
  }
  // A float stands for the vector of that float in every component, as in POV-Ray.
  Vec widen(const Vec& v, std::size_t n, const PovToken& at) const {
    if (v.size() == n) return v;
    if (v.size() == 1) return Vec(n, v[0]);
    if (v.size() < n) {
      Vec out = v;
      out.resize(n, 0);
      return out;
    }
    fail(at, "expected " + std::to_string(n) + " components, found a vector of " + std::to_string(v.size()));
  }
  Vec primary(int depth) {
    const PovToken t = next();
    if (t.kind == PovToken::Number) return {t.number};
    if (t.kind == PovToken::Op && t.text == "(") {
      Vec v = expression(depth + 1);
      expect(")", "')'");
      return v;
    }
    if (t.kind == PovToken::Op && t.text == "<") {
      Vec v;
      for (;;) {
        const Vec c = expression(depth + 1);
        if (c.size() != 1) fail(t, "a vector's components are floats");
        v.push_back(c[0]);
        if (v.size() > 8192) fail(t, "a vector of more than 8192 components");  // poly 32 has 6545
        if (at_op(",")) {
          next();
          continue;
        }
        if (peek().kind == PovToken::Number) continue;  // POV-Ray reads <1 2> as <1, 2>; its samples rely on it
        break;
      }
      expect(">", "'>' or ','");
      return v;
    }
    if (t.kind != PovToken::Name) fail(t, "expected a number or vector, found " + describe(t));
    if (at_op("(")) return call(t, depth);
    static const std::map<std::string, Vec> constants = {
        {"x", {1, 0, 0}}, {"y", {0, 1, 0}}, {"z", {0, 0, 1}}, {"u", {1, 0}},   {"v", {0, 1}},  {"t", {0, 0, 0, 1}},
        {"pi", {std::numbers::pi}},    {"clock", {0}},   {"true", {1}},    {"yes", {1}},    {"on", {1}},    {"false", {0}},
        {"no", {0}},      {"off", {0}},     {"clock_delta", {1}}, {"frame_number", {0}}, {"version", {3.7}}};
    if (const auto c = constants.find(t.text); c != constants.end()) return c->second;
    if (t.text == "image_width") return {static_cast<double>(image_width())};
    if (t.text == "image_height") return {static_cast<double>(image_height())};
    if (const auto d = declared_.find(t.text); d != declared_.end()) return d->second;
    unusable(t);
  }
  // A name that is no float or vector here: declared as something else, or not at all.
  [[noreturn]] void unusable(const PovToken& t) const {
    if (const auto u = unread_.find(t.text); u != unread_.end())
      fail(t, "'" + t.text + "' is " + u->second.second + " (declared at " + where(u->second.first) +
                  "), which this reader does not read");
    if (declared_objects_.count(t.text)) fail(t, "'" + t.text + "' is an object: use it as object { " + t.text + " }");
    fail(t, "'" + t.text + "' is not declared" +
                (missing_include_ ? " (an #include file was not found, so its names are unknown here)" : ""));
  }
  Vec call(const PovToken& name, int depth) {
    if (unread_.count(name.text)) unusable(name);  // a macro from an include, say
    expect("(", "'('");
    std::vector<Vec> args;
    if (!at_op(")"))
      for (;;) {
        args.push_back(expression(depth + 1));
        if (!at_op(",")) break;
        next();
      }
    expect(")", "')' or ','");
    const std::string& f = name.text;
    auto scalar = [&](std::size_t i) {
      if (args[i].size() != 1) fail(name, f + " takes floats");
      return args[i][0];
    };
    auto want = [&](std::size_t n) {
      if (args.size() != n) fail(name, f + " takes " + std::to_string(n) + " argument" + (n == 1 ? "" : "s"));
    };
    auto result = [&](double v) -> Vec {
      if (!std::isfinite(v)) fail(name, f + " gives no finite number here");
      return {v};
    };
    static const std::map<std::string, double (*)(double)> one = {
        {"sqrt", [](double v) { return std::sqrt(v); }},     {"sin", [](double v) { return std::sin(v); }},
        {"cos", [](double v) { return std::cos(v); }},       {"tan", [](double v) { return std::tan(v); }},
        {"asin", [](double v) { return std::asin(v); }},     {"acos", [](double v) { return std::acos(v); }},
        {"atan", [](double v) { return std::atan(v); }},     {"abs", [](double v) { return std::fabs(v); }},
        {"exp", [](double v) { return std::exp(v); }},       {"log", [](double v) { return std::log10(v); }},
        {"ln", [](double v) { return std::log(v); }},        {"floor", [](double v) { return std::floor(v); }},
        {"ceil", [](double v) { return std::ceil(v); }},     {"int", [](double v) { return std::trunc(v); }},
        {"radians", [](double v) { return v * std::numbers::pi / 180; }}, {"degrees", [](double v) { return v * 180 / std::numbers::pi; }}};
    if (const auto g = one.find(f); g != one.end()) {
      want(1);
      return result(g->second(scalar(0)));
    }
    if (f == "pow" || f == "atan2" || f == "mod") {
      want(2);
      const double a = scalar(0), b = scalar(1);
      return result(f == "pow" ? std::pow(a, b) : f == "atan2" ? std::atan2(a, b) : std::fmod(a, b));
    }
    if (f == "min" || f == "max") {
      if (args.empty()) fail(name, f + " takes at least one float");
      double v = scalar(0);
      for (std::size_t i = 1; i < args.size(); ++i) v = f == "min" ? std::min(v, scalar(i)) : std::max(v, scalar(i));
      return {v};
    }
    if (f == "vlength") {
      want(1);
      double s = 0;
      for (double c : args[0]) s += c * c;
      return result(std::sqrt(s));
    }
    if (f == "vnormalize") {
      want(1);
      double s = 0;
      for (double c : args[0]) s += c * c;
      if (s == 0) fail(name, "vnormalize of a zero vector");
      Vec v = args[0];
      for (double& c : v) c /= std::sqrt(s);
      return v;
    }
    fail(name, "'" + f + "' is not a function this reader knows");
  }
  double number() {
    const PovToken at = peek();
    const Vec v = expression();
    if (v.size() != 1) fail(at, "expected a float, found a vector");
    return v[0];
  }
  glm::dvec3 vector3() {
    const PovToken at = peek();
    const Vec v = widen(expression(), 3, at);
    if (v.size() != 3) fail(at, "expected a vector of 3 components");
    return {v[0], v[1], v[2]};
  }

  int image_width() const {
    return width_ > 0 ? width_ : 800;
  }
  int image_height() const {
    return height_ > 0 ? height_ : 600;
  }

  // --- colours ---
  glm::dvec3 colour(const PovToken& at) {
    if (at_name("color") || at_name("colour")) next();
    static const std::map<std::string, std::size_t> forms = {{"rgb", 3}, {"rgbf", 4}, {"rgbt", 4}, {"rgbft", 5},
                                                              {"srgb", 3}, {"srgbf", 4}, {"srgbt", 4}, {"srgbft", 5}};
    glm::dvec3 c(0);
    bool any = false;
    for (;;) {
      const PovToken& t = peek();
      if (t.kind == PovToken::Name && forms.count(t.text)) {
        const PovToken form = next();
        const PovToken vat = peek();
        const Vec v = widen(expression(), forms.at(form.text), vat);
        if (v.size() > 3 && (v[3] != 0 || (v.size() > 4 && v[4] != 0)))
          warn(form, "the colour's filter and transmit are ignored: algray's surfaces are opaque here");
        c = {v[0], v[1], v[2]};
        if (form.text[0] == 's')
          for (int i = 0; i < 3; ++i) c[i] = c[i] <= 0.04045 ? c[i] / 12.92 : std::pow((c[i] + 0.055) / 1.055, 2.4);
        any = true;
        continue;
      }
      if (t.kind == PovToken::Name && (t.text == "red" || t.text == "green" || t.text == "blue")) {
        const std::string channel = next().text;
        c[channel == "red" ? 0 : channel == "green" ? 1 : 2] = number();
        any = true;
        continue;
      }
      if (t.kind == PovToken::Name && (t.text == "filter" || t.text == "transmit")) {
        next();
        if (number() != 0) warn(t, "the colour's " + t.text + " is ignored: algray's surfaces are opaque here");
        continue;
      }
      break;
    }
    if (!any) {
      const PovToken vat = peek();
      const Vec v = widen(expression(), 3, vat);
      c = {v[0], v[1], v[2]};
    }
    for (int i = 0; i < 3; ++i)
      if (!(c[i] >= 0) || !std::isfinite(c[i])) fail(at, "colour components must not be negative");
    return c;
  }
  // pigment { colour }: a pattern or map is skipped with a warning.
  glm::dvec3 pigment(const PovToken& at) {
    expect("{", "'{' after pigment");
    glm::dvec3 c(0);
    bool coloured = false;
    while (!at_op("}")) {
      if (peek().kind == PovToken::End) fail(at, "this pigment is never closed");
      const PovToken& t = peek();
      if (t.kind == PovToken::Name && (t.text == "color" || t.text == "colour" || t.text == "rgb" || t.text == "rgbf" ||
                                    t.text == "rgbt" || t.text == "rgbft" || t.text == "srgb" || t.text == "red" ||
                                    t.text == "green" || t.text == "blue")) {
        c = colour(t);
        coloured = true;
      } else if (!coloured && (t.kind == PovToken::Op || declared_.count(t.text))) {
        c = colour(t);
        coloured = true;
      } else {
        const PovToken skipped = next();
        warn(skipped, "pigment '" + skipped.text + "' is ignored: algray reads plain colours");
        skip_item();
      }
    }
    next();
    return c;
  }
  void finish(Object& o) {
    o.finished = true;
    const PovToken open = peek();
    expect("{", "'{' after finish");
    while (!at_op("}")) {
      if (peek().kind == PovToken::End) fail(open, "this finish is never closed");
      const PovToken t = next();
      if (t.kind == PovToken::Name && t.text == "ambient") {
        const Vec v = expression();
        o.ambient = std::clamp(v.size() == 1 ? v[0] : (v[0] + v[1] + v[2]) / 3, 0.0, 1.0);
      } else if (t.kind == PovToken::Name && t.text == "diffuse") {
        o.diffuse = std::clamp(number(), 0.0, 1.0);
      } else if (t.kind == PovToken::Name && t.text == "phong") {
        o.specular = std::clamp(number(), 0.0, 1.0);
      } else if (t.kind == PovToken::Name && t.text == "phong_size") {
        o.exponent = std::clamp(number(), 1.0, 10000.0);
      } else {
        warn(t, "finish '" + t.text + "' is ignored (algray reads ambient, diffuse, phong and phong_size)");
        skip_item();
      }
    }
    next();
  }
  static void take_finish(Object& o, const Object& from) {
    o.ambient = from.ambient;
    o.diffuse = from.diffuse;
    o.specular = from.specular;
    o.exponent = from.exponent;
    o.finished = true;
  }
  // texture { pigment {...} finish {...} ... }; interior_texture likewise for the inside (its finish is skipped).
  void texture(Object& o, bool inside) {
    const PovToken open = peek();
    expect("{", "'{' after texture");
    while (!at_op("}")) {
      if (peek().kind == PovToken::End) fail(open, "this texture is never closed");
      const PovToken t = next();
      if (t.kind == PovToken::Name && t.text == "pigment") {
        (inside ? o.back : o.front) = pigment(t);
      } else if (t.kind == PovToken::Name && t.text == "finish" && !inside) {
        finish(o);
      } else {
        warn(t, "texture '" + t.text + "' is ignored (algray reads a texture's pigment colour and finish)");
        skip_item();
      }
    }
    next();
  }

  // --- transforms ---
  static glm::dmat4 rotation(const glm::dvec3& degrees) {
    glm::dmat4 m(1);
    for (int axis = 0; axis < 3; ++axis) {
      const double a = degrees[axis] * std::numbers::pi / 180, c = std::cos(a), s = std::sin(a);
      const int i = (axis + 1) % 3, j = (axis + 2) % 3;
      glm::dmat4 r(1);
      r[i][i] = c;  // glm: [column][row]; the usual matrix's (i, j) entry -s is column j, row i
      r[j][i] = -s;
      r[i][j] = s;
      r[j][j] = c;
      m = r * m;
    }
    return m;
  }
  // A transform statement at the cursor, or nullopt when the next word is none.
  std::optional<glm::dmat4> transform_step() {
    if (peek().kind != PovToken::Name) return std::nullopt;
    const std::string w = peek().text;
    if (w == "scale") {
      const PovToken at = next();
      const glm::dvec3 s = vector3();
      if (s.x == 0 || s.y == 0 || s.z == 0) fail(at, "scale by zero");
      glm::dmat4 m(1);
      m[0][0] = s.x;
      m[1][1] = s.y;
      m[2][2] = s.z;
      return m;
    }
    if (w == "rotate") {
      next();
      return rotation(vector3());
    }
    if (w == "translate") {
      next();
      glm::dmat4 m(1);
      m[3] = glm::dvec4(vector3(), 1);
      return m;
    }
    if (w == "matrix") {
      const PovToken at = next();
      const PovToken vat = peek();
      const Vec v = expression();
      if (v.size() != 12) fail(vat, "matrix takes 12 numbers, found " + std::to_string(v.size()));
      glm::dmat4 m(1);
      for (int row = 0; row < 4; ++row)
        for (int col = 0; col < 3; ++col) m[row][col] = v[static_cast<std::size_t>(row * 3 + col)];
      if (std::fabs(glm::determinant(m)) < 1e-300) fail(at, "this matrix is singular");
      return m;
    }
    return std::nullopt;
  }

  // --- objects ---
  // plane { <n>, d modifiers } in clipped_by, the keyword next: (n, -d), n.x - d <= 0 kept (POV-Ray's inside, the
  // side away from n; inverse keeps the other), and its own transforms in `own`.
  glm::dvec4 clip_plane(glm::dmat4& own) {
    const PovToken shape = next();
    expect("{", "'{'");
    const PovToken at = peek();
    const glm::dvec3 n = vector3();
    optional_comma();
    const double d = number();
    if (glm::length(n) == 0) fail(at, "the plane's normal is zero");
    glm::dvec4 plane(n, -d);
    while (!at_op("}")) {
      if (auto m = transform_step()) {
        own = *m * own;
        continue;
      }
      const PovToken t = next();
      if (t.kind == PovToken::End) fail(shape, "this plane is never closed");
      if (t.text == "inverse") {
        plane = -plane;
        continue;
      }
      warn(t, "'" + t.text + "' in a clipping plane is ignored");
      skip_item();
    }
    next();
    return plane;
  }
  Clip clip_shape(const PovToken& at, glm::dmat4& own) {
    const PovToken shape = next();
    if (shape.kind != PovToken::Name || (shape.text != "sphere" && shape.text != "box" && shape.text != "object"))
      fail(shape, std::string(at.text) + " takes a sphere or a box here; algray clips to one of those");
    expect("{", "'{'");
    Clip c;
    if (shape.text == "object") {  // object { NAME ... } of a declared box or sphere
      const PovToken name = next();
      const auto d = declared_clips_.find(name.text);
      if (d == declared_clips_.end()) {
        if (name.kind == PovToken::Name && !declared_objects_.count(name.text)) unusable(name);
        fail(name, std::string(at.text) + " takes a sphere or a box here; algray clips to one of those");
      }
      c = d->second.first;
      own = d->second.second;
    } else if (shape.text == "sphere") {
      c.centre = vector3();
      optional_comma();
      c.radius = number();
      if (!(c.radius > 0)) fail(shape, "the sphere's radius must be positive");
    } else {
      c.sphere = false;
      const glm::dvec3 a = vector3();
      optional_comma();
      const glm::dvec3 b = vector3();
      c.min = glm::min(a, b);
      c.max = glm::max(a, b);
      if (!(c.min.x < c.max.x && c.min.y < c.max.y && c.min.z < c.max.z)) fail(shape, "the box has no volume");
    }
    while (!at_op("}")) {
      if (auto m = transform_step()) {
        own = *m * own;
        continue;
      }
      const PovToken t = next();
      if (t.kind == PovToken::End) fail(shape, "this " + shape.text + " is never closed");
      warn(t, "'" + t.text + "' in a clipping shape is ignored");
      skip_item();
    }
    next();
    return c;
  }
  void clip_block(Object& o, const PovToken& at) {
    expect("{", "'{'");
    // bounded_by { clipped_by } and clipped_by { bounded_by }: the same region, already recorded.
    if ((at.text == "bounded_by" && at_name("clipped_by")) || (at.text == "clipped_by" && at_name("bounded_by"))) {
      if (o.clips.empty() && o.planes.empty())
        fail(peek(), peek().text + " names no region yet: give the other one first");
      next();
      for (auto& [c, t] : o.clips) c.bound = false;  // clipped_by { bounded_by }: the bound clips too
    } else {
      while (!at_op("}")) {
        glm::dmat4 own(1);
        if (at_name("plane") && at_op("{", 1)) {
          // A plane clips (clipped_by); as a bound it is POV-Ray's hint, which algray has no use for.
          const PovToken plane = peek();
          const glm::dvec4 p = clip_plane(own);
          if (at.text == "clipped_by")
            o.planes.push_back({p, own});
          else
            warn(plane, "bounded_by { plane } is ignored: a bound is POV-Ray's hint, not a clip");
          continue;
        }
        Clip c = clip_shape(at, own);
        c.bound = at.text == "bounded_by";
        o.clips.push_back({c, own});
      }
    }
    expect("}", "'}'");
  }
  void modifiers(std::vector<Object*> objects, const PovToken& open) {
    while (!at_op("}")) {
      if (peek().kind == PovToken::End) fail(open, "this '{' is never closed");
      if (auto m = transform_step()) {
        for (Object* o : objects) {
          o->transform = *m * o->transform;
          for (auto& [clip, t] : o->clips) t = *m * t;
          for (auto& [plane, t] : o->planes) t = *m * t;
        }
        continue;
      }
      const PovToken t = next();
      if (t.kind != PovToken::Name) fail(t, "expected an object modifier, found " + describe(t));
      if (t.text == "pigment") {
        const glm::dvec3 c = pigment(t);
        for (Object* o : objects)
          if (!o->front) o->front = c;
      } else if (t.text == "texture" || t.text == "interior_texture") {
        Object scratch;
        texture(scratch, t.text == "interior_texture");
        for (Object* o : objects) {
          if (scratch.front && !o->front) o->front = scratch.front;
          if (scratch.back && !o->back) o->back = scratch.back;
          if (scratch.finished) take_finish(*o, scratch);
        }
      } else if (t.text == "finish") {
        Object scratch;
        finish(scratch);
        for (Object* o : objects) take_finish(*o, scratch);
      } else if (t.text == "clipped_by" || t.text == "bounded_by") {
        if (objects.size() != 1) fail(t, t.text + " on a union: give it to each object inside");
        clip_block(*objects.front(), t);
      } else if (t.text == "inverse") {
        for (Object* o : objects) o->inverse = !o->inverse;
      } else if (t.text == "sturm" || t.text == "hollow" || t.text == "double_illuminate") {
        // What changes nothing algray draws: its solver is exact enough without sturm.
        switch_value();
      } else if (t.text == "no_shadow" || t.text == "no_image" || t.text == "no_reflection" ||
                 t.text == "no_radiosity") {
        switch_value();
        warn(t, t.text + " is ignored");
      } else if (at_op("{")) {
        warn(t, "'" + t.text + "' is ignored (algray reads pigment, texture, finish, transforms and clips)");
        skip_block();
      } else {
        fail(t, "'" + t.text + "' is no object modifier this reader knows");
      }
    }
    next();
  }
  // The optional on/off after a flag such as hollow.
  void switch_value() {
    static const std::set<std::string> words = {"on", "off", "true", "false", "yes", "no"};
    if (peek().kind == PovToken::Number || (peek().kind == PovToken::Name && words.count(peek().text))) next();
  }
  static SparsePoly sphere_poly(const glm::dvec3& c, double r) {
    SparsePoly p = SparsePoly::constant(c.x * c.x + c.y * c.y + c.z * c.z - r * r);
    for (int a = 0; a < 3; ++a) {
      SparsePoly::Exponents e{0, 0, 0};
      e[static_cast<std::size_t>(a)] = 2;
      p.add(e, 1);
      e[static_cast<std::size_t>(a)] = 1;
      p.add(e, -2 * c[a]);
    }
    return p;
  }
  // poly's coefficient order (see the top of the file).
  SparsePoly listed_poly(int order, const Vec& coefficients, const PovToken& at) const {
    const std::size_t count = static_cast<std::size_t>((order + 1) * (order + 2) * (order + 3) / 6);
    if (coefficients.size() != count)
      fail(at, "a poly of order " + std::to_string(order) + " has " + std::to_string(count) + " coefficients, found " +
                   std::to_string(coefficients.size()));
    SparsePoly p;
    std::size_t n = 0;
    for (int i = order; i >= 0; --i)
      for (int j = order - i; j >= 0; --j)
        for (int k = order - i - j; k >= 0; --k) p.add({i, j, k}, coefficients[n++]);
    return p;
  }
  int order_of(const PovToken& at) {
    const double o = number();
    if (o != std::floor(o) || o < 1 || o > kMaxDegree)
      fail(at, "the order must be a whole number from 1 to " + std::to_string(kMaxDegree) + " (algray's degrees)");
    optional_comma();
    return static_cast<int>(o);
  }
  // One object and its modifiers into out: a CSG group's members each, a shape as one.
  void object(const PovToken& kind, std::vector<Object>& out) {
    expect("{", "'{'");
    const std::size_t first = out.size();
    if (kind.text == "union" || kind.text == "merge")
      union_members(kind, out);
    else if (kind.text == "intersection")
      intersection_members(kind, out);
    else if (kind.text == "object")
      object_reference(out);
    else
      out.push_back(shape(kind));
    std::vector<Object*> members;
    for (std::size_t i = first; i < out.size(); ++i) members.push_back(&out[i]);
    modifiers(members, kind);
  }
  void union_members(const PovToken& kind, std::vector<Object>& out) {
    const std::size_t first = out.size();
    while (peek().kind == PovToken::Name && is_object(peek().text) && at_op("{", 1)) object(next(), out);
    if (out.size() == first) fail(kind, "this " + kind.text + " holds no object algray reads");
  }
  void intersection_members(const PovToken& kind, std::vector<Object>& out) {
    // POV-Ray's samples cut a surface with a Clear sphere or box: read as the surface clipped to that region.
    warn(kind, "intersection is read as its algebraic objects clipped by its spheres and boxes; the cut faces "
               "are not drawn (POV-Ray's samples make them Clear)");
    const std::size_t first = out.size();
    std::vector<std::pair<Clip, glm::dmat4>> clips;
    while (peek().kind == PovToken::Name && at_op("{", 1)) {
      const std::string w = peek().text;
      if (w == "sphere" || w == "box" || (w == "object" && declared_clips_.count(peek(2).text))) {
        glm::dmat4 own(1);
        const Clip c = clip_shape(kind, own);
        clips.push_back({c, own});
      } else if (is_object(w)) {
        object(next(), out);
      } else {
        break;
      }
    }
    if (out.size() == first) fail(kind, "this intersection holds no algebraic object algray reads");
    if (clips.empty()) fail(kind, "this intersection has no sphere or box to cut its objects with");
    for (std::size_t i = first; i < out.size(); ++i) out[i].clips.insert(out[i].clips.end(), clips.begin(), clips.end());
  }
  // object { NAME modifiers } or object { OBJECT modifiers }
  void object_reference(std::vector<Object>& out) {
    const PovToken name = next();
    if (name.kind == PovToken::Name && is_object(name.text) && at_op("{")) {
      object(name, out);
    } else if (name.kind == PovToken::Name && declared_objects_.count(name.text)) {
      for (const Object& o : declared_objects_.at(name.text)) out.push_back(o);
    } else if (name.kind == PovToken::Name) {
      unusable(name);
    } else {
      fail(name, "expected a declared object's name, found " + describe(name));
    }
  }
  // A sphere, torus or polynomial shape, up to its modifiers.
  Object shape(const PovToken& kind) {
    Object o;
    o.at = kind;
    o.kind = kind.text;
    if (kind.text == "sphere") {
      const glm::dvec3 c = vector3();
      optional_comma();
      const double r = number();
      if (!(r > 0)) fail(kind, "the sphere's radius must be positive");
      o.poly = sphere_poly(c, r);
      o.natural = Clip{true, c, {}, {}, r * 1.001};
    } else if (kind.text == "torus") {
      const double big = number();
      optional_comma();
      const double small = number();
      if (!(big > 0 && small > 0)) fail(kind, "a torus' radii must be positive");
      o.poly = torus_poly(big, small);
      o.natural = Clip{true, {0, 0, 0}, {}, {}, (big + small) * 1.001};
    } else if (kind.text == "poly" || kind.text == "quartic" || kind.text == "cubic") {
      const int order = kind.text == "poly" ? order_of(kind) : kind.text == "quartic" ? 4 : 3;
      const PovToken vat = peek();
      o.poly = listed_poly(order, expression(), vat);
    } else {  // polynomial
      o.poly = polynomial_terms(order_of(kind));
    }
    if (o.poly.degree() < 1) fail(kind, "this " + kind.text + " is constant: there is no surface");
    return o;
  }
  // (x^2 + y^2 + z^2 + R^2 - r^2)^2 - 4 R^2 (x^2 + z^2), about the y axis.
  static SparsePoly torus_poly(double big, double small) {
    SparsePoly q = SparsePoly::constant(big * big - small * small);
    for (int a = 0; a < 3; ++a) {
      SparsePoly::Exponents e{0, 0, 0};
      e[static_cast<std::size_t>(a)] = 2;
      q.add(e, 1);
    }
    PolyBudget budget;
    SparsePoly torus = multiply(q, q, budget);
    torus.add({2, 0, 0}, -4 * big * big);
    torus.add({0, 0, 2}, -4 * big * big);
    return torus;
  }
  // polynomial's xyz(i, j, k): c terms.
  SparsePoly polynomial_terms(int order) {
    SparsePoly poly;
    while (at_name("xyz")) {
      const PovToken term = next();
      expect("(", "'('");
      int e[3];
      for (int i = 0; i < 3; ++i) {
        const double v = number();
        if (v != std::floor(v) || v < 0 || v > order) fail(term, "exponents are whole numbers from 0 to the order");
        e[i] = static_cast<int>(v);
        if (i < 2) expect(",", "','");
      }
      expect(")", "')'");
      expect(":", "':'");
      if (e[0] + e[1] + e[2] > order) fail(term, "this term's degree is above the polynomial's order");
      poly.add({e[0], e[1], e[2]}, number());
      optional_comma();
    }
    return poly;
  }
  static bool is_object(const std::string& w) {
    return w == "sphere" || w == "torus" || w == "poly" || w == "polynomial" || w == "quartic" || w == "cubic" ||
           w == "union" || w == "merge" || w == "object" || w == "intersection";
  }

  // --- scene items ---
  void camera() {
    const PovToken open = peek();
    expect("{", "'{' after camera");
    while (!at_op("}")) {
      const PovToken t = next();
      if (t.kind == PovToken::End) fail(open, "this camera is never closed");
      if (t.kind != PovToken::Name) fail(t, "expected a camera item, found " + describe(t));
      if (t.text == "perspective") camera_.orthographic = false;
      else if (t.text == "orthographic") camera_.orthographic = true;
      else if (t.text == "location") camera_.location = vector3();
      else if (t.text == "look_at") camera_.look_at = vector3();
      else if (t.text == "direction") camera_.direction = vector3();
      else if (t.text == "right") camera_.right = vector3();
      else if (t.text == "up") camera_.up = vector3();
      else if (t.text == "sky") camera_.sky = vector3();
      else if (t.text == "angle") {
        camera_.angle = number();
        if (!(*camera_.angle > 0 && *camera_.angle < 180)) fail(t, "angle must be between 0 and 180 degrees");
      } else if (t.text == "fisheye" || t.text == "panoramic" || t.text == "cylinder" || t.text == "spherical" ||
                 t.text == "omnimax" || t.text == "ultra_wide_angle" || t.text == "mesh_camera")
        fail(t, "a " + t.text + " camera: algray's cameras are perspective or orthographic");
      else if (t.text == "rotate" || t.text == "translate" || t.text == "scale" || t.text == "matrix")
        fail(t, "camera transforms are not read; give location and look_at instead");
      else {
        warn(t, "camera '" + t.text + "' is ignored");
        skip_item();
      }
      camera_at_ = open;
    }
    next();
  }
  void light() {
    const PovToken open = peek();
    expect("{", "'{' after light_source");
    PovLight l;
    l.position = vector3();
    optional_comma();
    l.colour = colour(open);
    while (!at_op("}")) {
      if (auto m = transform_step()) {
        l.position = glm::dvec3(*m * glm::dvec4(l.position, 1));
        l.edge_u = glm::dvec3(*m * glm::dvec4(l.edge_u, 0));
        l.edge_v = glm::dvec3(*m * glm::dvec4(l.edge_v, 0));
        continue;
      }
      const PovToken t = next();
      if (t.kind == PovToken::End) fail(open, "this light_source is never closed");
      if (t.text == "area_light") {
        l.area = true;
        l.edge_u = vector3();
        optional_comma();
        l.edge_v = vector3();
        optional_comma();
        const double n1 = number();
        optional_comma();
        const double n2 = number();
        l.samples = static_cast<int>(std::clamp(std::max(n1, n2), 1.0, static_cast<double>(kMaxLightSamplesPerSide)));
      } else if (t.text == "shadowless") {
        l.shadows = false;
      } else if (t.text == "adaptive" || t.text == "jitter" || t.text == "orient" || t.text == "circular") {
        if (t.text == "adaptive") number();  // algray samples the area light's grid evenly
      } else {
        warn(t, "light_source '" + t.text + "' is ignored: algray's lights are points and rectangles");
        skip_item();
      }
    }
    next();
    lights_.push_back(l);
  }
  void background() {
    const PovToken open = peek();
    expect("{", "'{' after background");
    background_ = colour(open);
    expect("}", "'}'");
  }
  // --- directives ---
  // The file #include names, read and its tokens put in place of the directive.
  void include(const PovToken& d) {
    const PovToken file = next();
    if (file.kind != PovToken::String) fail(file, "expected a file name after #include");
    const std::filesystem::path name(file.text);
    bool plain = name.extension() == ".inc" && name.is_relative();
    for (const auto& part : name) plain = plain && part != "..";
    if (!plain) fail(file, "#include reads .inc files by a relative name without '..' (see algray's POV-Ray notes)");
    const int depth = files_[static_cast<std::size_t>(d.file)].depth + 1;
    if (depth > kMaxIncludeDepth) fail(d, "#include nested more than " + std::to_string(kMaxIncludeDepth) + " deep");
    if (files_.size() > static_cast<std::size_t>(kMaxIncludes))
      fail(d, "more than " + std::to_string(kMaxIncludes) + " #include files read");
    std::string looked;
    for (const auto& dir : include_dirs_) {
      const std::filesystem::path path = dir / name;
      std::error_code ec;
      if (!std::filesystem::is_regular_file(path, ec)) {
        looked += (looked.empty() ? "" : ", ") + dir.string();
        continue;
      }
      std::ifstream in(path, std::ios::binary);
      std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      if (!in && !in.eof()) fail(file, "cannot read " + path.string());
      const int index = static_cast<int>(files_.size());
      files_.push_back({std::make_unique<LocatedText>(text, path.string()), depth});
      std::vector<PovToken> tokens = tokenize(text, index);
      tokens.pop_back();  // its End
      if (tokens_.size() + tokens.size() > kMaxTokens) fail(d, "the #include files hold too many tokens");
      tokens_.insert(tokens_.begin() + static_cast<std::ptrdiff_t>(pos_), tokens.begin(), tokens.end());
      return;
    }
    // As before includes were read: a scene that only takes colours from a missing colors.inc still renders.
    warn(d, "#include \"" + file.text + "\" is not found (looked in " + looked + "); it is ignored");
    missing_include_ = true;
  }
  // Skips to the #end that closes the block opened before the cursor; with stop_at_else, to its #else instead
  // when there is one. Returns whether it stopped at an #else.
  bool skip_to_end(const PovToken& open, bool stop_at_else) {
    static const std::set<std::string> openers = {"if", "ifdef", "ifndef", "while", "for", "switch", "macro"};
    int depth = 0;
    for (;;) {
      const PovToken t = next();
      if (t.kind == PovToken::End) fail(open, "this #" + open.text + " has no #end");
      if (t.kind != PovToken::Directive) continue;
      if (openers.count(t.text)) ++depth;
      else if (t.text == "end" && depth-- == 0) return false;
      else if (t.text == "else" && depth == 0 && stop_at_else) return true;
    }
  }
  // Skips a value this reader does not read: NAME { ... }, or tokens up to ';' or the next directive.
  void skip_value() {
    if (peek().kind == PovToken::Name && at_op("{", 1)) {
      next();
      skip_block();
    } else {
      int depth = 0;
      while (peek().kind != PovToken::End && !(depth == 0 && (at_op(";") || peek().kind == PovToken::Directive))) {
        const PovToken t = next();
        if (t.kind == PovToken::Op && (t.text == "(" || t.text == "{" || t.text == "[")) ++depth;
        if (t.kind == PovToken::Op && (t.text == ")" || t.text == "}" || t.text == "]")) --depth;
      }
    }
    if (at_op(";")) next();
  }
  bool is_declared(const std::string& name) const {
    return declared_.count(name) || declared_objects_.count(name) || unread_.count(name) || declared_clips_.count(name);
  }
  void forget(const std::string& name) {
    declared_clips_.erase(name);
    declared_.erase(name);
    declared_objects_.erase(name);
    unread_.erase(name);
  }
  void declaration(const PovToken& d) {
    const PovToken name = next();
    if (name.kind != PovToken::Name) fail(name, "expected a name after #" + d.text);
    expect("=", "'='");
    forget(name.text);
    static const std::set<std::string> colour_words = {"color", "colour", "rgb", "rgbf", "rgbt", "rgbft", "srgb",
                                                        "srgbf", "srgbt", "srgbft", "red", "green", "blue"};
    const PovToken value = peek();
    if (value.kind == PovToken::Name && colour_words.count(value.text)) {
      const glm::dvec3 c = colour(name);
      declared_[name.text] = {c.x, c.y, c.z};
    } else if (value.kind == PovToken::Name && value.text == "box" && at_op("{", 1)) {
      // A box is no surface here, but clips one: intersection { OBJECT object { NAME } } and bounded_by use it.
      const std::size_t start = pos_;
      try {
        glm::dmat4 own(1);
        const Clip c = clip_shape(name, own);
        declared_clips_[name.text] = {c, own};
      } catch (const SceneError& e) {
        if (d.file == 0) throw;
        pos_ = start;
        unread_[name.text] = {name, "a box algray cannot read (" + e.where + ": " + e.message + ")"};
        skip_value();
        return;
      }
    } else if (value.kind == PovToken::Name && is_object(value.text) && at_op("{", 1) && d.file != 0) {
      // An include file's object this reader cannot read is an error only where the scene uses it.
      const std::size_t start = pos_;
      std::vector<Object> objects;
      try {
        object(next(), objects);
        declared_objects_[name.text] = std::move(objects);
      } catch (const SceneError& e) {
        pos_ = start;
        unread_[name.text] = {name, "a " + value.text + " algray cannot draw (" + e.where + ": " + e.message + ")"};
        skip_value();
        return;
      }
    } else if (value.kind == PovToken::Name && is_object(value.text) && at_op("{", 1)) {
      std::vector<Object> objects;
      object(next(), objects);
      declared_objects_[name.text] = std::move(objects);
    } else if (value.kind == PovToken::Name && declared_objects_.count(value.text)) {
      next();
      declared_objects_[name.text] = declared_objects_.at(value.text);
    } else if (value.kind == PovToken::Name && at_op("{", 1)) {
      // A texture, pigment, finish or another object: its name is remembered so that a use can say what it is.
      if (d.file == 0)
        warn(name, "#" + d.text + " " + name.text + " = " + value.text + " { ... } is ignored: algray declares " +
                       "floats, vectors, colours and the objects it reads");
      unread_[name.text] = {name, "a " + value.text};
      skip_value();
      return;
    } else if (d.file != 0) {
      // In an include file a value this reader cannot evaluate (a macro's result, a string) is skipped.
      const std::size_t start = pos_;
      try {
        declared_[name.text] = expression();
      } catch (const SceneError&) {
        pos_ = start;
        unread_[name.text] = {name, "a value"};
        skip_value();
        return;
      }
    } else {
      declared_[name.text] = expression();
    }
    if (at_op(";")) next();
  }
  void directive(const PovToken& d) {
    if (d.text == "version") {
      number();
      if (at_op(";")) next();
    } else if (d.text == "include") {
      include(d);
    } else if (d.text == "declare" || d.text == "local") {
      // An include file's declarations warn about nothing: only what the scene uses of them matters.
      const bool was = quiet_;
      quiet_ = quiet_ || d.file != 0;
      try {
        declaration(d);
      } catch (...) {
        quiet_ = was;
        throw;
      }
      quiet_ = was;
    } else if (d.text == "undef") {
      const PovToken name = next();
      if (name.kind != PovToken::Name) fail(name, "expected a name after #undef");
      forget(name.text);
    } else if (d.text == "macro") {
      const PovToken name = next();
      if (name.kind != PovToken::Name) fail(name, "expected a name after #macro");
      if (d.file == 0) warn(d, "#macro " + name.text + " is skipped: this reader does not expand macros");
      unread_[name.text] = {name, "a macro"};
      skip_to_end(d, false);
    } else if (d.text == "ifdef" || d.text == "ifndef" || d.text == "if") {
      bool holds;
      if (d.text == "if") {
        holds = number() != 0;
      } else {
        expect("(", "'('");
        const PovToken name = next();
        if (name.kind != PovToken::Name) fail(name, "expected a name");
        expect(")", "')'");
        holds = is_declared(name.text) == (d.text == "ifdef");
      }
      if (holds || skip_to_end(d, true)) open_ifs_.push_back(d);
    } else if (d.text == "else") {
      if (open_ifs_.empty()) fail(d, "#else without #if, #ifdef or #ifndef");
      skip_to_end(open_ifs_.back(), false);  // the branch that was read ends here
      open_ifs_.pop_back();
    } else if (d.text == "end") {
      if (open_ifs_.empty()) fail(d, "#end without #if, #ifdef or #ifndef");
      open_ifs_.pop_back();
    } else if (d.text == "debug" || d.text == "warning") {
      skip_value();
    } else if (d.text == "default") {
      warn(d, "#default is ignored: algray's objects take POV-Ray's default finish unless they give their own");
      skip_block();
    } else if (d.text == "while" || d.text == "for" || d.text == "switch") {
      warn(d, "#" + d.text + " ... #end is skipped: this reader does not run loops or switches");
      skip_to_end(d, false);
    } else {
      fail(d, "#" + d.text + " is not read: algray reads #declare, #local, #undef, #include, #if, #ifdef, " +
                  "#ifndef, #else, #end, #version (and skips #macro, #while, #for, #switch, #debug, #warning)");
    }
  }
  // object { NAME ... } in the scene, the '{' next, of a declared object algray cannot draw (grafbic's axes, infinite
  // quadric cylinders from axisbox.inc): skipped with a warning, as any other object algray does not draw; if the
  // scene then has nothing to draw, run() gives the reason as the error.
  bool undrawable_object(const PovToken& name) {
    const auto u = unread_.find(name.text);
    if (name.kind != PovToken::Name || u == unread_.end() || u->second.second.find(" algray cannot ") == std::string::npos)
      return false;
    const std::string why = "'" + name.text + "' is " + u->second.second + " (declared at " + where(u->second.first) +
                            "), which this reader does not read";
    if (!undrawn_) undrawn_ = {name, why};
    warn(name, why + "; skipped");
    skip_block();
    return true;
  }
  void item() {
    const PovToken t = next();
    if (t.kind == PovToken::Directive) return directive(t);
    if (t.kind != PovToken::Name) fail(t, "expected a scene item, found " + describe(t));
    if (t.text == "camera") return camera();
    if (t.text == "light_source") return light();
    if (t.text == "background") return background();
    if (t.text == "global_settings") {
      const PovToken open = peek();
      expect("{", "'{'");
      while (!at_op("}")) {
        const PovToken s = next();
        if (s.kind == PovToken::End) fail(open, "global_settings is never closed");
        if (s.text == "assumed_gamma") {
          if (number() != 1) warn(s, "assumed_gamma other than 1 is ignored: algray's colours are linear");
        } else {
          warn(s, "global_settings '" + s.text + "' is ignored");
          skip_item();
        }
      }
      next();
      return;
    }
    if (t.text == "object" && at_op("{") && undrawable_object(peek(1))) return;
    if (is_object(t.text)) return object(t, objects_);
    if (at_op("{")) {
      warn(t, "'" + t.text + "' is ignored: algray reads poly, polynomial, quartic, cubic, sphere and torus objects");
      skip_block();
      return;
    }
    fail(t, "'" + t.text + "' is no scene item this reader knows");
  }

  // --- the scene ---
  // The region an object is drawn in, in POV-Ray's world (or the box frame's, see run()); nullopt for an object
  // without one. A region from bounded_by alone is marked `bound`.
  std::optional<Clip> region(const Object& o) const {
    std::optional<Clip> best;
    auto place = [&](const Clip& c, const glm::dmat4& t, bool loose) {
      const glm::dmat3 l(t);
      Clip w = c;
      if (c.sphere && loose) {  // a sphere or torus' own bound need only enclose it: the largest stretch will do
        const glm::dmat3 g = glm::transpose(l) * l;
        glm::dvec3 v(1, 0.7, 0.3);
        double stretch2 = 0;
        for (int k = 0; k < 60; ++k) {  // power iteration: the largest eigenvalue of L^T L
          const glm::dvec3 next = g * v;
          stretch2 = glm::length(next) / glm::length(v);
          v = next / glm::length(next);
        }
        w.centre = glm::dvec3(t * glm::dvec4(c.centre, 1));
        w.radius = c.radius * std::sqrt(stretch2) * 1.001;
      } else if (c.sphere) {
        const glm::dmat3 g = glm::transpose(l) * l;
        const double s2 = g[0][0];
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            if (std::fabs(g[i][j] - (i == j ? s2 : 0)) > 1e-9 * s2)
              fail(o.at, "a clipping sphere scaled unevenly is an ellipsoid; algray clips to spheres and boxes");
        w.centre = glm::dvec3(t * glm::dvec4(c.centre, 1));
        w.radius = c.radius * std::sqrt(s2);
      } else {
        for (int col = 0; col < 3; ++col) {
          int nonzero = 0;
          const double norm = glm::length(l[col]);
          for (int row = 0; row < 3; ++row) nonzero += std::fabs(l[col][row]) > 1e-9 * norm;
          if (nonzero != 1)
            fail(o.at,
                 "a clipping box sheared, or turned differently from another box of the scene; algray's boxes "
                 "are axis-aligned (a scene with one turned box is written in that box's frame)");
        }
        const glm::dvec3 a(t * glm::dvec4(c.min, 1)), b(t * glm::dvec4(c.max, 1));
        w.min = glm::min(a, b);
        w.max = glm::max(a, b);
      }
      return w;
    };
    bool bound_only = !o.clips.empty();
    for (const auto& [c, t] : o.clips) {
      const Clip w = place(c, t, false);
      bound_only = bound_only && c.bound;
      if (!best || inside(w, *best)) best = w;
      else if (!inside(*best, w))
        fail(o.at, "this object is clipped by two regions that overlap; algray clips to one sphere or box");
    }
    if (best) best->bound = bound_only;
    if (!best && o.natural) best = place(*o.natural, o.transform, true);
    return best;
  }
  glm::dmat4 box_frame(const PovToken*& at) const;
  // --- the stages of run(): what they settle, in order ---
  struct Translated {
    Camera camera;
    std::vector<PovLight> lights;
    const PovToken* framed_by = nullptr;  // the turned clipping box whose frame the scene is written in
    std::optional<Clip> extent;        // the objects' common region, in POV-Ray's coordinates
    const Object* clipped_by = nullptr;
    std::vector<const Object*> open;  // objects with no region at all
    glm::dvec3 mirror{1, 1, 1};       // algray's point q is POV-Ray's q * mirror
    std::vector<SparsePoly> polys;    // the objects in algray's coordinates
    CameraSpec view;
    int width = 0, height = 0;
    std::optional<Clip> drawn;  // the extent in algray's coordinates
    std::string extent_note;    // why it differs from POV-Ray's region, if it does
    double gate_reach = 0;      // drawn is a gate (bounded_by alone) with this reach; 0: a cut
    std::vector<glm::dvec4> planes;  // the clipping planes in algray's coordinates, a.q + d <= 0 kept
  };
  void frame(Translated& scene);
  void common_region(Translated& scene);
  void clip_planes(Translated& scene, const glm::dmat4& flip);
  std::vector<SparsePoly> algray_polys(const glm::dmat4& flip);
  void algray_view(Translated& scene);
  void off_axis(Translated& scene, double& distance, glm::dvec3& axis);
  void fit_extent(Translated& scene);
  void gate_reach(Translated& scene);
  PovTranslation write_toml(const Translated& scene) const;
  static bool same(const Clip& a, const Clip& b) {
    if (a.sphere != b.sphere) return false;
    const double tolerance = 1e-9 * (1 + a.radius);
    if (a.sphere) return glm::length(a.centre - b.centre) < tolerance && std::fabs(a.radius - b.radius) < tolerance;
    return glm::length(a.min - b.min) + glm::length(a.max - b.max) < 1e-9 * (1 + glm::length(a.max - a.min));
  }
  // Whether a lies within b.
  static bool inside(const Clip& a, const Clip& b) {
    const glm::dvec3 lo = a.sphere ? a.centre - glm::dvec3(a.radius) : a.min;
    const glm::dvec3 hi = a.sphere ? a.centre + glm::dvec3(a.radius) : a.max;
    if (b.sphere) {
      if (a.sphere) return glm::length(a.centre - b.centre) + a.radius <= b.radius * (1 + 1e-9);
      for (int i = 0; i < 8; ++i) {
        const glm::dvec3 p(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
        if (glm::length(p - b.centre) > b.radius * (1 + 1e-9)) return false;
      }
      return true;
    }
    for (int i = 0; i < 3; ++i)
      if (lo[i] < b.min[i] - 1e-9 * (1 + std::fabs(b.min[i])) || hi[i] > b.max[i] + 1e-9 * (1 + std::fabs(b.max[i])))
        return false;
    return true;
  }
  static Clip enclosing(const Clip& a, const Clip& b) {
    Clip out;
    out.sphere = false;
    auto lo = [](const Clip& c) { return c.sphere ? c.centre - glm::dvec3(c.radius) : c.min; };
    auto hi = [](const Clip& c) { return c.sphere ? c.centre + glm::dvec3(c.radius) : c.max; };
    out.min = glm::min(lo(a), lo(b));
    out.max = glm::max(hi(a), hi(b));
    return out;
  }

  struct File {
    std::unique_ptr<LocatedText> text;
    int depth = 0;  // how many #includes deep
  };
  std::vector<File> files_;
  std::vector<std::filesystem::path> include_dirs_;
  std::vector<std::string>& warnings_;
  int width_, height_;
  std::vector<PovToken> tokens_;
  std::size_t pos_ = 0;
  std::map<std::string, Vec> declared_;
  std::map<std::string, std::vector<Object>> declared_objects_;
  std::map<std::string, std::pair<Clip, glm::dmat4>> declared_clips_;  // declared boxes, with their transforms
  std::map<std::string, std::pair<PovToken, std::string>> unread_;  // name: where declared, and what it is
  bool missing_include_ = false;
  bool quiet_ = false;  // warnings are dropped (reading an include file's declarations)
  std::vector<PovToken> open_ifs_;                                    // #if, #ifdef, #ifndef being read
  std::vector<Object> objects_;
  std::optional<std::pair<PovToken, std::string>> undrawn_;  // the first object skipped by undrawable_object, and why
  Camera camera_;
  std::optional<PovToken> camera_at_;
  std::vector<PovLight> lights_;
  std::optional<glm::dvec3> background_;
};

// The rigid frame of the first clipping box turned off the axes: the map from POV-Ray's world to that frame, in
// which the box is axis-aligned; the identity where every box is axis-aligned already. A box stays a box under a
// transform whose columns are orthogonal (rotations, translations, scales in any order); a sheared one is left
// to region()'s message.
glm::dmat4 PovReader::box_frame(const PovToken*& at) const {
  for (const Object& o : objects_)
    for (const auto& [c, t] : o.clips) {
      if (c.sphere) continue;
      const glm::dmat3 l(t);
      bool aligned = true, orthogonal = true;
      for (int col = 0; col < 3; ++col) {
        int nonzero = 0;
        const double norm = glm::length(l[col]);
        for (int row = 0; row < 3; ++row) nonzero += std::fabs(l[col][row]) > 1e-9 * norm;
        aligned = aligned && nonzero == 1;
        for (int other = col + 1; other < 3; ++other)
          orthogonal = orthogonal && std::fabs(glm::dot(l[col], l[other])) <= 1e-9 * norm * glm::length(l[other]);
      }
      if (aligned || !orthogonal) continue;
      glm::dmat3 q(glm::normalize(l[0]), glm::normalize(l[1]), glm::normalize(l[2]));
      if (glm::determinant(q) < 0) q[2] = -q[2];  // a rotation: the frame keeps the camera's handedness
      glm::dmat4 to_world(q);
      to_world[3] = glm::dvec4(glm::dvec3(t[3]), 1);
      at = &o.at;
      return glm::inverse(to_world);
    }
  return glm::dmat4(1);
}

namespace {

// Where a ray o + t d (t >= 0) is inside a sphere or box: [a, b], or nullopt where it misses.
std::optional<std::pair<double, double>> span(const Clip& c, const glm::dvec3& o, const glm::dvec3& d) {
  double a = 0, b = std::numeric_limits<double>::infinity();
  if (c.sphere) {
    const glm::dvec3 oc = o - c.centre;
    const double half_b = glm::dot(oc, d), cc = glm::dot(oc, oc) - c.radius * c.radius;
    const double disc = half_b * half_b - cc;
    if (disc < 0) return std::nullopt;
    a = std::max(a, -half_b - std::sqrt(disc));
    b = std::min(b, -half_b + std::sqrt(disc));
  } else {
    for (int i = 0; i < 3; ++i) {
      if (d[i] == 0) {
        if (o[i] < c.min[i] || o[i] > c.max[i]) return std::nullopt;
        continue;
      }
      const double t0 = (c.min[i] - o[i]) / d[i], t1 = (c.max[i] - o[i]) / d[i];
      a = std::max(a, std::min(t0, t1));
      b = std::min(b, std::max(t0, t1));
    }
  }
  if (a > b) return std::nullopt;
  return std::pair{a, b};
}

// What a grid of camera rays sees of the surfaces: each ray (unit direction) and its roots, all surfaces together.
struct Sight {
  struct Ray {
    glm::dvec3 o, d;
    std::vector<double> roots;
  };
  std::vector<Ray> rays;
  static constexpr int kColumns = 64, kRows = 48;
};
// Roots beyond a clipping plane (planes: a.q + d <= 0 kept) are cut away, as algray draws them.
Sight look(const CameraSpec& camera, int width, int height, const std::vector<SparsePoly>& polys, double scale,
           const std::vector<glm::dvec4>& planes) {
  Sight sight;
  const RayBasis basis = make_ray_basis(camera, width, height);
  for (int j = 0; j < Sight::kRows; ++j)
    for (int i = 0; i < Sight::kColumns; ++i) {
      const PixelRay ray = pixel_ray(basis, false, i * width / Sight::kColumns, j * height / Sight::kRows);
      Sight::Ray r{ray.origin, glm::normalize(ray.direction), {}};
      for (const SparsePoly& p : polys) {
        for (const double t : ray_roots(p, r.o, r.d, 1e-5 * scale, 1e5 * scale))
          if (std::all_of(planes.begin(), planes.end(),
                          [&](const glm::dvec4& k) { return glm::dot(glm::dvec3(k), r.o + t * r.d) + k.w <= 0; }))
            r.roots.push_back(t);
      }
      std::sort(r.roots.begin(), r.roots.end());
      sight.rays.push_back(std::move(r));
    }
  return sight;
}
// How well drawing within `region` agrees with what `shown` says each ray shows: intersection over union.
double agreement(const Sight& sight, const std::vector<bool>& shown, const Clip& region) {
  long both = 0, either = 0;
  for (std::size_t k = 0; k < sight.rays.size(); ++k) {
    const Sight::Ray& r = sight.rays[k];
    bool drawn = false;
    if (const auto s = span(region, r.o, r.d))
      for (double t : r.roots) drawn = drawn || (t >= s->first && t <= s->second);
    both += drawn && shown[k];
    either += drawn || shown[k];
  }
  return either ? static_cast<double>(both) / static_cast<double>(either) : 1.0;
}
// A sphere about the first points the rays see, `margin` times as large as needed.
std::optional<Clip> seen_sphere(const Sight& sight, const std::vector<bool>& shown, double margin) {
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi = -lo;
  std::vector<glm::dvec3> points;
  for (std::size_t k = 0; k < sight.rays.size(); ++k)
    if (shown[k] && !sight.rays[k].roots.empty()) {
      points.push_back(sight.rays[k].o + sight.rays[k].roots.front() * sight.rays[k].d);
      lo = glm::min(lo, points.back());
      hi = glm::max(hi, points.back());
    }
  if (points.empty()) return std::nullopt;
  Clip c;
  c.centre = 0.5 * (lo + hi);
  for (const glm::dvec3& p : points) c.radius = std::max(c.radius, glm::length(p - c.centre));
  c.radius = std::max(c.radius * margin, 1e-3 * glm::length(hi - lo) + 1e-9);
  return c;
}

}  // namespace

// The scene as algray's TOML: its objects, turned into the frame of a turned clipping box if there is one (frame),
// clipped to one region (common_region), mirrored where POV-Ray's camera is left-handed, the camera and image
// (algray_view), an extent fitted where POV-Ray's own region is not a clip (fit_extent), then written out.
PovTranslation PovReader::run() {
  while (peek().kind != PovToken::End) item();
  if (objects_.empty() && undrawn_) fail(undrawn_->first, undrawn_->second);
  if (objects_.empty())
    fail(peek(), "the scene holds no object algray reads (poly, polynomial, quartic, cubic, sphere, torus)");
  if (objects_.size() > kMaxSurfaces)
    fail(objects_[kMaxSurfaces].at, std::to_string(objects_.size()) + " objects: algray draws up to " +
                                        std::to_string(kMaxSurfaces) + " surfaces in one scene");
  Translated scene;
  scene.camera = camera_;
  scene.lights = lights_;
  frame(scene);
  common_region(scene);
  // Handedness: a left-handed camera (the default) is read with z negated; a right-handed one as written.
  const Camera& cam = scene.camera;
  if (glm::length(cam.right) == 0 || glm::length(cam.up) == 0 || glm::length(cam.direction) == 0)
    fail(camera_at_ ? *camera_at_ : objects_.front().at, "the camera's right, up and direction must not be zero");
  const bool left_handed = glm::dot(glm::cross(cam.right, cam.up), cam.direction) > 0;
  scene.mirror = glm::dvec3(1, 1, left_handed ? -1 : 1);
  glm::dmat4 flip(1);
  flip[2][2] = scene.mirror.z;

  scene.polys = algray_polys(flip);
  clip_planes(scene, flip);
  algray_view(scene);
  fit_extent(scene);
  return write_toml(scene);
}

void PovReader::frame(Translated& scene) {
  // A clipping box turned off the axes: the whole scene (objects, clips, camera, lights) is written in the box's
  // own frame, turned and moved from POV-Ray's, in which algray's axis-aligned box is that box. The picture is
  // the same, since the camera moves with everything else.
  const glm::dmat4 to_frame = box_frame(scene.framed_by);
  if (!scene.framed_by) return;
  const glm::dmat3 turn(to_frame);
  auto point = [&](const glm::dvec3& p) { return glm::dvec3(to_frame * glm::dvec4(p, 1)); };
  for (Object& o : objects_) {
    o.transform = to_frame * o.transform;
    for (auto& [c, t] : o.clips) t = to_frame * t;
    for (auto& [plane, t] : o.planes) t = to_frame * t;
  }
  scene.camera.location = point(scene.camera.location);
  if (scene.camera.look_at) scene.camera.look_at = point(*scene.camera.look_at);
  scene.camera.direction = turn * scene.camera.direction;
  scene.camera.right = turn * scene.camera.right;
  scene.camera.up = turn * scene.camera.up;
  scene.camera.sky = turn * scene.camera.sky;
  for (PovLight& l : scene.lights) {
    l.position = point(l.position);
    l.edge_u = turn * l.edge_u;
    l.edge_v = turn * l.edge_v;
  }
}

void PovReader::common_region(Translated& scene) {
  // One region for the scene: the clipped objects' common clip, holding every self-bounded one (spheres, tori),
  // or, with none clipped, a box around them all. Objects with no region at all are `open`.
  std::optional<Clip>& extent = scene.extent;
  const Object*& clipped_by = scene.clipped_by;
  std::vector<const Object*>& open = scene.open;
  for (const Object& o : objects_)
    if (!o.clips.empty() || !o.natural) {
      std::optional<Clip> r = region(o);
      if (!r) {
        open.push_back(&o);
        continue;
      }
      if (extent && !same(*extent, *r) && extent->bound && r->bound) {
        // Bounds alone (bounded_by, no clip) are POV-Ray's hints, not clips (grafbic's two bicorns have spheres of
        // radius 3 and 2.99): the scene's is one that holds them all, which fit_extent fits to what rays see.
        if (inside(*r, *extent)) {
          r = extent;
        } else if (!inside(*extent, *r)) {
          r = enclosing(*extent, *r);
          r->bound = true;
        }
      } else if (extent && !same(*extent, *r)) {
        fail(o.at, "this object is clipped differently from the " + clipped_by->kind + " at line " +
                       std::to_string(clipped_by->at.line) + "; algray clips every surface of a scene to one region");
      }
      if (extent) r->bound = r->bound && extent->bound;
      extent = r;
      clipped_by = &o;
    }
  if (!open.empty() && clipped_by)
    fail(open.front()->at, "this " + open.front()->kind + " has no clipped_by or bounded_by, but the " +
                               clipped_by->kind + " at line " + std::to_string(clipped_by->at.line) +
                               " has; algray clips every surface of a scene to one region");
  for (const Object& o : objects_)
    if (o.clips.empty() && o.natural) {
      const Clip r = *region(o);
      if (!extent)
        extent = r;
      else if (clipped_by && !inside(r, *extent))
        fail(o.at, "this " + o.kind + " reaches outside the clip of the " + clipped_by->kind + " at line " +
                       std::to_string(clipped_by->at.line) + "; algray clips every surface of a scene to one region");
      else if (!clipped_by && !inside(r, *extent))
        extent = enclosing(*extent, r);
    }
}

std::vector<SparsePoly> PovReader::algray_polys(const glm::dmat4& flip) {
  // The surfaces in algray's coordinates: algray's point q is POV-Ray's flip(q); the object's own point is
  // transform^-1 of that.
  std::vector<SparsePoly> polys;
  for (const Object& o : objects_) {
    const glm::dmat4 a = glm::inverse(o.transform) * flip;
    std::array<std::array<double, 4>, 3> m{};
    for (std::size_t r = 0; r < 3; ++r) {
      for (std::size_t c = 0; c < 3; ++c) m[r][c] = a[static_cast<int>(c)][static_cast<int>(r)];
      m[r][3] = a[3][static_cast<int>(r)];
    }
    SparsePoly p;
    try {
      PolyBudget budget;
      p = substitute(o.poly, m, budget);
    } catch (const PolyTooLarge& e) {
      fail(o.at, e.what());
    }
    if (o.inverse)
      for (auto& [e, c] : p.terms) c = -c;
    for (const auto& [e, c] : p.terms)
      if (!std::isfinite(c)) fail(o.at, "the coefficients overflow after the transforms");
    polys.push_back(std::move(p));
  }

  return polys;
}

void PovReader::clip_planes(Translated& scene, const glm::dmat4& flip) {
  // Each object's planes in algray's coordinates: the plane P (P.(x, 1) <= 0 kept) under the map M from its own
  // coordinates to POV-Ray's world is P M^-1 there, and P M^-1 flip in algray's (flip is its own inverse).
  // algray cuts every surface of a scene by the same planes: all objects' planes together, each once.
  const auto same_plane = [](const glm::dvec4& a, const glm::dvec4& b) { return glm::length(a - b) <= 1e-9; };
  std::vector<std::vector<glm::dvec4>> own(objects_.size());
  for (std::size_t n = 0; n < objects_.size(); ++n) {
    const Object& o = objects_[n];
    for (const auto& [p, t] : o.planes) {
      glm::dvec4 q = flip * (glm::transpose(glm::inverse(t)) * p);
      const double length = glm::length(glm::dvec3(q));
      if (!(length > 0) || !std::isfinite(length))
        fail(o.at, "a clipping plane of this " + o.kind + " degenerates under its transforms");
      q /= length;
      for (int i = 0; i < 4; ++i)
        if (std::fabs(q[i]) < 1e-15) q[i] = 0;  // a rotation's rounding, not a tilt
      own[n].push_back(q);
      if (std::none_of(scene.planes.begin(), scene.planes.end(), [&](const glm::dvec4& k) { return same_plane(k, q); }))
        scene.planes.push_back(q);
    }
  }
  if (scene.planes.size() > kMaxClipPlanes)
    fail(objects_.front().at, "the objects are clipped by " + std::to_string(scene.planes.size()) +
                                  " different planes together; algray cuts a scene by at most " +
                                  std::to_string(kMaxClipPlanes) + ", the same for every surface");
  if (scene.planes.empty()) return;
  for (std::size_t n = 0; n < objects_.size(); ++n) {
    const bool all = std::all_of(scene.planes.begin(), scene.planes.end(), [&](const glm::dvec4& k) {
      return std::any_of(own[n].begin(), own[n].end(), [&](const glm::dvec4& q) { return same_plane(k, q); });
    });
    if (!all)
      warn(objects_[n].at, "algray cuts every surface of a scene by the same planes: this " + objects_[n].kind +
                               " is also cut by the clipped_by planes of the scene's other objects");
  }
}

void PovReader::algray_view(Translated& scene) {
  // The camera: angle sets direction's length from right's; the view is |up| tall at |direction|.
  double distance = glm::length(scene.camera.direction);
  if (scene.camera.angle && !scene.camera.orthographic)
    distance = 0.5 * glm::length(scene.camera.right) / std::tan(*scene.camera.angle * std::numbers::pi / 360);
  const glm::dvec3 forward =
      scene.camera.look_at ? *scene.camera.look_at - scene.camera.location : glm::normalize(scene.camera.direction);
  if (glm::length(forward) == 0)
    fail(camera_at_ ? *camera_at_ : objects_.front().at, "look_at is the camera's location");
  const glm::dvec3 up = scene.camera.look_at ? scene.camera.sky : scene.camera.up;
  if (glm::length(glm::cross(glm::normalize(forward), glm::normalize(up))) < 1e-9)
    fail(camera_at_ ? *camera_at_ : objects_.front().at, "the camera looks along its sky (or up) vector");
  CameraSpec& view = scene.view;
  glm::dvec3 axis = glm::normalize(forward);
  if (!scene.camera.look_at) off_axis(scene, distance, axis);
  view.eye = scene.camera.location * scene.mirror;
  view.look_at = (scene.camera.location + axis) * scene.mirror;
  view.up = up * scene.mirror;
  view.projection = scene.camera.orthographic ? Projection::Orthographic : Projection::Perspective;
  view.ortho_height = glm::length(scene.camera.up);
  view.fov_y_degrees = 2 * std::atan(0.5 * glm::length(scene.camera.up) / distance) * 180 / std::numbers::pi;
  // POV-Ray stretches right x up over whatever image it renders; algray's images keep that shape by default.
  scene.width = image_width();
  scene.height =
      std::min(height_ > 0 ? height_
                           : std::max(1, static_cast<int>(std::lround(scene.width * glm::length(scene.camera.up) /
                                                                      glm::length(scene.camera.right)))),
               32768);
}

// A perspective camera without look_at whose direction is not normal to right and up: the image plane is the one
// right and up span, at the tip of direction, and the view is off its axis. algray's camera then looks along the
// plane's normal, `distance` away, with the image's centre shifted (camera.shift) to where direction meets it.
void PovReader::off_axis(Translated& scene, double& distance, glm::dvec3& axis) {
  const Camera& cam = scene.camera;
  const glm::dvec3 r = glm::normalize(cam.right), u = glm::normalize(cam.up);
  const PovToken& at = camera_at_ ? *camera_at_ : objects_.front().at;
  if (std::fabs(glm::dot(r, u)) > 1e-9) {
    warn(at, "the camera's right and up are not at right angles: POV-Ray shows the image sheared, algray does not");
    return;
  }
  glm::dvec3 normal = glm::cross(r, u);
  const glm::dvec3 direction = distance * glm::normalize(cam.direction);
  if (glm::dot(normal, direction) < 0) normal = -normal;
  const double along = glm::dot(normal, direction);
  if (along <= 1e-6 * distance)
    fail(at, "the camera's direction lies in the plane of its right and up: POV-Ray shows no image of it");
  const glm::dvec3 off = direction - along * normal;
  if (glm::length(off) <= 1e-12 * distance) return;  // on axis: the camera as before, bit for bit
  if (cam.orthographic) {
    warn(at, "an orthographic camera whose direction is not normal to right and up projects obliquely in "
             "POV-Ray; algray projects along direction");
    return;
  }
  scene.view.shift = glm::dvec2(glm::dot(off, r) / glm::length(cam.right), glm::dot(off, u) / glm::length(cam.up));
  if (!(std::fabs(scene.view.shift.x) <= kMaxCameraShift && std::fabs(scene.view.shift.y) <= kMaxCameraShift))
    fail(at, "the camera's direction points more than " + std::to_string(static_cast<int>(kMaxCameraShift)) +
                 " image widths or heights off its image: algray's off-axis views go that far");
  distance = along;
  axis = normal;
}

void PovReader::fit_extent(Translated& scene) {
  // The extent in algray's coordinates.
  const glm::dvec3 mirror = scene.mirror;
  const std::optional<Clip>& extent = scene.extent;
  const std::vector<const Object*>& open = scene.open;
  const CameraSpec& view = scene.view;
  std::optional<Clip>& drawn = scene.drawn;
  if (extent) {
    drawn = *extent;
    drawn->centre *= mirror;
    const glm::dvec3 a = extent->min * mirror, b = extent->max * mirror;
    drawn->min = glm::min(a, b);
    drawn->max = glm::max(a, b);
  }
  // bounded_by alone (common_region leaves no object without a region beside it): POV-Ray's rule is the gate.
  if (drawn && drawn->bound) {
    gate_reach(scene);
    return;
  }
  if (open.empty()) return;
  // Objects without a region: POV-Ray draws all of the surface that the rays meet, which no sphere or box holds in
  // general. algray draws within the sphere or box that agrees best with that on a grid of rays traced here.
  const double scale = std::max({1.0, glm::length(view.eye), drawn ? glm::length(drawn->centre - view.eye) : 0.0});
  const Sight sight = look(view, scene.width, scene.height, scene.polys, scale, scene.planes);
  std::vector<bool> shown;
  for (const Sight::Ray& r : sight.rays)
    shown.push_back(!r.roots.empty() && (!drawn || span(*drawn, r.o, r.d).has_value()));
  std::vector<Clip> candidates;
  if (drawn && !scene.camera.orthographic) {
    // The self-bounded objects' region moved k times as far from the eye: the same rays meet it, each over k
    // times its stretch.
    std::vector<double> ks = {1};
    for (int i = 1; i <= 40; ++i) {
      ks.push_back(std::pow(16.0, i / 40.0));
      ks.push_back(std::pow(0.5, i / 40.0));
    }
    std::sort(ks.begin(), ks.end(), [](double a, double b) { return std::fabs(std::log(a)) < std::fabs(std::log(b)); });
    for (double k : ks) {
      Clip c = *drawn;
      c.centre = view.eye + k * (c.centre - view.eye);
      c.radius *= k;
      c.min = view.eye + k * (c.min - view.eye);
      c.max = view.eye + k * (c.max - view.eye);
      candidates.push_back(c);
    }
  } else if (drawn) {
    candidates.push_back(*drawn);
  }
  for (double margin : {1.25, 1.1, 1.5, 2.0, 3.0})
    if (const auto c = seen_sphere(sight, shown, margin)) candidates.push_back(*c);
  const Object& o = *open.front();
  if (candidates.empty())
    fail(o.at, "this " + o.kind +
                   " has no clipped_by or bounded_by, and no ray of the camera meets it; POV-Ray draws it without "
                   "end, algray within a sphere or box: add clipped_by { sphere { ... } }");
  double best = -1;
  for (const Clip& c : candidates) {
    const double iou = agreement(sight, shown, c);
    if (iou > best + 1e-9) {
      best = iou;
      drawn = c;
    }
  }
  std::ostringstream note;
  note.precision(4);
  note << "no clipped_by or bounded_by: POV-Ray draws this " << o.kind << " without end; algray draws it within the "
       << (drawn->sphere ? "sphere" : "box") << " that agrees best with that on a " << Sight::kColumns << " x "
       << Sight::kRows << " grid of rays traced here (IoU " << best << ")";
  scene.extent_note = note.str();
  warn(o.at, scene.extent_note);
}

// The gate's reach: POV-Ray looks along a ray that meets the bound without end, algray within the far sphere, so
// the far sphere is made to hold the first surface point of every ray of a grid that passes the bound, with room
// to spare (kGateMargin), and never less than kDefaultGateReach. Where that needs more than kMaxGateReach, what
// lies beyond is not drawn, with a note.
void PovReader::gate_reach(Translated& scene) {
  // Beyond the farthest point seen: the grid's rays are kColumns x kRows of the image's, and a surface seen
  // through the bound can reach farther between them.
  constexpr double kGateMargin = 1.5;
  const Clip& gate = *scene.drawn;
  const glm::dvec3 centre = gate.sphere ? gate.centre : 0.5 * (gate.min + gate.max);
  const double radius = gate.sphere ? gate.radius : 0.5 * glm::length(gate.max - gate.min);
  const CameraSpec& view = scene.view;
  const double scale = std::max({1.0, glm::length(view.eye), glm::length(centre - view.eye)});
  const Sight sight = look(view, scene.width, scene.height, scene.polys, scale, scene.planes);
  double needed = 0;
  for (const Sight::Ray& r : sight.rays)
    if (!r.roots.empty() && span(gate, r.o, r.d))
      needed = std::max(needed, glm::length(r.o + r.roots.front() * r.d - centre) / radius);
  scene.gate_reach = std::clamp(needed * kGateMargin, kDefaultGateReach, kMaxGateReach);
  std::ostringstream note;
  note.precision(4);
  note << "bounded_by alone: a ray gate, as POV-Ray's; the rays that pass it see the surface within " << scene.gate_reach
       << " times its radius, which holds what a " << Sight::kColumns << " x " << Sight::kRows
       << " grid of rays traced here sees through it (the farthest " << needed << " times its radius away)";
  if (needed * kGateMargin > kMaxGateReach) {
    note.str("");
    note << "bounded_by alone: a ray gate, as POV-Ray's, whose rays see the surface within " << kMaxGateReach
         << " times its radius; POV-Ray draws surface up to " << needed << " times its radius away";
    warn(scene.clipped_by->at, note.str());
  }
  scene.extent_note = note.str();
}

PovTranslation PovReader::write_toml(const Translated& scene) const {
  std::ostringstream toml;
  const std::size_t slash = files_[0].text->source().find_last_of('/');
  const std::string file = files_[0].text->source().substr(slash == std::string::npos ? 0 : slash + 1);
  toml << "# Translated from " << files_[0].text->source() << " (POV-Ray)\n";
  if (scene.framed_by)
    toml << "# Written in the frame of the clipping box of the " << scene.framed_by->text << " at "
         << where(*scene.framed_by) << " (turned and moved from POV-Ray's world: the same picture)\n";
  for (std::size_t n = 0; n < objects_.size(); ++n) {
    const Object& o = objects_[n];
    toml << "\n[[surface]]\nname = " << toml_quoted(file + " " + std::to_string(n + 1) + " (" + o.kind + ")")
         << "\nterms = [";
    const char* sep = "";
    for (const auto& [e, c] : scene.polys[n].terms) {
      toml << sep << "[" << e[0] << ", " << e[1] << ", " << e[2] << ", " << toml_number(c) << "]";
      sep = ", ";
    }
    toml << "]\n";
    // POV-Ray's inside is P < 0, algray's back; without an interior texture both sides look alike.
    const glm::dvec3 front = o.front.value_or(glm::dvec3(0));
    const glm::dvec3 back = o.back.value_or(front);
    for (const auto& [side, colour] : {std::pair{"front", front}, std::pair{"back", back}})
      toml << "\n[surface.material." << side << "]\ncolour = " << toml_vector(glm::min(colour, glm::dvec3(1)))
           << "\nambient = " << toml_number(o.ambient) << "\ndiffuse = " << toml_number(o.diffuse)
           << "\nspecular = " << toml_number(o.specular) << "\nexponent = " << toml_number(o.exponent) << "\n";
  }

  const Clip& e = *scene.drawn;
  toml << "\n[extent]" << (scene.extent_note.empty() ? "" : "  # " + scene.extent_note) << "\n";
  if (e.sphere)
    toml << "type = \"sphere\"\ncentre = " << toml_vector(e.centre) << "\nradius = " << toml_number(e.radius) << "\n";
  else
    toml << "type = \"box\"\nmin = " << toml_vector(e.min) << "\nmax = " << toml_vector(e.max) << "\n";
  if (scene.gate_reach > 0) toml << "gate = true\nreach = " << toml_number(scene.gate_reach) << "\n";

  for (const glm::dvec4& p : scene.planes)
    toml << "\n[[clip]]  # clipped_by { plane }\nplane = [" << toml_number(p.x) << ", " << toml_number(p.y) << ", "
         << toml_number(p.z) << ", " << toml_number(p.w) << "]\n";

  toml << "\n[camera]\neye = " << toml_vector(scene.view.eye) << "\nlook_at = " << toml_vector(scene.view.look_at)
       << "\nup = " << toml_vector(scene.view.up) << "\n";
  if (scene.camera.orthographic)
    toml << "projection = \"orthographic\"\nheight = " << toml_number(scene.view.ortho_height) << "\n";
  else
    toml << "projection = \"perspective\"\nfov_y = " << toml_number(scene.view.fov_y_degrees) << "\n";
  if (scene.view.shift != glm::dvec2(0))
    toml << "shift = [" << toml_number(scene.view.shift.x) << ", " << toml_number(scene.view.shift.y)
         << "]  # POV-Ray's direction is not normal to its right and up: an off-axis view\n";

  toml << "\n[image]\nwidth = " << scene.width << "\nheight = " << scene.height
       << "\nbackground = " << toml_vector(glm::min(background_.value_or(glm::dvec3(0)), glm::dvec3(1))) << "\n";

  for (const PovLight& l : scene.lights) {
    const double strength = std::max({l.colour.x, l.colour.y, l.colour.z});
    toml << "\n[[light]]\ntype = \"" << (l.area ? "rectangle" : "point")
         << "\"\nposition = " << toml_vector(l.position * scene.mirror) << "\n";
    if (l.area)
      toml << "edge_u = " << toml_vector(l.edge_u * scene.mirror)
           << "\nedge_v = " << toml_vector(l.edge_v * scene.mirror) << "\nsamples = " << l.samples << "\n";
    toml << "colour = " << toml_vector(strength > 0 ? l.colour / strength : glm::dvec3(1))
         << "\nintensity = " << toml_number(strength) << "\nshadows = " << (l.shadows ? "true" : "false") << "\n";
  }
  if (scene.lights.empty())
    toml << "\n[[light]]  # POV-Ray lights nothing without a light_source\ntype = \"point\"\nposition = "
         << toml_vector(scene.camera.location * scene.mirror) << "\nintensity = 0.0\nshadows = false\n";
  return {toml.str(), where(objects_.front().at), excerpt(objects_.front().at)};
}

}  // namespace

PovTranslation povray_to_toml(const std::string& text, const std::string& source, std::vector<std::string>& warnings,
                              int width, int height) {
  return PovReader(text, source, warnings, width, height).run();
}

}  // namespace algray
