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

#if RAY_ORIGIN == ALGRAY_ORIGIN_POINT
#include "bernstein.h"
#include "point_form.h"

#if ALGRAY_ESCALATE || ALGRAY_COMPENSATED || ISOLATION != ALGRAY_ISOLATION_BERNSTEIN
#error "the point form is built in plain float or double with Bernstein isolation"
#endif

/* shadow_segment for LANES light samples (lx, ly, lz): *self where the sample is behind the tangent plane, and the
 * lanes returned where the segment from o (t = 0) to the sample (t = 1) holds [*t_in, *t_out] of the extent. */
LMASK shadow_segments(REAL3 p, REAL3 n, REAL3 o, REAL3 o_unit, LREAL lx, LREAL ly, LREAL lz, REAL extent_inv_scale,
                      int extent_kind, REAL3 box_half, LMASK* self, LREAL* dx, LREAL* dy, LREAL* dz, LREAL* t_in,
                      LREAL* t_out) {
  *self = (lx - p.x) * n.x + (ly - p.y) * n.y + (lz - p.z) * n.z <= 0;
  *dx = (lx - o.x) * extent_inv_scale;
  *dy = (ly - o.y) * extent_inv_scale;
  *dz = (lz - o.z) * extent_inv_scale;
  LREAL lo = 0, hi;
  LMASK hit;
  if (extent_kind == ALGRAY_EXTENT_SPHERE) {
    /* clip_to_extent's sphere, lane by lane */
    const LREAL a = *dx * *dx + *dy * *dy + *dz * *dz;
    const LREAL b = o_unit.x * *dx + o_unit.y * *dy + o_unit.z * *dz;
    const REAL c = dot(o_unit, o_unit) - (REAL)1;
    const LREAL disc = b * b - a * c;
    hit = disc > 0 && a > 0;
    const LREAL q = -(b + copysign(sqrt(fmax(disc, (LREAL)0)), b));
    const LREAL t0 = q / a, t1 = c / q;
    lo = fmax(fmin(t0, t1), (LREAL)0);
    hi = fmax(t0, t1);
  } else {
    hi = REAL_MAX;
    const LREAL ix = (REAL)1 / *dx, iy = (REAL)1 / *dy, iz = (REAL)1 / *dz;
    const LREAL ax = (-box_half.x - o_unit.x) * ix, bx = (box_half.x - o_unit.x) * ix;
    const LREAL ay = (-box_half.y - o_unit.y) * iy, by = (box_half.y - o_unit.y) * iy;
    const LREAL az = (-box_half.z - o_unit.z) * iz, bz = (box_half.z - o_unit.z) * iz;
    lo = fmax(fmax(lo, fmin(ax, bx)), fmax(fmin(ay, by), fmin(az, bz)));
    hi = fmin(fmin(hi, fmax(ax, bx)), fmin(fmax(ay, by), fmax(az, bz)));
    hit = hi > lo;
  }
  *t_in = fmax(lo, (LREAL)0);
  *t_out = fmin(hi, (LREAL)1);
  return !*self && hit && hi > lo && *t_out > *t_in;
}

/* Bit s0 + j of a mask for each lane j of m. */
ALGRAY_INLINE ulong lane_bits(LMASK m, uint s0) {
  ulong bits = 0;
  for (uint j = 0; j < LANES; ++j)
    if (lane_get_mask(m, j)) bits |= (ulong)1 << (s0 + j);
  return bits;
}

/* Which of the traced lanes' segments hold a root: what isolate_bernstein reports for each, from the scaled
 * Bernstein coefficients c on [t_in, t_out] (power basis power, the same polynomial). The signs of c settle most
 * (bernstein_root_by_signs), a sign change at seven points of the segment most of the rest, and the search the
 * remainder: in lanes (isolate_bernstein_lanes), or alone in a one-lane build. */
LMASK segment_roots(const LREAL* c, const LREAL* power, LREAL t_in, LREAL t_out, LMASK traced,
                    __constant const REAL* binomials) {
  LMASK positive = c[0] > 0, negative = c[0] < 0;
  ALGRAY_UNROLL
  for (int k = 1; k <= DEGREE; ++k) {
    positive = positive && c[k] > 0;
    negative = negative && c[k] < 0;
  }
  const LREAL start = c[0], end = c[DEGREE];
  const LMASK none = positive || negative;
  LMASK root = traced && !none && (start == 0 || end == 0 || (start < 0 && end > 0) || (start > 0 && end < 0));
  LMASK open = traced && !none && !root;
  if (!LANE_ANY(open)) return root;
  const LMASK crossed = sign_change_sampled(power, t_in, t_out, start, open);
  root = root || crossed;
  open = open && !crossed;
  if (!LANE_ANY(open)) return root;
  __constant const REAL* row = binomials + DEGREE * NCOEF;
  LREAL b[NCOEF], cur[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) b[k] = c[k] / row[k]; /* bernstein_from_scaled */
#if LANES > 1
  Isolation iso[LANES];
  isolate_bernstein_lanes(LANES, open, b, t_in, t_out, iso, cur);
  for (uint j = 0; j < LANES; ++j)
    if (lane_get_mask(open, j) && iso[j].status != ISOLATION_NONE) lane_set_mask(&root, j, 1);
  return root;
#else
  const Isolation iso = isolate_bernstein(b, b, t_in, t_out, cur);
  return iso.status != ISOLATION_NONE;
#endif
}

/* The shadow kernels' answer for surface point i in the point form: its occlusion mask, with the number of rays
 * traced added to *traced. LANES light samples at a time, so the one-lane build (shadow_serial, GPUs) takes the
 * same decisions ray by ray. P is expanded about the origin once, when the first ray is traced. */
ulong shadow_mask_point_form(__global const REAL4* points, __global const float4* normals, uint i,
                             __global const REAL4* light_points, uint light_count, REAL offset, REAL4 extent_centre,
                             REAL extent_inv_scale, REAL4 extent_box_half, int extent_kind,
                             __global const uint* mono_exps, __global const REAL* mono_coefs, uint mono_count,
                             __constant const REAL* binomials, ulong mask, uint* traced) {
  REAL3 p, n, o, o_unit;
  shadow_origin(points, normals, i, offset, extent_centre, extent_inv_scale, &p, &n, &o, &o_unit);
  PolyVec q[POINT_FORM_COLUMNS];
  int expanded = 0;
  for (uint s0 = 0; s0 < light_count; s0 += LANES) {
    REAL lx[LANES], ly[LANES], lz[LANES];
    LMASK wanted;
    for (uint j = 0; j < LANES; ++j) {
      const uint s = min(s0 + j, light_count - 1);
      lx[j] = light_points[s].x;
      ly[j] = light_points[s].y;
      lz[j] = light_points[s].z;
      lane_set_mask(&wanted, j, s0 + j < light_count && !((mask >> s) & 1));
    }
#if LANES > 1
    const LREAL Lx = LANE_VEC(vload, LANES)(0, lx), Ly = LANE_VEC(vload, LANES)(0, ly),
                Lz = LANE_VEC(vload, LANES)(0, lz);
#else
    const LREAL Lx = lx[0], Ly = ly[0], Lz = lz[0];
#endif
    LMASK self;
    LREAL dx, dy, dz, t_in, t_out;
    LMASK trace = shadow_segments(p, n, o, o_unit, Lx, Ly, Lz, extent_inv_scale, extent_kind, extent_box_half.xyz,
                                  &self, &dx, &dy, &dz, &t_in, &t_out);
    mask |= lane_bits(wanted && self, s0);
    trace = trace && wanted;
    if (!LANE_ANY(trace)) continue;
    *traced += (uint)popcount(lane_bits(trace, 0));
    if (!expanded) {
      taylor_at_point(mono_exps, mono_coefs, mono_count, o_unit, q);
      expanded = 1;
    }
    LREAL power[NCOEF], c[NCOEF];
    point_form_restrict(q, dx, dy, dz, power);
    point_form_segment(power, t_in, t_out, binomials, c);
    mask |= lane_bits(segment_roots(c, power, t_in, t_out, trace, binomials), s0);
  }
  return mask;
}
#endif

#endif /* ALGRAY_SHADOW_H */
