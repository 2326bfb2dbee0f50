/* Camera rays and their clipping to the extent; docs/outputs.md's camera convention, as the kernels compute it. */
#ifndef ALGRAY_RAY_H
#define ALGRAY_RAY_H

#include "algray_shared.h"
#include "lanes.h"
#include "real.h"

/* Pixel (px, py), py = 0 the top row, gets the ray o + t*d with
 *   o = o00 + (px + 0.5)*ou + (py + 0.5)*ov,   d = d00 + (px + 0.5)*du + (py + 0.5)*dv,
 * every operation rounded in REAL in exactly this order. Perspective cameras have ou = ov = 0,
 * orthographic ones du = dv = 0, so one formula serves both without a branch. */
typedef struct {
  REAL3 o;
  REAL3 d;
} Ray;

/* One axis (or all three, for REAL3) of the formula above: base + f_x * along_x + f_y * along_y, summed in that
 * order; f_x, f_y are the pixel's centre, (REAL)px + 0.5 and (REAL)py + 0.5. */
#define CAMERA_AXIS(f_x, f_y, base, along_x, along_y) (((base) + (f_x) * (along_x)) + (f_y) * (along_y))

Ray camera_ray(uint px, uint py, REAL4 o00, REAL4 ou, REAL4 ov, REAL4 d00, REAL4 du, REAL4 dv) {
  /* No fused multiply-adds: the file's header must let anyone rebuild this ray bit for bit. */
#pragma OPENCL FP_CONTRACT OFF
  const REAL fx = (REAL)px + (REAL)0.5;
  const REAL fy = (REAL)py + (REAL)0.5;
  Ray r;
  r.o = CAMERA_AXIS(fx, fy, o00.xyz, ou.xyz, ov.xyz);
  r.d = CAMERA_AXIS(fx, fy, d00.xyz, du.xyz, dv.xyz);
  return r;
}

/* [t_in, t_out] of rays o + t*d inside the extent, given in unit coordinates u = (p - centre)/scale, where the
 * sphere is the unit sphere, the box is |u_i| <= half_i and the cylinder about axis a (kind
 * ALGRAY_EXTENT_CYLINDER + a) is the part of the infinite one of radius half_(across a) between its caps at
 * u_a = +-half_a; returns where they enter it. Written once over a real
 * type T and its comparisons' type M (REAL and int, or LREAL and LMASK of lanes.h), so that every lane of the
 * vector instance is the scalar one's result bit for bit. A ray that misses leaves t_in, t_out undefined. ANY(m):
 * whether any lane of m is set. Where no ray meets the sphere, its square root and divisions are skipped (more
 * than half of a typical view's lanes miss it, in whole groups). */
#define DEFINE_CLIP_TO_EXTENT(name, T, M, ANY)                                                                       \
  ALGRAY_INLINE M name(T ox, T oy, T oz, T dx, T dy, T dz, int kind, REAL3 box_half, T* t_in, T* t_out) {            \
    T lo = 0, hi;                                                                                                    \
    M hit;                                                                                                           \
    if (kind == ALGRAY_EXTENT_SPHERE) {                                                                              \
      T a, b, c;                                                                                                     \
      {                                                                                                              \
        /* as dot() sums them: three products, added left to right */                                                \
        _Pragma("OPENCL FP_CONTRACT OFF") a = (dx * dx + dy * dy) + dz * dz;                                         \
        b = (ox * dx + oy * dy) + oz * dz;                                                                           \
        c = ((ox * ox + oy * oy) + oz * oz) - (REAL)1;                                                               \
      }                                                                                                              \
      const T disc = b * b - a * c;                                                                                  \
      hit = disc > 0 && a > 0;                                                                                       \
      hi = 0;                                                                                                        \
      if (ANY(hit)) {                                                                                                \
        /* The product form avoids cancellation when one intersection is near the origin. */                         \
        const T q = -(b + copysign(sqrt(disc), b));                                                                  \
        const T t0 = q / a, t1 = c / q;                                                                              \
        lo = fmax(fmin(t0, t1), (T)0);                                                                               \
        hi = fmax(t0, t1);                                                                                           \
      }                                                                                                              \
    } else if (kind >= ALGRAY_EXTENT_CYLINDER) {                                                                     \
      _Pragma("OPENCL FP_CONTRACT OFF") const int axis = kind - ALGRAY_EXTENT_CYLINDER;                              \
      /* (p1, p2) across the axis, pa along it */                                                                    \
      const T p1 = axis == 0 ? oy : ox, p2 = axis == 2 ? oy : oz, pa = axis == 0 ? ox : axis == 1 ? oy : oz;         \
      const T q1 = axis == 0 ? dy : dx, q2 = axis == 2 ? dy : dz, qa = axis == 0 ? dx : axis == 1 ? dy : dz;         \
      const REAL rho = axis == 0 ? box_half.y : box_half.x;                                                          \
      const REAL eta = axis == 0 ? box_half.x : axis == 1 ? box_half.y : box_half.z;                                 \
      /* the caps as a box's slab: +-inf for rays across the axis */                                                 \
      const T ia = (REAL)1 / qa;                                                                                     \
      const T s0 = (-eta - pa) * ia, s1 = (eta - pa) * ia;                                                           \
      lo = fmax(lo, fmin(s0, s1));                                                                                   \
      hi = fmin((T)REAL_MAX, fmax(s0, s1));                                                                          \
      /* the side, as the sphere's quadratic across the axis; a ray along the axis meets it everywhere or nowhere */ \
      const T a = q1 * q1 + q2 * q2, b = p1 * q1 + p2 * q2, c = (p1 * p1 + p2 * p2) - rho * rho;                     \
      const T disc = b * b - a * c;                                                                                  \
      const M side = a > 0 && disc > 0;                                                                              \
      hit = side || (a == 0 && c <= 0);                                                                              \
      if (ANY(side)) {                                                                                               \
        const T q = -(b + copysign(sqrt(disc), b));                                                                  \
        const T t0 = q / a, t1 = c / q;                                                                              \
        lo = side ? fmax(lo, fmin(t0, t1)) : lo;                                                                     \
        hi = side ? fmin(hi, fmax(t0, t1)) : hi;                                                                     \
      }                                                                                                              \
    } else {                                                                                                         \
      hi = REAL_MAX;                                                                                                 \
      /* +-inf for axis-parallel rays, which the min/max below handle */                                             \
      const T ix = (REAL)1 / dx, iy = (REAL)1 / dy, iz = (REAL)1 / dz;                                               \
      const T ax = (-box_half.x - ox) * ix, bx = (box_half.x - ox) * ix;                                             \
      const T ay = (-box_half.y - oy) * iy, by = (box_half.y - oy) * iy;                                             \
      const T az = (-box_half.z - oz) * iz, bz = (box_half.z - oz) * iz;                                             \
      lo = fmax(fmax(lo, fmin(ax, bx)), fmax(fmin(ay, by), fmin(az, bz)));                                           \
      hi = fmin(fmin(hi, fmax(ax, bx)), fmin(fmax(ay, by), fmax(az, bz)));                                           \
      hit = hi > lo;                                                                                                 \
    }                                                                                                                \
    *t_in = lo;                                                                                                      \
    *t_out = hi;                                                                                                     \
    return hit && hi > lo;                                                                                           \
  }

#define CLIP_ONE_ANY(m) (m)
DEFINE_CLIP_TO_EXTENT(clip_axes_to_extent, REAL, int, CLIP_ONE_ANY)
#undef CLIP_ONE_ANY

int clip_to_extent(REAL3 o, REAL3 d, int kind, REAL3 box_half, REAL* t_in, REAL* t_out) {
  return clip_axes_to_extent(o.x, o.y, o.z, d.x, d.y, d.z, kind, box_half, t_in, t_out);
}

/* LANES rays side by side, one coordinate per vector (lanes.h); with LANES = 1, one ray. */
typedef struct {
  LREAL ox, oy, oz, dx, dy, dz;
} LaneRays;

#if LANES == 1
#define clip_lanes_to_extent clip_axes_to_extent /* LREAL and LMASK are REAL and int */

/* The ray o + t*d as the one lane of LaneRays. */
ALGRAY_INLINE LaneRays one_lane_rays(REAL3 o, REAL3 d) {
  LaneRays r;
  r.ox = o.x;
  r.oy = o.y;
  r.oz = o.z;
  r.dx = d.x;
  r.dy = d.y;
  r.dz = d.z;
  return r;
}
#else
DEFINE_CLIP_TO_EXTENT(clip_lanes_to_extent, LREAL, LMASK, LANE_ANY)

/* The pixel centres (REAL)px + 0.5 of columns px0 .. px0 + LANES - 1, each as camera_ray computes it: px0 + j is
 * exact in REAL for any image width a float can index. */
LREAL lane_pixel_centres(uint px0) {
#define LANE_INDEX(j) ((REAL)(j))
  return ((LREAL)((REAL)px0) + LANES_OF(LREAL, LANE_INDEX)) + (REAL)0.5;
#undef LANE_INDEX
}

/* camera_ray for pixels px0 .. px0 + LANES - 1 of row py: each lane that ray bit for bit. */
LaneRays camera_rays_lanes(uint px0, uint py, REAL4 o00, REAL4 ou, REAL4 ov, REAL4 d00, REAL4 du, REAL4 dv) {
#pragma OPENCL FP_CONTRACT OFF
  const LREAL fx = lane_pixel_centres(px0);
  const REAL fy = (REAL)py + (REAL)0.5;
  LaneRays r;
  r.ox = CAMERA_AXIS(fx, fy, o00.x, ou.x, ov.x);
  r.oy = CAMERA_AXIS(fx, fy, o00.y, ou.y, ov.y);
  r.oz = CAMERA_AXIS(fx, fy, o00.z, ou.z, ov.z);
  r.dx = CAMERA_AXIS(fx, fy, d00.x, du.x, dv.x);
  r.dy = CAMERA_AXIS(fx, fy, d00.y, du.y, dv.y);
  r.dz = CAMERA_AXIS(fx, fy, d00.z, du.z, dv.z);
  return r;
}
#endif

#endif /* ALGRAY_RAY_H */
