// Outside text (file names, the environment, drivers' strings) made fit for JSON, and JSON written without throwing.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace algray {

// Whether `text` is well-formed UTF-8 (no overlong forms, surrogates or code points past U+10FFFF).
bool is_utf8(std::string_view text);
// The offset of the byte that starts the first sequence that is not, or npos where all of `text` is.
std::size_t first_non_utf8(std::string_view text);

// `text` as UTF-8 for reading: unchanged when it is UTF-8 already, else with each byte that is not replaced by
// U+FFFD. For messages and names, where a reader needs the gist rather than the bytes.
std::string utf8_for_json(std::string_view text);

// The bytes of `text`, two lower-case hex digits each: a file name Linux allows but UTF-8 does not, kept exactly.
std::string hex_bytes(std::string_view text);

// object[key] = the path as readable text; where the path is not UTF-8 (Linux allows any byte but '/' and NUL),
// also object[key + "_bytes"] = its bytes in hex, so that a reader can get the exact file back.
void put_path(nlohmann::json& object, const std::string& key, const std::filesystem::path& path);

// The same for a list of paths: key_bytes, where present, has one entry per path (null for a UTF-8 one).
void put_paths(nlohmann::json& object, const std::string& key, const std::vector<std::string>& paths);

// j.dump(indent), except that a string which is not UTF-8 is written with U+FFFD where dump() would throw
// (nlohmann type_error 316): no JSON that algray writes can fail on a stray byte from outside.
std::string dump_json(const nlohmann::json& j, int indent = -1);

}  // namespace algray
