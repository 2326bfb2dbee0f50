// The kinds of scene file algray reads, by extension: the one list the loader, the help text, the error for an
// unknown type and the tests read.
#pragma once

#include <array>
#include <optional>
#include <string>

namespace algray {

enum class SceneFormat { Toml, Jsurf, SurfScript, PovRay, Png };

struct SceneFormatInfo {
  SceneFormat format;
  const char* extension;  // lower case, with its dot; files match it in any case
  const char* what;       // for people: "a SURFER file"
};

inline constexpr std::array<SceneFormatInfo, 5> kSceneFormats = {{
    {SceneFormat::Toml, ".toml", "an algray scene"},
    {SceneFormat::Jsurf, ".jsurf", "a SURFER/jsurf file"},
    {SceneFormat::SurfScript, ".pic", "a surf script"},
    {SceneFormat::PovRay, ".pov", "a POV-Ray scene"},
    {SceneFormat::Png, ".png", "an image algray rendered, which carries its scene"},
}};

// The format a scene path names by its extension (any case). A path without an extension is TOML, as it always
// was; nullopt for any other extension.
std::optional<SceneFormat> scene_format_of(const std::string& path);

// ".toml (an algray scene), .jsurf (a SURFER/jsurf file), ..." for help texts and messages.
std::string readable_scene_types();

// The SceneError message for a path whose extension is none of kSceneFormats.
std::string unknown_scene_type_message(const std::string& path);

}  // namespace algray
