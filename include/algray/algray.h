// The public C++ API of algray: scenes, devices, renders into memory, probes and batches, with typed errors.
//
// Everything here is the renderer the command line runs, reached without files or exit codes:
//
//   #include <algray/algray.h>
//   algray::api::Scene scene = algray::api::Scene::load("scenes/torus.toml");
//   scene.set("camera.fov_y", "30");
//   algray::api::Renderer renderer;                      // the first GPU, else the first device
//   algray::api::Image image = renderer.render(scene, {.width = 640, .height = 480, .preview = true});
//   image.save("torus.png");                             // the format follows the extension, written atomically
//
// A program links the CMake target algray::algray (find_package(algray)). The types below hold the library's
// own objects behind pointers, so this header needs nothing but the standard library.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace algray::api {

// "algray 0.1.0 (git abc1234)": the release and the revision the library was built from.
std::string version();

// Where the library's warnings about the process as a whole go, each one or more lines ending in a newline: so
// far, a kernel cache directory that cannot be used (said once per directory). Unset, they are dropped.
void set_warning_handler(std::function<void(const std::string&)> handler);

// Bad scene input. `file`, `line` and `column` say where (line and column are 0 where the input has none, as
// for a --set key or a missing file); `message` says what, `excerpt` shows the line with a caret under the
// column. what() is the whole text the command line prints.
struct SceneError : std::runtime_error {
  SceneError(const std::string& what, std::string file, int line, int column, std::string message, std::string excerpt);
  std::string file;
  int line = 0, column = 0;
  std::string message, excerpt;
};

// No device matches, or the device cannot do what the scene asks (double precision without fp64, too little
// memory for the image).
struct DeviceError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// An output that cannot be written as asked (unknown extension, missing or unwritable directory).
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A render stopped by its `cancelled` callback.
struct Cancelled : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// One OpenCL device, as `algray devices` lists it.
struct Device {
  int index = 0;  // what Renderer's `device` accepts as digits
  std::string platform, platform_version, name, vendor, version, driver, type;
  unsigned compute_units = 0;
  bool fp64 = false;
  std::uint64_t global_mem_bytes = 0, max_alloc_bytes = 0;
};
std::vector<Device> devices();

// A scene: a file or text read once, plus the keys set on it since, in order. Copies are independent.
class Scene {
 public:
  // A .toml or .jsurf file (by extension), or a PNG that algray rendered (the scene it embeds).
  static Scene load(const std::string& path);
  static Scene from_toml(const std::string& text, const std::string& name = "<string>");
  static Scene from_jsurf(const std::string& text, const std::string& name = "<string>");
  // The built-in default scene (the Barth sextic), as `algray render` without a scene renders it.
  static Scene default_scene();
  // An equation alone, with algray's defaults for the rest (`algray render -e EQUATION`).
  static Scene from_equation(const std::string& equation);

  // Sets a dotted scene key, or a parameter by its bare name, as `--set key=value` does: the value is read as
  // TOML ("30", "[0, 0, 5]", "\"sturm\""), or as a string when it is not valid TOML. Throws SceneError, and
  // then leaves the scene as it was.
  Scene& set(const std::string& key, const std::string& value);

  // The scene as TOML that reads back to the same scene, value for value.
  std::string to_toml() const;
  std::string name() const;
  std::string source() const;  // the file's path, or the name given with the text
  int width() const;
  int height() const;
  std::vector<std::string> equations() const;                      // one per surface, as written
  std::vector<std::pair<std::string, double>> parameters() const;  // name and value, sorted by name
  std::vector<std::string> warnings() const;                       // what the reader could not render as written
  // The camera as camera.azimuth, camera.elevation and camera.distance (degrees, degrees, world units) about its
  // look-at point, whether the scene placed it by them or by its eye: what set("camera.azimuth", ...) changes.
  std::array<double, 3> camera_angles() const;

  struct State;  // the library's scene and how to read it again

 private:
  explicit Scene(std::shared_ptr<const State> state) : state_(std::move(state)) {}
  std::shared_ptr<const State> state_;
  friend class Renderer;
};

// How far a render is: called after each tile on the rendering thread.
struct Progress {
  int tiles_done = 0, tiles_total = 0;
};

struct RenderSettings {
  int width = 0, height = 0;  // 0: the scene's image size; negative is refused (SceneError)
  bool preview = false;       // the paper's preview mode: no shadows (render.preview)
  std::string precision;      // "float", "double", "mixed" or "auto"; empty: the scene's
  // Solver channels: "iterations", "isolation", "classification", "flags" (the command line's --aov).
  std::vector<std::string> aovs;
  bool reference = false;  // every pixel solved exactly on the CPU by solver_ref instead of the device
  // Keep depth and normals (EXR's Z and N channels). Without them the film is half the size, as for a PNG, and
  // Image::depth() and normal() are empty.
  bool depth_and_normal = true;
  std::function<void(const Progress&)> on_progress;
  std::function<bool()> cancelled;  // asked before each tile; true stops the render with Cancelled
};

// A rendered image: row-major, top row first, linear colour; with the scene, solver and camera as metadata.
class Image {
 public:
  int width() const;
  int height() const;
  const std::vector<float>& rgba() const;    // 4 per pixel, straight alpha
  const std::vector<float>& depth() const;   // 1 per pixel: distance from the eye, +inf on a miss
  const std::vector<float>& normal() const;  // 3 per pixel: unit world-space normal, 0 on a miss
  // Solver channels by name ("solver.iterations", ...), one value per pixel.
  std::vector<std::string> channel_names() const;
  std::optional<std::vector<std::uint32_t>> uint_channel(const std::string& name) const;
  std::optional<std::vector<float>> float_channel(const std::string& name) const;
  // The --stats JSON of the render: passes, kernels, rays, timings.
  const std::string& stats_json() const;
  // .exr (every channel, the metadata) or .png (colour, and the scene to render it again), atomically.
  void save(const std::string& path) const;
  // The bytes save("x.png") writes, the scene included, without a file.
  std::string png() const;
  // 8-bit sRGB RGBA, 4 bytes per pixel, row-major: the pixels of png() (alpha 255 where the PNG has none).
  std::vector<std::uint8_t> srgba() const;

  struct State;

 private:
  explicit Image(std::shared_ptr<const State> state) : state_(std::move(state)) {}
  std::shared_ptr<const State> state_;
  friend class Renderer;
  friend class Video;
};

// A video of images added one at a time, in order: .mp4 (H.264), .webm (VP9) or .gif, encoded as they come by the
// ffmpeg program and put in place atomically by finish(). The first image sets the size; destroyed unfinished,
// nothing is left. OutputError for a bad path or another size; std::runtime_error when ffmpeg is missing or fails.
class Video {
 public:
  Video(const std::string& path, double fps);
  ~Video();
  Video(const Video&) = delete;
  Video& operator=(const Video&) = delete;
  void add(const Image& image);
  void finish();
  int frames() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// What one frame of a batch ended as, for a progress display.
struct BatchFrame {
  int done = 0, total = 0;
  std::string job;
  int frame = 0, frames = 0;
  std::string status;  // "ok", "failed" or "skipped"
  double frame_ms = 0, elapsed_ms = 0, eta_ms = 0;
};

struct BatchSettings {
  std::string jobs_path;                                       // a jobs file (.toml), as `algray batch` takes
  std::vector<std::pair<std::string, std::string>> overrides;  // set on every job's scene, after its own
  bool resume = false;                                         // skip frames whose outputs all exist
  std::optional<std::string> log_path;                         // default: beside the jobs file
  std::optional<std::string> stats_path;
  // Only frames shard_index, shard_index + shard_count, ... of all (algray batch --shard K/N); the log and stats
  // become the shard's own. shard_count 1 renders them all.
  int shard_index = 0, shard_count = 1;
  std::function<void(const BatchFrame&)> on_frame;
  std::function<void(const std::string&)> on_message;  // warnings and failures, one or more lines each
  // Asked before each frame; true stops the batch there, which returns Stopped (the frames done are logged).
  std::function<bool()> cancelled;
};

enum class BatchResult { Done, FramesFailed, BadInput, Stopped };

// One device, its OpenCL context and its program cache, kept for every render, probe and batch it runs.
class Renderer {
 public:
  // `device`: "" for the first GPU, else the first device; digits for an index of devices(); otherwise a
  // substring of the device or platform name. `cache`: keep built kernels on disk. The device opens on first
  // use, and a DeviceError then says why it could not.
  explicit Renderer(const std::string& device = "", bool cache = true);
  ~Renderer();
  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;

  Device device();
  Image render(const Scene& scene, const RenderSettings& settings = {});
  // The probe report as JSON (`algray probe --json`): every step of the scene's solver (or of all of them) on
  // the pixel's centre ray or on the ray origin + t direction, beside solver_ref's certified answer.
  std::string probe_pixel(const Scene& scene, int x, int y, bool all_solvers = false);
  std::string probe_ray(const Scene& scene, const std::array<double, 3>& origin, const std::array<double, 3>& direction,
                        bool all_solvers = false);
  BatchResult batch(const BatchSettings& settings);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace algray::api
