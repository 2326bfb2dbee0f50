/* Test and benchmark kernel: the smallest root in [0, 1] of a batch of univariate polynomials, one per work-item,
 * through the same isolation and refinement as the primary kernel (everything after the restriction). */
#include "algray_shared.h"
#include "isolate.h"
#include "real.h"
#include "restrict.h"
#include "surface.h"

/* polys: DEGREE + 1 coefficients per polynomial, in the basis the isolation works in (Bernstein on [0, 1], or
 * the power basis in t); mixed precision then has the low parts of all of them, in the same order. out: t (as t_hi +
 * t_lo), flags and work, in HitRecord's fields. */
__kernel void univariate(__global const REAL* polys, uint count, __constant const REAL* binomials,
                         __global HitRecord* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  REAL root[NCOEF], root_lo[NCOEF], iso_c[NCOEF];
  for (int k = 0; k <= DEGREE; ++k) {
    root[k] = polys[(size_t)i * NCOEF + k];
    /* mixed precision's low parts follow all high parts */
    root_lo[k] = ALGRAY_COMPENSATED ? polys[(size_t)count * NCOEF + (size_t)i * NCOEF + k] : (REAL)0;
  }
  RayTerms terms;
  /* The coefficients are given, rounded once: their own size is their noise's. */
  if (ALGRAY_ESCALATE) terms = known_terms(0);
  LaneIsolation iso;
  set_lane_isolation(&iso, 0, isolate_method(root, root_lo, (REAL)0, (REAL)1, iso_c, &terms, NO_PROBE));
  LaneRoots roots;
  refine_rays(1, &iso, iso_c, (REAL)0, (REAL)1, binomials, &roots, NO_PROBE);
  const uint flags = (uint)roots.flags & ~ALGRAY_HIT_IN_EXTENT; /* a polynomial on [0, 1] has no extent */
  HitRecord r;
  r.t_hi = (float)roots.t;
  r.t_lo = (flags & ALGRAY_HIT_FOUND) ? (float)(roots.t - (REAL)r.t_hi) : 0.0f;
  r.depth = r.t_hi;
  r.normal_x = r.normal_y = r.normal_z = 0;
  r.flags = flags;
  r.work = ALGRAY_WORK_PACK(min((uint)roots.steps, ALGRAY_WORK_MAX), min((uint)roots.iterations, ALGRAY_WORK_MAX));
  out[i] = r;
}
