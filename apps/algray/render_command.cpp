// `algray render`, `algray batch` and `algray devices`: requests to the library's calls, failures to exit codes.
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "algray/device/cl_runtime.h"
#include "algray/device/fp64_speed.h"
#include "algray/io/image_io.h"
#include "algray/util/json_text.h"
#include "algray/util/version.h"
#ifdef ALGRAY_WITH_MPI
#include "algray/cluster/mpi_render.h"
#endif
#include "commands.h"
#include "exit_codes.h"
#include "progress_line.h"

namespace algray::cli {

int report_error(const std::exception& e, std::ostream& err) {
  const ErrorReport report = describe_error(e);
  err << report.text;
  return report.bad_input ? kExitBadInput : kExitFailure;
}

namespace {

int exit_code(BatchOutcome outcome) {
  switch (outcome) {
    case BatchOutcome::Done:
      return kExitOk;
    case BatchOutcome::BadInput:
      return kExitBadInput;
    case BatchOutcome::FramesFailed:
    case BatchOutcome::Stopped:
      break;
  }
  return kExitFailure;
}

}  // namespace

namespace {

// The progress line of one render: "rendering NAME[ on N ranks]: P% (D/T tiles|bands)".
RenderCallbacks progress_callbacks(ProgressLine& progress, const std::string& what, const char* unit) {
  RenderCallbacks callbacks;
  if (progress.enabled())
    callbacks.on_progress = [&progress, what, unit](const RenderProgress& p) {
      char line[256];
      std::snprintf(line, sizeof line, "rendering %s: %3d%% (%d/%d %s)", what.c_str(),
                    100 * p.tiles_done / p.tiles_total, p.tiles_done, p.tiles_total, unit);
      progress.show(line);
    };
  return callbacks;
}

}  // namespace

// "wrote a.png and s.json (800x600) in 1.23 s": what a render wrote, once it is all written.
std::string written_line(const Scene& scene, const RenderOutputs& outputs, double seconds) {
  std::vector<std::string> files;
  if (outputs.heatmap_path) files.push_back(*outputs.heatmap_path);
  files.insert(files.end(), outputs.images.begin(), outputs.images.end());
  if (outputs.stats_path) files.push_back(*outputs.stats_path);
  std::string list;
  for (std::size_t i = 0; i < files.size(); ++i)
    list += (i == 0 ? "" : i + 1 == files.size() ? " and " : ", ") + files[i];
  char tail[128];
  std::snprintf(tail, sizeof tail, " (%dx%d) in %.2f s\n", scene.image.width, scene.image.height, seconds);
  return "wrote " + list + tail;
}

Scene load_request_scene(const std::optional<std::string>& path, const std::optional<std::string>& equation,
                         const std::vector<Override>& overrides) {
  return equation ? load_equation(*equation, overrides) : SceneLoader().load(path, overrides);
}

int run_render(const RenderRequest& req, std::ostream& out, std::ostream& err) {
  const auto started = std::chrono::steady_clock::now();
  // Everything the user gave is checked before any device work, so bad input costs nothing and writes nothing.
  Scene scene;
  try {
    scene = load_request_scene(req.scene_path, req.equation, req.overrides);
    err << warning_text(scene);
    check_outputs(scene, req.outputs, req.scene_path.value_or(""));
  } catch (const std::exception& e) {
    return report_error(e, err);
  }
  ProgressLine progress(req.progress);
  const RenderCallbacks callbacks = progress_callbacks(progress, scene.name, "tiles");
  try {
    RenderContext context(req.device_spec, req.use_cache);
    render_scene(scene, req.outputs, context, callbacks, started);
  } catch (const std::exception& e) {
    progress.finish();
    return report_error(e, err);
  }
  progress.finish();
  if (!req.quiet)
    out << written_line(scene, req.outputs,
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count())
        << std::flush;
  return kExitOk;
}

#ifdef ALGRAY_WITH_MPI
int run_render_across_ranks(const RenderRequest& req, MpiWorld& world, std::ostream& err) {
  const auto started = std::chrono::steady_clock::now();
  const bool lead = world.rank() == 0;
  // Every rank reads the scene; rank 0 alone checks the outputs and speaks for the job. Any rank's bad input
  // ends every rank with it, before any device work.
  Scene scene;
  int code = kExitOk;
  try {
    if (req.scene_path && *req.scene_path == "-")
      throw SceneError("scene -", "a scene on standard input cannot be shared among MPI ranks; give its file");
    if (req.outputs.reference || !req.outputs.aovs.empty() || req.outputs.heatmap_path)
      throw SceneError("mpirun",
                       "--reference, --aov and --heatmap are not available across MPI ranks yet; render "
                       "them in one process");
    scene = load_request_scene(req.scene_path, req.equation, req.overrides);
    if (lead) {
      err << warning_text(scene);
      check_outputs(scene, req.outputs, req.scene_path.value_or(""));
    }
  } catch (const std::exception& e) {
    code = report_error(e, err);
  }
  if (!every_rank_agrees(code == kExitOk)) {
    if (code == kExitOk && lead) err << "algray: another MPI rank refused the scene (see its message)\n";
    return kExitBadInput;
  }
  if (!lead) {
    std::unique_ptr<RenderContext> context;
    std::unique_ptr<Renderer> renderer;
    std::string cannot_render;
    try {
      context = std::make_unique<RenderContext>(req.device_spec, req.use_cache);
      renderer = std::make_unique<Renderer>(context->sessions(), context->cache());
    } catch (const std::exception& e) {
      cannot_render = describe_error(e).text;
    }
    render_bands_as_worker(renderer.get(), scene, cannot_render);
    return share_exit_code(kExitOk, world);
  }
  ProgressLine progress(req.progress);
  RenderCallbacks callbacks =
      progress_callbacks(progress, scene.name + " on " + std::to_string(world.size()) + " ranks", "rows");
  bool dealt = false;
  callbacks.render_pixels = [&](Renderer& renderer, const Scene& s, const RenderOptions& options) {
    dealt = true;
    return render_bands_as_rank0(renderer, s, options, outputs_hold_depth(req.outputs), world);
  };
  try {
    RenderContext context(req.device_spec, req.use_cache);
    render_scene(scene, req.outputs, context, callbacks, started);
  } catch (const std::exception& e) {
    progress.finish();
    code = report_error(e, err);
  }
  if (!dealt) release_workers(world);
  return share_exit_code(code, world);
}
#endif

int run_batch_command(const BatchRequest& request, bool show_progress, std::ostream& err) {
  ProgressLine progress(show_progress);
  BatchCallbacks callbacks;
  callbacks.on_message = [&](const std::string& text) { err << text; };
  if (progress.enabled())
    callbacks.on_frame = [&](const BatchProgress& p) {
      char line[512];
      std::snprintf(line, sizeof line, "[%*d/%d] %s frame %d/%d: %s %s | elapsed %s, eta %s   ",
                    static_cast<int>(std::to_string(p.total).size()), p.done, p.total, p.job->name.c_str(), p.frame + 1,
                    p.job->frames, p.status.c_str(), seconds_text(p.frame_ms).c_str(),
                    seconds_text(p.elapsed_ms).c_str(), seconds_text(p.eta_ms).c_str());
      progress.show(line);
    };
  return exit_code(run_batch(request, callbacks));
}

int run_merge_logs(const BatchRequest& request, std::ostream& err) {
  BatchCallbacks callbacks;
  callbacks.on_message = [&](const std::string& text) { err << text; };
  return exit_code(merge_shard_logs(request, callbacks));
}

int run_devices(const std::string& stats_path, std::ostream& out, std::ostream& err) {
  const auto list = enumerate_devices();
  if (list.empty()) {
    err << "algray: no OpenCL device found (on Debian: apt-get install pocl-opencl-icd)\n";
    return kExitFailure;
  }
  // Each device with fp64 is timed once in float and double (device/fp64_speed.h); the program cache keeps it.
  std::vector<std::optional<double>> slowdown(list.size());
  ProgramCache cache(true);
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (!list[i].fp64) continue;
    try {
      slowdown[i] = fp64_slowdown(list[i], cache);
    } catch (const std::exception& e) {
      err << "algray: device [" << list[i].index << "] " << list[i].name << ": double precision not timed: " << e.what()
          << "\n";
    }
  }
  out << describe_devices(list, slowdown);
  if (stats_path.empty()) return kExitOk;
  nlohmann::json j = {{"version", version_string()}, {"devices", nlohmann::json::array()}};
  for (const DeviceInfo& d : list)
    j["devices"].push_back(
        {{"index", d.index},
         {"platform", d.platform_name},
         {"platform_version", d.platform_version},
         {"name", d.name},
         {"vendor", d.vendor},
         {"version", d.version},
         {"driver", d.driver_version},
         {"type", d.type},
         {"compute_units", d.compute_units},
         {"fp64", d.fp64},
         {"fp64_hidden", d.fp64_hidden},
         {"fp64_slowdown", slowdown[static_cast<std::size_t>(&d - list.data())]
                               ? nlohmann::json(*slowdown[static_cast<std::size_t>(&d - list.data())])
                               : nlohmann::json()},
         {"global_mem_bytes", d.global_mem_bytes},
         {"max_alloc_bytes", d.max_alloc_bytes}});
  try {
    check_output_writable(stats_path);
    write_text_file(stats_path, dump_json(j, 2) + "\n");
  } catch (const std::exception& e) {
    return report_error(e, err);
  }
  return kExitOk;
}

}  // namespace algray::cli
