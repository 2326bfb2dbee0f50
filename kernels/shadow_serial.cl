/* The shadow kernel's answers one segment at a time, without batches or sign shortcuts: what tests hold it to. */
#include "algray_shared.h"
/* Shadow rays start off the surface and ask only whether there is a root: what adaptive builds doubt (isolation.h). */
#define ALGRAY_SHADOW_RAYS 1
#include "isolate.h"
#include "ray.h"
#include "real.h"
#include "restrict.h"
#include "shadow.h"
#include "surface.h"

#if RAY_ORIGIN == ALGRAY_ORIGIN_SCREEN
#error "the screen form is for camera rays; the host builds this kernel with RAY_ORIGIN=extent"
#endif

#if RAY_ORIGIN == ALGRAY_ORIGIN_POINT && LANES != 1
#error "shadow_serial is built with one lane"
#endif

/* The arguments and the result are shadow's (shadow.cl): ALGRAY_SHADOW_ARG_NAMES (algray_shared.h). */
__kernel void shadow_serial(__global const REAL4* points, __global const float4* normals, uint point_count,
                            __global const REAL4* light_points, uint light_count, REAL offset, REAL4 extent_centre,
                            REAL extent_inv_scale, REAL4 extent_box_half, int extent_kind,
                            __global const REAL4* clip_planes, uint clip_count, __global const uint* mono_exps,
                            __global const REAL* mono_coefs, uint mono_count, __constant const REAL* binomials,
                            uint even_axes, __global ulong* occluded, __global uint* rays_traced,
                            __global ulong* undecided) {
#if RAY_ORIGIN == ALGRAY_ORIGIN_POINT
  /* The point form one ray at a time: shadow.cl's code built with one lane. */
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
  for (uint s = 0; s < light_count; ++s) {
    const ulong bit = (ulong)1 << s;
    if (mask & bit) continue;
    REAL3 d_unit;
    REAL t_in, t_out;
    const int kind = shadow_segment(p, n, o, o_unit, light_points[s].xyz, extent_inv_scale, extent_kind,
                                    extent_box_half.xyz, clip_planes, clip_count, &d_unit, &t_in, &t_out);
    if (kind == SHADOW_SELF) mask |= bit;
    if (kind != SHADOW_TRACE) continue;
    ++traced;
    REAL iso_c[NCOEF];
#if SHADOW_SAMPLED
    /* isolate_on_segment's two steps, the search's through shadow_isolation (shadow.h) */
    REAL root[NCOEF], root_lo[NCOEF];
    RayTerms terms;
    segment_coefficients(o_unit, d_unit, t_in, t_out, mono_exps, mono_coefs, mono_count, binomials, even_axes, root,
                         root_lo, &terms, 0, 0, NO_PROBE);
    const Isolation iso = shadow_isolation(root, root_lo, t_in, t_out, binomials, iso_c, &terms);
#else
    const Isolation iso = isolate_on_segment(o_unit, d_unit, t_in, t_out, mono_exps, mono_coefs, mono_count,
                                             binomials, even_axes, iso_c, 0, 0, NO_PROBE);
#endif
    if (iso.status != ISOLATION_NONE) mask |= bit;
    if (iso.doubt) unsure |= bit;
  }
  occluded[i] = mask;
  if (ALGRAY_ESCALATE) undecided[i] = unsure;
  if (traced) atomic_add(rays_traced, traced);
#endif
}
