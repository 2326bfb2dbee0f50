// A scene rendered end to end: device, kernels, shading, metadata, image files and stats, for any front end.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "algray/device/cl_runtime.h"
#include "algray/device/program_cache.h"
#include "algray/render/renderer.h"
#include "algray/render/solver_aov.h"
#include "algray/scene/scene.h"

namespace algray {

// What a render writes besides rendering: the image files, stats, heat map and solver channels.
struct RenderOutputs {
  std::vector<std::string> images;          // image files; the format follows each extension
  std::optional<std::string> stats_path;    // the stats as JSON
  bool reference = false;                   // solve on the CPU with solver_ref instead of a device
  std::vector<SolverAov> aovs;              // solver channels added to EXR images
  std::optional<std::string> heatmap_path;  // solver work per pixel as a picture
  // Handed the rendered image after the files are written (a batch's --video keeps it); may be empty.
  std::function<void(FrameImage&&)> keep_image;
};

// How a render reports back while it runs: after each tile, and whether to stop (RenderCancelled).
struct RenderCallbacks {
  std::function<void(const RenderProgress&)> on_progress;
  std::function<bool()> cancelled;
  // Where the film's pixels come from when not from renderer.render(scene, options) alone: the bands of other
  // processes too (an MPI job, cluster/mpi_render.h). It returns what render() would, film and stats.
  std::function<RenderResult(Renderer& renderer, const Scene& scene, const RenderOptions& options)> render_pixels;
};

// A failure as a person reads it, and whether the input was at fault (a scene, an output path, a device: the
// command line's exit code 2) or not (a failed write, an OpenCL error: 1).
struct ErrorReport {
  std::string text;  // one or more lines, each ending in a newline
  bool bad_input = false;
};
ErrorReport describe_error(const std::exception& e);

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

// The device sessions and program cache, opened on first use and then shared by every render of the process:
// a batch compiles each kernel once and opens each device once. The spec is select_devices': one device, a
// list, or "all", which then render every image together.
class RenderContext {
 public:
  RenderContext(std::string device_spec, bool use_cache);
  ~RenderContext();
  // Throw DeviceError when a device cannot be opened.
  ClSession& session();  // the first device: the probe's, and the one an API user is told of
  std::vector<ClSession*> sessions();
  ProgramCache& cache();
  bool uses_cache() const { return use_cache_; }
  // The devices' renderer, made on first use and kept: it keeps each device's tile buffers between renders, so
  // the frames of a long-lived context (Python, the view, a batch) reuse them.
  Renderer& renderer();
  const Renderer* renderer_if_made() const { return renderer_.get(); }

 private:
  std::string device_spec_;
  bool use_cache_;
  std::vector<std::unique_ptr<ClSession>> sessions_;
  std::unique_ptr<ProgramCache> cache_;
  std::unique_ptr<Renderer> renderer_;  // after the sessions and the cache it uses: destroyed before them
};

// The scene a command names: a scene file, a PNG that algray rendered (its embedded scene), "-" for standard
// input, or, when unset, the built-in default. Standard input can be read once per loader: a second "-" is an
// error, not an empty scene. Throws SceneError.
class SceneLoader {
 public:
  Scene load(const std::optional<std::string>& path, const std::vector<Override>& overrides);

 private:
  bool stdin_read_ = false;
};

// The scene's warnings as the command line prints them: one "algray: warning: PREFIX..." line each.
std::string warning_text(const Scene& scene, const std::string& prefix = "");

// Bad input in the outputs (unknown format, missing or unwritable directory, an output that is the scene file
// `scene_path` or another output), found before any work: throws OutputError or SceneError.
void check_outputs(const Scene& scene, const RenderOutputs& outputs, const std::string& scene_path = "");

// Wall time of each step of the command, for --stats.
class PhaseTimer {
 public:
  explicit PhaseTimer(std::chrono::steady_clock::time_point start) : start_(start), last_(start) {}
  void mark(const std::string& phase) {
    const auto now = std::chrono::steady_clock::now();
    phases_.push_back({phase, std::chrono::duration<double, std::milli>(now - last_).count()});
    last_ = now;
  }
  // Moves `ms` of the last phase named `from` to a phase `to` (work done inside it, as the shading is inside
  // the render), so that the phases still add up to the total.
  void move(const std::string& from, const std::string& to, double ms) {
    for (auto it = phases_.rbegin(); it != phases_.rend(); ++it)
      if (it->first == from) {
        it->second -= ms;
        break;
      }
    phases_.push_back({to, ms});
  }
  double total_ms() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
  }
  nlohmann::json json() const {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& [name, ms] : phases_) j[name] = ms;
    return j;
  }

 private:
  std::chrono::steady_clock::time_point start_, last_;
  std::vector<std::pair<std::string, double>> phases_;
};

// A rendered frame in memory: the image with its metadata (and solver channels when asked for), the heat map when
// asked for, and what the stats are made of.
struct RenderedFrame {
  FrameImage image;
  std::optional<FrameImage> heatmap;
  RenderResult result;  // its image moved into `image`
  DeviceInfo device;    // the first of the devices (result.devices lists them all)
  PhaseTimer timer;     // the steps so far, from the command's start; the caller marks its own after
};

// What render_frame makes besides the colour: whether EXR's depth and normal channels are wanted (a PNG holds
// neither), the solver channels and the heat map.
struct FrameRequest {
  bool depth_and_normal = true;
  bool png = false;  // a PNG will be written: its sRGB table is made while the device starts
  bool reference = false;
  std::vector<SolverAov> aovs;
  bool heatmap = false;
  // One frame of a stream (the public API's renders): RenderOptions::race_precision.
  bool race_precision = false;
};

// Renders `scene` on the context's device (or with solver_ref) into memory. Throws on failure.
// `started`: when the command began, before the scene was read; the phases count from there.
RenderedFrame render_frame(const Scene& scene, const FrameRequest& request, RenderContext& context,
                           const RenderCallbacks& callbacks = {},
                           std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now());

// The --stats JSON of a frame: version, scene, device, solver, plan, passes, rays and timings.
nlohmann::json frame_stats(const Scene& scene, const RenderedFrame& frame, const std::vector<std::string>& images,
                           bool cache_used);

// Whether the outputs keep depth and normal (an EXR among them), so that the film needs them.
bool outputs_hold_depth(const RenderOutputs& outputs);

// Renders `scene` and writes the images, heat map and stats file; returns the stats. Throws on failure; outputs
// already written stay complete (each is replaced atomically).
nlohmann::json render_scene(const Scene& scene, const RenderOutputs& outputs, RenderContext& context,
                            const RenderCallbacks& callbacks = {},
                            std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now());

}  // namespace algray
