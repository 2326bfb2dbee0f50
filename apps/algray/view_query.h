// What the view server checks in a request before any scene work: text, settings, Host, token and frame cost.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace algray::cli {

// A request the page should not have sent, a scene setting the scene refuses, or a limit passed: answered with
// `status` and its reason, never a crash. key: the setting at fault, if one; column: where in its value (the
// command line's "character"); limit: the flag of the limit it passed, if one.
struct BadRequest : std::runtime_error {
  BadRequest(const std::string& what, std::string key_ = {}, int column_ = 0, int status_ = 400,
             std::string limit_ = {})
      : std::runtime_error(what), key(std::move(key_)), column(column_), status(status_), limit(std::move(limit_)) {}
  std::string key;
  int column;
  int status;
  std::string limit;
};

// Why `text` cannot be a parameter's name or value (a NUL byte, bytes that are not UTF-8), else nothing. Scene
// keys and values are text; a NUL would also cut C strings, and so the messages that quote the value, short.
std::optional<std::string> text_problem(std::string_view text);

// One set= item, split at its first '='.
struct Setting {
  std::string key, value;
};

// The set= items of a request, checked: at most `max_settings` (--max-settings), each key=value text, and each
// key once (a repeated key only repeats work: the last would win).
std::vector<Setting> parse_settings(const std::vector<std::string>& items, int max_settings);

// Whether an address to listen on reaches this machine only: localhost, 127.0.0.0/8, ::1 (or ::ffff:127.x.y.z).
bool is_loopback(const std::string& host);

// Whether a Host header names this server as a page on this machine would: localhost or a loopback address,
// with or without a port. Any other name is what a DNS-rebinding page sends.
bool is_loopback_host_header(const std::string& host_header);

// Whether `given` is `token`, in time that does not depend on where they differ.
bool token_matches(const std::string& given, const std::string& token);

// A number as a person writes it in a message: 2, 0.5, 1e+06.
std::string format_number(double x);

// A frame's cost in the unit of --max-frame-samples: camera rays x (1 + shadow points per hit, full mode only) x
// (1 + bounces, where a surface reflects or transmits), from the scene as TOML.
std::uint64_t frame_samples(const std::string& scene_toml, int width, int height, bool full);

}  // namespace algray::cli
