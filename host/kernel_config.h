// KernelConfig: every choice that changes a kernel's code, turned into build options and a cache key.
#pragma once

#include <string>

namespace algray {

inline constexpr int kMaxDegree = 32;

// Mixed: float, except that P*(t) is built in compensated float-float arithmetic (degrees up to 15).
enum class Precision { Float, Double, Mixed };
inline constexpr int kMaxMixedDegree = 15;
enum class Isolation { Bernstein, PowerDescartes, Sturm, DerivativeChain };
enum class Refinement { Brent, Bisection, RegulaFalsi, Illinois, Newton };
// Where P*(t) is built around: Auto (scenes only) is Screen for camera rays where it applies (screen_form_applies
// in render_plan.h), else Extent.
enum class RayOrigin { Auto, Extent, Eye, Screen };
struct KernelConfig;

// The lane counts a kernel can be built with, and the one a render uses on a device of `device_type` ("CPU",
// "GPU", ...) unless the scene sets render.lanes: 8 on a CPU, whose work-items run one after another, 1 on
// devices that already run work-items in SIMD.
bool valid_lanes(int lanes);
std::string lanes_choices();
int default_lanes(const std::string& device_type);
bool lanes_apply(const KernelConfig& config);

std::string to_string(Precision p);
std::string to_string(Isolation i);
std::string to_string(Refinement r);
std::string to_string(RayOrigin o);
// Parsers return false on an unknown name; `choices` then lists the accepted ones.
bool parse_precision(const std::string& name, Precision& out);
bool parse_isolation(const std::string& name, Isolation& out);
bool parse_refinement(const std::string& name, Refinement& out);
bool parse_ray_origin(const std::string& name, RayOrigin& out);
std::string precision_choices();
std::string isolation_choices();
std::string refinement_choices();
std::string ray_origin_choices();

// The refinement's iteration cap unless a scene sets one: 1000 for plain regula falsi, as in the paper (its
// one-sided convergence needs them), 100 for the others.
int default_max_iterations(Refinement r);

struct KernelConfig {
  std::string entry = "primary";  // kernel file (without .cl) and kernel function
  int degree = 1;
  Precision precision = Precision::Double;
  Isolation isolation = Isolation::Bernstein;
  Refinement refinement = Refinement::Brent;
  RayOrigin ray_origin = RayOrigin::Extent;
  double tolerance = 1e-9;   // the paper's eps: stop when the bracket is <= 4*eps*max(|t|,1)
  int max_iterations = 100;  // see default_max_iterations
  // Rays per work-item, side by side in vector lanes (kernels/lanes.h): more than 1 only for the primary kernel
  // with Bernstein isolation and Brent refinement (lanes_apply), where the plan asks for it.
  int lanes = 1;

  // "-D DEGREE=6 -D ALGRAY_DOUBLE=1 ..." with the tolerance as an exact hexadecimal literal.
  std::string build_options() const;
  // Everything above, readable; two configs build the same code iff their keys are equal.
  std::string key() const;
  std::string source_file() const { return entry + ".cl"; }
};

}  // namespace algray
