// The solver choices a scene makes (precision, isolation, refinement, ray origin): each list held once, with names.
#pragma once

#include <array>
#include <string>

namespace algray {

inline constexpr int kMaxDegree = 32;

// Mixed: float, except that P*(t) is built in compensated float-float arithmetic (degrees up to 15).
// Adaptive: float, and the rays whose float search rests on rounding noise are traced again in mixed precision
// (render/escalation.h); Bernstein isolation only, degrees up to 15.
enum class Precision { Float, Double, Mixed, Adaptive };
inline constexpr int kMaxMixedDegree = 15;
enum class Isolation { Bernstein, PowerDescartes, Sturm, DerivativeChain };
enum class Refinement { Brent, Bisection, RegulaFalsi, Illinois, Newton };
// Where P*(t) is built around: Auto (scenes only) is Screen for camera rays where it applies (screen_form_applies
// in render_plan.h), else Extent; for shadow rays it is Point where that applies (point_form_applies), else Extent.
// Point is the plan's choice for shadow rays, never a scene's: it is not in kRayOrigins.
enum class RayOrigin { Auto, Extent, Eye, Screen, Point };

// One choice: its value and its name in scenes, on the command line, in stats and in the probe.
template <typename E>
struct NamedChoice {
  E value;
  const char* name;
};

// Every choice of each kind, in the order help text, the probe's --all-solvers, benchmarks and tests list them.
// Adding a method here (and its kernel id in device/kernel_config.cpp) makes every one of them offer it.
inline constexpr std::array<NamedChoice<Precision>, 4> kPrecisions{{{Precision::Float, "float"},
                                                                    {Precision::Double, "double"},
                                                                    {Precision::Mixed, "mixed"},
                                                                    {Precision::Adaptive, "adaptive"}}};
inline constexpr std::array<NamedChoice<Isolation>, 4> kIsolations{{{Isolation::Bernstein, "bernstein"},
                                                                    {Isolation::PowerDescartes, "descartes"},
                                                                    {Isolation::Sturm, "sturm"},
                                                                    {Isolation::DerivativeChain, "derivative-chain"}}};
inline constexpr std::array<NamedChoice<Refinement>, 5> kRefinements{{{Refinement::Brent, "brent"},
                                                                      {Refinement::Bisection, "bisection"},
                                                                      {Refinement::RegulaFalsi, "regula-falsi"},
                                                                      {Refinement::Illinois, "illinois"},
                                                                      {Refinement::Newton, "newton"}}};
inline constexpr std::array<NamedChoice<RayOrigin>, 4> kRayOrigins{
    {{RayOrigin::Auto, "auto"}, {RayOrigin::Extent, "extent"}, {RayOrigin::Eye, "eye"}, {RayOrigin::Screen, "screen"}}};

// What each method can do, written once: scene validation, the plan and the build options all read these tables.
// A new method adds its row; the kernels refuse by #error what a row says a method cannot do.
struct IsolationAbilities {
  Isolation method;
  bool power_basis;  // isolates P*(t) in the power basis, and so takes ray_origin = "eye" as the paper does
  bool lanes;        // has a lane build (kernels/lanes.h), with a refinement that has one
  bool adaptive;     // adaptive precision checks its search against rounding noise and escalates what it doubts
  bool point_form;   // shadow rays can be built in the point form (kernels/point_form.h)
};
inline constexpr std::array<IsolationAbilities, 4> kIsolationAbilities{{
    {Isolation::Bernstein, false, true, true, true},
    {Isolation::PowerDescartes, true, false, false, false},
    {Isolation::Sturm, true, false, false, false},
    {Isolation::DerivativeChain, true, false, false, false},
}};
struct RefinementAbilities {
  Refinement method;
  bool lanes;  // has a lane build
};
inline constexpr std::array<RefinementAbilities, 5> kRefinementAbilities{{
    {Refinement::Brent, true},
    {Refinement::Bisection, false},
    {Refinement::RegulaFalsi, false},
    {Refinement::Illinois, false},
    {Refinement::Newton, false},
}};
const IsolationAbilities& abilities(Isolation i);
const RefinementAbilities& abilities(Refinement r);
// Whether rays can run in lanes (more than one per work-item) with this pair of methods.
bool lanes_supported(Isolation i, Refinement r);
// `isolation = "a" and refinement = "b"`: the pairs lanes_supported takes, for messages.
std::string lanes_methods();

std::string to_string(Precision p);
std::string to_string(Isolation i);
std::string to_string(Refinement r);
std::string to_string(RayOrigin o);
// Parsers return false on an unknown name; `choices` then lists the accepted ones.
bool parse_precision(const std::string& name, Precision& out);
bool parse_isolation(const std::string& name, Isolation& out);
bool parse_refinement(const std::string& name, Refinement& out);
bool parse_ray_origin(const std::string& name, RayOrigin& out);
// "a, b, c", or with `last` given "a, b or c".
std::string precision_choices(const char* last = nullptr);
std::string isolation_choices(const char* last = nullptr);
std::string refinement_choices(const char* last = nullptr);
std::string ray_origin_choices();
// Whether an isolation works on P*(t) in the power basis, as every one but Bernstein's does: only those take
// ray_origin = "eye", as the paper's solver does.
bool isolates_in_power_basis(Isolation i);
// As isolation_choices, of those alone.
std::string power_basis_isolation_choices(const char* last = nullptr);

// Whether a precision runs its rays in float (every one but double).
inline constexpr bool in_float(Precision p) { return p != Precision::Double; }
// Why adaptive precision cannot render a surface of `degree` with `isolation`, or "" when it can.
std::string adaptive_unsupported(int degree, Isolation isolation);

// The lane counts a kernel can be built with (render.lanes; kernels/lanes.h).
bool valid_lanes(int lanes);
std::string lanes_choices();

// The refinement's iteration cap unless a scene sets one: 1000 for plain regula falsi, as in the paper (its
// one-sided convergence needs them), 100 for the others.
int default_max_iterations(Refinement r);

}  // namespace algray
