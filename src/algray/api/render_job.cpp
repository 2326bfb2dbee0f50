// A scene end to end: outputs validated before any work, the frame rendered, then images and stats written atomically.
#include "algray/api/render_job.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <iostream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "algray/device/cl_runtime.h"
#include "algray/device/program_cache.h"
#include "algray/io/heatmap.h"
#include "algray/render/reference_render.h"
#include "algray/render/renderer.h"
#include "algray/render/shade.h"
#include "algray/scene/jsurf.h"
#include "algray/util/json_text.h"
#include "algray/util/version.h"

namespace algray {
namespace {

std::string join(const std::vector<std::string>& parts, const std::string& separator) {
  std::string out;
  for (const std::string& p : parts) out += (out.empty() ? "" : separator) + p;
  return out;
}

std::string vec_text(const glm::dvec3& v) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g", v.x, v.y, v.z);
  return buf;
}

// The extent as the header's algray/extent gives it: its kind and its numbers, then " gate reach R" for a gate.
std::string extent_text(const Extent& e) {
  const std::string gate = e.gate ? " gate reach " + std::to_string(e.reach) : "";
  if (e.kind == ExtentKind::Sphere)
    return "sphere centre " + vec_text(e.centre) + " radius " + std::to_string(e.radius) + gate;
  if (e.kind == ExtentKind::Box) return "box min " + vec_text(e.min) + " max " + vec_text(e.max) + gate;
  return "cylinder centre " + vec_text(e.centre) + " radius " + std::to_string(e.radius) + " axis " + "xyz"[e.axis] +
         " half_height " + std::to_string(e.half_height) + gate;
}

// The clipping planes as the header's algray/clip gives them: "a b c d" each (a*x + b*y + c*z + d <= 0 kept),
// separated by "; ".
std::string clip_text(const Extent& e) {
  std::string planes;
  for (const glm::dvec4& p : e.clips) {
    char w[40];
    std::snprintf(w, sizeof w, " %.17g", p.w);
    planes += (planes.empty() ? "" : "; ") + vec_text(glm::dvec3(p)) + w;
  }
  return planes;
}

// Metadata that lets anyone rebuild any pixel's ray from the file and docs/outputs.md's camera convention.
void add_metadata(FrameImage& img, const Scene& scene, const RenderResult& r, const DeviceInfo& device) {
  const RayBasis& b = r.basis;
  std::string devices = device.name + " (" + device.platform_name + ", " + device.driver_version + ")";
  for (std::size_t d = 1; d < r.devices.size(); ++d)
    devices += " + [" + std::to_string(r.devices[d].index) + "] " + r.devices[d].name;
  const CameraSpec& cam = scene.camera;
  img.string_attributes = {
      {"algray/scene", scene.source},
      {"algray/name", scene.name},
      {"algray/equation", scene.surface().equation},
      {"algray/polynomial", scene.surface().polynomial.to_string()},
      {"algray/isolation", to_string(r.config.isolation)},
      {"algray/refinement", to_string(r.config.refinement)},
      {"algray/rayOrigin", to_string(r.config.ray_origin)},
      {"algray/precision", to_string(r.config.precision)},
      {"algray/device", devices},
      {"algray/camera/projection", cam.projection == Projection::Perspective ? "perspective" : "orthographic"},
      {"algray/camera/eye", vec_text(cam.eye)},
      {"algray/camera/lookAt", vec_text(cam.look_at)},
      {"algray/camera/up", vec_text(cam.up)},
      {"algray/ray/o00", vec_text(b.o00)},
      {"algray/ray/ou", vec_text(b.ou)},
      {"algray/ray/ov", vec_text(b.ov)},
      {"algray/ray/d00", vec_text(b.d00)},
      {"algray/ray/du", vec_text(b.du)},
      {"algray/ray/dv", vec_text(b.dv)},
      {"algray/extent", extent_text(scene.extent)},
  };
  if (!scene.extent.clips.empty()) img.string_attributes.push_back({"algray/clip", clip_text(scene.extent)});
  img.double_attributes = {
      {"algray/degree", r.config.degree},
      {"algray/tolerance", r.config.tolerance},
      {"algray/maxIterations", r.config.max_iterations},
      {"algray/kernelMs", r.passes_kernel_ms()},
      {"algray/camera/fovY", cam.fov_y_degrees},
      {"algray/camera/orthoHeight", cam.ortho_height},
      {"algray/camera/shiftX", cam.shift.x},
      {"algray/camera/shiftY", cam.shift.y},
      // The ray basis above is per antialiasing sample: pixel (px, py) averages samples x samples rays.
      {"algray/antialiasSamples", r.plan.samples},
  };
  // The scene itself, as TOML that renders this image again: in the EXR header, and in a PNG text chunk that
  // `algray render image.png` reads back (as realsurf reloads its PNGs).
  const std::string scene_toml = scene_to_toml(scene);
  img.string_attributes.push_back({"algray/sceneToml", scene_toml});
  if (scene_toml.size() <= kMaxPngTextBytes) img.png_text.push_back({kPngSceneKey, scene_toml});
  // Every surface of a scene of several, beside the first surface's keys above that single-surface readers use.
  if (scene.surfaces.size() > 1) {
    img.double_attributes.push_back({"algray/surfaces", static_cast<double>(scene.surfaces.size())});
    for (std::size_t k = 0; k < scene.surfaces.size(); ++k) {
      const SceneSurface& s = scene.surfaces[k];
      const std::string prefix = "algray/surface" + std::to_string(k) + "/";
      img.string_attributes.push_back({prefix + "name", s.name});
      img.string_attributes.push_back({prefix + "equation", s.equation});
      img.string_attributes.push_back({prefix + "polynomial", s.polynomial.to_string()});
      img.double_attributes.push_back({prefix + "degree", s.polynomial.degree()});
    }
  }
  img.software = version_string();
  std::string equations;
  for (const SceneSurface& s : scene.surfaces) equations += (equations.empty() ? "" : "; ") + s.equation;
  img.comments = scene.name + ": " + equations + " = 0, rendered by algray";
  // A name from a file name need not be UTF-8, which PNG text must be; the comment is for people, so '?' will do.
  for (char& ch : img.comments)
    if (static_cast<unsigned char>(ch) >= 0x80 || static_cast<unsigned char>(ch) < 0x20) ch = '?';
  img.world_to_camera = world_to_camera_matrix(b, cam.eye);
  img.world_to_ndc = world_to_ndc_matrix(cam, b, scene.image.width, scene.image.height);
}

// Drivers' strings come from outside and need not be UTF-8.
nlohmann::json device_json(const DeviceInfo& device) {
  return {{"name", utf8_for_json(device.name)},
          {"platform", utf8_for_json(device.platform_name)},
          {"type", device.type},
          {"fp64", device.fp64},
          {"driver", utf8_for_json(device.driver_version)}};
}

nlohmann::json solver_json(const KernelConfig& config) {
  return {{"isolation", to_string(config.isolation)},
          {"refinement", to_string(config.refinement)},
          {"ray_origin", to_string(config.ray_origin)},
          {"precision", to_string(config.precision)},
          {"tolerance", config.tolerance},
          {"max_iterations", config.max_iterations}};
}

// A program, with the device time of its launches in every pass.
nlohmann::json program_json(const ProgramRecord& p, const std::vector<PassStats>& passes) {
  double kernel_ms = 0;
  for (const PassStats& pass : passes)
    for (std::size_t k = 0; k < pass.program_keys.size(); ++k)
      if (pass.program_keys[k] == p.key) kernel_ms += pass.program_ms[k];
  return {{"key", p.key},
          {"options", p.options},
          {"from_cache", p.origin != "built"},
          {"origin", p.origin},
          {"build_ms", p.build_ms},
          {"kernel_ms", kernel_ms}};
}

// A pass, with where each of its programs came from.
nlohmann::json pass_json(const PassStats& p, const std::vector<ProgramRecord>& programs) {
  nlohmann::json kernels = nlohmann::json::array();
  for (const std::string& key : p.program_keys) {
    std::string origin;
    for (const ProgramRecord& program : programs)
      if (program.key == key) origin = program.origin;
    kernels.push_back({{"key", key}, {"origin", origin}});
  }
  return {{"name", p.name},
          {"kernels", kernels},
          {"rays", p.rays},
          {"launches", p.launches},
          {"kernel_ms", p.kernel_ms},
          {"wall_ms", p.wall_ms},
          {"escalated", p.escalated},
          {"escalation_ms", p.escalation_ms}};
}

// Where the render's time went: device time of every launch (the shading kernel's too), the passes' wall time
// (launches, staging and readback), and shading's wall time (the shading kernel's launches, and the host's
// shading of bounces and refined pixels), which runs tile by tile inside the render, with its kernel's share.
nlohmann::json render_ms_json(const RenderResult& r) {
  double kernel_ms = r.shade_kernel_ms, passes_ms = 0;
  for (const PassStats& pass : r.passes) {
    kernel_ms += pass.kernel_ms;
    passes_ms += pass.wall_ms;
  }
  return {{"kernel", kernel_ms},
          {"passes_wall", passes_ms},
          {"shading", r.shade_ms},
          {"shading_kernel", r.shade_kernel_ms}};
}

// A device's share of the tiles, of the rays of every pass, and of the device time.
nlohmann::json device_share_json(const DeviceShare& d) {
  return {{"rank", d.rank},
          {"index", d.index},
          {"name", utf8_for_json(d.name)},
          {"tiles", d.tiles},
          {"rays", d.rays},
          {"kernel_ms", d.kernel_ms},
          {"programs_ms", d.programs_ms}};
}

}  // namespace

nlohmann::json frame_stats(const Scene& scene, const RenderedFrame& frame, const std::vector<std::string>& images,
                           bool cache_used) {
  const RenderResult& r = frame.result;
  nlohmann::json j;
  j["version"] = version_string();
  put_path(j, "scene", scene.source);
  j["name"] = utf8_for_json(scene.name);
  // Every value the render used, defaults included, as a scene file that renders the same picture again.
  j["scene_toml"] = utf8_for_json(scene_to_toml(scene));
  put_paths(j, "outputs", images);
  j["image"] = {{"width", scene.image.width}, {"height", scene.image.height}};
  j["device"] = device_json(frame.device);
  // .jsurf equations come from outside and need not be UTF-8.
  j["surface"] = {{"equation", utf8_for_json(scene.surface().equation)}, {"degree", r.config.degree}};
  for (const SceneSurface& s : scene.surfaces)
    j["surfaces"].push_back({{"name", utf8_for_json(s.name)},
                             {"equation", utf8_for_json(s.equation)},
                             {"degree", s.polynomial.degree()}});
  j["solver"] = solver_json(r.config);
  if (!r.precision_reason.empty()) j["solver"]["precision_reason"] = r.precision_reason;
  if (cache_used)
    put_path(j, "cache", ProgramCache::default_directory());
  else
    j["cache"] = "off";
  for (const ProgramRecord& p : r.programs) j["programs"].push_back(program_json(p, r.passes));
  j["plan"] = r.plan.json();
  for (const PassStats& p : r.passes) j["passes"].push_back(pass_json(p, r.programs));
  const PrimarySummary& p = r.primary;
  j["primary_rays"] = {{"count", p.rays},
                       {"hits", p.hits},
                       {"depth_limited", p.depth_limited},
                       {"isolation_steps", p.isolation_steps},
                       {"refine_iterations", p.refine_iterations}};
  // A pixel shows the surface when any of its antialiasing samples hit it.
  j["pixels"] = {{"count", p.pixels}, {"hits", p.pixels_hit}};
  j["render_ms"] = render_ms_json(r);
  for (const DeviceShare& d : r.devices) j["devices"].push_back(device_share_json(d));
  j["phases_ms"] = frame.timer.json();
  j["total_ms"] = frame.timer.total_ms();
  return j;
}

// An output that cannot be written is bad input, found before any rendering.
void check_output_writable(const std::string& path) { check_output_path(path); }

namespace {

// Two names of one file give one identity: its device and inode when it exists, else its normalised absolute path.
std::string file_identity(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) return "inode " + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
  std::error_code ec;
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(std::filesystem::absolute(path, ec), ec);
  return "path " + (ec ? std::filesystem::path(path).lexically_normal().string() : canonical.string());
}

}  // namespace

void check_distinct_files(const std::vector<RoleAndPath>& inputs, const std::vector<RoleAndPath>& outputs) {
  // Each file's identity, and whether it is an input.
  std::map<std::string, std::pair<const RoleAndPath*, bool>> seen;
  for (const RoleAndPath& in : inputs)
    if (!in.path.empty() && in.path != "-") seen.emplace(file_identity(in.path), std::make_pair(&in, true));
  for (const RoleAndPath& out : outputs) {
    const auto [it, fresh] = seen.emplace(file_identity(out.path), std::make_pair(&out, false));
    if (fresh) continue;
    const RoleAndPath& other = *it->second.first;
    if (it->second.second)
      throw OutputError(out.role + " " + out.path + " is the " + other.role + " " + other.path +
                        ": writing it would destroy the input");
    throw OutputError(out.role + " " + out.path + " and " + other.role + " " + other.path +
                      " are the same file: give each output its own name");
  }
}

void OutputWriter::write(const std::string& path, const std::function<void()>& write_file) {
  try {
    write_file();
    written_.push_back(path);
  } catch (const std::exception& e) {
    std::string message = e.what();
    message += "\n  written: " + (written_.empty() ? std::string("nothing") : join(written_, ", "));
    std::vector<std::string> unwritten;
    bool after = false;
    for (const std::string& p : planned_) {
      after = after || p == path;
      if (after) unwritten.push_back(p);
    }
    if (unwritten.empty()) unwritten.push_back(path);
    message += "\n  not written: " + join(unwritten, ", ");
    throw IncompleteOutputError(message);
  }
}

RenderContext::RenderContext(std::string device_spec, bool use_cache)
    : device_spec_(std::move(device_spec)), use_cache_(use_cache) {}

RenderContext::~RenderContext() = default;

ClSession& RenderContext::session() { return *sessions().front(); }

std::vector<ClSession*> RenderContext::sessions() {
  if (sessions_.empty()) sessions_ = open_sessions(select_devices(device_spec_));
  std::vector<ClSession*> out;
  for (const auto& session : sessions_) out.push_back(session.get());
  return out;
}

ProgramCache& RenderContext::cache() {
  if (!cache_) cache_ = std::make_unique<ProgramCache>(use_cache_);
  return *cache_;
}

Renderer& RenderContext::renderer() {
  if (!renderer_) renderer_ = std::make_unique<Renderer>(sessions(), cache());
  return *renderer_;
}

Scene SceneLoader::load(const std::optional<std::string>& path, const std::vector<Override>& overrides) {
  if (!path) return default_scene(overrides);
  if (*path != "-" && is_png_file(*path)) {
    // A PNG that algray rendered carries its scene: render it again, with any new overrides on top.
    std::vector<std::pair<std::string, std::string>> texts;
    try {
      texts = read_png_text(*path);
    } catch (const OutputError& e) {
      throw SceneError(*path, e.what());
    }
    for (const auto& [key, text] : texts)
      if (key == kPngSceneKey)
        return load_scene_text(text, *path + " (the scene in its " + kPngSceneKey + " text)", overrides);
    throw SceneError(*path, std::string("this PNG carries no algray scene (no ") + kPngSceneKey +
                                " text chunk): only images written by algray render can be rendered again");
  }
  if (*path == "-") {
    if (stdin_read_) throw SceneError("<stdin>", "standard input was already read");
    stdin_read_ = true;
    const std::string text = read_input_stream(std::cin, "<stdin>", "scene file");
    if (looks_like_jsurf(text)) return load_jsurf_text(text, "<stdin>", overrides);
    return load_scene_text(text, "<stdin>", overrides);
  }
  return load_scene_file(*path, overrides);
}

std::string warning_text(const Scene& scene, const std::string& prefix) {
  std::string text;
  for (const std::string& w : scene.warnings) text += "algray: warning: " + prefix + w + "\n";
  return text;
}

namespace {

// In the order render_scene writes them.
std::vector<RoleAndPath> planned_outputs(const RenderOutputs& outputs) {
  std::vector<RoleAndPath> out;
  if (outputs.heatmap_path) out.push_back({"--heatmap", *outputs.heatmap_path});
  for (const std::string& o : outputs.images) out.push_back({"output", o});
  if (outputs.stats_path) out.push_back({"--stats", *outputs.stats_path});
  return out;
}

}  // namespace

void check_outputs(const Scene& scene, const RenderOutputs& outputs, const std::string& scene_path) {
  if (outputs.reference && scene.surfaces.size() > 1)
    throw SceneError(scene.source,
                     "--reference solves one surface; this scene has " + std::to_string(scene.surfaces.size()));
  for (const std::string& out : outputs.images) {
    format_from_extension(out);
    check_output_writable(out);
  }
  if (outputs.stats_path) check_output_writable(*outputs.stats_path);
  if (outputs.heatmap_path) {
    format_from_extension(*outputs.heatmap_path);
    check_output_writable(*outputs.heatmap_path);
  }
  check_distinct_files({{"scene file", scene_path}}, planned_outputs(outputs));
}

namespace {

// No device: exact arithmetic on the CPU, rays rebuilt in the precision the kernels would use.
void render_reference_frame(const Scene& scene, bool diagnostics, RenderedFrame& frame, SolverWork& work) {
  frame.device.name = "CPU reference (solver_ref, exact arithmetic)";
  frame.device.type = "CPU";
  ReferenceResult ref = render_reference(scene, scene.render.precision.value_or(Precision::Double));
  frame.timer.mark("render");
  RenderResult& result = frame.result;
  result = std::move(ref.render);
  result.primary = summarise_hits(result.hits, result.plan.samples);
  frame.image = shade_frame(scene, result);
  frame.image.uint_channels.push_back({"reference.class", std::move(ref.classes)});
  if (diagnostics) work = solver_work(result);
  frame.timer.mark("shade");
}

// Only a film of at most 256 MB (4096^2 RGBA) is made ahead: the render's memory check (check_plan_fits, which
// needs the device) must refuse a render too large before its film is allocated, and a larger render takes
// seconds, beside which the overlap is noise.
bool film_made_ahead(int width, int height, bool depth_and_normal) {
  return static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) * (depth_and_normal ? 8 : 4) *
             sizeof(float) <=
         (std::uint64_t{256} << 20);
}

// The film (16 to 32 bytes a pixel, zero-filled, every page faulted in) is made on another thread while this one
// starts the device, which loads the OpenCL driver on one core for tens of milliseconds. Its depth and normal
// channels are made only for an EXR output, the one format that stores them. For a PNG output the sRGB encoder's
// table (some 40000 pow() calls, built on first use) is made there too.
struct FilmAhead {
  std::future<FrameImage> film;
  // The camera rays' hit records of the largest tile on a CPU (the plan's default tile; a GPU's is smaller and
  // makes its own), after the film on the same thread: both overlap the device's start, which needs no memory.
  std::future<PopulatedPages> tile_memory;
};

// The renderer's tile memory is made ahead only where it holds none large enough (its first render, or a larger
// tile than before).
FilmAhead start_film(const Scene& scene, bool png, bool depth_and_normal, const Renderer* renderer) {
  const int film_width = scene.image.width, film_height = scene.image.height;
  DeviceInfo cpu;
  cpu.type = "CPU";
  const std::size_t tile_bytes =
      tile_memory_bytes(make_render_plan(scene, Precision::Double, std::vector<PlanDevice>{{cpu}}));
  const bool make_tile = !renderer || !renderer->holds_tile_memory(tile_bytes);
  auto pages = std::make_shared<std::promise<PopulatedPages>>();
  FilmAhead ahead;
  if (make_tile) ahead.tile_memory = pages->get_future();
  ahead.film = std::async(std::launch::async, [=] {
    // The tile first: the render needs it when its programs are loaded, the film only after the first tile.
    if (make_tile) try {
        pages->set_value(PopulatedPages(tile_bytes));
      } catch (...) {
        pages->set_exception(std::current_exception());
      }
    if (png) srgb_byte(0.5f);
    return make_film(film_width, film_height, depth_and_normal);
  });
  return ahead;
}

void render_on_device(const Scene& scene, const FrameRequest& request, RenderContext& context,
                      const RenderCallbacks& callbacks, bool diagnostics, RenderedFrame& frame, SolverWork& work) {
  const bool depth_and_normal = request.depth_and_normal;
  const int film_width = scene.image.width, film_height = scene.image.height;
  const bool ahead = film_made_ahead(film_width, film_height, depth_and_normal);
  FilmAhead made;
  if (ahead) made = start_film(scene, request.png, depth_and_normal, context.renderer_if_made());
  Renderer& renderer = context.renderer();  // the first call opens the devices while the film is made
  frame.device = context.session().info;
  frame.timer.mark("device");
  RenderOptions options;
  // A larger film is made when the render has checked that it fits, with only the channels the outputs hold.
  if (ahead) {
    options.film = [&made] { return made.film.get(); };
    if (made.tile_memory.valid()) options.tile_memory = [&made] { return made.tile_memory.get(); };
  } else
    options.film = [=] { return make_film(film_width, film_height, depth_and_normal); };
  options.on_progress = callbacks.on_progress;
  options.cancelled = callbacks.cancelled;
  options.race_precision = request.race_precision;
  if (diagnostics) {
    options.on_primary_tile = [&](const PrimaryTile& tile) {
      if (work.isolation_steps.empty()) work = empty_solver_work(scene.image.width, scene.image.height, tile.samples);
      add_tile_work(work, tile);
    };
  }
  RenderResult& result = frame.result;
  result =
      callbacks.render_pixels ? callbacks.render_pixels(renderer, scene, options) : renderer.render(scene, options);
  frame.timer.mark("render");
  frame.timer.move("render", "shade", result.shade_ms);
  frame.image = std::move(result.image);
}

// The heat map's colour scale spans the whole image, so it needs every pixel's work before any colour: the
// work (16 bytes a pixel) and the picture are whole-image, bounded by the pixels, never by the samples.
void add_diagnostics(const FrameRequest& request, SolverWork& work, RenderedFrame& frame) {
  if (request.heatmap) {
    const std::string per =
        work.samples > 1 ? " (sum over " + std::to_string(work.samples * work.samples) + " samples)" : "";
    frame.heatmap = work_heatmap(work.width, work.height, work.total(), work.in_extent(),
                                 "isolation steps + refinement iterations per pixel" + per);
  }
  add_solver_aovs(frame.image, std::move(work), request.aovs);
  frame.timer.mark("diagnostics");
}

}  // namespace

RenderedFrame render_frame(const Scene& scene, const FrameRequest& request, RenderContext& context,
                           const RenderCallbacks& callbacks, std::chrono::steady_clock::time_point started) {
  RenderedFrame frame{{}, {}, {}, {}, PhaseTimer(started)};
  frame.timer.mark("scene");  // reading and checking it, before this call
  const bool diagnostics = !request.aovs.empty() || request.heatmap;
  SolverWork work;  // per output pixel: the solver channels and the heat map are pictures of the whole image
  if (request.reference)
    render_reference_frame(scene, diagnostics, frame, work);
  else
    render_on_device(scene, request, context, callbacks, diagnostics, frame, work);
  add_metadata(frame.image, scene, frame.result, frame.device);
  frame.timer.mark("metadata");
  if (diagnostics) add_diagnostics(request, work, frame);
  return frame;
}

bool outputs_hold_depth(const RenderOutputs& outputs) {
  return std::any_of(outputs.images.begin(), outputs.images.end(),
                     [](const std::string& out) { return format_from_extension(out) == ImageFormat::Exr; });
}

nlohmann::json render_scene(const Scene& scene, const RenderOutputs& outputs, RenderContext& context,
                            const RenderCallbacks& callbacks, std::chrono::steady_clock::time_point started) {
  FrameRequest request;
  request.depth_and_normal = outputs_hold_depth(outputs);
  for (const std::string& out : outputs.images) request.png |= format_from_extension(out) == ImageFormat::Png;
  request.reference = outputs.reference;
  request.aovs = outputs.aovs;
  request.heatmap = outputs.heatmap_path.has_value();
  RenderedFrame frame = render_frame(scene, request, context, callbacks, started);
  // Every path was checked before rendering, so a write that fails now (a full disk) is a failure, not bad input.
  std::vector<std::string> planned;
  for (const RoleAndPath& o : planned_outputs(outputs)) planned.push_back(o.path);
  OutputWriter writer(planned);
  if (outputs.heatmap_path)
    writer.write(*outputs.heatmap_path, [&] { write_image(*outputs.heatmap_path, *frame.heatmap); });
  for (const std::string& out : outputs.images) writer.write(out, [&] { write_image(out, frame.image); });
  frame.timer.mark("write");
  nlohmann::json stats = frame_stats(scene, frame, outputs.images, context.uses_cache());
  if (outputs.stats_path)
    writer.write(*outputs.stats_path, [&] { write_text_file(*outputs.stats_path, dump_json(stats, 2) + "\n"); });
  if (outputs.keep_image) outputs.keep_image(std::move(frame.image));
  return stats;
}

ErrorReport describe_error(const std::exception& e) {
  if (dynamic_cast<const SceneError*>(&e)) return {std::string(e.what()) + "\n", true};
  std::string text = "algray: ";
  if (const auto* cl_error = dynamic_cast<const cl::Error*>(&e))
    text += "OpenCL error " + std::to_string(cl_error->err()) + " in ";
  text += std::string(e.what()) + "\n";
  const bool bad_input = dynamic_cast<const OutputError*>(&e) || dynamic_cast<const DeviceError*>(&e);
  return {text, bad_input};
}

}  // namespace algray
