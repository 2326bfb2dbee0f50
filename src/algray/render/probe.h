// The probe: one ray through the render's own kernel code with its solver steps recorded (kernels/probe.cl).
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "algray/device/cl_runtime.h"
#include "algray/device/kernel_config.h"
#include "algray/device/program_cache.h"
#include "algray/scene/camera.h"
#include "algray/scene/scene.h"
#include "kernels/algray_shared.h"

namespace algray {

// The ray to probe: a pixel's, through its centre exactly as a render without antialiasing traces it (the
// primary kernel's camera_rays()), or one given in world coordinates, as the secondary-ray kernel takes rays.
struct ProbeTarget {
  bool given_ray = false;
  int px = 0, py = 0;
  glm::dvec3 origin{0}, direction{0, 0, -1};
};

// One isolation step (ALGRAY_EVENT_STEP).
struct ProbeStep {
  int decision = 0;           // ALGRAY_STEP_*
  int count = -1;             // sign variations (Sturm: distinct roots) on the interval; -1 where none was counted
  int level = 0;              // halving level: the interval is 2^-level of [t_in, t_out] wide
  double lo = 0, hi = 0;      // the interval's ends as fractions of [t_in, t_out]
  double f_lo = 0, f_hi = 0;  // P* there, in the solver's scaling
};

// One refinement iterate, or one step of the derivative chain's solve on a derivative of P*.
struct ProbeIterate {
  int number = 0;
  int order = 0;            // 0: refinement of P*; k: the derivative chain working on the k-th derivative
  double y = 0, value = 0;  // the point and the polynomial's value there
  double lo = 0, hi = 0;    // the bracket after this iterate
  double t = 0;             // y as a ray parameter
};

// Why adaptive precision's float kernel doubted the ray (ALGRAY_EVENT_DOUBT), which ends its search.
struct ProbeDoubt {
  int reason = 0;         // ALGRAY_DOUBT_* (doubt_reason() in render/escalation.h names it)
  int level = 0;          // halving level of the interval
  double lo = 0, hi = 0;  // the interval, as fractions of [t_in, t_out]
  double value = 0;       // what stood within the noise: a coefficient, P at an end, or the slope's margin
  double noise = 0;       // the noise bound it was held to
};

// A doubt settled after all (ALGRAY_EVENT_CONFIRMED): a flat-doubted root (kernels/surface.h confirm_flat_roots),
// P from the monomials at t - delta and t + delta, delta = ALGRAY_DOUBT_POSITION |t|; or an accept-doubted bracket
// (kernels/methods/bernstein.h settle_brackets), P at its ends; or a discard-doubted interval (discards_settled),
// P at its ends. Each value beyond its rounding bound. A search may settle several doubts: this is the last.
struct ProbeConfirmed {
  double before = 0, before_rounding = 0;
  double after = 0, after_rounding = 0;
  bool float_float = false;  // evaluated in float-float, float's rounding having been too large (discards: always)
  bool bracket = false;      // the bracket's ends, with the signs float gave there
  bool discard = false;      // a root-free interval's ends, of its coefficients' sign (at an end that stood clear of
                             // the noise, float's value and that noise)
};

// Everything the kernel recorded for one ray and one solver configuration.
struct SolverTrace {
  KernelConfig config;
  std::string program_origin;  // "built", "memory" or "disk"
  PixelRay ray;                // the ray the kernel traced, world coordinates (rounded to its precision)
  bool in_extent = false;
  double t_in = 0, t_out = 0;  // the kernel's clipping of the ray to the extent
  int basis = 0;               // ALGRAY_BASIS_* of `coefficients`
  // P* as the solver started from it: in unit coordinates, scaled so the surface's largest coefficient is 1.
  std::vector<double> coefficients, coefficients_lo;  // low parts are nonzero in mixed precision only
  // The same polynomial in the power basis of s, t = t_in + s (t_out - t_in); for ALGRAY_BASIS_POWER_EYE, of t.
  std::vector<double> power;
  std::vector<ProbeStep> steps;
  std::vector<ProbeIterate> chain_iterates;     // derivative chain only
  int isolation_status = ALGRAY_ISOLATED_NONE;  // ALGRAY_ISOLATED_* (ALGRAY_EVENT_ISOLATED)
  bool halving_limit = false;
  double iso_lo = 0, iso_hi = 0, iso_f_lo = 0, iso_f_hi = 0;
  std::vector<ProbeIterate> iterates;
  std::optional<ProbeDoubt> doubt;  // adaptive precision: the decision that sent the ray to the second pass
  std::optional<ProbeConfirmed> confirmed;  // adaptive precision: the doubt withdrawn; no second pass then
  // Adaptive precision: discard doubts settled on the way (confirmed->discard), each with the doubt it settled; the
  // search went on past each interval, and may have doubted again.
  std::vector<std::pair<ProbeDoubt, ProbeConfirmed>> settled_discards;
  HitRecord hit{};                  // exactly what the render writes for this ray
  double t = std::numeric_limits<double>::infinity();     // hit.t_hi + hit.t_lo; +inf without a root
  std::uint32_t events_offered = 0, events_recorded = 0;  // the log overflowed if they differ

  bool found() const { return (hit.flags & ALGRAY_HIT_FOUND) != 0; }
  std::uint32_t isolation_steps() const { return ALGRAY_WORK_ISOLATION_STEPS(hit.work); }
  std::uint32_t refine_iterations() const { return ALGRAY_WORK_REFINE_ITERATIONS(hit.work); }
  // A fraction of [t_in, t_out] as a ray parameter, as the kernel maps it.
  double t_at(double fraction) const { return t_in + fraction * (t_out - t_in); }
};

// Builds (or fetches) the probe program for `config` (its entry is replaced by "probe") and traces the ray
// against surface `surface` of the scene. Image size and camera come from the scene, as in a render.
// Events the log keeps by default: plain regula falsi's 1000 iterations after 52 levels of halving fit; a
// longer log (the derivative chain at high degree) is cut, and events_offered says by how much.
inline constexpr std::uint32_t kProbeLogCapacity = 16384;
SolverTrace trace_probe(ClSession& session, ProgramCache& cache, const Scene& scene, std::size_t surface,
                        KernelConfig config, const ProbeTarget& target, std::uint32_t capacity = kProbeLogCapacity);

// Bernstein coefficients b_k (of s in [0, 1]) in the power basis of s, in long double.
std::vector<double> bernstein_to_power(const std::vector<double>& b, const std::vector<double>& b_lo);

// Names for the recorded codes, as the text and JSON reports print them.
const char* step_decision_name(int decision);
const char* basis_name(int basis);

}  // namespace algray
