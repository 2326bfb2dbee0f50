/* The shadow-ray kernel: for each lit surface point, which sample points of one light the surface hides. */
#include "algray_shared.h"
#include "isolate.h"
#include "ray.h"
#include "real.h"
#include "restrict.h"
#include "surface.h"

#if RAY_ORIGIN == ALGRAY_ORIGIN_SCREEN
#error "the screen form is for camera rays; the host builds this kernel with RAY_ORIGIN=extent"
#endif

/* One work-item per surface point. points[i].xyz is the point (world), normals[i].xyz its unit normal on the
 * side the camera sees; light_points[0 .. light_count) are the light's sample points. Bit s of occluded[i]
 * is set when sample s is hidden: by the surface's own side facing away from it, or by a root of P*(t) on
 * the shadow ray from the offset point to the sample. Bits already set (another surface hid the sample) are
 * not traced again. The shadow ray stops at the first evidence of a root, an isolating interval, and never
 * refines it. offset: how far the origin moves along the normal, in world units. rays_traced counts the
 * shadow rays that reached the root isolation, for the render statistics. */
__kernel void shadow(__global const REAL4* points, __global const float4* normals, uint point_count,
                     __global const REAL4* light_points, uint light_count, REAL offset, REAL4 extent_centre,
                     REAL extent_inv_scale, REAL4 extent_box_half, int extent_kind, __global const uint* mono_exps,
                     __global const REAL* mono_coefs, uint mono_count, __constant const REAL* binomials,
                     uint even_axes, __global ulong* occluded, __global uint* rays_traced) {
  const uint i = get_global_id(0);
  if (i >= point_count) return;
  const REAL3 p = points[i].xyz;
  const float4 nf = normals[i];
  const REAL3 n = (REAL3)((REAL)nf.x, (REAL)nf.y, (REAL)nf.z);
  /* Off the surface to the camera's side: the point's own root moves behind the ray's start. */
  const REAL3 o = p + offset * n;
  const REAL3 o_unit = (o - extent_centre.xyz) * extent_inv_scale;
  ulong mask = occluded[i];
  uint traced = 0;
  for (uint s = 0; s < light_count; ++s) {
    const ulong bit = (ulong)1 << s;
    if (mask & bit) continue;
    /* A light behind the tangent plane is hidden by the surface itself, whatever the roots say. The plane is
     * the surface point's, as in the shading, not the offset origin's. */
    if (dot(light_points[s].xyz - p, n) <= 0) {
      mask |= bit;
      continue;
    }
    const REAL3 to_light = light_points[s].xyz - o;
    /* The segment from the origin (t = 0) to the light sample (t = 1), inside the extent. */
    const REAL3 d_unit = to_light * extent_inv_scale;
    REAL t_in, t_out;
    if (!clip_to_extent(o_unit, d_unit, extent_kind, extent_box_half.xyz, &t_in, &t_out)) continue;
    t_in = fmax(t_in, (REAL)0);
    t_out = fmin(t_out, (REAL)1);
    if (!(t_out > t_in)) continue;
    ++traced;
    REAL iso_c[NCOEF];
    const Isolation iso = isolate_on_segment(o_unit, d_unit, t_in, t_out, mono_exps, mono_coefs, mono_count,
                                             binomials, even_axes, iso_c);
    if (iso.status != ISOLATION_NONE) mask |= bit;
  }
  occluded[i] = mask;
  if (traced) atomic_add(rays_traced, traced);
}
