/* Float-float arithmetic for adaptive float kernels' checks: P at a point of a ray, to float's digits squared. */
#ifndef ALGRAY_FLOAT_FLOAT_H
#define ALGRAY_FLOAT_FLOAT_H

#include "lanes.h"
#include "ray.h"
#include "real.h"

/* Adaptive precision's evaluations in float-float; compiled in every build and called by adaptive ones. */

/* Float-float numbers hi + lo, |lo| within half an ulp of hi, of one ray or of lanes: each product and sum below
 * keeps its rounding error (fma, Knuth's two-sum), so its relative error is a few REAL_EPS^2, not REAL_EPS. */
typedef struct {
  LREAL hi, lo;
} FloatFloat;

/* hi + e renormalised, for |hi| >= |e| or hi = 0 (Dekker's fast two-sum). */
ALGRAY_INLINE FloatFloat ff_normalised(LREAL hi, LREAL e) {
  FloatFloat r;
  r.hi = hi + e;
  r.lo = e - (r.hi - hi);
  return r;
}
ALGRAY_INLINE FloatFloat ff_add(FloatFloat a, FloatFloat b) {
  const LREAL s = a.hi + b.hi, bb = s - a.hi;
  return ff_normalised(s, ((a.hi - (s - bb)) + (b.hi - bb)) + (a.lo + b.lo));
}
ALGRAY_INLINE FloatFloat ff_mul(FloatFloat a, FloatFloat b) {
  const LREAL p = a.hi * b.hi;
  return ff_normalised(p, fma(a.hi, b.hi, -p) + (a.hi * b.lo + a.lo * b.hi));
}
ALGRAY_INLINE FloatFloat ff_of(LREAL x) {
  FloatFloat r;
  r.hi = x;
  r.lo = 0;
  return r;
}
/* x + t d: the product exact (fma), t's low part and the sum's rounding at REAL_EPS^2 */
ALGRAY_INLINE FloatFloat ff_point_axis(LREAL x, FloatFloat t, LREAL d) {
  const LREAL p = t.hi * d;
  FloatFloat b;
  b.hi = p;
  b.lo = fma(t.hi, d, -p) + t.lo * d;
  return ff_add(ff_of(x), b);
}
/* t_in + s (t_out - t_in) for a fraction s of at most REAL_MAX_HALVINGS bits (the search's interval ends): the
 * difference exact (two-sum), then as ff_point_axis's point, at REAL_EPS^2 of |t|. */
ALGRAY_INLINE FloatFloat ff_segment_point(LREAL t_in, LREAL t_out, LREAL s) {
  return ff_point_axis(t_in, ff_add(ff_of(t_out), ff_of(-t_in)), s);
}

/* P at o + t d in float-float for each lane of r, coefficients hi + lo (adaptive builds get the low parts after
 * the per-degree sums; DeviceSurface), and a bound on its rounding, each part with room:
 *  - the products and sums, at most 6 (REAL_EPS / 2)^2 each relative to its operands' sizes: (3 DEGREE + count + 8)
 *    2 REAL_EPS^2 times the terms sum_m |a_m| |x|^i |y|^j |z|^k (which also covers the coefficients' low parts);
 *  - the point, whose coordinates are off by at most dq = 2 REAL_EPS^2 (|o| + |t d|) each (t's and their own
 *    roundings): sum over the axes of dq times the terms' derivative along it, taken at |q| + dq, which bounds
 *    P's change.
 * Underflowing low parts can only make the bound too small by FLT_MIN-sized amounts: the absolute term. */
static LREAL direct_value_ff(const LaneRays* r, FloatFloat t, __global const uint* exps, __global const REAL* coefs,
                             uint count, LREAL* rounding) {
  FloatFloat px[NCOEF], py[NCOEF], pz[NCOEF];
  const FloatFloat x = ff_point_axis(r->ox, t, r->dx), y = ff_point_axis(r->oy, t, r->dy),
                   z = ff_point_axis(r->oz, t, r->dz);
  px[0] = py[0] = pz[0] = ff_of(1);
  for (int n = 1; n <= DEGREE; ++n) {
    px[n] = ff_mul(px[n - 1], x);
    py[n] = ff_mul(py[n - 1], y);
    pz[n] = ff_mul(pz[n - 1], z);
  }
  const LREAL eps2 = (LREAL)(2 * REAL_EPS * REAL_EPS), at = fabs(t.hi);
  const LREAL dqx = (fabs(r->ox) + at * fabs(r->dx)) * eps2, dqy = (fabs(r->oy) + at * fabs(r->dy)) * eps2,
              dqz = (fabs(r->oz) + at * fabs(r->dz)) * eps2;
  LREAL bx[NCOEF], by[NCOEF], bz[NCOEF];
  bx[0] = by[0] = bz[0] = 1;
  for (int n = 1; n <= DEGREE; ++n) {
    bx[n] = bx[n - 1] * (fabs(x.hi) + dqx);
    by[n] = by[n - 1] * (fabs(y.hi) + dqy);
    bz[n] = bz[n - 1] * (fabs(z.hi) + dqz);
  }
  __global const REAL* lows = coefs + count + NCOEF;
  FloatFloat value = ff_of(0);
  LREAL size = 0, slope_x = 0, slope_y = 0, slope_z = 0;
  for (uint m = 0; m < count; ++m) {
    const uint i = exps[m] & 0xffu, j = (exps[m] >> 8) & 0xffu, k = (exps[m] >> 16) & 0xffu;
    FloatFloat a;
    a.hi = coefs[m];
    a.lo = lows[m];
    value = ff_add(value, ff_mul(ff_mul(a, px[i]), ff_mul(py[j], pz[k])));
    const REAL c = fabs(coefs[m]);
    size += c * bx[i] * by[j] * bz[k];
    if (i) slope_x += c * (REAL)i * bx[i - 1] * by[j] * bz[k];
    if (j) slope_y += c * (REAL)j * bx[i] * by[j - 1] * bz[k];
    if (k) slope_z += c * (REAL)k * bx[i] * by[j] * bz[k - 1];
  }
  const LREAL arithmetic = size * (REAL)(3 * DEGREE + (int)count + 8) * eps2;
  const LREAL point = (dqx * slope_x + dqy * slope_y) + dqz * slope_z;
  *rounding = (arithmetic + point) * (REAL)(1 + 1.0 / 1024) + (REAL)(8 * (int)count) * FLT_MIN;
  return value.hi + value.lo;
}

/* Whether v, P with its rounding bound `rounding`, stands beyond it with the strict sign of c (float's value at the
 * same point): float's sign there proven. Of one ray or of lanes. */
#define SIGN_PROVEN(v, rounding, c) ((c) != 0 && fabs(v) > (rounding) && ((v) > 0) == ((c) > 0))

/* P in float-float at the search's last interval ends evaluated (fractions of [t_in, t_out]; -1 where none yet),
 * with its rounding bounds, of one ray or of lanes: an interval doubted for an end value within the noise reads
 * the sign there from these (proven_sign_of), and its halves and its neighbour, which share that end, read it
 * again without evaluating P. */
typedef struct {
  LREAL at[2], value[2], rounding[2];
} ProvenEnds;

ALGRAY_INLINE void no_proven_ends(ProvenEnds* p) {
  p->at[0] = p->at[1] = -1;
  p->value[0] = p->value[1] = p->rounding[0] = p->rounding[1] = 0;
}

/* Whether P at fraction s is in p. */
ALGRAY_INLINE LMASK proven_at(const ProvenEnds* p, LREAL s) { return p->at[0] == s || p->at[1] == s; }

/* Whether p holds P at fraction s beyond its rounding, with the strict sign of c (float's value there). */
ALGRAY_INLINE LMASK proven_sign_of(const ProvenEnds* p, LREAL s, LREAL c) {
  const LMASK first = p->at[0] == s, second = p->at[1] == s;
  const LREAL v = LANE_SEL(p->value[1], p->value[0], first), rounding = LANE_SEL(p->rounding[1], p->rounding[0], first);
  return (first || second) && SIGN_PROVEN(v, rounding, c);
}

/* P in float-float at the fraction s of [t_in, t_out], into p for the lanes in `take`: in the place of the one
 * that is not at `keep` (the interval's other end). */
static void prove_end(LMASK take, const LaneRays* r, LREAL t_in, LREAL t_out, LREAL s, LREAL keep,
                      __global const uint* exps, __global const REAL* coefs, uint count, ProvenEnds* p) {
  LREAL rounding;
  const LREAL v = direct_value_ff(r, ff_segment_point(t_in, t_out, s), exps, coefs, count, &rounding);
  const LMASK second = take && p->at[0] == keep, first = take && !second;
  p->at[0] = LANE_SEL(p->at[0], s, first);
  p->value[0] = LANE_SEL(p->value[0], v, first);
  p->rounding[0] = LANE_SEL(p->rounding[0], rounding, first);
  p->at[1] = LANE_SEL(p->at[1], s, second);
  p->value[1] = LANE_SEL(p->value[1], v, second);
  p->rounding[1] = LANE_SEL(p->rounding[1], rounding, second);
}

#endif /* ALGRAY_FLOAT_FLOAT_H */
