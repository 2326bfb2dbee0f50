/* Test kernel: P restricted to segments as the extent form's shadow rays restrict it, RESTRICT_RAYS at a time. */
#include "algray_shared.h"

/* With the host's ALGRAY_SHADOW_BATCH (a vector register's rays, coefficient k of every ray in the lanes of one
 * vector: restrict.h's batch_* steps) or one ray at a time (the vector step every other kernel takes), so that a test
 * holds the first to the second coefficient by coefficient: a shadow pass's occlusion masks would hide a difference
 * in the last bits of a few coefficients. */
#if ALGRAY_SHADOW_BATCH > 1
#define RESTRICT_RAYS ALGRAY_SHADOW_BATCH
#else
#define RESTRICT_RAYS 1
#endif

#include "isolate.h"
#include "real.h"
#include "restrict.h"
#include "surface.h" /* segment_factors */

/* segments: two REAL4 per segment in unit coordinates, (o, t_in) and (d, t_out); work-item g restricts segments
 * g * RESTRICT_RAYS onwards, count of them in all (the host pads count to a multiple of RESTRICT_RAYS). out: the
 * DEGREE + 1 coefficients of each, restrict_to_rays' result in the isolation's basis. The arguments are
 * ALGRAY_RESTRICT_CHECK_ARG_NAMES (algray_shared.h). */
__kernel void restrict_check(__global const REAL4* segments, uint count, __global const uint* mono_exps,
                             __global const REAL* mono_coefs, uint mono_count, __constant const REAL* binomials,
                             uint even_axes, __global REAL* out) {
  const uint first = (uint)get_global_id(0) * RESTRICT_RAYS;
  if (first >= count) return;
  AxisFactor fx[RESTRICT_RAYS], fy[RESTRICT_RAYS], fz[RESTRICT_RAYS];
  for (int r = 0; r < RESTRICT_RAYS; ++r) {
    const REAL4 o = segments[2 * (first + (uint)r)], d = segments[2 * (first + (uint)r) + 1];
    segment_factors(o.xyz, d.xyz, o.w, d.w, even_axes, &fx[r], &fy[r], &fz[r]);
  }
  REAL c[RESTRICT_RAYS][NCOEF], c_lo[RESTRICT_RAYS][NCOEF];
  restrict_to_rays(mono_exps, mono_coefs, mono_count, binomials, fx, fy, fz, c, c_lo);
  for (int r = 0; r < RESTRICT_RAYS; ++r)
    for (int k = 0; k <= DEGREE; ++k) out[(size_t)(first + (uint)r) * NCOEF + (size_t)k] = c[r][k];
}
