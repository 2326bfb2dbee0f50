/* The power basis on an isolating interval: shifting and scaling P*(s) onto it, and its value for refinement. */
#ifndef ALGRAY_POWER_BASIS_H
#define ALGRAY_POWER_BASIS_H

#include "isolation.h"

/* c(x) -> c(x + a), by repeated synthetic division. */
static void taylor_shift(REAL* c, REAL a) {
  ALGRAY_UNROLL
  for (int i = 0; i < DEGREE; ++i) ALGRAY_UNROLL
  for (int k = DEGREE - 1; k >= i; --k) c[k] += a * c[k + 1];
}

/* A1(y) = p(alpha + beta*y): the polynomial on one subinterval, mapped to [0,1]. */
static void power_on_interval(const REAL* p, REAL alpha, REAL beta, REAL* a1) {
  poly_copy(a1, p);
  if (alpha != 0) taylor_shift(a1, alpha);
  REAL s = 1;
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) {
    a1[k] *= s;
    s *= beta;
  }
}

static REAL power_value(const REAL* c, REAL y) {
  REAL h = c[DEGREE];
  ALGRAY_UNROLL
  for (int k = DEGREE - 1; k >= 0; --k) h = h * y + c[k];
  return h;
}

/* Value and slope at y of a polynomial in the power basis, by Horner's scheme with its derivative. */
static REAL power_value_slope(const REAL* c, REAL y, REAL* slope) {
  REAL h = c[DEGREE], d = 0;
  ALGRAY_UNROLL
  for (int k = DEGREE - 1; k >= 0; --k) {
    d = d * y + h;
    h = h * y + c[k];
  }
  *slope = d;
  return h;
}

/* Where the power-basis methods' P*(s) starts, in t, and how long a step of s is: s in [0, 1] over the segment
 * [t_in, t_out], or, built around the ray's origin as the paper does (RAY_ORIGIN=eye), t itself from t_in. */
ALGRAY_INLINE REAL power_s0(REAL t_in) { return RAY_ORIGIN == ALGRAY_ORIGIN_EYE ? t_in : (REAL)0; }
ALGRAY_INLINE REAL power_len_s(REAL t_in, REAL t_out) {
  return RAY_ORIGIN == ALGRAY_ORIGIN_EYE ? t_out - t_in : (REAL)1;
}

/* isolate.h's interface for the refinement: on the isolating interval the polynomial is A1(y), y in [0, 1], in the
 * power basis, ready as it is; no start for the refinement, which begins as the paper has it. */
static REAL isolated_start(const REAL* c) {
  (void)c;
  return -1;
}

static void prepare_isolated(REAL* c, __constant const REAL* binomials) {
  (void)c;
  (void)binomials;
}

static REAL isolated_value(const REAL* c, REAL y) { return power_value(c, y); }

static REAL isolated_value_slope(const REAL* c, REAL y, REAL* slope) { return power_value_slope(c, y, slope); }

/* sum |c_k| y^k: Horner's rounding error at y is a small multiple of REAL_EPS times this. */
static REAL isolated_magnitude(const REAL* c, REAL y) {
  REAL h = fabs(c[DEGREE]);
  ALGRAY_UNROLL
  for (int k = DEGREE - 1; k >= 0; --k) h = h * y + fabs(c[k]);
  return h;
}

#endif /* ALGRAY_POWER_BASIS_H */
