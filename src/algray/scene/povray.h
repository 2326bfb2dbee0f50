// POV-Ray scenes (`.pov`): the algebraic objects, their transforms and clips, the camera, lights, pigments and
// background, written out as an algray scene that shows what POV-Ray shows.
#pragma once

#include <string>
#include <vector>

namespace algray {

// The scene as algray TOML. `width` and `height` are the size it will be rendered at (0: algray's 800 x 600);
// POV-Ray's `image_width` and `image_height` read them. Errors throw SceneError at source:line:column; what
// the reader skips (textures' finishes, media, other objects, #include, ...) is a located warning naming it.
// `first_object_at` and its excerpt locate errors the scene reader finds in the translation.
struct PovTranslation {
  std::string toml;
  std::string first_object_at, first_object_excerpt;
};
PovTranslation povray_to_toml(const std::string& text, const std::string& source, std::vector<std::string>& warnings,
                              int width = 0, int height = 0);

}  // namespace algray
