// Reading TOML files with located errors: typed accessors that throw SceneError naming file:line:column.
#pragma once

#include <toml++/toml.h>

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "algray/scene/scene.h"

namespace algray {

// A string or a float as TOML text, read back exactly: control characters escaped, floats to 17 digits.
std::string toml_quoted(const std::string& s);
std::string toml_number(double v);
std::string toml_vector(const glm::dvec3& v);  // [x, y, z], each as toml_number

// A letter or _, then letters, digits or _: a bare TOML key segment, and a parameter name.
bool is_identifier(const std::string& s);

// Limits on the shape of TOML text that check_toml_shape enforces before toml++ sees it: its parser recurses per
// key part and per nested value, and a hostile file must get an error, not a stack overflow.
inline constexpr std::size_t kMaxTomlKeyParts = 32;
// The largest scene coordinate or length, and (its inverse) the smallest extent: see TomlReader::coordinate.
inline constexpr double kMaxCoordinate = 1e18;
inline constexpr int kMaxTomlNesting = 64;

// Throws SceneError at source:line:column when a dotted key has more than kMaxTomlKeyParts parts or arrays and
// inline tables nest deeper than kMaxTomlNesting.
void check_toml_shape(const std::string& text, const std::string& source);

// Levenshtein distance, to suggest the key the user probably meant.
std::size_t edit_distance(const std::string& a, const std::string& b);

// Wraps one TOML text: every accessor checks a node's type and range and fails with its source position and
// an excerpt of the line. Nodes created by --set carry the override as their source and are named by it.
class TomlReader {
 public:
  TomlReader(std::string source, const std::string& text) : source_(std::move(source)) {
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines_.push_back(line);
  }

  [[noreturn]] void fail(const toml::source_region& region, const std::string& message,
                         std::size_t column_offset = 0) const {
    const auto& path = region.path;
    // A node from an override carries the override as its path: it has no line of this text to show.
    if (path && *path != source_) throw SceneError(*path, message);
    if (region.begin.line == 0) throw SceneError(source_, message);
    const std::size_t line = region.begin.line;
    const std::size_t column = region.begin.column + column_offset;
    std::string excerpt;
    if (line <= lines_.size()) {
      excerpt = "  " + lines_[line - 1] + "\n  " + std::string(column > 0 ? column - 1 : 0, ' ') + "^";
    }
    throw SceneError(source_ + ":" + std::to_string(line) + ":" + std::to_string(column), message, excerpt);
  }

  const std::string& source() const { return source_; }

  const std::string& line_text(std::size_t line) const {
    static const std::string empty;
    return line >= 1 && line <= lines_.size() ? lines_[line - 1] : empty;
  }

  double number(const toml::node& node, const std::string& what) const {
    double v;
    if (auto i = node.value_exact<std::int64_t>())
      v = static_cast<double>(*i);
    else if (auto f = node.value_exact<double>())
      v = *f;
    else
      fail(node.source(), what + " must be a number");
    if (!std::isfinite(v))
      fail(node.source(), what + " must be finite, not " + std::string(std::isnan(v) ? "nan" : "inf"));
    return v;
  }

  long long integer(const toml::node& node, const std::string& what, long long lo, long long hi) const {
    auto i = node.value_exact<std::int64_t>();
    if (!i) fail(node.source(), what + " must be an integer");
    if (*i < lo || *i > hi)
      fail(node.source(), what + " must be between " + std::to_string(lo) + " and " + std::to_string(hi));
    return *i;
  }

  bool boolean(const toml::node& node, const std::string& what) const {
    auto b = node.value_exact<bool>();
    if (!b) fail(node.source(), what + " must be true or false");
    return *b;
  }

  // A number in [lo, hi].
  double number_in(const toml::node& node, const std::string& what, double lo, double hi) const {
    const double v = number(node, what);
    if (v < lo || v > hi) {
      std::ostringstream range;
      range << what << " must be between " << lo << " and " << hi;
      fail(node.source(), range.str());
    }
    return v;
  }

  std::string string(const toml::node& node, const std::string& what) const {
    auto s = node.value_exact<std::string>();
    if (!s) fail(node.source(), what + " must be a string");
    return *s;
  }

  // A point or vector of the scene: each component within +-kMaxCoordinate.
  glm::dvec3 vec3(const toml::node& node, const std::string& what) const {
    const toml::array* a = node.as_array();
    if (!a || a->size() != 3) fail(node.source(), what + " must be an array of 3 numbers");
    glm::dvec3 v;
    for (int i = 0; i < 3; ++i)
      v[i] = coordinate(*a->get(static_cast<std::size_t>(i)), what + "[" + std::to_string(i) + "]");
    return v;
  }

  // A coordinate or length of the scene. Beyond kMaxCoordinate, squared lengths overflow float, and the rays, extent
  // and lights would turn into inf and nan somewhere between here and the kernels.
  double coordinate(const toml::node& node, const std::string& what) const {
    const double v = number(node, what);
    if (std::fabs(v) > kMaxCoordinate)
      fail(node.source(), what + " is too large: scene coordinates and lengths must be within +-1e18");
    return v;
  }

  glm::dvec4 colour(const toml::node& node, const std::string& what, bool allow_alpha) const {
    const toml::array* a = node.as_array();
    if (!a || a->size() < 3 || a->size() > (allow_alpha ? 4u : 3u))
      fail(node.source(), what + " must be an array of 3" + std::string(allow_alpha ? " or 4" : "") +
                              " numbers (linear RGB" + (allow_alpha ? "[A]" : "") + ")");
    glm::dvec4 c{0, 0, 0, 1};
    for (std::size_t i = 0; i < a->size(); ++i) {
      c[static_cast<int>(i)] = number(*a->get(i), what);
      if (c[static_cast<int>(i)] < 0) fail(a->get(i)->source(), what + " components must not be negative");
    }
    if (c.a > 1) fail(a->get(3)->source(), what + " alpha must be at most 1");
    return c;
  }

  // Rejects keys that are not in `allowed`, suggesting the nearest allowed one.
  void check_keys(const toml::table& table, const std::string& table_name, const std::set<std::string>& allowed) const {
    for (auto&& [key, node] : table) {
      const std::string k(key.str());
      if (allowed.count(k)) continue;
      std::string hint;
      std::size_t best = 3;
      for (const std::string& a : allowed)
        if (std::size_t d = edit_distance(k, a); d < best) {
          best = d;
          hint = a;
        }
      std::string message = "unknown key '" + (table_name.empty() ? k : table_name + "." + k) + "'";
      if (!hint.empty()) message += " (did you mean '" + hint + "'?)";
      std::string known;
      for (const std::string& a : allowed) known += (known.empty() ? "" : ", ") + a;
      message += "; allowed here: " + known;
      fail(key.source().begin.line ? key.source() : node.source(), message);
    }
  }

  const toml::table* subtable(const toml::table& root, const std::string& name) const {
    const toml::node* n = root.get(name);
    if (!n) return nullptr;
    if (!n->is_table()) fail(n->source(), "'" + name + "' must be a table ([" + name + "])");
    return n->as_table();
  }

  // Column of character `offset` of a string value, counting escapes as one character.
  std::size_t string_column_offset(const toml::node& node, std::size_t offset) const {
    const std::string& line = line_text(node.source().begin.line);
    std::size_t col = node.source().begin.column;  // 1-based, at the opening quote
    if (col == 0 || col > line.size()) return 0;
    const char quote = line[col - 1];
    if ((quote != '"' && quote != '\'') || line.compare(col - 1, 3, std::string(3, quote)) == 0) return 0;
    std::size_t i = col, chars = 0;  // i: 0-based index of the first character inside the quotes
    while (i < line.size() && chars < offset && line[i] != quote) {
      if (quote == '"' && line[i] == '\\' && i + 1 < line.size()) {
        const char e = line[i + 1];
        i += e == 'u' ? 6 : e == 'U' ? 10 : 2;
      } else {
        ++i;
      }
      ++chars;
    }
    return i + 1 - col;
  }

 private:
  std::string source_;
  std::vector<std::string> lines_;
};

}  // namespace algray
