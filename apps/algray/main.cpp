// The algray command line: `algray render`, `algray probe`, `algray batch`, `algray devices` and `algray view`.
// Built twice: algray-full (ALGRAY_FULL) runs every command; algray, without the web server and Open MPI, hands
// `algray view` and runs under an MPI launcher to it (hand_off.h).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>

#ifdef ALGRAY_WITH_MPI
#include "algray/cluster/mpi_batch.h"
#include "algray/cluster/mpi_world.h"
#endif
#include "algray/device/program_cache.h"
#include "algray/io/image_io.h"
#include "algray/io/video_writer.h"
#include "algray/render/solver_aov.h"
#include "algray/scene/scene_formats.h"
#include "algray/scene/solver_options.h"
#include "algray/util/version.h"
#include "commands.h"
#include "exit_codes.h"
#include "hand_off.h"

namespace {

using namespace algray;
using namespace algray::cli;

// The options every scene-taking command shares: the scene, its overrides and the device.
struct SceneOptions {
  std::string scene_path;
  std::string equation;  // -e: an equation alone, with algray's defaults for the rest
  double radius = 0;     // --radius: extent.radius
  std::vector<std::string> sets;
  std::vector<std::string> sections;  // --section: plane sections added, each a linear equation
  std::vector<std::string> clips;     // --clip: clipping planes added, each a linear inequality (the side kept)
  int width = 0, height = 0;
  std::string precision, isolation, refinement, tolerance, max_iterations;
  std::string device_spec;
  bool no_cache = false, preview = false;
};

// --no-fp64: every device counts as having no double precision (ALGRAY_NO_FP64, set as the flag is parsed, before
// any device is opened), so that the float-only path can be tried anywhere.
void add_no_fp64_flag(CLI::App* cmd) {
  cmd->add_flag_callback(
      "--no-fp64", [] { ::setenv("ALGRAY_NO_FP64", "1", 1); },
      "act as if no device had double precision (as ALGRAY_NO_FP64=1 does): auto precision picks adaptive float, and "
      "double is refused");
}

// Batch takes a jobs file where the others take a scene, and no scene positional.
void add_scene_options(CLI::App* cmd, SceneOptions& o, bool scene_positional = true) {
  if (scene_positional) {
    auto* scene = cmd->add_option("scene", o.scene_path,
                                  "scene file: " + readable_scene_types() +
                                      "; or - for standard input; default: the built-in Barth sextic");
    cmd->add_option("-e,--equation", o.equation,
                    "render this equation P(x,y,z) (as `x^4+y^4+z^4-1`) with algray's defaults: a sphere extent of "
                    "radius 2 (--radius), framed from 3R through 45 degrees, a key and a fill light, 2x2 "
                    "antialiasing")
        ->excludes(scene);
  }
  cmd->add_option("--radius", o.radius,
                  "the sphere extent's radius (overrides extent.radius, before any --set: --set extent.type=box then "
                  "makes the cube about that sphere)");
  cmd->add_option("--width", o.width, "image width in pixels (overrides image.width)");
  cmd->add_option("--height", o.height, "image height in pixels (overrides image.height)");
  cmd->add_option("--device", o.device_spec,
                  "device index or name substring (see `algray devices`); a comma-separated list of them, or all, "
                  "renders each image on those devices together");
  cmd->add_option("--precision", o.precision, precision_choices("or") + " (overrides render.precision)");
  cmd->add_option("--isolation", o.isolation,
                  "root isolation: " + isolation_choices("or") + " (overrides render.isolation)");
  cmd->add_option("--refine", o.refinement,
                  "root refinement: " + refinement_choices("or") + " (overrides render.refinement)");
  cmd->add_option("--tolerance", o.tolerance, "the stopping tolerance eps (overrides render.tolerance)");
  cmd->add_option("--max-iterations", o.max_iterations,
                  "the refinement's iteration cap (overrides render.max_iterations)");
  cmd->add_option("--set", o.sets,
                  "override a scene key: name=value (a bare name is a parameter); repeatable, e.g. --set a=2 --set "
                  "camera.azimuth=60 --set extent.type=box --set section.0.colour=[1,0,0] --set 'section=[]'");
  cmd->add_option("--section", o.sections,
                  "draw the curve where this plane meets the surface (surf's cut_with_plane), a linear equation in "
                  "x, y, z such as z=0.5 or x+y=1; repeatable, appended to the scene's [[section]] list before any "
                  "--set");
  cmd->add_option("--clip", o.clips,
                  "cut the surface open with a plane, keeping the side this linear inequality in x, y, z gives, such "
                  "as 'z<0.5' or 'x+y>=1' (quote it for the shell); repeatable, up to " +
                      std::to_string(kMaxClipPlanes) + " in a scene, appended to its [[clip]] list before any --set");
  cmd->add_flag("--preview", o.preview,
                "the paper's preview mode: primary rays only (no shadows); sets render.preview");
  cmd->add_flag("--no-cache", o.no_cache, "compile kernels from source; neither read nor write the program cache");
  add_no_fp64_flag(cmd);
}

// --radius, --section and --clip, then --set, then the other flags, which are overrides like any --set applied
// last so that they win. Returns false
// (after saying why) on a malformed --set.
bool collect_overrides(const CLI::App* cmd, const SceneOptions& o, std::vector<Override>& out) {
  // --radius, --section and --clip first: they make the sphere, the sections and the planes that a --set may then
  // change.
  if (cmd->count("--radius")) out.push_back({"extent.radius", cmd->get_option("--radius")->as<std::string>()});
  for (const std::string& s : o.sections) out.push_back({kSectionOverrideKey, s});
  for (const std::string& s : o.clips) out.push_back({kClipOverrideKey, s});
  for (const std::string& s : o.sets) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0) {
      std::cerr << "algray: --set " << s << ": expected name=value\n";
      return false;
    }
    out.push_back({s.substr(0, eq), s.substr(eq + 1)});
  }
  if (cmd->count("--width")) out.push_back({"image.width", std::to_string(o.width)});
  if (cmd->count("--height")) out.push_back({"image.height", std::to_string(o.height)});
  if (!o.precision.empty()) out.push_back({"render.precision", "\"" + o.precision + "\""});
  if (!o.isolation.empty()) out.push_back({"render.isolation", "\"" + o.isolation + "\""});
  if (!o.refinement.empty()) out.push_back({"render.refinement", "\"" + o.refinement + "\""});
  // Numbers pass through as written, so that the scene's own checks report them.
  if (!o.tolerance.empty()) out.push_back({"render.tolerance", o.tolerance});
  if (!o.max_iterations.empty()) out.push_back({"render.max_iterations", o.max_iterations});
  if (o.preview) out.push_back({"render.preview", "true"});
  return true;
}

// "a,b,c" into exactly n finite numbers.
bool parse_numbers(const std::string& text, std::size_t n, std::vector<double>& out) {
  out.clear();
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    try {
      std::size_t used = 0;
      out.push_back(std::stod(part, &used));
      if (used != part.size() || !std::isfinite(out.back())) return false;
    } catch (const std::exception&) {
      return false;
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out.size() == n;
}

// Ends the process after a render: its outputs are written, synced and renamed by now. Without the destructors
// of statics and the exit handlers of the OpenCL driver (PoCL's and LLVM's: about 4 ms of a 1024^2 preview),
// which free only what the process's exit frees anyway. LeakSanitizer checks at exit, so there it exits.
[[noreturn]] void end_process(int code) {
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
#if defined(__SANITIZE_ADDRESS__)
  std::exit(code);
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(leak_sanitizer)
  std::exit(code);
#endif
#endif
  std::_Exit(code);
}

// Where `algray render` writes without -o: a PNG, which every image viewer opens and which carries its scene.
constexpr const char* kDefaultOutput = "algray.png";

// `algray render`: its options, then the request they make.
struct RenderCommand {
  CLI::App* cmd = nullptr;
  RenderRequest request;
  SceneOptions scene;
  std::string stats_path, aov_text;

  void add_to(CLI::App& app) {
    cmd = app.add_subcommand("render", "render a scene (default: the built-in Barth sextic)");
    add_scene_options(cmd, scene);
    cmd->add_option("-o,--output", request.outputs.images, "output image; .exr or .png by extension; may be repeated")
        ->default_str(kDefaultOutput);
    cmd->add_flag("-q,--quiet", request.quiet, "print nothing on success (else: what was written, and how long it took)");
    cmd->add_option("--stats", stats_path, "write render statistics as JSON");
    cmd->add_flag("--reference", request.outputs.reference,
                  "solve every pixel exactly on the CPU (solver_ref, all cores, slow); adds a reference.class channel");
    cmd->add_option("--aov", aov_text, "solver channels for EXR outputs, comma-separated: " + aov_choices());
    cmd->add_option("--heatmap", request.outputs.heatmap_path,
                    "write a heat map of solver work per pixel (isolation steps + refinement iterations), .png");
  }

  int run() {
    if (!scene.scene_path.empty()) request.scene_path = scene.scene_path;
    if (!scene.equation.empty()) request.equation = scene.equation;
    if (request.outputs.images.empty()) request.outputs.images.push_back(kDefaultOutput);
    if (!collect_overrides(cmd, scene, request.overrides)) return kExitBadInput;
    request.device_spec = scene.device_spec;
    if (!aov_text.empty()) {
      std::string error;
      if (!parse_aov_list(aov_text, request.outputs.aovs, error)) {
        std::cerr << "algray: --aov " << aov_text << ": " << error << "\n";
        return kExitBadInput;
      }
    }
    request.use_cache = !scene.no_cache;
    if (!stats_path.empty()) request.outputs.stats_path = stats_path;
    request.progress = ::isatty(STDERR_FILENO) != 0;
#ifdef ALGRAY_WITH_MPI
    // Started by an MPI launcher, the ranks share the image's rows; started alone, MPI is never initialised.
    if (started_by_mpi_launcher()) {
      std::optional<MpiWorld> world;
      try {
        world.emplace();
      } catch (const std::exception& e) {
        return report_error(e, std::cerr);
      }
      request.progress = request.progress && world->rank() == 0;
      return run_render_across_ranks(request, *world, std::cerr);
    }
#endif
    return run_render(request, std::cout, std::cerr);
  }
};

// `algray probe`: its options, the target ray and the plot's range, then the request they make.
struct ProbeCommand {
  CLI::App* cmd = nullptr;
  ProbeRequest request;
  SceneOptions scene;
  std::string pixel_text, ray_text, plot_range_text;

  void add_to(CLI::App& app) {
    cmd = app.add_subcommand(
        "probe", "trace one ray through the render's own solver code and show every step beside solver_ref's answer");
    add_scene_options(cmd, scene);
    auto* pixel_opt = cmd->add_option("--pixel", pixel_text,
                                      "X,Y: the pixel's centre ray, as a render without antialiasing traces it");
    auto* ray_opt = cmd->add_option("--ray", ray_text, "ox,oy,oz,dx,dy,dz: a ray o + t d in world coordinates");
    pixel_opt->excludes(ray_opt);
    cmd->add_flag("--all-solvers", request.all_solvers,
                  "every isolation x refinement side by side, the scene's own first");
    cmd->add_option("--plot", request.plot_path,
                    "draw P*(t) on [t_in, t_out] with the isolating interval, the root and solver_ref's roots "
                    "(.svg or .png)");
    cmd->add_option("--plot-range", plot_range_text,
                    "what --plot shows: segment (default), isolating (the isolating interval), or T0,T1");
    cmd->add_flag("--json", request.json, "print the report as JSON (for scripts) instead of text");
    cmd->add_option("--stats", request.stats_path, "write the report as JSON to this file too");
  }

  // --pixel or --ray into the request's target; false after saying what is wrong.
  bool read_target() {
    std::vector<double> v;
    if (!pixel_text.empty()) {
      if (!parse_numbers(pixel_text, 2, v) || std::fabs(v[0]) > 1e9 || std::fabs(v[1]) > 1e9 ||
          v[0] != std::floor(v[0]) || v[1] != std::floor(v[1])) {
        std::cerr << "algray: --pixel " << pixel_text << ": expected two integers X,Y\n";
        return false;
      }
      request.target.px = static_cast<int>(v[0]);
      request.target.py = static_cast<int>(v[1]);
      return true;
    }
    if (!ray_text.empty()) {
      if (!parse_numbers(ray_text, 6, v)) {
        std::cerr << "algray: --ray " << ray_text << ": expected six numbers ox,oy,oz,dx,dy,dz\n";
        return false;
      }
      request.target.given_ray = true;
      request.target.origin = {v[0], v[1], v[2]};
      request.target.direction = {v[3], v[4], v[5]};
      return true;
    }
    std::cerr << "algray: probe needs --pixel X,Y or --ray ox,oy,oz,dx,dy,dz\n";
    return false;
  }

  // --plot-range into the request; false after saying what is wrong.
  bool read_plot_range() {
    if (!plot_range_text.empty() && !request.plot_path) {
      std::cerr << "algray: --plot-range goes with --plot\n";
      return false;
    }
    if (plot_range_text == "isolating") {
      request.plot_range.kind = PlotRange::Kind::Isolating;
    } else if (!plot_range_text.empty() && plot_range_text != "segment") {
      std::vector<double> v;
      // The width must be finite too: the plot divides by it.
      if (!parse_numbers(plot_range_text, 2, v) || !(v[0] < v[1]) || !std::isfinite(v[1] - v[0])) {
        std::cerr << "algray: --plot-range " << plot_range_text
                  << ": expected segment, isolating, or two increasing numbers T0,T1\n";
        return false;
      }
      request.plot_range = {PlotRange::Kind::Given, v[0], v[1]};
    }
    return true;
  }

  int run() {
    if (!scene.scene_path.empty()) request.scene_path = scene.scene_path;
    if (!scene.equation.empty()) request.equation = scene.equation;
    if (!collect_overrides(cmd, scene, request.overrides)) return kExitBadInput;
    request.device_spec = scene.device_spec;
    request.use_cache = !scene.no_cache;
    if (!read_target() || !read_plot_range()) return kExitBadInput;
    return run_probe(request, std::cout, std::cerr);
  }
};

// `algray batch`: a jobs file where the others take a scene.
struct BatchCommand {
  CLI::App* cmd = nullptr;
  BatchRequest request;
  SceneOptions scene;
  std::string shard_text;
  bool merge_logs = false;

  void add_to(CLI::App& app) {
    cmd = app.add_subcommand(
        "batch", "render a TOML list of jobs (sweeps, orbits) in one process with one device and program cache");
    cmd->add_option("jobs", request.jobs_path, "jobs file (.toml), or - for standard input")->required();
    add_scene_options(cmd, scene, false);
    cmd->add_flag("--resume", request.resume, "skip frames whose outputs all exist already");
    cmd->add_option("--log", request.log_path,
                    "JSON-lines log, one line per frame (default: beside the jobs file, <name>.log.jsonl)");
    cmd->add_option("--stats", request.stats_path, "write a summary of the batch as JSON");
    cmd->add_option("--video", request.video_path,
                    "encode every frame of every job, in order, into this " + video_extensions() +
                        " as the frames come (with the ffmpeg program), at the first job's fps (default 30); jobs "
                        "may then have no output of their own");
    cmd->add_option("--shard", shard_text,
                    "K/N: render only frames K, K+N, K+2N, ... of all (0 <= K < N), writing the shard's own log and "
                    "stats; default in a Slurm array job: from SLURM_ARRAY_TASK_ID and _COUNT (or _MIN/_MAX)");
    cmd->add_flag("--merge-logs", merge_logs,
                  "render nothing: join the shard logs (<log>.shard-K-of-N) into the batch's log and report "
                  "frames that no shard rendered");
    cmd->add_flag("--mixed-shard-counts", request.merge_mixed_counts,
                  "with --merge-logs: join shard logs of different shard counts too (refused by default: one count "
                  "is a stale run)");
  }

  int run() {
    if (!collect_overrides(cmd, scene, request.overrides)) return kExitBadInput;
    request.device_spec = scene.device_spec;
    request.use_cache = !scene.no_cache;
    if (merge_logs) return run_merge_logs(request, std::cerr);
    try {
      std::string error;
      BatchShard shard;
      if (!shard_text.empty() && !parse_shard(shard_text, shard, error)) {
        std::cerr << "algray: --shard " << shard_text << ": " << error << "\n";
        return kExitBadInput;
      }
      request.shard = shard_text.empty() ? shard_from_slurm_environment() : shard;
    } catch (const std::exception& e) {
      return report_error(e, std::cerr);
    }
    bool progress = ::isatty(STDERR_FILENO) != 0;
#ifdef ALGRAY_WITH_MPI
    // Started by an MPI launcher, the ranks share the batch's frames; started alone, MPI is never initialised.
    std::optional<MpiWorld> world;
    if (started_by_mpi_launcher()) {
      try {
        world.emplace();
      } catch (const std::exception& e) {
        return report_error(e, std::cerr);
      }
      request.distribute = [&world](const BatchRequest& r, const BatchCallbacks& c) {
        return run_mpi_batch(r, c, *world);
      };
      progress = progress && world->rank() == 0;
    }
#endif
    return run_batch_command(request, progress, std::cerr);
  }
};

struct DevicesCommand {
  CLI::App* cmd = nullptr;
  std::string stats_path;

  void add_to(CLI::App& app) {
    cmd = app.add_subcommand("devices", "list OpenCL platforms and devices");
    cmd->add_option("--stats", stats_path, "write the list as JSON too");
    add_no_fp64_flag(cmd);
  }

  int run() { return run_devices(stats_path, std::cout, std::cerr); }
};

// `algray view`: the scene options every scene command takes, and where to listen.
struct ViewCommand {
  CLI::App* cmd = nullptr;
  ViewRequest request;
  SceneOptions scene;

  void add_to(CLI::App& app) {
    cmd = app.add_subcommand("view", "explore a scene live in the browser: a local web server for its page and frames");
    add_scene_options(cmd, scene);
    cmd->add_option("--port", request.port, "port to listen on (default: any free port; the URL is printed)")
        ->check(CLI::Range(0, 65535));
    cmd->add_option("--host", request.host,
                    "address to listen on (default 127.0.0.1; any other is reachable from other machines)");
    cmd->add_flag("--open", request.open, "open the page in the default browser (xdg-open)");
    cmd->add_option("--token", request.token,
                    "require ?token=TOKEN in every URL (default: none on loopback, else a random one, printed)");
    ViewLimits& l = request.limits;
    cmd->add_option("--max-connections", l.max_connections, "connections open at once; more are answered 429")
        ->capture_default_str()
        ->check(CLI::Range(1, 1024));
    cmd->add_option("--max-streams", l.max_streams, "pages' frame streams open at once; more are answered 429")
        ->capture_default_str()
        ->check(CLI::Range(1, 1024));
    cmd->add_option("--max-header-bytes", l.max_header_bytes, "bytes of a request's line and headers; more: 431")
        ->capture_default_str()
        ->check(CLI::Range(1024, 1 << 24));
    cmd->add_option("--header-timeout", l.header_timeout_s, "seconds to receive a request's line and headers")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 3600.0));
    cmd->add_option("--request-timeout", l.request_timeout_s,
                    "seconds from a request's first byte to its answer, waiting and rendering included")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 86400.0));
    cmd->add_option("--max-settings", l.max_settings, "set= items per request")
        ->capture_default_str()
        ->check(CLI::Range(1, 4096));
    cmd->add_option("--max-parse-ms", l.max_parse_ms, "milliseconds applying one request's set= items")
        ->capture_default_str()
        ->check(CLI::Range(1.0, 3600e3));
    cmd->add_option("--max-frame-samples", l.max_frame_samples,
                    "camera rays x (1 + shadow points) x (1 + bounces) per frame")
        ->capture_default_str()
        ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1} << 50));
  }

#ifdef ALGRAY_FULL
  int run() {
    if (!scene.scene_path.empty()) request.scene_path = scene.scene_path;
    if (!scene.equation.empty()) request.equation = scene.equation;
    if (!collect_overrides(cmd, scene, request.overrides)) return kExitBadInput;
    request.device_spec = scene.device_spec;
    request.use_cache = !scene.no_cache;
    return run_view(request, std::cout, std::cerr);
  }
#endif
};

}  // namespace

int main(int argc, char** argv) {
  install_output_cleanup_handlers();
  set_cache_warning_handler([](const std::string& text) { std::cerr << text << std::flush; });

  CLI::App app{"algray: ray tracing of real algebraic surfaces P(x,y,z) = 0 on any OpenCL device"};
  app.set_version_flag("--version", version_string(), "print the version and the git revision, and exit");
  app.require_subcommand(1);
  RenderCommand render;
  ProbeCommand probe;
  BatchCommand batch;
  DevicesCommand devices;
  ViewCommand view;
  render.add_to(app);
  probe.add_to(app);
  batch.add_to(app);
  devices.add_to(app);
  view.add_to(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitBadInput;
  }
  if (devices.cmd->parsed()) return devices.run();
#ifdef ALGRAY_FULL
  if (view.cmd->parsed()) return view.run();
#else
  // The arguments were checked here (bad input is 2 without starting the other binary); algray-full parses them
  // again. ALGRAY_FULL_HAS_MPI: algray-full was built with the cluster layer.
  if (view.cmd->parsed() ||
      (ALGRAY_FULL_HAS_MPI && started_by_mpi_launcher() && (render.cmd->parsed() || batch.cmd->parsed())))
    return hand_off_to_full(argv, std::cerr);
#endif
  if (batch.cmd->parsed()) return batch.run();
  if (probe.cmd->parsed()) return probe.run();
  end_process(render.run());
}
