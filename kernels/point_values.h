/* P from the monomials at points of rays, with a bound on its rounding: adaptive builds' checks of what they doubt. */
#ifndef ALGRAY_POINT_VALUES_H
#define ALGRAY_POINT_VALUES_H

#include "float_float.h"
#include "lanes.h"
#include "ray.h"
#include "real.h"
#include "restrict.h"

/* P at two points q0 and q1 from the monomials, side by side in the two lanes of a vector (one chain of operations
 * for both: two scalar evaluations were a tenth of the Barth decic's float camera pass), and a bound on each one's
 * rounding. Each term's roundings (the powers, the coefficient, the products and the point's coordinates) are at
 * most 2 DEGREE + 4 of REAL_EPS / 2 relative to |term|; each addition's at most REAL_EPS / 2 of the partial sum it
 * leaves, and the bound adds up those partial sums as they run (a running error bound, Higham, "Accuracy and
 * Stability of Numerical Algorithms", 3.1). Near a root the terms cancel and the partial sums stay far below count
 * times the terms' sum, which bounded the additions until 2026-12-07. Four partial sums, each a chain of additions
 * waiting on the one before, paired at the end. REAL_EPS per rounding, twice what each can be, is the room for
 * second-order terms and for the bound's own sums. Measured on the Barth decic (1024x768 preview, float): of its
 * 42,400 flat-doubted roots, the float evaluations left 6,068 to float-float with the terms' sum times count, 1,603
 * with this bound. */
static REAL2 direct_values(REAL3 q0, REAL3 q1, __global const uint* exps, __global const REAL* coefs, uint count,
                           REAL2* rounding) {
  const REAL2 x = (REAL2)(q0.x, q1.x), y = (REAL2)(q0.y, q1.y), z = (REAL2)(q0.z, q1.z);
  REAL2 px[NCOEF], py[NCOEF], pz[NCOEF];
  px[0] = py[0] = pz[0] = (REAL2)(1);
  ALGRAY_UNROLL
  for (int n = 1; n <= DEGREE; ++n) {
    px[n] = px[n - 1] * x;
    py[n] = py[n - 1] * y;
    pz[n] = pz[n - 1] * z;
  }
  REAL2 value[4], size[4], partial[4];
  ALGRAY_UNROLL
  for (int a = 0; a < 4; ++a) value[a] = size[a] = partial[a] = (REAL2)(0);
  for (uint m = 0; m < count; m += 4) ALGRAY_UNROLL
  for (uint a = 0; a < 4; ++a) {
    if (m + a >= count) break;
    const uint e = exps[m + a];
    const REAL2 term = coefs[m + a] * px[e & 0xffu] * py[(e >> 8) & 0xffu] * pz[(e >> 16) & 0xffu];
    value[a] += term;
    size[a] += fabs(term);
    partial[a] += fabs(value[a]);
  }
  const REAL2 low = value[0] + value[1], high = value[2] + value[3], sum = low + high;
  const REAL2 sizes = (size[0] + size[1]) + (size[2] + size[3]);
  const REAL2 partials =
      ((partial[0] + partial[1]) + (partial[2] + partial[3])) + ((fabs(low) + fabs(high)) + fabs(sum));
  *rounding = (sizes * (REAL)(2 * DEGREE + 4) + partials) * REAL_EPS;
  return sum;
}

/* Whether values v0 and v1 stand beyond their roundings with opposite signs (of one ray or of lanes): then P
 * changes sign between them. */
#define CERTAIN_SIGN_CHANGE(v0, rounding0, v1, rounding1) \
  (fabs(v0) > (rounding0) && fabs(v1) > (rounding1) && ((v0) > 0) != ((v1) > 0))

/* Lanes in `doubted` whose isolating interval [lo, hi] (fractions of [t_in, t_out] of the rays r) has P from the
 * monomials at both ends of the signs float gave there (f_lo, f_hi, which differ), each value beyond its rounding:
 * then P changes sign inside, as surely as where float's own end values stand clear of its noise. Lane by lane in
 * float first (direct_values at the ends as float places them, a sign change between points within float's rounding
 * of the ends), then, for the lanes float's rounding left open, together in float-float (direct_value_ff at the ends
 * to float's digits squared). Measured on the Barth decic (1024x768 preview, float): float settled 7,016 of the 7,654
 * brackets float-float settled alone, and the first pass took 40.6 -> 37.6 ms. *v_lo ... *rounding_hi: the values
 * and their bounds; *in_float_float: the lanes evaluated in float-float. */
static LMASK bracket_ends_proven(LMASK doubted, const LaneRays* r, LREAL t_in, LREAL t_out, LREAL lo, LREAL hi,
                                 LREAL f_lo, LREAL f_hi, __global const uint* exps, __global const REAL* coefs,
                                 uint count, LREAL* v_lo, LREAL* rounding_lo, LREAL* v_hi, LREAL* rounding_hi,
                                 LMASK* in_float_float) {
  REAL value_lo[LANES], bound_lo[LANES], value_hi[LANES], bound_hi[LANES];
  const uint doubted_bits = lane_mask_bits(doubted);
  uint proven_bits = 0;
  for (uint j = 0; j < (uint)LANES; ++j) {
    value_lo[j] = value_hi[j] = bound_lo[j] = bound_hi[j] = 0; /* no sign proven */
    if (!((doubted_bits >> j) & 1u)) continue;
    const REAL3 o = lane_origin(r, j), d = lane_direction(r, j);
    const REAL start = lane_get(t_in, j), length = lane_get(t_out, j) - start;
    REAL2 bound;
    const REAL2 value = direct_values(o + (start + lane_get(lo, j) * length) * d,
                                      o + (start + lane_get(hi, j) * length) * d, exps, coefs, count, &bound);
    value_lo[j] = value.s0;
    value_hi[j] = value.s1;
    bound_lo[j] = bound.s0;
    bound_hi[j] = bound.s1;
    if (SIGN_PROVEN(value.s0, bound.s0, lane_get(f_lo, j)) && SIGN_PROVEN(value.s1, bound.s1, lane_get(f_hi, j)))
      proven_bits |= 1u << j;
  }
  *v_lo = LANES_LOAD(value_lo);
  *rounding_lo = LANES_LOAD(bound_lo);
  *v_hi = LANES_LOAD(value_hi);
  *rounding_hi = LANES_LOAD(bound_hi);
  const LMASK in_float = lanes_of_bits(proven_bits);
  *in_float_float = doubted && !in_float;
  if (!LANE_ANY(*in_float_float)) return in_float;
  LREAL ff_rounding_lo, ff_rounding_hi;
  const LREAL ff_lo = direct_value_ff(r, ff_segment_point(t_in, t_out, lo), exps, coefs, count, &ff_rounding_lo);
  const LREAL ff_hi = direct_value_ff(r, ff_segment_point(t_in, t_out, hi), exps, coefs, count, &ff_rounding_hi);
  *v_lo = LANE_SEL(*v_lo, ff_lo, *in_float_float);
  *rounding_lo = LANE_SEL(*rounding_lo, ff_rounding_lo, *in_float_float);
  *v_hi = LANE_SEL(*v_hi, ff_hi, *in_float_float);
  *rounding_hi = LANE_SEL(*rounding_hi, ff_rounding_hi, *in_float_float);
  return in_float ||
         (*in_float_float && SIGN_PROVEN(ff_lo, ff_rounding_lo, f_lo) && SIGN_PROVEN(ff_hi, ff_rounding_hi, f_hi));
}

#endif /* ALGRAY_POINT_VALUES_H */
