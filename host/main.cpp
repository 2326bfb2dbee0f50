// The algray command line: `algray render` and `algray devices`.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <iostream>

#include "cl_runtime.h"
#include "image_io.h"
#include "render_job.h"

int main(int argc, char** argv) {
  using namespace algray;
  install_output_cleanup_handlers();

  CLI::App app{"algray: ray tracing of real algebraic surfaces P(x,y,z) = 0 on any OpenCL device"};
  app.require_subcommand(1);

  RenderRequest request;
  std::string scene_path;
  std::vector<std::string> sets;
  int width = 0, height = 0;
  std::string precision, isolation, refinement, tolerance, max_iterations;
  bool no_cache = false, preview = false;
  std::string stats_path;
  CLI::App* render = app.add_subcommand("render", "render a scene (default: the built-in Barth sextic)");
  render->add_option("scene", scene_path, "scene file (.toml)");
  render->add_option("-o,--output", request.outputs, "output image; .exr or .png by extension; may be repeated")
      ->default_str("algray.exr");
  render->add_option("--width", width, "image width in pixels (overrides image.width)");
  render->add_option("--height", height, "image height in pixels (overrides image.height)");
  render->add_option("--device", request.device_spec, "device index or name substring (see `algray devices`)");
  render->add_option("--precision", precision, "float, double or mixed (overrides render.precision)");
  render->add_option("--isolation", isolation,
                     "root isolation: bernstein, descartes, sturm or derivative-chain (overrides render.isolation)");
  render->add_option(
      "--refine", refinement,
      "root refinement: brent, bisection, regula-falsi, illinois or newton (overrides render.refinement)");
  render->add_option("--tolerance", tolerance, "the stopping tolerance eps (overrides render.tolerance)");
  render->add_option("--max-iterations", max_iterations,
                     "the refinement's iteration cap (overrides render.max_iterations)");
  render->add_option("--set", sets, "override a scene key: name=value (a bare name is a parameter)");
  render->add_option("--stats", stats_path, "write render statistics as JSON");
  render->add_flag("--preview", preview,
                   "the paper's preview mode: primary rays only (no shadows); sets render.preview");
  render->add_flag("--no-cache", no_cache, "compile kernels from source; neither read nor write the program cache");
  render->add_flag(
      "--reference", request.reference,
      "solve every pixel exactly on the CPU (solver_ref, all cores, slow); adds a reference.class channel");

  CLI::App* devices = app.add_subcommand("devices", "list OpenCL platforms and devices");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitBadInput;
  }

  if (devices->parsed()) {
    const auto list = enumerate_devices();
    if (list.empty()) {
      std::cerr << "algray: no OpenCL device found (on Debian: apt-get install pocl-opencl-icd)\n";
      return kExitFailure;
    }
    std::cout << describe_devices(list);
    return kExitOk;
  }

  if (!scene_path.empty()) request.scene_path = scene_path;
  if (request.outputs.empty()) request.outputs.push_back("algray.exr");
  for (const std::string& s : sets) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0) {
      std::cerr << "algray: --set " << s << ": expected name=value\n";
      return kExitBadInput;
    }
    request.overrides.push_back({s.substr(0, eq), s.substr(eq + 1)});
  }
  // Flags are overrides like any --set, applied last so they win.
  if (render->count("--width")) request.overrides.push_back({"image.width", std::to_string(width)});
  if (render->count("--height")) request.overrides.push_back({"image.height", std::to_string(height)});
  if (!precision.empty()) request.overrides.push_back({"render.precision", "\"" + precision + "\""});
  if (!isolation.empty()) request.overrides.push_back({"render.isolation", "\"" + isolation + "\""});
  if (!refinement.empty()) request.overrides.push_back({"render.refinement", "\"" + refinement + "\""});
  // Numbers pass through as written, so that the scene's own checks report them.
  if (!tolerance.empty()) request.overrides.push_back({"render.tolerance", tolerance});
  if (!max_iterations.empty()) request.overrides.push_back({"render.max_iterations", max_iterations});
  if (preview) request.overrides.push_back({"render.preview", "true"});
  request.use_cache = !no_cache;
  if (!stats_path.empty()) request.stats_path = stats_path;
  request.progress = ::isatty(STDERR_FILENO) != 0;
  return run_render(request, std::cerr);
}
