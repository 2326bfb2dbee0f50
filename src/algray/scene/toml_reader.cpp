// Edit distance for the TOML readers' key suggestions.
#include "algray/scene/toml_reader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

#include "algray/scene/located_text.h"

namespace algray {

std::string toml_quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string toml_number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  std::string s = buf;
  if (std::isfinite(v) && s.find_first_of(".eE") == std::string::npos) s += ".0";
  if (!std::isfinite(v)) s = std::isnan(v) ? "nan" : v > 0 ? "inf" : "-inf";
  return s;
}

std::string toml_vector(const glm::dvec3& v) {
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "[" + std::string.
  std::string out = "[";
  out += toml_number(v.x);
  out += ", ";
  out += toml_number(v.y);
  out += ", ";
  out += toml_number(v.z);
  out += "]";
  return out;
}

bool is_identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isalnum(c) || c == '_'; });
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] != b[j - 1] ? 1u : 0u)});
      diag = up;
    }
  }
  return row[b.size()];
}

}  // namespace algray

namespace algray {
namespace {

bool is_bare_key_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '+';
}

}  // namespace

void check_toml_shape(const std::string& text, const std::string& source) {
  // A light lexer, not a parser: it skips strings and comments and counts the segments of each dotted chain
  // (a.b.c, also 1.5, which counts 2) and the depth of [ and {. toml++ recurses once per segment, so a key of
  // 50,000 parts overflowed the stack; nothing real comes near these limits.
  TextCursor cursor(text);
  const std::size_t& i = cursor.i;
  const auto advance = [&](std::size_t n) { cursor.advance(n); };
  std::size_t chain = 0, chain_line = 0, chain_column = 0;
  bool after_dot = false;  // the chain's last token was a dot, so the next segment continues it
  int depth = 0;
  const auto fail = [&](std::size_t l, std::size_t c, const std::string& message) {
    throw SceneError(source + ":" + std::to_string(l) + ":" + std::to_string(c), message);
  };
  const auto segment = [&](std::size_t l, std::size_t c) {
    if (!after_dot || chain == 0) {
      chain = 0;
      chain_line = l;
      chain_column = c;
    }
    after_dot = false;
    if (++chain > kMaxTomlKeyParts)
      fail(chain_line, chain_column,
           "a dotted key (or value) with more than " + std::to_string(kMaxTomlKeyParts) + " parts");
  };
  while (!cursor.done()) {
    const char c = text[i];
    const std::size_t l = static_cast<std::size_t>(cursor.line), col = static_cast<std::size_t>(cursor.column);
    if (c == '#') {
      while (i < text.size() && text[i] != '\n') advance(1);
      continue;
    }
    if (c == '"' || c == '\'') {
      const bool triple = text.compare(i, 3, std::string(3, c)) == 0;
      advance(triple ? 3 : 1);
      while (i < text.size()) {
        if (c == '"' && text[i] == '\\') {
          advance(2);
          continue;
        }
        if (triple ? text.compare(i, 3, std::string(3, c)) == 0 : text[i] == c) {
          advance(triple ? 3 : 1);
          break;
        }
        if (!triple && text[i] == '\n') break;  // unterminated: toml++ reports it
        advance(1);
      }
      segment(l, col);
      continue;
    }
    if (is_bare_key_char(c)) {
      while (i < text.size() && is_bare_key_char(text[i])) advance(1);
      segment(l, col);
      continue;
    }
    if (c == ' ' || c == '\t') {
      advance(1);
      continue;
    }
    if (c == '.' && chain > 0 && !after_dot) {
      after_dot = true;
      advance(1);
      continue;
    }
    chain = 0;
    after_dot = false;
    if (c == '[' || c == '{') {
      if (++depth > kMaxTomlNesting)
        fail(l, col, "arrays and tables nested more than " + std::to_string(kMaxTomlNesting) + " deep");
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
    advance(1);
  }
}

}  // namespace algray
