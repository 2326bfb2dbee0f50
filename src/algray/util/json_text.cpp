// Outside text made fit for JSON: a UTF-8 check, readable and exact forms of a path, and a dump that never throws.
#include "algray/util/json_text.h"

namespace algray {

namespace {

// The length of the UTF-8 sequence at text[i], or 0 where the bytes there are not one (RFC 3629's table).
std::size_t sequence_length(std::string_view text, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char b0 = byte(i);
  if (b0 < 0x80) return 1;
  std::size_t n = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // the allowed range of the second byte
  if (b0 >= 0xC2 && b0 <= 0xDF) {
    n = 2;
  } else if (b0 >= 0xE0 && b0 <= 0xEF) {
    n = 3;
    if (b0 == 0xE0) lo = 0xA0;  // overlong
    if (b0 == 0xED) hi = 0x9F;  // surrogates
  } else if (b0 >= 0xF0 && b0 <= 0xF4) {
    n = 4;
    if (b0 == 0xF0) lo = 0x90;  // overlong
    if (b0 == 0xF4) hi = 0x8F;  // past U+10FFFF
  } else {
    return 0;
  }
  if (i + n > text.size()) return 0;
  if (byte(i + 1) < lo || byte(i + 1) > hi) return 0;
  for (std::size_t k = 2; k < n; ++k)
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
  return n;
}

}  // namespace

std::size_t first_non_utf8(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = sequence_length(text, i);
    if (n == 0) return i;
    i += n;
  }
  return std::string_view::npos;
}

bool is_utf8(std::string_view text) { return first_non_utf8(text) == std::string_view::npos; }

std::string utf8_for_json(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = sequence_length(text, i);
    if (n == 0) {
      out += "\xEF\xBF\xBD";
      ++i;
    } else {
      out.append(text.substr(i, n));
      i += n;
    }
  }
  return out;
}

std::string hex_bytes(std::string_view text) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string out;
  out.reserve(2 * text.size());
  for (const char c : text) {
    const auto b = static_cast<unsigned char>(c);
    out += kDigits[b >> 4];
    out += kDigits[b & 0xF];
  }
  return out;
}

void put_path(nlohmann::json& object, const std::string& key, const std::filesystem::path& path) {
  const std::string& text = path.native();
  object[key] = utf8_for_json(text);
  if (!is_utf8(text)) object[key + "_bytes"] = hex_bytes(text);
}

void put_paths(nlohmann::json& object, const std::string& key, const std::vector<std::string>& paths) {
  nlohmann::json readable = nlohmann::json::array();
  nlohmann::json bytes = nlohmann::json::array();
  bool exact_needed = false;
  for (const std::string& p : paths) {
    readable.push_back(utf8_for_json(p));
    const bool utf8 = is_utf8(p);
    exact_needed = exact_needed || !utf8;
    bytes.push_back(utf8 ? nlohmann::json() : nlohmann::json(hex_bytes(p)));
  }
  object[key] = std::move(readable);
  if (exact_needed) object[key + "_bytes"] = std::move(bytes);
}

std::string dump_json(const nlohmann::json& j, int indent) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace algray
