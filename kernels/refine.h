/* Root refinement inside an isolating interval: Dekker-Brent, bisection, regula falsi (plain or Illinois), Newton. */
#ifndef ALGRAY_REFINE_H
#define ALGRAY_REFINE_H

#include "lanes.h"
#include "probe_log.h"
#include "real.h"

/* refine_root(c, f0, f1, tol_y, scale, start, running, iterations, probe_log), one per method below, needs
 * isolated_value(c, y) from the isolation method: the polynomial at y in [0,1] of the isolating interval. f0 and f1
 * are its values at 0 and 1, of opposite signs. tol_y is the stopping width in y; scale is the size of the
 * polynomial's coefficients on the isolating interval; start is the isolation's estimate of the root in (0, 1)
 * (isolated_start), or anything outside it for none. Returns the root's y and counts the iterations (function
 * evaluations) in *iterations, for the lanes in `running` (Brent, the one method built for lanes), or for one ray
 * (the others). */

/* Degree 1: P* on the isolating interval is the line f0 (1 - y) + f1 y, and its root f0 / (f0 - f1) is within 1.5
 * ulps: f0 and f1 have opposite signs, so f0 - f1 does not cancel. That is far inside any stopping width, where
 * every method would only converge to it, so at degree 1 none runs and no evaluation is counted. Over lanes, each
 * lane's root. */
ALGRAY_INLINE LREAL line_root(LREAL f0, LREAL f1) { return f0 / (f0 - f1); }

/* The paper's value stop, |P*(y)| <= eps_m, made independent of how P is scaled: the value is within the
 * rounding error of evaluating it at y, so its sign carries no more information. The error is measured at y
 * (isolated_magnitude), not by the largest coefficient: on a wide power-basis bracket the coefficients are
 * orders of magnitude larger than the terms near the root, and a coefficient-sized threshold stopped early
 * there: 726 of 4096 pixels more than 1e-6 deep on (z + x/10)^21 = a (derivative chain, double). It is at most
 * (DEGREE + 1) * scale, which skips computing it far from the root. */
static LMASK value_within_rounding(const LREAL* c, LREAL y, LREAL fy, LREAL scale) {
  return !(fabs(fy) > REAL_EPS * (REAL)(DEGREE + 1) * scale) && fabs(fy) <= REAL_EPS * isolated_magnitude(c, y);
}

#if LANES > 1 && !SOLVER_LANES
#error "LANES > 1 needs an isolation and a refinement with lane builds (SOLVER_LANES)"
#endif

#if REFINEMENT == ALGRAY_REFINEMENT_BRENT
/* Dekker-Brent over lanes (lanes.h): each lane where `running` is set refines its own polynomial, and a lane
 * that has stopped keeps its state, so every lane ends as one ray alone would, bit for bit. *iterations gets
 * each lane's count of function evaluations.
 * A lane with a start in (0, 1) (isolated_start: degree 2's formula) evaluates it first: it becomes b, the
 * bracket's end of the other sign c, and the other end a; the stopping rule then decides as always. Without a
 * start, the secant of the ends is the first step, as the paper has it. */
static LREAL refine_root(const LREAL* c, LREAL f0, LREAL f1, LREAL tol_y, LREAL scale, LREAL start, LMASK running,
                         LMASK* iterations, ProbeLog* probe_log) {
  /* b: best estimate; c_: contrapoint, f(c_) of the other sign; a: the previous b. */
  LREAL a = 0, fa = f0, b = 1, fb = f1, cp = 0, fc = f0;
  LMASK done = !running;
  LMASK it = 0;
  const LMASK started = running && start > 0 && start < 1;
  if (LANE_ANY(started)) {
    const LREAL fs = isolated_value(c, LANE_SEL((LREAL)0.5, start, started));
    const LMASK root_above = (fs > 0) == (f0 > 0); /* the sign change is between the start and 1 */
    a = LANE_SEL(a, LANE_SEL((LREAL)1, (LREAL)0, root_above), started);
    fa = LANE_SEL(fa, LANE_SEL(f1, f0, root_above), started);
    cp = LANE_SEL(cp, LANE_SEL((LREAL)0, (LREAL)1, root_above), started);
    fc = LANE_SEL(fc, LANE_SEL(f0, f1, root_above), started);
    b = LANE_SEL(b, start, started);
    fb = LANE_SEL(fb, fs, started);
    it += LANE_SEL((LMASK)0, (LMASK)1, started);
    PROBE_ITERATE(0, b, fb, fmin(b, cp), fmax(b, cp));
  }
  for (int n = 0; n < MAX_ITERATIONS; ++n) {
    const LMASK swap = !done && fabs(fc) < fabs(fb);
    a = LANE_SEL(a, b, swap);
    fa = LANE_SEL(fa, fb, swap);
    b = LANE_SEL(b, cp, swap);
    fb = LANE_SEL(fb, fc, swap);
    cp = LANE_SEL(cp, a, swap);
    fc = LANE_SEL(fc, fa, swap);
    /* The paper's stopping rule: |P*(b)| at machine precision, or a bracket at most the stopping width. The
     * value is within rounding when it is below the terms' rounding error (isolated_magnitude), which is at
     * most (DEGREE + 1) * scale: only then is the magnitude worth computing. */
    LMASK stop = fabs(cp - b) <= tol_y;
    const LMASK small = !done && !stop && !(fabs(fb) > REAL_EPS * (REAL)(DEGREE + 1) * scale);
    if (LANE_ANY(small)) stop = stop || (small && fabs(fb) <= REAL_EPS * isolated_magnitude(c, b));
    done = done || stop;
    if (LANE_ALL(done)) break;
    /* inverse quadratic interpolation through (a, fa), (b, fb), (c, fc), else the secant */
    const LMASK quadratic = fa != fc && fb != fc && fa != fb;
    const LMASK secant = !quadratic && fa != fb;
    LREAL num = 0, den = 1;
    if (LANE_ANY(quadratic)) { /* never on a first step without a start (a and c one point): its divisions wait */
      const LREAL r = fb / fc, s = fb / fa, q = fa / fc;
      num = s * (q * (q - r) * (cp - b) - (r - (REAL)1) * (b - a));
      den = (q - (REAL)1) * (r - (REAL)1) * (s - (REAL)1);
    }
    /* one division for either step: b - fb (b - a) / (fb - fa), or b - num / den */
    const LREAL step_num = LANE_SEL(fb * (b - a), num, quadratic), step_den = LANE_SEL(fb - fa, den, quadratic);
    const LREAL cand = LANE_SEL(b, b - step_num / step_den, quadratic || secant);
    /* The paper's acceptance rule: the step must stay well inside the bracket and shrink; also toward c. */
    const LREAL step = cand - b;
    const LMASK accept = (quadratic || secant) && isfinite(cand) && step * (cp - b) > 0 &&
                         fabs(step) < (REAL)0.75 * fabs(cp - b) && fabs(step) < (REAL)0.5 * fabs(b - a);
    LREAL next = LANE_SEL(b + (REAL)0.5 * (cp - b), cand, accept);
    next = LANE_SEL(next, b + copysign((REAL)0.5 * tol_y, cp - b), fabs(next - b) < (REAL)0.5 * tol_y);
    const LREAL fnext = isolated_value(c, next);
    /* the sign change is now between a and b */
    const LMASK moved = !done && (fnext > 0) == (fc > 0);
    cp = LANE_SEL(cp, b, moved);
    fc = LANE_SEL(fc, fb, moved);
    a = LANE_SEL(b, a, done);
    fa = LANE_SEL(fb, fa, done);
    b = LANE_SEL(next, b, done);
    fb = LANE_SEL(fnext, fb, done);
    it += LANE_SEL((LMASK)0, (LMASK)1, !done);
    PROBE_ITERATE(n + LANE_ANY(started), b, fb, fmin(b, cp), fmax(b, cp));
  }
  *iterations = it;
  return b;
}

#elif REFINEMENT == ALGRAY_REFINEMENT_BISECTION
static REAL refine_root(const REAL* c, REAL f0, REAL f1, REAL tol_y, REAL scale, REAL start, int running,
                        int* iterations, ProbeLog* probe_log) {
  (void)start; /* the paper's start */
  (void)running; /* one ray */
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
  *iterations = (int)it;
  return (REAL)0.5 * (lo + hi);
}
#elif REFINEMENT == ALGRAY_REFINEMENT_REGULA_FALSI || REFINEMENT == ALGRAY_REFINEMENT_ILLINOIS
/* False position: the secant through the bracket's ends. Plain, as in the paper, one end can stay fixed for
 * good, so the bracket never shrinks below the stopping width and only |P*| <= eps_m or the iteration cap
 * stops it (the paper's Barth decic defects). The Illinois variant halves the value kept at an end that has
 * survived twice in a row, which breaks that one-sidedness. */
static REAL refine_root(const REAL* c, REAL f0, REAL f1, REAL tol_y, REAL scale, REAL start, int running,
                        int* iterations, ProbeLog* probe_log) {
  (void)start; /* the paper's start */
  (void)running; /* one ray */
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
      if (REFINEMENT == ALGRAY_REFINEMENT_ILLINOIS && kept < 0) fb *= (REAL)0.5;
      kept = kept < 0 ? kept - 1 : -1;
    } else {
      b = x;
      fb = fx;
      if (REFINEMENT == ALGRAY_REFINEMENT_ILLINOIS && kept > 0) fa *= (REAL)0.5;
      kept = kept > 0 ? kept + 1 : 1;
    }
    PROBE_ITERATE(it, x, fx, a, b);
  }
  (void)kept;
  *iterations = (int)it;
  return x;
}
#elif REFINEMENT == ALGRAY_REFINEMENT_NEWTON
/* Newton's method inside the bracket: a step that would leave it, or that fails to halve |P*|, is replaced by
 * bisection, so it converges like bisection at worst and quadratically near a simple root. Needs
 * isolated_value_slope(c, y, &slope) from the isolation method. */
static REAL refine_root(const REAL* c, REAL f0, REAL f1, REAL tol_y, REAL scale, REAL start, int running,
                        int* iterations, ProbeLog* probe_log) {
  (void)start; /* the paper's start */
  (void)running; /* one ray */
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
  *iterations = (int)it;
  return x;
}
#endif /* build_switches.h holds REFINEMENT to the methods above */

#endif /* ALGRAY_REFINE_H */
