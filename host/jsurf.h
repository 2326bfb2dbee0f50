// SURFER/jsurf `.jsurf` files (Java properties) translated into an algray scene with jsurf's framing.
#pragma once

#include <string>
#include <vector>

namespace algray {

// The scene a .jsurf file describes, as algray TOML, so that --set overrides apply to it like to any scene.
// Errors (malformed values, unsupported features) throw SceneError naming source:line:column in the .jsurf
// text; features algray renders differently from jsurf, or ignores, are appended to `warnings`.
std::string jsurf_to_toml(const std::string& text, const std::string& source, std::vector<std::string>& warnings);

// Whether text read from standard input is a .jsurf file rather than TOML: it sets surface_equation as a
// Java property (TOML has no such top-level key in algray scenes).
bool looks_like_jsurf(const std::string& text);

}  // namespace algray
