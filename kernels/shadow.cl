/* The shadow-ray kernel: for each lit surface point, which sample points of one light the surface hides. */
#include "algray_shared.h"
/* Shadow rays start off the surface and ask only whether there is a root: what adaptive builds doubt (isolation.h). */
#define ALGRAY_SHADOW_RAYS 1

/* Shadow rays restrict P in batches (see RESTRICT_RAYS in restrict.h): the host's ALGRAY_SHADOW_BATCH where it
 * gives one (a vector register's rays, in its lanes), else the width that measured fastest for the vector width
 * the degree takes. */
#if ALGRAY_SHADOW_BATCH > 1
#define RESTRICT_RAYS ALGRAY_SHADOW_BATCH
#else
#define RESTRICT_RAYS (DEGREE <= 7 ? 4 : 2)
#endif

#include "isolate.h"
#include "ray.h"
#include "real.h"
#include "restrict.h"
#include "shadow.h"
#include "surface.h"

#if RAY_ORIGIN == ALGRAY_ORIGIN_SCREEN
#error "the screen form is for camera rays; the host builds this kernel with RAY_ORIGIN=extent or point"
#endif
#if ALGRAY_ESCALATE && ISOLATION_POWER_BASIS
#error "adaptive shadow rays settle what the signs of Bernstein coefficients show (bernstein_root_by_signs)"
#endif

#if RAY_ORIGIN != ALGRAY_ORIGIN_POINT

/* Adaptive builds' checks of the signs against the noise (the helpers below compile everywhere, adaptive builds
 * call them). */

/* Whether the scaled coefficients c have one strict sign throughout with each but c_0 beyond limit[k]: with the
 * limits of segment_has_root's caller, what bernstein_root_by_signs and signs_clear_of settle as no root, from the
 * compares by_signs makes alone. */
ALGRAY_INLINE int one_sign_beyond(const REAL* c, const REAL* limit) {
  int above = c[0] > 0, below = c[0] < 0;
  ALGRAY_UNROLL
  for (int k = 1; k <= DEGREE; ++k) {
    above &= c[k] > limit[k];
    below &= c[k] < -limit[k];
  }
  return above | below;
}

/* Whether the scaled coefficients c (before bernstein_from_scaled) settle bernstein_root_by_signs' answer with
 * every coefficient it reads clear of the noise for terms of size `terms`: then no rounding could change it.
 * c_0, P at the ray's start, does not count (first_counted): the isolation takes its sign as it is.
 *  - No root (one sign throughout): each b_k beyond the search's own noise, DOUBT_NOISE(scale, terms) with
 *    `scale` from search_scale_bound, tested as |c_k| beyond the noise times C(n,k): the search's first interval
 *    would find no sign variation and no coefficient within its noise, and answer the same. (noise_bound, whose
 *    scale is the terms themselves, settled fewer: the Barth decic's adaptive shadow pass took 950 ms with it
 *    against 909, 1024x768.) With room of 8 REAL_EPS: for the product by C(n,k) and the search's division, and
 *    the terms' sums may contract differently in another kernel; the room keeps every ray this settles one the
 *    search would settle too.
 *  - A root (the ends' signs differ): P at the far end beyond noise_bound(terms), the bound for any scale. */
ALGRAY_INLINE int signs_clear_of(const REAL* c, int by_signs, REAL scale, REAL terms) {
  /* c_0 exactly zero: the search doubts a root at the start, so the shortcut must not settle it */
  if (by_signs == ISOLATION_BRACKET) return c[0] != 0 && fabs(c[DEGREE]) > noise_bound(terms);
  const REAL noise = DOUBT_NOISE(scale, terms) * (1 + 8 * REAL_EPS);
  int clear = 1;
  ALGRAY_UNROLL
  for (int k = 1; k <= DEGREE; ++k) clear &= fabs(c[k]) > noise * degree_binomial(k);
  return clear;
}

/* Whether the segment, restricted to root (and root_lo, both consumed), holds a root: what shadow_isolation (or,
 * where it is not built, isolate_restricted) reports, without it when the coefficients' signs already settle it
 * (Bernstein builds; adaptive ones only when the signs stand clear of the noise: of extent_terms, the bound on
 * every ray's terms in the extent, then of the ray's terms' upper bound, then of their sum; each check costs more
 * and passes more rays). clear_limit[k]: the noise of extent_terms for any scale times C(n,k), which most rays'
 * coefficients stand beyond with one sign, settled without the scale's noise (one_sign_beyond: the checks were
 * 12% of the Cayley cubic's adaptive shadow pass, whose rays each take about 90 cycles).
 * *doubt gets the search's. f: the ray's coordinates' factors, for adaptive builds' terms. */
ALGRAY_INLINE int segment_has_root(REAL* root, REAL* root_lo, REAL t_in, REAL t_out, __constant const REAL* binomials,
                                   uint* doubt, __global const uint* exps, __global const REAL* coefs, uint count,
                                   AxisFactor fx, AxisFactor fy, AxisFactor fz, REAL extent_terms,
                                   const REAL* clear_limit) {
  *doubt = 0;
  if (ALGRAY_ESCALATE && one_sign_beyond(root, clear_limit)) return 0;
  int by_signs = -1; /* bernstein_root_by_signs' answer, -1 for none */
  REAL scale = 0;
#if !ISOLATION_POWER_BASIS
  by_signs = bernstein_root_by_signs(root);
  if (ALGRAY_ESCALATE && by_signs == ISOLATION_NONE) scale = search_scale_bound(root); /* one lane: LANES = 1 here */
  if (by_signs >= 0 && (!ALGRAY_ESCALATE || signs_clear_of(root, by_signs, scale, extent_terms)))
    return by_signs != ISOLATION_NONE;
#endif
  RayTerms terms;
  if (ALGRAY_ESCALATE) {
    terms = ray_terms(exps, coefs, count, fx, fy, fz);
    if (by_signs >= 0 && (signs_clear_of(root, by_signs, scale, terms.value) ||
                          signs_clear_of(root, by_signs, scale, ray_terms_exact(&terms))))
      return by_signs != ISOLATION_NONE;
  }
  REAL iso_c[NCOEF];
#if SHADOW_SAMPLED
  restricted_to_isolation_basis(root, root_lo, binomials, NO_PROBE);
  const Isolation iso = shadow_isolation(root, root_lo, t_in, t_out, binomials, iso_c, &terms);
#else
  const Isolation iso = isolate_restricted(root, root_lo, t_in, t_out, binomials, iso_c, &terms, NO_PROBE);
#endif
  *doubt = iso.doubt;
  return iso.status != ISOLATION_NONE;
}

#endif

/* One work-item per surface point. points[i].xyz is the point (world), normals[i].xyz its unit normal on the
 * side the camera sees; light_points[0 .. light_count) are the light's sample points. Bit s of occluded[i]
 * is set when sample s is hidden: by the surface's own side facing away from it, or by a root of P*(t) on
 * the shadow ray from the offset point to the sample. Bits already set (another surface hid the sample) are
 * not traced again. The shadow ray stops at the first evidence of a root, an isolating interval, and never
 * refines it. offset: how far the origin moves along the normal, in world units. rays_traced counts the
 * shadow rays that reached the root isolation, for the render statistics.
 * Adaptive builds also set bit s of undecided[i] where the float search doubted sample s; others never touch it.
 * The answers are shadow_serial's, bit for bit: the segments are restricted RESTRICT_RAYS at a time, each
 * with the operations it would get alone, and the shortcuts return what the search would. The point form
 * (point_form.h) takes the same arguments and gives the same answers. The arguments are ALGRAY_SHADOW_ARG_NAMES
 * (algray_shared.h), by which the host sets them. */
__kernel void shadow(__global const REAL4* points, __global const float4* normals, uint point_count,
                     __global const REAL4* light_points, uint light_count, REAL offset, REAL4 extent_centre,
                     REAL extent_inv_scale, REAL4 extent_box_half, int extent_kind, __global const REAL4* clip_planes,
                     uint clip_count, __global const uint* mono_exps, __global const REAL* mono_coefs, uint mono_count,
                     __constant const REAL* binomials, uint even_axes, __global ulong* occluded,
                     __global uint* rays_traced, __global ulong* undecided) {
#if RAY_ORIGIN == ALGRAY_ORIGIN_POINT
  (void)even_axes;
  shadow_point_form_item(points, normals, point_count, light_points, light_count, offset, extent_centre,
                         extent_inv_scale, extent_box_half, extent_kind, clip_planes, clip_count, mono_exps, mono_coefs,
                         mono_count, binomials, occluded, rays_traced, undecided);
#else
  const uint i = launch_item_index();
  if (i >= point_count) return;
  REAL3 p, n, o, o_unit;
  shadow_origin(points, normals, i, offset, extent_centre, extent_inv_scale, &p, &n, &o, &o_unit);
  ulong mask = occluded[i], unsure = 0;
  uint traced = 0;
  /* Adaptive builds: every Bernstein coefficient of a segment in the extent is at most its terms, which
   * extent_terms bounds with room to spare, so no coefficients' scale makes the search's noise larger than
   * noise_bound's. */
  const REAL extent_terms = ALGRAY_ESCALATE ? one_ray_terms_within(mono_coefs, mono_count, 1) : 0; /* |u| <= 1 */
  REAL clear_limit[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k)
    clear_limit[k] = ALGRAY_ESCALATE ? noise_bound(extent_terms) * (REAL)(1 + 8 * REAL_EPS) * degree_binomial(k) : 0;
  /* The batch waiting for its restriction: ray r is light sample sample[r] on [t_in[r], t_out[r]]. */
  AxisFactor fx[RESTRICT_RAYS], fy[RESTRICT_RAYS], fz[RESTRICT_RAYS];
  REAL t_in[RESTRICT_RAYS], t_out[RESTRICT_RAYS];
  uint sample[RESTRICT_RAYS];
  int pending = 0;
  /* s == light_count restricts what is left over. */
  for (uint s = 0; s <= light_count; ++s) {
    if (s < light_count) {
      const ulong bit = (ulong)1 << s;
      if (mask & bit) continue;
      REAL3 d_unit;
      const int kind = shadow_segment(p, n, o, o_unit, light_points[s].xyz, extent_inv_scale, extent_kind,
                                      extent_box_half.xyz, clip_planes, clip_count, &d_unit, &t_in[pending],
                                      &t_out[pending]);
      if (kind == SHADOW_SELF) mask |= bit;
      if (kind != SHADOW_TRACE) continue;
      ++traced;
      segment_factors(o_unit, d_unit, t_in[pending], t_out[pending], even_axes, &fx[pending], &fy[pending],
                      &fz[pending]);
      sample[pending] = s;
      if (++pending < RESTRICT_RAYS) continue;
    }
    if (pending == 0) break;
    /* A short batch repeats its first ray in the empty places, whose answers are not read. */
    for (int r = pending; r < RESTRICT_RAYS; ++r) {
      fx[r] = fx[0];
      fy[r] = fy[0];
      fz[r] = fz[0];
    }
    REAL root[RESTRICT_RAYS][NCOEF], root_lo[RESTRICT_RAYS][NCOEF];
    restrict_to_rays(mono_exps, mono_coefs, mono_count, binomials, fx, fy, fz, root, root_lo);
    for (int r = 0; r < pending; ++r) {
      uint doubt;
      if (segment_has_root(root[r], root_lo[r], t_in[r], t_out[r], binomials, &doubt, mono_exps, mono_coefs, mono_count,
                           fx[r], fy[r], fz[r], extent_terms, clear_limit))
        mask |= (ulong)1 << sample[r];
      if (doubt) unsure |= (ulong)1 << sample[r];
    }
    pending = 0;
  }
  occluded[i] = mask;
  if (ALGRAY_ESCALATE) undecided[i] = unsure;
  if (traced) atomic_add(rays_traced, traced);
#endif
}
