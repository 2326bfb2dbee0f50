/* Camera rays and their clipping to the extent; docs/outputs.md's camera convention, as the kernels compute it. */
#ifndef ALGRAY_RAY_H
#define ALGRAY_RAY_H

#include "algray_shared.h"
#include "lanes.h"
#include "real.h"

/* Pixel (px, py), py = 0 the top row, gets the ray o + t*d with
 *   o = o00 + (px + 0.5)*ou + (py + 0.5)*ov,   d = d00 + (px + 0.5)*du + (py + 0.5)*dv,
 * every operation rounded in REAL in exactly this order (camera_rays), without fused multiply-adds: the file's
 * header must let anyone rebuild this ray bit for bit. Perspective cameras have ou = ov = 0, orthographic ones
 * du = dv = 0, so one formula serves both without a branch. */

/* One axis of the formula above: base + f_x * along_x + f_y * along_y, summed in that order; f_x, f_y are the
 * pixel's centre, (REAL)px + 0.5 and (REAL)py + 0.5. */
#define CAMERA_AXIS(f_x, f_y, base, along_x, along_y) (((base) + (f_x) * (along_x)) + (f_y) * (along_y))

/* [*lo, *hi] of rays o + t*d cut by the clip planes clip_planes[0 .. clip_count), each the half-space n.u + e <= 0
 * kept, (n, e) in unit coordinates (the host's DeviceSurface::set_extent_args). Each plane is a convex cut, so the
 * segment stays one interval: a ray crossing the plane loses the part beyond where it crosses, a ray along it all
 * or nothing. Returns the lanes that are not along a plane outside it; of one ray or of lanes, each lane with one
 * ray's operations. */
ALGRAY_INLINE LMASK cut_by_clip_planes(LREAL ox, LREAL oy, LREAL oz, LREAL dx, LREAL dy, LREAL dz,
                                       __global const REAL4* clip_planes, uint clip_count, LREAL* lo, LREAL* hi) {
  LMASK kept = lanes_of_bits(~0u); /* every lane */
  for (uint k = 0; k < clip_count; ++k) {
    const REAL4 plane = clip_planes[k];
    LREAL s, v;
    {
      /* as dot() sums them: three products, added left to right */
#pragma OPENCL FP_CONTRACT OFF
      s = ((plane.x * ox + plane.y * oy) + plane.z * oz) + plane.w;
      v = (plane.x * dx + plane.y * dy) + plane.z * dz;
    }
    /* +-inf or NaN where v == 0, never selected */
    const LREAL cross = -s / v;
    *lo = LANE_SEL(*lo, fmax(*lo, cross), v < (REAL)0);
    *hi = LANE_SEL(*hi, fmin(*hi, cross), v > (REAL)0);
    kept = kept && (v != (REAL)0 || s <= (REAL)0);
  }
  return kept;
}

/* [*lo, *hi] of rays o + t*d inside the sphere |u|^2 <= r2 about the origin, from t = 0 on; returns the lanes that
 * meet it. Where no ray meets it, its square root and divisions are skipped (more than half of a typical view's
 * lanes miss it, in whole groups). */
ALGRAY_INLINE LMASK sphere_span(LREAL ox, LREAL oy, LREAL oz, LREAL dx, LREAL dy, LREAL dz, REAL r2, LREAL* lo,
                                 LREAL* hi) {
  LREAL a, b, c;
  {
    /* as dot() sums them: three products, added left to right */
#pragma OPENCL FP_CONTRACT OFF
    a = (dx * dx + dy * dy) + dz * dz;
    b = (ox * dx + oy * dy) + oz * dz;
    c = ((ox * ox + oy * oy) + oz * oz) - r2;
  }
  const LREAL disc = b * b - a * c;
  const LMASK hit = disc > 0 && a > 0;
  *lo = 0;
  *hi = 0;
  if (LANE_ANY(hit)) {
    /* The product form avoids cancellation when one intersection is near the origin. */
    const LREAL q = -(b + copysign(sqrt(disc), b));
    const LREAL t0 = q / a, t1 = c / q;
    *lo = fmax(fmin(t0, t1), (LREAL)0);
    *hi = fmax(t0, t1);
  }
  return hit;
}

/* [t_in, t_out] of rays o + t*d inside the extent, given in unit coordinates u = (p - centre)/scale, where the
 * sphere is the one of radius box_half.x (the unit sphere, but for a gate), the box is |u_i| <= half_i and the
 * cylinder about axis a (kind ALGRAY_EXTENT_CYLINDER + a) is the part of the infinite one of radius half_(across a)
 * between its caps at u_a = +-half_a, then cut by the clip planes (cut_by_clip_planes); returns where they enter
 * what is left. A gate (kind + ALGRAY_EXTENT_GATE) only chooses the rays: those that meet its shape from t = 0 on
 * get the unit sphere's segment, the far sphere, before the planes cut it. Of one ray or of lanes (lanes.h), each
 * lane with one ray's operations. A ray that misses leaves t_in, t_out undefined. */
ALGRAY_INLINE LMASK clip_lanes_to_extent(LREAL ox, LREAL oy, LREAL oz, LREAL dx, LREAL dy, LREAL dz, int kind,
                                         REAL3 box_half, __global const REAL4* clip_planes, uint clip_count,
                                         LREAL* t_in, LREAL* t_out) {
  const int shape = kind & ~ALGRAY_EXTENT_GATE;
  LREAL lo = 0, hi;
  LMASK hit;
  if (shape == ALGRAY_EXTENT_SPHERE) {
    hit = sphere_span(ox, oy, oz, dx, dy, dz, box_half.x * box_half.x, &lo, &hi);
  } else if (shape >= ALGRAY_EXTENT_CYLINDER) {
#pragma OPENCL FP_CONTRACT OFF
    const int axis = shape - ALGRAY_EXTENT_CYLINDER;
    /* (p1, p2) across the axis, pa along it */
    const LREAL p1 = axis == 0 ? oy : ox, p2 = axis == 2 ? oy : oz, pa = axis == 0 ? ox : axis == 1 ? oy : oz;
    const LREAL q1 = axis == 0 ? dy : dx, q2 = axis == 2 ? dy : dz, qa = axis == 0 ? dx : axis == 1 ? dy : dz;
    const REAL rho = axis == 0 ? box_half.y : box_half.x;
    const REAL eta = axis == 0 ? box_half.x : axis == 1 ? box_half.y : box_half.z;
    /* the caps as a box's slab: +-inf for rays across the axis */
    const LREAL ia = (REAL)1 / qa;
    const LREAL s0 = (-eta - pa) * ia, s1 = (eta - pa) * ia;
    lo = fmax(lo, fmin(s0, s1));
    hi = fmin((LREAL)REAL_MAX, fmax(s0, s1));
    /* the side, as the sphere's quadratic across the axis; a ray along the axis meets it everywhere or nowhere */
    const LREAL a = q1 * q1 + q2 * q2, b = p1 * q1 + p2 * q2, c = (p1 * p1 + p2 * p2) - rho * rho;
    const LREAL disc = b * b - a * c;
    const LMASK side = a > 0 && disc > 0;
    hit = side || (a == 0 && c <= 0);
    if (LANE_ANY(side)) {
      const LREAL q = -(b + copysign(sqrt(disc), b));
      const LREAL t0 = q / a, t1 = c / q;
      lo = side ? fmax(lo, fmin(t0, t1)) : lo;
      hi = side ? fmin(hi, fmax(t0, t1)) : hi;
    }
  } else {
    hi = REAL_MAX;
    /* +-inf for axis-parallel rays, which the min/max below handle */
    const LREAL ix = (REAL)1 / dx, iy = (REAL)1 / dy, iz = (REAL)1 / dz;
    const LREAL ax = (-box_half.x - ox) * ix, bx = (box_half.x - ox) * ix;
    const LREAL ay = (-box_half.y - oy) * iy, by = (box_half.y - oy) * iy;
    const LREAL az = (-box_half.z - oz) * iz, bz = (box_half.z - oz) * iz;
    lo = fmax(fmax(lo, fmin(ax, bx)), fmax(fmin(ay, by), fmin(az, bz)));
    hi = fmin(fmin(hi, fmax(ax, bx)), fmin(fmax(ay, by), fmax(az, bz)));
    hit = hi > lo;
  }
  /* a gate's rays that meet it, along the far sphere (which holds the gate, so they all meet it) */
  if (kind & ALGRAY_EXTENT_GATE) {
    const LMASK passed = hit && hi > lo;
    hit = passed && sphere_span(ox, oy, oz, dx, dy, dz, (REAL)1, &lo, &hi);
  }
  /* without planes, nothing of the cut runs: the extent's segment as it always was */
  if (clip_count > 0) hit = hit && cut_by_clip_planes(ox, oy, oz, dx, dy, dz, clip_planes, clip_count, &lo, &hi);
  *t_in = lo;
  *t_out = hi;
  return hit && hi > lo;
}

/* LANES rays side by side, one coordinate per vector (lanes.h); with LANES = 1, one ray. */
typedef struct {
  LREAL ox, oy, oz, dx, dy, dz;
} LaneRays;

/* The ray o + t*d in every lane of LaneRays (the one lane where LANES = 1). */
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

/* Lane j of rays as one ray (REAL3 origin and direction). */
ALGRAY_INLINE REAL3 lane_origin(const LaneRays* rays, uint j) {
  return (REAL3)(lane_get(rays->ox, j), lane_get(rays->oy, j), lane_get(rays->oz, j));
}
ALGRAY_INLINE REAL3 lane_direction(const LaneRays* rays, uint j) {
  return (REAL3)(lane_get(rays->dx, j), lane_get(rays->dy, j), lane_get(rays->dz, j));
}

/* One ray's clip_lanes_to_extent: the ray in every lane, lane 0 read (in one-ray builds, the only lane). */
static int clip_to_extent(REAL3 o, REAL3 d, int kind, REAL3 box_half, __global const REAL4* clip_planes,
                          uint clip_count, REAL* t_in, REAL* t_out) {
  LREAL lo, hi;
  const LMASK hit = clip_lanes_to_extent((LREAL)o.x, (LREAL)o.y, (LREAL)o.z, (LREAL)d.x, (LREAL)d.y, (LREAL)d.z, kind,
                                         box_half, clip_planes, clip_count, &lo, &hi);
  *t_in = lane_get(lo, 0);
  *t_out = lane_get(hi, 0);
  return lane_get_mask(hit, 0) != 0;
}

/* The pixel centres (REAL)px + 0.5 of columns px0 .. px0 + LANES - 1: px0 + j is exact in REAL for any image width a
 * float can index. */
static LREAL lane_pixel_centres(uint px0) {
#define LANE_INDEX(j) ((REAL)(j))
  return ((LREAL)((REAL)px0) + LANES_OF(LREAL, LANE_INDEX)) + (REAL)0.5;
#undef LANE_INDEX
}

/* The camera rays through the pixel centres (fx, fy), one per lane (the formula above). */
ALGRAY_INLINE LaneRays camera_rays_through(LREAL fx, REAL fy, REAL4 o00, REAL4 ou, REAL4 ov, REAL4 d00, REAL4 du,
                                           REAL4 dv) {
#pragma OPENCL FP_CONTRACT OFF
  LaneRays r;
  r.ox = CAMERA_AXIS(fx, fy, o00.x, ou.x, ov.x);
  r.oy = CAMERA_AXIS(fx, fy, o00.y, ou.y, ov.y);
  r.oz = CAMERA_AXIS(fx, fy, o00.z, ou.z, ov.z);
  r.dx = CAMERA_AXIS(fx, fy, d00.x, du.x, dv.x);
  r.dy = CAMERA_AXIS(fx, fy, d00.y, du.y, dv.y);
  r.dz = CAMERA_AXIS(fx, fy, d00.z, du.z, dv.z);
  return r;
}

/* The camera rays of pixels px0 .. px0 + LANES - 1 of row py, one per lane. */
static LaneRays camera_rays(uint px0, uint py, REAL4 o00, REAL4 ou, REAL4 ov, REAL4 d00, REAL4 du, REAL4 dv) {
  return camera_rays_through(lane_pixel_centres(px0), (REAL)py + (REAL)0.5, o00, ou, ov, d00, du, dv);
}

/* The index of this work-item in a launch of ray_launch's shape (render/device_surface.cpp): rows of work-items,
 * each get_global_size(0) wide, numbered row after row. Rows keep every dimension of a launch under 65,536
 * work-items, where PoCL compiles one variant of a kernel (it compiles another, for seconds, past that). */
ALGRAY_INLINE uint launch_item_index(void) { return (uint)(get_global_id(1) * get_global_size(0) + get_global_id(0)); }

#endif /* ALGRAY_RAY_H */
