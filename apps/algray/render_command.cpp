// `algray render`, `algray batch` and `algray devices`: requests to the library's calls, failures to exit codes.
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "algray/device/cl_runtime.h"
#include "algray/io/image_io.h"
#include "algray/util/version.h"
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
    case BatchOutcome::Done: return kExitOk;
    case BatchOutcome::BadInput: return kExitBadInput;
    case BatchOutcome::FramesFailed:
    case BatchOutcome::Stopped: break;
  }
  return kExitFailure;
}

}  // namespace

int run_render(const RenderRequest& req, std::ostream& err) {
  const auto started = std::chrono::steady_clock::now();
  // Everything the user gave is checked before any device work, so bad input costs nothing and writes nothing.
  Scene scene;
  try {
    scene = SceneLoader().load(req.scene_path, req.overrides);
    err << warning_text(scene);
    check_outputs(scene, req.outputs, req.scene_path.value_or(""));
  } catch (const std::exception& e) {
    return report_error(e, err);
  }
  ProgressLine progress(req.progress);
  RenderCallbacks callbacks;
  if (progress.enabled())
    callbacks.on_progress = [&](const RenderProgress& p) {
      char line[256];
      std::snprintf(line, sizeof line, "rendering %s: %3d%% (%d/%d tiles)", scene.name.c_str(),
                    100 * p.tiles_done / p.tiles_total, p.tiles_done, p.tiles_total);
      progress.show(line);
    };
  try {
    RenderContext context(req.device_spec, req.use_cache);
    render_scene(scene, req.outputs, context, callbacks, started);
  } catch (const std::exception& e) {
    progress.finish();
    return report_error(e, err);
  }
  return kExitOk;
}

int run_batch_command(const BatchRequest& request, bool show_progress, std::ostream& err) {
  ProgressLine progress(show_progress);
  BatchCallbacks callbacks;
  callbacks.on_message = [&](const std::string& text) { err << text; };
  if (progress.enabled())
    callbacks.on_frame = [&](const BatchProgress& p) {
      char line[512];
      std::snprintf(line, sizeof line, "[%*d/%d] %s frame %d/%d: %s %s | elapsed %s, eta %s   ",
                    static_cast<int>(std::to_string(p.total).size()), p.done, p.total, p.job->name.c_str(),
                    p.frame + 1, p.job->frames, p.status.c_str(), seconds_text(p.frame_ms).c_str(),
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
  out << describe_devices(list);
  if (stats_path.empty()) return kExitOk;
  nlohmann::json j = {{"version", version_string()}, {"devices", nlohmann::json::array()}};
  for (const DeviceInfo& d : list)
    j["devices"].push_back({{"index", d.index},
                            {"platform", d.platform_name},
                            {"platform_version", d.platform_version},
                            {"name", d.name},
                            {"vendor", d.vendor},
                            {"version", d.version},
                            {"driver", d.driver_version},
                            {"type", d.type},
                            {"compute_units", d.compute_units},
                            {"fp64", d.fp64},
                            {"global_mem_bytes", d.global_mem_bytes},
                            {"max_alloc_bytes", d.max_alloc_bytes}});
  try {
    check_output_writable(stats_path);
    write_text_file(stats_path, j.dump(2) + "\n");
  } catch (const std::exception& e) {
    return report_error(e, err);
  }
  return kExitOk;
}

}  // namespace algray::cli
