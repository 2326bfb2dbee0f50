// Probe reports: one ray with one or every solver, beside solver_ref's certified answer; text, JSON, plot.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "algray/api/render_job.h"
#include "algray/io/probe_plot.h"
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

// Bad input in a probe's target, before any device work: a pixel outside the image, a ray without direction
// (SceneError naming --pixel or --ray).
void check_probe_target(const Scene& scene, const ProbeTarget& target);

// Every solver asked for (the scene's own, or with all_solvers every isolation x refinement) on the target's ray,
// for each surface, with solver_ref's answer. Throws DeviceError when the device cannot be opened.
std::vector<SurfaceProbe> probe_scene(const Scene& scene, const ProbeTarget& target, bool all_solvers,
                                      RenderContext& context);

// The plot of one surface's probe over `range`: P*(t) from solver_ref's exact restriction, with the solver's
// intervals, its root and the reference's roots.
ProbePlot make_plot(const Scene& scene, const ProbeTarget& target, const SurfaceProbe& probe, const PlotRange& range);

}  // namespace algray
