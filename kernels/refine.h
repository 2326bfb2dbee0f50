/* Root refinement inside an isolating interval: Dekker-Brent, bisection, regula falsi (plain or Illinois), Newton. */
#ifndef ALGRAY_REFINE_H
#define ALGRAY_REFINE_H

#include "probe_log.h"
#include "real.h"

/* Needs isolated_value(c, y) from the isolation method: the polynomial at y in [0,1] of the isolating interval.
 * f0 and f1 are its values at 0 and 1, of opposite signs. tol_y is the stopping width in y; scale is the size
 * of the polynomial's coefficients on the isolating interval. Returns the root's y and counts the iterations
 * (function evaluations) in *iterations. */

/* The paper's value stop, |P*(y)| <= eps_m, made independent of how P is scaled: the value is within the
 * rounding error of evaluating it at y, so its sign carries no more information. The error is measured at y
 * (isolated_magnitude), not by the largest coefficient: on a wide power-basis bracket the coefficients are
 * orders of magnitude larger than the terms near the root, and a coefficient-sized threshold stopped early
 * there: 726 of 4096 pixels more than 1e-6 deep on (z + x/10)^21 = a (derivative chain, double). It is at most
 * (DEGREE + 1) * scale, which skips computing it far from the root. */
int value_within_rounding(const REAL* c, REAL y, REAL fy, REAL scale) {
  if (fabs(fy) > REAL_EPS * (REAL)(DEGREE + 1) * scale) return 0;
  return fabs(fy) <= REAL_EPS * isolated_magnitude(c, y);
}

#if REFINEMENT == ALGRAY_REFINEMENT_BRENT
REAL refine_root(const REAL* c, REAL f0, REAL f1, REAL tol_y, REAL scale, uint* iterations PROBE_PARAM) {
  /* b: best estimate; c_: contrapoint, f(c_) of the other sign; a: the previous b. */
  REAL a = 0, fa = f0, b = 1, fb = f1, cp = 0, fc = f0;
  uint it = 0;
  for (; it < MAX_ITERATIONS; ++it) {
    if (fabs(fc) < fabs(fb)) {
      a = b;
      fa = fb;
      b = cp;
      fb = fc;
      cp = a;
      fc = fa;
    }
    /* The paper's stopping rule: |P*(b)| at machine precision, or a bracket at most the stopping width. */
    if (fabs(cp - b) <= tol_y || value_within_rounding(c, b, fb, scale)) break;
    REAL cand = b;
    int have = 0;
    if (fa != fc && fb != fc && fa != fb) {
      /* inverse quadratic interpolation through (a, fa), (b, fb), (c, fc) */
      const REAL r = fb / fc, s = fb / fa, q = fa / fc;
      const REAL num = s * (q * (q - r) * (cp - b) - (r - (REAL)1) * (b - a));
      const REAL den = (q - (REAL)1) * (r - (REAL)1) * (s - (REAL)1);
      cand = b - num / den;
      have = 1;
    } else if (fa != fb) {
      cand = b - fb * (b - a) / (fb - fa); /* secant */
      have = 1;
    }
    /* The paper's acceptance rule: the step must stay well inside the bracket and shrink; also toward c. */
    const REAL step = cand - b;
    const int accept = have && isfinite(cand) && step * (cp - b) > 0 && fabs(step) < (REAL)0.75 * fabs(cp - b) &&
                       fabs(step) < (REAL)0.5 * fabs(b - a);
    REAL next = accept ? cand : b + (REAL)0.5 * (cp - b);
    if (fabs(next - b) < (REAL)0.5 * tol_y) next = b + copysign((REAL)0.5 * tol_y, cp - b);
    a = b;
    fa = fb;
    b = next;
    fb = isolated_value(c, b);
    if ((fb > 0) == (fc > 0)) { /* the sign change is now between a and b */
      cp = a;
      fc = fa;
    }
    PROBE_ITERATE(it, b, fb, fmin(b, cp), fmax(b, cp));
  }
  *iterations = it;
  return b;
}
#elif REFINEMENT == ALGRAY_REFINEMENT_BISECTION
REAL refine_root(const REAL* c, REAL f0, REAL f1, REAL tol_y, REAL scale, uint* iterations PROBE_PARAM) {
  REAL lo = 0, hi = 1, flo = f0;
  (void)f1;
  (void)scale;
  uint it = 0;
  for (; it < MAX_ITERATIONS && hi - lo > tol_y; ++it) {
    const REAL mid = (REAL)0.5 * (lo + hi);
    const REAL fm = isolated_value(c, mid);
    if (fm == 0) {
      PROBE_ITERATE(it, mid, fm, mid, mid);
      lo = hi = mid;
      ++it;
      break;
    }
    if ((fm < 0) == (flo < 0)) {
      lo = mid;
      flo = fm;
    } else {
      hi = mid;
    }
    PROBE_ITERATE(it, mid, fm, lo, hi);
  }
  *iterations = it;
  return (REAL)0.5 * (lo + hi);
}
#elif REFINEMENT == ALGRAY_REFINEMENT_REGULA_FALSI || REFINEMENT == ALGRAY_REFINEMENT_ILLINOIS
/* False position: the secant through the bracket's ends. Plain, as in the paper, one end can stay fixed for
 * good, so the bracket never shrinks below the stopping width and only |P*| <= eps_m or the iteration cap
 * stops it (the paper's Barth decic defects). The Illinois variant halves the value kept at an end that has
 * survived twice in a row, which breaks that one-sidedness. */
REAL refine_root(const REAL* c, REAL f0, REAL f1, REAL tol_y, REAL scale, uint* iterations PROBE_PARAM) {
  REAL a = 0, fa = f0, b = 1, fb = f1, x = fabs(f0) < fabs(f1) ? (REAL)0 : (REAL)1;
  int kept = 0; /* +1: a survived the last step(s), -1: b did */
  uint it = 0;
  for (; it < MAX_ITERATIONS && b - a > tol_y; ++it) {
    x = a - fa * (b - a) / (fb - fa);
    if (!(x > a && x < b)) x = (REAL)0.5 * (a + b); /* rounding pushed it out: stay inside */
    const REAL fx = isolated_value(c, x);
    if (value_within_rounding(c, x, fx, scale)) {
      PROBE_ITERATE(it, x, fx, a, b);
      ++it;
      break;
    }
    if ((fx < 0) == (fa < 0)) {
      a = x;
      fa = fx;
#if REFINEMENT == ALGRAY_REFINEMENT_ILLINOIS
      if (kept < 0) fb *= (REAL)0.5;
#endif
      kept = kept < 0 ? kept - 1 : -1;
    } else {
      b = x;
      fb = fx;
#if REFINEMENT == ALGRAY_REFINEMENT_ILLINOIS
      if (kept > 0) fa *= (REAL)0.5;
#endif
      kept = kept > 0 ? kept + 1 : 1;
    }
    PROBE_ITERATE(it, x, fx, a, b);
  }
  (void)kept;
  *iterations = it;
  return x;
}
#elif REFINEMENT == ALGRAY_REFINEMENT_NEWTON
/* Newton's method inside the bracket: a step that would leave it, or that fails to halve |P*|, is replaced by
 * bisection, so it converges like bisection at worst and quadratically near a simple root. Needs
 * isolated_value_slope(c, y, &slope) from the isolation method. */
REAL refine_root(const REAL* c, REAL f0, REAL f1, REAL tol_y, REAL scale, uint* iterations PROBE_PARAM) {
  REAL a = 0, b = 1, fa = f0;
  REAL x = fabs(f0) < fabs(f1) ? (REAL)0 : (REAL)1, slope;
  REAL fx = isolated_value_slope(c, x, &slope);
  REAL previous = INFINITY;
  uint it = 0;
  for (; it < MAX_ITERATIONS && b - a > tol_y; ++it) {
    if (value_within_rounding(c, x, fx, scale)) break;
    REAL next = x - fx / slope;
    if (!(next > a && next < b) || !(fabs(fx) <= (REAL)0.5 * previous)) next = (REAL)0.5 * (a + b);
    previous = fabs(fx);
    x = next;
    fx = isolated_value_slope(c, x, &slope);
    if ((fx < 0) == (fa < 0)) {
      a = x;
      fa = fx;
    } else {
      b = x;
    }
    PROBE_ITERATE(it, x, fx, a, b);
  }
  *iterations = it;
  return x;
}
#else
#error "REFINEMENT must name a refinement method"
#endif

#endif /* ALGRAY_REFINE_H */
