// SURFER/jsurf `.jsurf` files (Java properties) translated into an algray scene with jsurf's framing.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace algray {

// The scene a .jsurf file describes, as algray TOML, so that --set overrides apply to it like to any scene.
// Errors (malformed values, unsupported features) throw SceneError naming source:line:column in the .jsurf
// text; features algray renders differently from jsurf, or ignores, are appended to `warnings`.
// Where a line of the translated TOML came from: "file:line:column" in the .jsurf, the property's key and that
// line of the file with a caret under the value.
struct JsurfOrigin {
  std::string where, key, excerpt;
};
// `origins`, when given, receives the origin of each TOML line (1-based) made from a property's value.
std::string jsurf_to_toml(const std::string& text, const std::string& source, std::vector<std::string>& warnings,
                          std::map<int, JsurfOrigin>* origins = nullptr);

// Whether text read from standard input is a .jsurf file rather than TOML: it sets surface_equation as a
// Java property (TOML has no such top-level key in algray scenes).
bool looks_like_jsurf(const std::string& text);

}  // namespace algray
