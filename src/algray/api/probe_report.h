// `algray probe`: probes one ray with one or every solver, beside solver_ref's certified answer; text, JSON, plot.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "algray/render/probe.h"
#include "algray/render/reference_render.h"
#include "algray/scene/scene.h"

namespace algray {

// The stretch of the ray the plot shows: the whole segment [t_in, t_out], the isolating interval of the scene's
// solver (with a tenth of its width either side, to show its ends), or a given [from, to].
struct PlotRange {
  enum class Kind { Segment, Isolating, Given } kind = Kind::Segment;
  double from = 0, to = 0;
};

struct ProbeRequest {
  std::optional<std::string> scene_path;  // unset: the built-in default scene
  std::vector<Override> overrides;        // --set and the solver flags, in order
  std::string device_spec;
  ProbeTarget target;
  bool all_solvers = false;              // every isolation x refinement, side by side
  std::optional<std::string> plot_path;  // .svg or .png
  PlotRange plot_range;
  bool json = false;                      // JSON on stdout instead of text
  std::optional<std::string> stats_path;  // the JSON report written to a file as well
  bool use_cache = true;
};

// solver_ref's view of the probed ray: its certificate and every root on the segment.
struct ProbeReference {
  RayCertificate certificate;
  struct Root {
    double t = 0;
    int multiplicity = 0;
    std::string kind;  // ref::to_string of its classification
  };
  std::vector<Root> roots;  // in increasing order, on [certificate.lo, certificate.hi]
};
ProbeReference probe_reference(const Scene& scene, std::size_t surface, const PixelRay& ray, Precision precision);

// The probe of one surface: every solver asked for, on the same ray.
struct SurfaceProbe {
  std::size_t surface = 0;
  std::vector<SolverTrace> traces;  // the scene's own solver first
  ProbeReference reference;
};

// Text for people and JSON for scripts; the same content.
void print_probe(std::ostream& out, const Scene& scene, const ProbeTarget& target,
                 const std::vector<SurfaceProbe>& probes);
nlohmann::json probe_json(const Scene& scene, const ProbeTarget& target, const std::vector<SurfaceProbe>& probes);

// Runs the command; errors go to err, the report to out. Returns the CLI exit code.
int run_probe(const ProbeRequest& request, std::ostream& out, std::ostream& err);

}  // namespace algray
