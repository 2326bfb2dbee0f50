/* Camera rays and their clipping to the extent; the README's camera convention, as the kernels compute it. */
#ifndef ALGRAY_RAY_H
#define ALGRAY_RAY_H

#include "algray_shared.h"
#include "real.h"

/* Pixel (px, py), py = 0 the top row, gets the ray o + t*d with
 *   o = o00 + (px + 0.5)*ou + (py + 0.5)*ov,   d = d00 + (px + 0.5)*du + (py + 0.5)*dv,
 * every operation rounded in REAL in exactly this order. Perspective cameras have ou = ov = 0,
 * orthographic ones du = dv = 0, so one formula serves both without a branch. */
typedef struct {
  REAL3 o;
  REAL3 d;
} Ray;

Ray camera_ray(uint px, uint py, REAL4 o00, REAL4 ou, REAL4 ov, REAL4 d00, REAL4 du, REAL4 dv) {
  /* No fused multiply-adds: the file's header must let anyone rebuild this ray bit for bit. */
#pragma OPENCL FP_CONTRACT OFF
  const REAL fx = (REAL)px + (REAL)0.5;
  const REAL fy = (REAL)py + (REAL)0.5;
  Ray r;
  const REAL3 ox = fx * ou.xyz;
  const REAL3 oy = fy * ov.xyz;
  r.o = (o00.xyz + ox) + oy;
  const REAL3 dx = fx * du.xyz;
  const REAL3 dy = fy * dv.xyz;
  r.d = (d00.xyz + dx) + dy;
  return r;
}

/* [t_in, t_out] of the ray inside the extent, given in unit coordinates u = (p - centre)/scale,
 * where the sphere is the unit sphere and the box is |u_i| <= half_i. Returns 0 when it misses. */
int clip_to_extent(REAL3 o, REAL3 d, int kind, REAL3 box_half, REAL* t_in, REAL* t_out) {
  REAL lo = 0, hi;
  if (kind == ALGRAY_EXTENT_SPHERE) {
    const REAL a = dot(d, d);
    const REAL b = dot(o, d);
    const REAL c = dot(o, o) - (REAL)1;
    const REAL disc = b * b - a * c;
    if (disc <= 0 || a <= 0) return 0;
    /* The product form avoids cancellation when one intersection is near the origin. */
    const REAL q = -(b + copysign(sqrt(disc), b));
    REAL t0 = q / a, t1 = c / q;
    if (t0 > t1) { const REAL s = t0; t0 = t1; t1 = s; }
    lo = fmax(t0, (REAL)0);
    hi = t1;
  } else {
    hi = REAL_MAX;
    const REAL3 inv = (REAL)1 / d;  /* +-inf for axis-parallel rays, which the min/max below handle */
    const REAL3 ta = (-box_half - o) * inv;
    const REAL3 tb = (box_half - o) * inv;
    const REAL3 tmin = fmin(ta, tb), tmax = fmax(ta, tb);
    lo = fmax(fmax(lo, tmin.x), fmax(tmin.y, tmin.z));
    hi = fmin(fmin(hi, tmax.x), fmin(tmax.y, tmax.z));
  }
  *t_in = lo;
  *t_out = hi;
  return hi > lo;
}

#endif /* ALGRAY_RAY_H */
