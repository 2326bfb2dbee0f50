// The CPU reference image: every pixel's ray solved by solver_ref in exact arithmetic, on all cores.
#pragma once

#include <cstdint>
#include <vector>

#include "algray/render/renderer.h"
#include "algray/scene/scene.h"
#include "solver_ref/solver_ref.h"

namespace algray {

// What the reference certifies for one pixel (EXR channel "reference.class").
enum class PixelClass : std::uint32_t {
  OutsideExtent = 0,    // the ray does not meet the extent
  Miss = 1,             // certified: no root in [t_in, t_out]
  SimpleRoot = 2,       // the smallest root is simple: P changes sign there
  OddMultipleRoot = 3,  // odd multiplicity >= 3 (singular or inflectional), still a sign change
  EvenRoot = 4,         // even multiplicity: touches without crossing (tangent ray, node, isolated point)
  OnSurface = 5,        // P vanishes on the whole segment
  NearEnd = 6,          // the smallest root lies within the clipping margin of t_in or t_out: ambiguous
  RayRounding = 7,      // a miss or simple root whose answer a few ulps' change of the ray can flip: ambiguous
};

// "outside extent", "miss", "simple root", ...: the classes' names as reports print them.
const char* pixel_class_name(PixelClass c);

struct ReferenceResult {
  RenderResult render;                 // hit records as the kernels would write them (work = 0)
  std::vector<std::uint32_t> classes;  // PixelClass per pixel
  std::vector<double> t;               // the certified root's nearest double; +inf without one
};

// Relative width of the reference's root enclosures, and the margin (relative to max(t_out, 1), in units of
// the ray precision's epsilon) within which a root at the clipping ends counts as ambiguous.
inline constexpr double kReferenceWidth = 1e-13;
inline constexpr double kReferenceEndMargin = 256;

// A kernel never sees the exact ray: it moves the ray into unit coordinates and builds the segment's end points,
// each a rounding of the ray's components. A miss or a simple root counts as certified only if P* keeps its
// shape under that: at every critical point of P* before the second root, |P*| must exceed the first-order
// change of P under a move of each ray component by kReferenceRayRoundings units of the ray precision's
// roundoff. Otherwise (a near-touch of another sheet, two nearly equal roots) the pixel is RayRounding.
inline constexpr double kReferenceRayRoundings = 8;

// [t_in, t_out] of a ray in the extent and its clipping planes, in long double: close to the kernels' clipping,
// which is what the reference needs (roots near the ends are treated as ambiguous), not exact. False when the ray
// misses.
bool extent_interval(const Extent& extent, const PixelRay& ray, long double& t_in, long double& t_out);

// Whether moving each component of `ray` by kReferenceRayRoundings * eps of its size could change the number of
// roots P* (`restricted`, the exact restriction of the polynomial with `monomials` to `ray`) has on [lo, limit]:
// that needs a critical point of P* there where |P*| is within the first-order change of P.
bool flips_under_ray_rounding(const std::vector<mpq_class>& restricted, const std::vector<Monomial>& monomials,
                              const PixelRay& ray, const mpq_class& lo, const mpq_class& limit, long double eps);

// What solver_ref certifies for one ray against one polynomial, as the reference image does for each pixel.
struct RayCertificate {
  PixelClass cls = PixelClass::OutsideExtent;
  long double t_in = 0, t_out = 0;    // extent_interval(); both 0 outside the extent
  mpq_class lo, hi, width;            // the interval solved on (t_in, t_out widened by the end margin), enclosure width
  std::vector<mpq_class> restricted;  // P*(t) exactly, power basis of t
  ref::Answer answer;                 // the smallest root on [lo, hi]
};
// `ray` is taken at its exact value; `ray_precision` sets the margins of what counts as ambiguous.
RayCertificate certify_ray(const Polynomial& polynomial, const std::vector<Monomial>& monomials, const Extent& extent,
                           const PixelRay& ray, Precision ray_precision);

// Rays are rebuilt in `ray_precision` exactly as the kernels build them (docs/outputs.md's convention), and P is the
// scene's exact polynomial. threads = 0 uses every core.
ReferenceResult render_reference(const Scene& scene, Precision ray_precision, unsigned threads = 0);

// How a kernel's hits compare with the reference, over the pixels the reference certifies (a miss or a simple
// root); every other pixel inside the extent is ambiguous and never counts as agreement.
struct ReferenceComparison {
  long certified = 0, ambiguous = 0;
  long ray_rounding = 0;                     // of the ambiguous ones, PixelClass::RayRounding
  long disagreements = 0;                    // certified pixels where kernel and reference differ on hit or miss
  long simple_hits = 0;                      // certified simple roots that the kernel hit too
  double median_depth = 0, worst_depth = 0;  // relative error of the kernel's t on those
  int worst_x = -1, worst_y = -1, disagree_x = -1, disagree_y = -1;  // first disagreement, worst depth
};
ReferenceComparison compare_with_reference(const HitBuffer& kernel, const ReferenceResult& reference);

}  // namespace algray
