/* Root isolation by the derivative chain: the roots of A' cut [0,1] into pieces on which A is monotone. */
#ifndef ALGRAY_DERIVATIVE_CHAIN_H
#define ALGRAY_DERIVATIVE_CHAIN_H

#include "methods/power_basis.h"

/* The chain: level m (CHAIN_BOTTOM <= m < DEGREE) is the derivative of A of degree m, its m + 1 coefficients
 * starting at chain_offset(m); level DEGREE is A itself, kept apart. All levels at once is ~DEGREE^2/2 values:
 * kept, as the inner solves evaluate each level many times. */
#define CHAIN_STORAGE ((DEGREE - 1) * (DEGREE + 2) / 2 + 1)
static int chain_offset(int m) { return (m - 1) * (m + 2) / 2; }

/* The cap on one inner solve: from [0, 1], bisection alone is down to adjacent numbers after REAL_MAX_HALVINGS
 * steps, and the Newton steps allowed in between rarely double that. Reaching it sets iso.budget. */
#define CHAIN_MAX_STEPS (4 * REAL_MAX_HALVINGS)

/* d = c' for c of degree m + 1, scaled by a power of two to a largest coefficient in [1/2, 1): exact, and
 * without it the factors k would reach DEGREE! ~ 1e35 down the chain and overflow float. The exponent is
 * clamped so the scale itself stays a normal number. */
static void chain_derivative(const REAL* c, int m, REAL* d) {
  REAL big = 0;
  for (int k = 0; k <= m; ++k) {
    d[k] = (REAL)(k + 1) * c[k + 1];
    big = fmax(big, fabs(d[k]));
  }
  if (!(big > 0) || !isfinite(big)) return;
  int e;
  frexp(big, &e);
  const REAL scale = ldexp((REAL)1, -clamp(e, -100, 100));
  for (int k = 0; k <= m; ++k) d[k] *= scale;
}

/* Horner on one level. The degree varies at run time, so these loops stay rolled: a fully unrolled loop over
 * DEGREE with the terms above m masked off measured no faster. */
static REAL chain_value(const REAL* c, int m, REAL y) {
  REAL h = c[m];
  for (int k = m - 1; k >= 0; --k) h = h * y + c[k];
  return h;
}

static REAL chain_value_slope(const REAL* c, int m, REAL y, REAL* slope) {
  REAL h = c[m], d = 0;
  for (int k = m - 1; k >= 0; --k) {
    d = d * y + h;
    h = h * y + c[k];
  }
  *slope = d;
  return h;
}

/* A(1) is the sum of the coefficients; summed with its rounding errors carried (Neumaier), so that a root at
 * the far end, where the ray leaves the extent, is seen on its true side: plain summation flips its sign about
 * half the time, and a simple root just inside would be missed. */
static REAL chain_value_at_one(const REAL* a) {
  REAL s = a[0], e = 0;
  ALGRAY_UNROLL
  for (int k = 1; k <= DEGREE; ++k) {
    const REAL t = s + a[k];
    e += fabs(s) >= fabs(a[k]) ? (s - t) + a[k] : (a[k] - t) + s;
    s = t;
  }
  return s + e;
}

/* The root of level c (degree m) in the piece [lo, hi], on which c is monotone with f_lo, f_hi of opposite
 * signs. Newton from the secant point, as long as it stays inside the bracket and each step is under half the
 * one before the last (as in rtsafe), bisection otherwise; no refinement method of refine.h runs here.
 * The root is only a piece boundary for the level above, which is extremal there: an error d in it moves that
 * level's value by ~d^2, so its sign tests only go wrong for a pair of its roots closer than ~2d, which the
 * stopping width tol lets pass as located (no sign change, as in settle_cluster). Below A', such a missed pair
 * leaves a wiggle of order d^3 in the level above that: a near triple root of A, found within ~2d either way.
 * The last Newton step usually lands far closer than tol anyway. */
static REAL chain_root(const REAL* c, int m, REAL lo, REAL hi, REAL f_lo, REAL f_hi, REAL tol, Isolation* iso,
                       ProbeLog* probe_log) {
  const int rising = f_lo < 0;
  REAL x = lo - f_lo * ((hi - lo) / (f_hi - f_lo));
  if (!(x > lo && x < hi)) x = (REAL)0.5 * (lo + hi);
  REAL step = hi - lo, step_before = hi - lo;
  REAL newton_before = 0; /* the previous step, if it was Newton's */
  for (int it = 0; it < CHAIN_MAX_STEPS; ++it) {
    ++iso->steps;
    REAL slope;
    const REAL f = chain_value_slope(c, m, x, &slope);
    PROBE(ALGRAY_EVENT_CHAIN_ITERATE, it, 0u, (uint)(DEGREE - m), x, f, lo, hi);
    if (f == 0) return x;
    if ((f < 0) == rising)
      lo = x;
    else
      hi = x;
    if (hi - lo <= tol) return x;
    REAL next = x - f / slope;
    const int newton = next > lo && next < hi && fabs(next - x) < (REAL)0.5 * step_before;
    if (!newton) next = (REAL)0.5 * (lo + hi);
    if (next == lo || next == hi) return x; /* the bracket is down to adjacent numbers */
    step_before = step;
    step = fabs(next - x);
    if (newton) {
      /* Done when this step's error, predicted from the last two steps (step^3 / newton_before^2 where Newton
       * converges quadratically, step itself where a near double root slows it to halving), is below tol: it
       * saves the one evaluation that would only confirm it. */
      if (step <= tol || step * step * step <= (REAL)0.25 * tol * newton_before * newton_before) return next;
      newton_before = step;
    } else {
      newton_before = 0;
    }
    x = next;
  }
  iso->budget = 1;
  return x;
}

/* The bottom of the chain is solved in closed form: the quadratic derivative (the linear one for DEGREE 2),
 * which spares the Newton solves of the two lowest levels (measured: the torus needs under a third of the
 * evaluations). Its roots in (0, 1), in increasing order, in r; returns how many. A double root is kept: one
 * boundary too many is harmless. */
#define CHAIN_BOTTOM (DEGREE >= 3 ? 2 : 1)
static int chain_bottom_roots(const REAL* c, REAL* r) {
  const REAL c0 = c[0], c1 = c[1];
  const REAL c2 = CHAIN_BOTTOM == 2 ? c[2] : (REAL)0;
  REAL x0 = -1, x1 = -1;
  if (c2 == 0) {
    if (c1 != 0) x0 = -c0 / c1;
  } else {
    const REAL disc = c1 * c1 - (REAL)4 * c0 * c2;
    if (disc >= 0) {
      /* the root away from cancellation, then the other from the product of the roots */
      const REAL q = (REAL)-0.5 * (c1 + copysign(sqrt(disc), c1));
      x0 = q / c2;
      x1 = q != 0 ? c0 / q : x0;
      if (x1 < x0) {
        const REAL t = x0;
        x0 = x1;
        x1 = t;
      }
    }
  }
  int n = 0;
  if (x0 > 0 && x0 < 1) r[n++] = x0;
  if (x1 > 0 && x1 < 1) r[n++] = x1;
  return n;
}

/* The walk along A's piece boundaries, left to right, looking for the first sign change. */
typedef struct {
  REAL x, f; /* the previous boundary and A there */
  int sign;  /* the sign of A at the last boundary where it was nonzero */
  REAL zero; /* the first boundary of the current run where A is exactly 0, or -1 */
} ChainWalk;

/* Visits the next boundary x of A's pieces. A sign change between two boundaries is a bracket; an exact zero
 * on a boundary is a root only if A has the other sign after it (a double root only touches, and is invisible
 * as in settle_cluster), or if it is the far end, where nothing follows to tell. A NaN is neither a sign nor a
 * zero, so a degenerate polynomial finds nothing. Returns 1 when it settled iso->status. */
static int chain_visit(ChainWalk* w, Isolation* iso, const REAL* a, REAL x, ProbeLog* probe_log) {
  ++iso->steps;
  const REAL f = x == (REAL)1 ? chain_value_at_one(a) : power_value(a, x);
  const int s = (f > 0) - (f < 0);
  if (s != 0 && s == -((w->f > 0) - (w->f < 0))) {
    iso->status = ISOLATION_BRACKET;
    iso->lo = w->x;
    iso->hi = x;
    iso->f_lo = w->f;
    iso->f_hi = f;
    PROBE_STEP(*iso, -1, ALGRAY_STEP_ISOLATED, 0);
    return 1;
  }
  REAL root = -1;
  if (f == 0) {
    if (w->zero < 0) w->zero = x;
    if (x == (REAL)1) root = w->zero;
  } else if (s != 0) {
    if (w->zero >= 0 && s != w->sign) root = w->zero;
    w->zero = -1;
    w->sign = s;
  }
  if (root >= 0) {
    iso->status = ISOLATION_EXACT;
    iso->lo = iso->hi = root;
    iso->f_lo = iso->f_hi = 0;
    PROBE_STEP(*iso, -1, ALGRAY_STEP_EXACT_ZERO, 0);
    return 1;
  }
  PROBE(ALGRAY_EVENT_STEP, -1, ALGRAY_STEP_PIECE, 0u, w->x, x, w->f, f);
  w->x = x;
  w->f = f;
  return 0;
}

/* Walks A's pieces from y = 0 until walk finds the first sign change (chain_visit) or reaches the end 1. The
 * roots in (0, 1) of each level of the chain are the piece boundaries of the level above, up to A. */
ALGRAY_INLINE void walk_chain_pieces(const REAL* a, REAL t_in, REAL t_out, ChainWalk* walk, Isolation* iso,
                                     ProbeLog* probe_log) {
#if DEGREE > 1
  /* The stopping width where it is smallest on [t_in, t_out], nearest t = 0, as a fraction of the interval. */
  const REAL len = t_out - t_in;
  const REAL t_near = t_in <= 0 && t_out >= 0 ? (REAL)0 : fmin(fabs(t_in), fabs(t_out));
  const REAL tol = stop_width(t_near) / len;

  REAL chain[CHAIN_STORAGE];
  chain_derivative(a, DEGREE - 1, chain + chain_offset(DEGREE - 1));
  for (int m = DEGREE - 2; m >= CHAIN_BOTTOM; --m)
    chain_derivative(chain + chain_offset(m + 1), m, chain + chain_offset(m));
  REAL bottom[2];
  const int bottom_count = chain_bottom_roots(chain + chain_offset(CHAIN_BOTTOM), bottom);
  int bottom_taken = 0;
  ++iso->steps;

  /* The levels as a pipeline, each a stream of its roots in increasing order: a level takes the next root of
   * the level below as its next piece boundary, and sends a root up when that piece changes sign. Pulled from
   * the top by the walk along A, so nothing right of A's first sign change is ever solved. Per level m: the
   * last boundary taken and its value there, and in `done` whether that was the end 1. */
  REAL last_x[NCOEF], last_f[NCOEF];
  uint done = 0;
  for (int m = CHAIN_BOTTOM + 1; m < DEGREE; ++m) {
    last_x[m] = 0;
    last_f[m] = chain[chain_offset(m)];
  }
  int m = DEGREE - 1; /* the level whose next root is wanted */
  int have = 0;       /* y is a new piece boundary for level m */
  REAL y = 0;
  for (;;) {
    if (!have) {
      if (m == CHAIN_BOTTOM) {
        y = bottom_taken < bottom_count ? bottom[bottom_taken++] : (REAL)1;
      } else if ((done >> m) & 1) {
        y = 1; /* all its roots are out: the end is its last word */
      } else {
        --m;
        continue;
      }
    } else {
      const REAL* c = chain + chain_offset(m);
      ++iso->steps;
      const REAL v = chain_value(c, m, y);
      const REAL u = last_f[m];
      REAL root = -1;
      if ((u < 0 && v > 0) || (u > 0 && v < 0))
        root = chain_root(c, m, last_x[m], y, u, v, tol, iso, probe_log);
      else if (v == 0 && y < (REAL)1)
        root = y; /* a root on a boundary: one too many is harmless, a monotone piece split in two */
      last_x[m] = y;
      last_f[m] = v;
      if (y == (REAL)1) done |= 1u << m;
      if (root >= 0) {
        y = root;
      } else if (y < (REAL)1) {
        have = 0;
        continue;
      }
    }
    /* y is the next root of level m, or the end 1: the next piece boundary of the level above */
    if (m == DEGREE - 1) {
      if (chain_visit(walk, iso, a, y, probe_log) || y == (REAL)1) break;
      have = 0;
    } else {
      ++m;
      have = 1;
    }
  }
#else
  (void)t_in;
  (void)t_out;
  chain_visit(walk, iso, a, (REAL)1, probe_log);
#endif
}

/* p is P*(s) in the power basis, the extent interval being s in [s0, s0 + len_s], mapped once to A(y) on
 * [0, 1]. A's first piece with a sign change is the bracket (walk_chain_pieces). A zero of A at y = 0 is a root whatever its
 * multiplicity, as in the other methods: the ray starts on the surface. iso.steps counts polynomial
 * evaluations: piece ends at every level, inner solver iterations, the closed-form bottom as one. On return
 * `a1` is A1 on [lo, hi] when the status is a bracket. */
static Isolation isolate_derivative_chain(const REAL* p, REAL s0, REAL len_s, REAL t_in, REAL t_out, REAL* a1,
                                          ProbeLog* probe_log) {
  Isolation iso = isolation_none();
  REAL a[NCOEF];
  power_on_interval(p, s0, len_s, a);
  ++iso.steps;
  if (a[0] == 0) {
    iso.status = ISOLATION_EXACT;
    iso.lo = iso.hi = 0;
    PROBE_STEP(iso, -1, ALGRAY_STEP_EXACT_ZERO, 0);
    return iso;
  }
  ChainWalk walk;
  walk.x = 0;
  walk.f = a[0];
  walk.sign = a[0] > 0 ? 1 : -1;
  walk.zero = -1;

  walk_chain_pieces(a, t_in, t_out, &walk, &iso, probe_log);
  /* The bracket's own polynomial, from A as its end values were, so that refinement sees the same signs. */
  if (iso.status == ISOLATION_BRACKET) power_on_interval(a, iso.lo, iso.hi - iso.lo, a1);
  return iso;
}

/* The method's entry (isolate.h): P*(s) in the power basis as power_s0 and power_len_s place it. */
static Isolation isolate_method(REAL* root, REAL* root_lo, REAL t_in, REAL t_out, REAL* iso_c, RayTerms* terms,
                                ProbeLog* probe_log) {
  (void)root_lo;
  (void)terms;
  return isolate_derivative_chain(root, power_s0(t_in), power_len_s(t_in, t_out), t_in, t_out, iso_c, probe_log);
}

#endif /* ALGRAY_DERIVATIVE_CHAIN_H */
