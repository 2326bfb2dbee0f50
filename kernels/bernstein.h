/* Root isolation by Descartes' rule on Bernstein coefficients over [t_in, t_out], with de Casteljau halving. */
#ifndef ALGRAY_BERNSTEIN_H
#define ALGRAY_BERNSTEIN_H

#include "isolation.h"

/* The restriction produced scaled coefficients c_k = C(n,k) b_k; Descartes' rule and de Casteljau want b_k. */
void bernstein_from_scaled(REAL* c, __constant const REAL* binomials) {
  __constant const REAL* row = binomials + DEGREE * NCOEF;
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) c[k] /= row[k];
}

/* Keeps the part of the curve on [0, x]. In place: after pass r, c[r] is the r-th left coefficient. */
void casteljau_keep_left(REAL* c, REAL x) {
  const REAL x1 = (REAL)1 - x;
  ALGRAY_UNROLL
  for (int r = 1; r <= DEGREE; ++r)
    ALGRAY_UNROLL
    for (int k = DEGREE; k >= r; --k) c[k] = x1 * c[k - 1] + x * c[k];
}

/* Keeps the part on [x, 1]. */
void casteljau_keep_right(REAL* c, REAL x) {
  const REAL x1 = (REAL)1 - x;
  ALGRAY_UNROLL
  for (int r = 1; r <= DEGREE; ++r)
    ALGRAY_UNROLL
    for (int k = 0; k <= DEGREE - r; ++k) c[k] = x1 * c[k] + x * c[k + 1];
}

/* Halves c at 1/2 in one de Casteljau triangle: c becomes the left half, right the right half. */
void casteljau_halve(REAL* c, REAL* right) {
  REAL t[NCOEF];
  poly_copy(t, c);
  right[DEGREE] = t[DEGREE];
  ALGRAY_UNROLL
  for (int r = 1; r <= DEGREE; ++r) {
    ALGRAY_UNROLL
    for (int k = 0; k <= DEGREE - r; ++k) t[k] = (REAL)0.5 * (t[k] + t[k + 1]);
    c[r] = t[0];
    right[DEGREE - r] = t[DEGREE - r];
  }
}

/* Coefficients on the dyadic interval [idx/2^level, (idx+1)/2^level], recomputed from the whole interval's. */
void bernstein_restrict(const REAL* root, int level, ulong idx, REAL* out) {
  poly_copy(out, root);
  const REAL width = ldexp((REAL)1, -level);
  const REAL lo = (REAL)idx * width, hi = lo + width;
  if (hi < (REAL)1) casteljau_keep_left(out, hi);
  if (lo > (REAL)0) casteljau_keep_right(out, lo / hi);
}

/* Finds the leftmost subinterval of [0,1] that isolates the smallest root of the polynomial with Bernstein
 * coefficients `root`. Depth-first, left half first; the path is the pair (level, idx), so no stack is kept.
 * The right half of the latest split is cached, as the left half is usually rejected at once.
 * On return `cur` holds the Bernstein coefficients on [iso.lo, iso.hi]. */
Isolation isolate_bernstein(const REAL* root, REAL t_in, REAL t_out, REAL* cur) {
  Isolation iso = isolation_none();
  REAL sib[NCOEF];
  int sib_level = -1;
  ulong sib_idx = 0;
  int level = 0;
  ulong idx = 0;
  const REAL len = t_out - t_in;
  const int start_sign = (root[0] > 0) - (root[0] < 0);
  poly_copy(cur, root);

  for (;;) {
    ++iso.steps;
    const REAL width = ldexp((REAL)1, -level);
    iso.lo = (REAL)idx * width;
    iso.hi = iso.lo + width;
    iso.f_lo = cur[0];
    iso.f_hi = cur[DEGREE];
    if (cur[0] == 0) {
      iso.status = ISOLATION_EXACT;
      return iso;
    }
    if (crossed_at_left_end(&iso, start_sign)) return iso;
    const int v = sign_variations(cur);
    if (v == 1 && cur[DEGREE] != 0) {
      iso.status = ISOLATION_BRACKET;
      return iso;
    }
    if (v >= 1) {
      const int located = interval_located(width, iso.lo, t_in, len);
      if (!located && level < REAL_MAX_HALVINGS) {
        casteljau_halve(cur, sib);
        ++level;
        idx *= 2;
        sib_level = level;
        sib_idx = idx + 1;
        continue;
      }
      if (settle_cluster(&iso, located)) return iso;
    }
    if (!next_interval(&level, &idx)) {
      /* Intervals are half open; the far end is the one point left to look at. */
      iso.status = root[DEGREE] == 0 ? ISOLATION_EXACT : ISOLATION_NONE;
      iso.lo = iso.hi = 1;
      iso.f_lo = iso.f_hi = 0;
      return iso;
    }
    if (sib_level == level && sib_idx == idx)
      poly_copy(cur, sib);
    else
      bernstein_restrict(root, level, idx, cur);
  }
}

/* Turns Bernstein coefficients into the form isolated_value() expects: c_k * C(n,k). */
void prepare_isolated(REAL* c, __constant const REAL* binomials) {
  __constant const REAL* row = binomials + DEGREE * NCOEF;
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) c[k] *= row[k];
}

/* x^DEGREE by repeated multiplication: pown() goes through exp and log on some devices. */
REAL power_of(REAL x) {
  REAL p = 1;
  ALGRAY_UNROLL
  for (int k = 0; k < DEGREE; ++k) p *= x;
  return p;
}

/* Value at y in [0,1] of a prepared polynomial in O(n): Horner in y/(1-y), mirrored past 1/2 so the ratio
 * stays at most 1. */
REAL isolated_value(const REAL* c, REAL y) {
  if (y <= (REAL)0.5) {
    const REAL r = y / ((REAL)1 - y);
    REAL h = c[DEGREE];
    ALGRAY_UNROLL
    for (int k = DEGREE - 1; k >= 0; --k) h = h * r + c[k];
    return h * power_of(1 - y);
  }
  const REAL r = ((REAL)1 - y) / y;
  REAL h = c[0];
  ALGRAY_UNROLL
  for (int k = 1; k <= DEGREE; ++k) h = h * r + c[k];
  return h * power_of(y);
}

#endif /* ALGRAY_BERNSTEIN_H */
