// `algray probe`: one ray's report and plot from the parsed request, failures to exit codes.
#include "algray/io/image_io.h"
#include "algray/util/json_text.h"
#include "commands.h"
#include "exit_codes.h"

namespace algray::cli {

int run_probe(const ProbeRequest& req, std::ostream& out, std::ostream& err) {
  Scene scene;
  try {
    scene = req.equation ? load_equation(*req.equation, req.overrides) : SceneLoader().load(req.scene_path, req.overrides);
    err << warning_text(scene);
    check_probe_target(scene, req.target);
    if (req.plot_path) {
      check_probe_plot_path(*req.plot_path);
      check_output_writable(*req.plot_path);
    }
    if (req.stats_path) check_output_writable(*req.stats_path);
    std::vector<RoleAndPath> outputs;
    if (req.stats_path) outputs.push_back({"--stats", *req.stats_path});
    if (req.plot_path) outputs.push_back({"--plot", *req.plot_path});
    check_distinct_files({{"scene file", req.scene_path.value_or("")}}, outputs);
  } catch (const std::exception& e) {
    return report_error(e, err);
  }
  // Paths were checked above: a write that fails from here on is a failure (exit 1), not bad input.
  std::vector<std::string> planned;
  if (req.stats_path) planned.push_back(*req.stats_path);
  if (req.plot_path) planned.push_back(*req.plot_path);
  OutputWriter writer(planned);
  try {
    RenderContext context(req.device_spec, req.use_cache);
    const std::vector<SurfaceProbe> probes = probe_scene(scene, req.target, req.all_solvers, context);
    if (req.json || req.stats_path) {
      const nlohmann::json j = probe_json(scene, req.target, probes);
      if (req.json) out << dump_json(j, 2) << "\n";
      if (req.stats_path)
        writer.write(*req.stats_path, [&] { write_text_file(*req.stats_path, dump_json(j, 2) + "\n"); });
    }
    if (!req.json) print_probe(out, scene, req.target, probes);
    if (req.plot_path) {
      // The surface whose root the render shows (the nearest), else the first the ray meets at all.
      const SurfaceProbe* hit = nullptr;
      for (const SurfaceProbe& p : probes) {
        const SolverTrace& tr = p.traces.front();
        if (tr.in_extent && (!hit || tr.t < hit->traces.front().t)) hit = &p;
      }
      if (!hit) {
        err << "algray: " << *req.plot_path << " not written: the ray misses the extent, so there is nothing to plot\n";
        return kExitFailure;
      }
      const auto plot = make_plot(scene, req.target, *hit, req.plot_range);
      writer.write(*req.plot_path, [&] { write_probe_plot(*req.plot_path, plot); });
    }
  } catch (const std::exception& e) {
    return report_error(e, err);
  }
  return kExitOk;
}

}  // namespace algray::cli
