// One `algray render` invocation end to end: scene, device, kernels, shading, image files and stats.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "algray/device/cl_runtime.h"
#include "algray/device/program_cache.h"
#include "algray/scene/scene.h"
#include "algray/render/solver_aov.h"

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

// A file a command reads or writes, named by its role for messages: {"--stats", "s.json"}.
struct RoleAndPath {
  std::string role;
  std::string path;
};

// Throws OutputError when an output is one of the inputs, or two outputs are one file, by any spelling (a/../b,
// a hard or symbolic link): the run would destroy its own input or write one file twice.
void check_distinct_files(const std::vector<RoleAndPath>& inputs, const std::vector<RoleAndPath>& outputs);

// The render finished but not every file was written (a full disk, say): a failure (exit 1), not bad input. The
// message names what was written and what was not.
struct IncompleteOutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Writes a command's outputs one after another once its work is done. A failure then is not bad input: it throws
// IncompleteOutputError with the reason, what was written and what was not (this one and those planned after it).
class OutputWriter {
 public:
  explicit OutputWriter(std::vector<std::string> planned) : planned_(std::move(planned)) {}
  void write(const std::string& path, const std::function<void()>& write_file);

 private:
  std::vector<std::string> planned_;  // every output, in the order they are written
  std::vector<std::string> written_;
};

// Throws OutputError when `path` cannot be written (missing or unwritable directory, or a directory itself): bad
// input, found before any work.
void check_output_writable(const std::string& path);

// The device session and program cache, opened on first use and then shared by every render of the process:
// a batch compiles each kernel once and opens the device once.
class RenderContext {
 public:
  RenderContext(std::string device_spec, bool use_cache);
  ~RenderContext();
  ClSession& session();  // throws DeviceError when the device cannot be opened
  ProgramCache& cache();

 private:
  std::string device_spec_;
  bool use_cache_;
  std::unique_ptr<ClSession> session_;
  std::unique_ptr<ProgramCache> cache_;
};

// The scene a command names: a scene file, "-" for standard input (once per process), or, when unset, the
// built-in default. Throws SceneError.
Scene load_scene(const std::optional<std::string>& path, const std::vector<Override>& overrides);

// The scene's warnings, one "algray: warning: ..." line each.
void print_warnings(const Scene& scene, std::ostream& err, const std::string& prefix = "");

// Bad input in the request's outputs (unknown format, missing or unwritable directory), found before any work:
// throws OutputError or SceneError.
void check_outputs(const Scene& scene, const RenderRequest& request);

// Renders `scene` on the context's device and writes the request's images, heat map and stats file; returns
// the stats. Throws on failure; outputs already written stay complete (each is replaced atomically).
// `started`: when the command began, before the scene was read; the stats' phases and total count from there.
nlohmann::json render_scene(const Scene& scene, const RenderRequest& request, RenderContext& context,
                            std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now());

// Prints a failure as the CLI does and returns its exit code: bad input (scene, output path, device) is 2,
// anything else 1.
int report_error(const std::exception& e, std::ostream& err);

// Runs the request, printing errors (and nothing else on success, unless progress) to `err`.
int run_render(const RenderRequest& request, std::ostream& err);

}  // namespace algray
