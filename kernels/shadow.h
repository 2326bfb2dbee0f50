/* A shadow ray's segment: from a lit surface point, moved off the surface, to one light sample, inside the extent. */
#ifndef ALGRAY_SHADOW_H
#define ALGRAY_SHADOW_H

#include "algray_shared.h"
#include "ray.h"
#include "real.h"

#define SHADOW_SELF 0  /* the light sample is behind the point's tangent plane: hidden by the surface itself */
#define SHADOW_CLEAR 1 /* the segment misses the extent: nothing hides the sample */
#define SHADOW_TRACE 2 /* the roots of P* on [*t_in, *t_out] of o_unit + t * *d_unit decide */

/* p: the surface point (world), n its unit normal on the camera's side, o = p moved along n, o_unit the same in
 * unit coordinates; light: the sample point. The segment runs from o (t = 0) to the sample (t = 1). */
int shadow_segment(REAL3 p, REAL3 n, REAL3 o, REAL3 o_unit, REAL3 light, REAL extent_inv_scale, int extent_kind,
                   REAL3 extent_box_half, REAL3* d_unit, REAL* t_in, REAL* t_out) {
  /* A light behind the tangent plane is hidden by the surface itself, whatever the roots say. The plane is the
   * surface point's, as in the shading, not the offset origin's. */
  if (dot(light - p, n) <= 0) return SHADOW_SELF;
  *d_unit = (light - o) * extent_inv_scale;
  if (!clip_to_extent(o_unit, *d_unit, extent_kind, extent_box_half, t_in, t_out)) return SHADOW_CLEAR;
  *t_in = fmax(*t_in, (REAL)0);
  *t_out = fmin(*t_out, (REAL)1);
  return *t_out > *t_in ? SHADOW_TRACE : SHADOW_CLEAR;
}

/* Work-item i's surface point p and normal n, and the shadow rays' origin o off the surface to the camera's side
 * (the point's own root moves behind the ray's start), in world and unit coordinates. */
void shadow_origin(__global const REAL4* points, __global const float4* normals, uint i, REAL offset,
                   REAL4 extent_centre, REAL extent_inv_scale, REAL3* p, REAL3* n, REAL3* o, REAL3* o_unit) {
  *p = points[i].xyz;
  const float4 nf = normals[i];
  *n = (REAL3)((REAL)nf.x, (REAL)nf.y, (REAL)nf.z);
  *o = *p + offset * *n;
  *o_unit = (*o - extent_centre.xyz) * extent_inv_scale;
}

/* The kernels' common arguments and the work-item's surface point: see shadow.cl. */
#define SHADOW_KERNEL_PARAMS                                                                                         \
  __global const REAL4 *points, __global const float4 *normals, uint point_count, __global const REAL4 *light_points, \
      uint light_count, REAL offset, REAL4 extent_centre, REAL extent_inv_scale, REAL4 extent_box_half,              \
      int extent_kind, __global const uint *mono_exps, __global const REAL *mono_coefs, uint mono_count,             \
      __constant const REAL *binomials, uint even_axes, __global ulong *occluded,                                \
      __global uint *rays_traced SHADOW_UNDECIDED_PARAM

/* Adaptive builds take one more argument, undecided: per surface point, the samples whose shadow rays the
 * float search doubted, which the host traces again in float-float. Other builds take nothing more. */
#if ALGRAY_ESCALATE
#define SHADOW_UNDECIDED_PARAM , __global ulong *undecided
#define SHADOW_UNDECIDED(i, mask) (undecided[i] = (mask))
#else
#define SHADOW_UNDECIDED_PARAM
#define SHADOW_UNDECIDED(i, mask) ((void)(mask))
#endif

#endif /* ALGRAY_SHADOW_H */
