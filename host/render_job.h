// One `algray render` invocation end to end: scene, device, kernels, shading, image files and stats.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "scene.h"
#include "solver_aov.h"

namespace algray {

// Exit codes of the CLI: bad input is 2 (nothing written), any other failure is 1.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitBadInput = 2;

struct RenderRequest {
  std::optional<std::string> scene_path;    // unset: the built-in default scene
  std::vector<Override> overrides;          // --set, --width, --height, --precision, in order
  std::vector<std::string> outputs;         // image files; the format follows each extension
  std::string device_spec;                  // --device
  bool use_cache = true;                    // --no-cache turns it off
  std::optional<std::string> stats_path;    // --stats FILE.json
  bool progress = false;                    // per-tile progress on stderr
  bool reference = false;                   // --reference: solve on the CPU with solver_ref instead of a device
  std::vector<SolverAov> aovs;              // --aov: solver channels added to EXR outputs
  std::optional<std::string> heatmap_path;  // --heatmap: solver work per pixel as a picture
};

// Throws OutputError when `path` cannot be written (missing or unwritable directory, or a directory itself): bad
// input, found before any work.
void check_output_writable(const std::string& path);

// Runs the request, printing errors (and nothing else on success, unless progress) to `err`.
int run_render(const RenderRequest& request, std::ostream& err);

}  // namespace algray
