// surf scripts (`.pic`): the part of surf's command language its galleries use, run and written out as an algray
// scene with surf's framing.
#pragma once

#include <string>
#include <vector>

namespace algray {

// The scene a surf script draws, as algray TOML, so that --set overrides apply to it like to any scene.
// `drawn_at` is "file:line:column" of the draw_surface the scene comes from (errors the scene reader finds in
// the translation point there), `drawn_excerpt` that line with a caret.
struct SurfTranslation {
  std::string toml;
  std::string drawn_at, drawn_excerpt;
};

// Runs the script: variables, arithmetic on numbers and polynomials, `if (...) goto`, and the reserved
// variables of the subset (surfaces, position, clip, image, colours, lights, materials). Errors throw
// SceneError naming source:line:column; statements outside the subset are skipped with a located warning in
// `warnings`, and so is each drawing command algray cannot follow (cut_with_plane, draw_curve, ...).
// `width` and `height`, when nonzero, are the image size the scene will be rendered at (overrides of the
// script's): surf's framing depends on which side is shorter.
SurfTranslation surf_script_to_toml(const std::string& text, const std::string& source,
                                    std::vector<std::string>& warnings, int width = 0, int height = 0);

}  // namespace algray
