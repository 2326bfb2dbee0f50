// The view server's checks of a request's text, settings, Host header and token, and a frame's cost.
#include "view_query.h"

#include <arpa/inet.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <set>
#include <sstream>

#include "algray/util/json_text.h"

namespace algray::cli {

std::optional<std::string> text_problem(std::string_view text) {
  // Whichever problem comes first in the text (a NUL byte is itself UTF-8).
  const std::size_t nul = text.find('\0'), bad = first_non_utf8(text);
  if (bad < nul) return "is not UTF-8 (byte " + std::to_string(bad + 1) + ")";
  if (nul != std::string_view::npos) return "holds a NUL byte at byte " + std::to_string(nul + 1);
  return std::nullopt;
}

std::vector<Setting> parse_settings(const std::vector<std::string>& items, int max_settings) {
  if (items.size() > static_cast<std::size_t>(max_settings))
    throw BadRequest("the request has " + std::to_string(items.size()) + " set= items; --max-settings allows " +
                         std::to_string(max_settings),
                     {}, 0, 413, "--max-settings");
  std::vector<Setting> settings;
  std::set<std::string> keys;
  for (const std::string& item : items) {
    if (const auto problem = text_problem(item)) throw BadRequest("a set= item " + *problem);
    const std::size_t eq = item.find('=');
    if (eq == 0 || eq == std::string::npos) throw BadRequest("a setting is key=value, not '" + item + "'");
    Setting s{item.substr(0, eq), item.substr(eq + 1)};
    if (!keys.insert(s.key).second)
      throw BadRequest("set= gives " + s.key + " more than once; a request gives each setting once", s.key);
    settings.push_back(std::move(s));
  }
  return settings;
}

bool is_loopback(const std::string& host) {
  if (host == "localhost") return true;
  unsigned char a[16];
  if (::inet_pton(AF_INET, host.c_str(), a) == 1) return a[0] == 127;
  if (::inet_pton(AF_INET6, host.c_str(), a) != 1) return false;
  static const unsigned char loopback6[16] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1};
  static const unsigned char mapped[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xFF, 0xFF};
  return std::memcmp(a, loopback6, 16) == 0 || (std::memcmp(a, mapped, 12) == 0 && a[12] == 127);
}

bool is_loopback_host_header(const std::string& host_header) {
  std::string host = host_header, port;
  if (!host.empty() && host.front() == '[') {
    const std::size_t close = host.find(']');
    if (close == std::string::npos) return false;
    port = host.substr(close + 1);
    host = host.substr(1, close - 1);
    if (!port.empty() && port.front() != ':') return false;
  } else if (const std::size_t colon = host.find(':'); colon != std::string::npos) {
    port = host.substr(colon);
    host.resize(colon);
  }
  if (!port.empty()) {
    port.erase(0, 1);
    if (port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos) return false;
  }
  // localhost. with the root's dot is the same name.
  if (host == "localhost.") host.pop_back();
  for (char& c : host) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return is_loopback(host);
}

bool token_matches(const std::string& given, const std::string& token) {
  unsigned diff = given.size() != token.size();
  for (std::size_t i = 0; i < token.size(); ++i)
    diff |= static_cast<unsigned char>(token[i]) ^ static_cast<unsigned char>(i < given.size() ? given[i] : 0);
  return diff == 0;
}

std::string format_number(double x) {
  std::ostringstream out;
  out << x;
  return out.str();
}

namespace {

// Whether a material table (or one nested in it) lets rays go on: reflectivity or transparency above zero.
bool passes_rays_on(const toml::table& t) {
  for (const auto& [key, node] : t) {
    if ((key == "reflectivity" || key == "transparency") && node.value_or(0.0) > 0) return true;
    if (const toml::table* sub = node.as_table(); sub && passes_rays_on(*sub)) return true;
  }
  return false;
}

}  // namespace

std::uint64_t frame_samples(const std::string& scene_toml, int width, int height, bool full) {
  const toml::table t = toml::parse(scene_toml);
  const std::uint64_t aa = static_cast<std::uint64_t>(std::max<std::int64_t>(1, t["antialias"]["samples"].value_or(1)));
  const std::uint64_t camera = static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) * aa * aa;
  std::uint64_t shadow_points = 0;
  if (full)
    if (const toml::array* lights = t["light"].as_array())
      for (const toml::node& l : *lights)
        if (const toml::table* light = l.as_table(); light && (*light)["shadows"].value_or(true)) {
          const std::uint64_t n =
              static_cast<std::uint64_t>(std::max<std::int64_t>(1, (*light)["samples"].value_or(1)));
          shadow_points += n * n;
        }
  bool bounces = false;
  const toml::node* surfaces = t.get("surface");
  if (const toml::table* one = surfaces ? surfaces->as_table() : nullptr) bounces = passes_rays_on(*one);
  if (const toml::array* many = surfaces ? surfaces->as_array() : nullptr)
    for (const toml::node& s : *many)
      if (const toml::table* st = s.as_table()) bounces = bounces || passes_rays_on(*st);
  const std::uint64_t depth =
      bounces ? static_cast<std::uint64_t>(std::max<std::int64_t>(0, t["render"]["max_depth"].value_or(0))) : 0;
  return camera * (1 + shadow_points) * (1 + depth);
}

}  // namespace algray::cli
