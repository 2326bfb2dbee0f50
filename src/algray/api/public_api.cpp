// The public C++ API (include/algray/algray.h) over the library's layers: the same calls the command line makes.
#include <algray/algray.h>

#include <algorithm>
#include <regex>

#include "algray/api/batch.h"
#include "algray/api/probe_report.h"
#include "algray/api/render_job.h"
#include "algray/io/image_io.h"
#include "algray/device/program_cache.h"
#include "algray/io/video_writer.h"
#include "algray/scene/jsurf.h"
#include "algray/util/json_text.h"
#include "algray/util/version.h"

namespace algray::api {

struct Scene::State {
  enum class Kind { File, Toml, Jsurf, Equation, Default } kind = Kind::Default;
  std::string text_or_path;
  std::string name;  // of a text
  std::vector<Override> overrides;
  algray::Scene scene;  // read with every override so far
};

struct Image::State {
  FrameImage image;
  std::string stats;
};

struct Renderer::State {
  State(const std::string& device, bool cache) : context(device, cache) {}
  RenderContext context;
};

namespace {

// "file:line:column" (as TomlReader writes them) into its three parts; anything else is a file alone.
void split_where(const std::string& where, std::string& file, int& line, int& column) {
  static const std::regex located(R"(^(.*):([0-9]+):([0-9]+)$)");
  std::smatch m;
  if (std::regex_match(where, m, located)) {
    file = m[1];
    line = std::stoi(m[2]);
    column = std::stoi(m[3]);
  } else {
    file = where;
  }
}

// Runs `f`, turning the library's exceptions into the API's.
template <typename F>
auto translated(F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const algray::SceneError& e) {
    std::string file;
    int line = 0, column = 0;
    split_where(e.where, file, line, column);
    throw SceneError(e.what(), file, line, column, e.message, e.excerpt);
  } catch (const algray::DeviceError& e) {
    throw DeviceError(e.what());
  } catch (const algray::OutputError& e) {
    throw OutputError(e.what());
  } catch (const RenderCancelled& e) {
    throw Cancelled(e.what());
  }
}

algray::Scene read_scene(const Scene::State& s, const std::vector<Override>& overrides) {
  switch (s.kind) {
    case Scene::State::Kind::File:
      return SceneLoader().load(s.text_or_path, overrides);
    case Scene::State::Kind::Toml:
      return load_scene_text(s.text_or_path, s.name, overrides);
    case Scene::State::Kind::Jsurf:
      return load_jsurf_text(s.text_or_path, s.name, overrides);
    case Scene::State::Kind::Equation:
      return load_equation(s.text_or_path, overrides);
    case Scene::State::Kind::Default:
      break;
  }
  return algray::default_scene(overrides);
}

std::shared_ptr<const Scene::State> read_state(Scene::State state) {
  return translated([&] {
    state.scene = read_scene(state, state.overrides);
    return std::make_shared<const Scene::State>(std::move(state));
  });
}

Device to_device(const DeviceInfo& d) {
  return {d.index,          d.platform_name, d.platform_version, d.name, d.vendor,           d.version,
          d.driver_version, d.type,          d.compute_units,    d.fp64, d.global_mem_bytes, d.max_alloc_bytes};
}

}  // namespace

SceneError::SceneError(const std::string& what, std::string file_, int line_, int column_, std::string message_,
                       std::string excerpt_)
    : std::runtime_error(what),
      file(std::move(file_)),
      line(line_),
      column(column_),
      message(std::move(message_)),
      excerpt(std::move(excerpt_)) {}

std::string version() { return version_string(); }

void set_warning_handler(std::function<void(const std::string&)> handler) {
  set_cache_warning_handler(std::move(handler));
}

std::vector<Device> devices() {
  std::vector<Device> out;
  for (const DeviceInfo& d : enumerate_devices()) out.push_back(to_device(d));
  return out;
}

Scene Scene::load(const std::string& path) { return Scene(read_state({State::Kind::File, path, path, {}, {}})); }
Scene Scene::from_toml(const std::string& text, const std::string& name) {
  return Scene(read_state({State::Kind::Toml, text, name, {}, {}}));
}
Scene Scene::from_jsurf(const std::string& text, const std::string& name) {
  return Scene(read_state({State::Kind::Jsurf, text, name, {}, {}}));
}
Scene Scene::default_scene() { return Scene(read_state({})); }
Scene Scene::from_equation(const std::string& equation) {
  return Scene(read_state({State::Kind::Equation, equation, "--equation", {}, {}}));
}

Scene& Scene::set(const std::string& key, const std::string& value) {
  State next = *state_;
  next.overrides.push_back({key, value});
  state_ = read_state(std::move(next));
  return *this;
}

std::string Scene::to_toml() const { return scene_to_toml(state_->scene); }
std::string Scene::name() const { return state_->scene.name; }
std::string Scene::source() const { return state_->scene.source; }
int Scene::width() const { return state_->scene.image.width; }
int Scene::height() const { return state_->scene.image.height; }
std::vector<std::string> Scene::equations() const {
  std::vector<std::string> out;
  for (const SceneSurface& s : state_->scene.surfaces) out.push_back(s.equation);
  return out;
}
std::vector<std::pair<std::string, double>> Scene::parameters() const {
  return {state_->scene.parameters.begin(), state_->scene.parameters.end()};
}
std::vector<std::string> Scene::warnings() const { return state_->scene.warnings; }
std::array<double, 3> Scene::camera_angles() const {
  const CameraAngles a = algray::camera_angles(state_->scene.camera);
  return {a.azimuth, a.elevation, a.distance};
}

int Image::width() const { return state_->image.width; }
int Image::height() const { return state_->image.height; }
const std::vector<float>& Image::rgba() const { return state_->image.rgba; }
const std::vector<float>& Image::depth() const { return state_->image.depth; }
const std::vector<float>& Image::normal() const { return state_->image.normal; }
std::vector<std::string> Image::channel_names() const {
  std::vector<std::string> out;
  for (const auto& c : state_->image.uint_channels) out.push_back(c.name);
  for (const auto& c : state_->image.float_channels) out.push_back(c.name);
  return out;
}
std::optional<std::vector<std::uint32_t>> Image::uint_channel(const std::string& name) const {
  for (const auto& c : state_->image.uint_channels)
    if (c.name == name) return c.values;
  return std::nullopt;
}
std::optional<std::vector<float>> Image::float_channel(const std::string& name) const {
  for (const auto& c : state_->image.float_channels)
    if (c.name == name) return c.values;
  return std::nullopt;
}
const std::string& Image::stats_json() const { return state_->stats; }
void Image::save(const std::string& path) const {
  translated([&] { write_image(path, state_->image); });
}
std::vector<std::uint8_t> Image::srgba() const { return srgba_bytes(state_->image); }
std::string Image::png() const {
  return translated([&] { return png_bytes(state_->image); });
}

Renderer::Renderer(const std::string& device, bool cache) : state_(std::make_unique<State>(device, cache)) {}
Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

Device Renderer::device() {
  return translated([&] { return to_device(state_->context.session().info); });
}

Image Renderer::render(const Scene& scene, const RenderSettings& settings) {
  return translated([&] {
    // The settings are overrides like the command line's flags, applied after the scene's own keys; without any
    // the scene as read already is the one to render.
    // 0 means the scene's size; a negative one is a mistake, not a request for that.
    for (const auto& [key, size] : {std::pair{"width", settings.width}, std::pair{"height", settings.height}})
      if (size < 0)
        throw algray::SceneError(key, std::to_string(size) + ": an image size is positive (0 keeps the scene's)");
    std::vector<Override> overrides = scene.state_->overrides;
    if (settings.width > 0) overrides.push_back({"image.width", std::to_string(settings.width)});
    if (settings.height > 0) overrides.push_back({"image.height", std::to_string(settings.height)});
    if (settings.preview) overrides.push_back({"render.preview", "true"});
    if (!settings.precision.empty()) overrides.push_back({"render.precision", "\"" + settings.precision + "\""});
    const bool as_read = overrides.size() == scene.state_->overrides.size();
    const algray::Scene s = as_read ? scene.state_->scene : read_scene(*scene.state_, overrides);
    FrameRequest request;
    request.reference = settings.reference;
    request.depth_and_normal = settings.depth_and_normal;
    // A renderer of the API draws frame after frame (the view, Python, notebooks): its previews with the
    // precision left open race double against adaptive and keep the faster.
    request.race_precision = true;
    if (!settings.aovs.empty()) {
      std::string list, error;
      for (const std::string& a : settings.aovs) list += (list.empty() ? "" : ",") + a;
      if (!parse_aov_list(list, request.aovs, error)) throw algray::SceneError("aovs", error);
    }
    RenderOutputs outputs;
    outputs.reference = settings.reference;
    check_outputs(s, outputs);
    RenderCallbacks callbacks;
    if (settings.on_progress)
      callbacks.on_progress = [&](const RenderProgress& p) { settings.on_progress({p.tiles_done, p.tiles_total}); };
    callbacks.cancelled = settings.cancelled;
    RenderedFrame frame = render_frame(s, request, state_->context, callbacks);
    std::string stats = dump_json(frame_stats(s, frame, {}, state_->context.uses_cache()), 2);
    return Image(std::make_shared<const Image::State>(Image::State{std::move(frame.image), std::move(stats)}));
  });
}

namespace {

std::string probe_report(const algray::Scene& scene, const ProbeTarget& target, bool all_solvers,
                         RenderContext& context) {
  check_probe_target(scene, target);
  return dump_json(probe_json(scene, target, probe_scene(scene, target, all_solvers, context)), 2);
}

}  // namespace

std::string Renderer::probe_pixel(const Scene& scene, int x, int y, bool all_solvers) {
  return translated([&] {
    ProbeTarget target;
    target.px = x;
    target.py = y;
    return probe_report(scene.state_->scene, target, all_solvers, state_->context);
  });
}

std::string Renderer::probe_ray(const Scene& scene, const std::array<double, 3>& origin,
                                const std::array<double, 3>& direction, bool all_solvers) {
  return translated([&] {
    ProbeTarget target;
    target.given_ray = true;
    target.origin = {origin[0], origin[1], origin[2]};
    target.direction = {direction[0], direction[1], direction[2]};
    return probe_report(scene.state_->scene, target, all_solvers, state_->context);
  });
}

BatchResult Renderer::batch(const BatchSettings& settings) {
  BatchRequest request;
  request.jobs_path = settings.jobs_path;
  for (const auto& [key, value] : settings.overrides) request.overrides.push_back({key, value});
  request.resume = settings.resume;
  request.log_path = settings.log_path;
  request.stats_path = settings.stats_path;
  if (settings.shard_count != 1 || settings.shard_index != 0) {
    const BatchShard shard{settings.shard_index, settings.shard_count};
    std::string error;
    if (!check_shard(shard, error))
      throw SceneError("shard " + std::to_string(shard.index) + "/" + std::to_string(shard.count) + ": " + error,
                       "shard", 0, 0, error, "");
    request.shard = shard;
  }
  BatchCallbacks callbacks;
  callbacks.on_message = settings.on_message;
  callbacks.cancelled = settings.cancelled;
  if (settings.on_frame)
    callbacks.on_frame = [&](const BatchProgress& p) {
      settings.on_frame(
          {p.done, p.total, p.job->name, p.frame, p.job->frames, p.status, p.frame_ms, p.elapsed_ms, p.eta_ms});
    };
  switch (run_batch(request, callbacks, state_->context)) {
    case BatchOutcome::Done:
      return BatchResult::Done;
    case BatchOutcome::FramesFailed:
      return BatchResult::FramesFailed;
    case BatchOutcome::BadInput:
      return BatchResult::BadInput;
    case BatchOutcome::Stopped:
      break;
  }
  return BatchResult::Stopped;
}

struct Video::State {
  std::string path;
  double fps;
  std::unique_ptr<VideoWriter> writer;
};

Video::Video(const std::string& path, double fps) : state_(std::make_unique<State>(State{path, fps, nullptr})) {
  translated([&] {
    if (!video_format_of(path))
      throw algray::OutputError("cannot write '" + path + "': a video is " + video_extensions());
    if (!(fps > 0 && fps <= 1000)) throw algray::OutputError("cannot write '" + path + "': fps must be in (0, 1000]");
    return 0;
  });
}

Video::~Video() = default;

void Video::add(const Image& image) {
  translated([&] {
    const FrameImage& frame = image.state_->image;
    if (!state_->writer)
      state_->writer = std::make_unique<VideoWriter>(state_->path, frame.width, frame.height, state_->fps);
    state_->writer->add(frame);
    return 0;
  });
}

void Video::finish() {
  translated([&] {
    if (!state_->writer) throw algray::OutputError("cannot write '" + state_->path + "': no image was added");
    state_->writer->finish();
    return 0;
  });
}

int Video::frames() const { return state_->writer ? state_->writer->frames() : 0; }

}  // namespace algray::api
