/* POV-Ray's root isolation: a Sturm sequence of P*(s) on the interval, bisection by its distinct-root counts. */
#ifndef ALGRAY_STURM_H
#define ALGRAY_STURM_H

#include "methods/power_basis.h"

/* Member k of the sequence has degree at most DEGREE - k, as degrees strictly fall, so the members share one
 * triangular store: slot k holds DEGREE - k + 1 coefficients from this offset, zero past the member's degree. */
#define STURM_SLOT(k) ((k) * NCOEF - (k) * ((k)-1) / 2)
#define STURM_STORE (NCOEF * (NCOEF + 1) / 2)

/* A remainder that is zero in exact arithmetic (A1 has a multiple root) comes out as rounding noise, which
 * normalising would blow up into a member of random roots. Each division rounds every remainder coefficient a
 * few times at the size of the largest term subtracted, on members that carry the roundings of the divisions
 * before them (up to DEGREE), so noise is taken as STURM_ZERO_ULPS * DEGREE * eps of that size. The counts are
 * not sensitive to the factor: 1, 4 and 16 gave the same double results on 320000 random cases and float
 * failures within sampling noise of each other (23, 29, 37), and 1, 4 and 64 about the same float renders. */
#define STURM_ZERO_ULPS 4

/* 2^-e for a positive x in [2^e, 2^(e+1)), from the exponent bits: ldexp and ilogb are library calls on
 * PoCL, which measured 11% of the whole Barth decic kernel. Clamped to a normal number at the ends of the
 * range, where any power of two will do. */
static REAL inverse_power_of_two(REAL x) {
#if ALGRAY_DOUBLE
  const long e = (as_long(x) >> 52) & 0x7ff;
  return as_double(clamp(2046L - e, 1L, 2046L) << 52);
#else
  const int e = (as_int(x) >> 23) & 0xff;
  return as_float(clamp(254 - e, 1, 254) << 23);
#endif
}

/* Scales c[0..d] by the power of two that brings its largest |coefficient| into [1, 2): exact, so the signs of
 * the values, and for S0 the values themselves up to that factor, are the unscaled polynomial's. */
static void sturm_normalise(REAL* c, int d, REAL sign) {
  REAL largest = 0;
  for (int j = 0; j <= d; ++j) largest = fmax(largest, fabs(c[j]));
  const REAL scale = sign * inverse_power_of_two(largest);
  for (int j = 0; j <= d; ++j) c[j] *= scale;
}

/* What a remainder coefficient that is zero in exact arithmetic may come out as, when the largest quotient
 * term was q_largest. Members are below 2 in every coefficient, so the terms subtracted are below
 * 2 max(1, |q|). */
static REAL sturm_remainder_noise(REAL q_largest) {
  return (REAL)(STURM_ZERO_ULPS * DEGREE) * REAL_EPS * (REAL)2 * fmax((REAL)1, q_largest);
}

/* S0 = A1, S1 = A1', S(k+1) = -rem(S(k-1), S(k)), each scaled to a largest |coefficient| in [1, 2) so that
 * one noise level fits every member and nothing overflows at degree 32. A remainder within rounding noise of
 * zero ends the sequence: A1 then has a multiple root (or two roots closer than the noise can tell apart), the
 * last member is their gcd, and the counts below are of distinct roots, a multiple root counting once. Degrees
 * are data, so neither this nor the generic path below is unrolled: O(DEGREE^2) of straight-line code at
 * degree 32 would buy nothing for loops that run once per ray. */
static void sturm_sequence(const REAL* a1, REAL* seq) {
  for (int j = 0; j < STURM_STORE; ++j) seq[j] = 0;
  int a = DEGREE; /* degree of S(k-1) */
  while (a > 0 && a1[a] == 0) --a;
  for (int j = 0; j <= a; ++j) seq[j] = a1[j];
  sturm_normalise(seq, a, (REAL)1);
  if (a == 0) return; /* a constant has no roots: the sequence is S0 alone */
  REAL* prev = seq;
  REAL* cur = seq + STURM_SLOT(1);
  for (int j = 1; j <= a; ++j) cur[j - 1] = (REAL)j * prev[j];
  int b = a - 1; /* degree of S(k) */
  sturm_normalise(cur, b, (REAL)1);

  REAL r[NCOEF];
  for (int k = 1; k < DEGREE && b > 0; ++k) {
    for (int j = 0; j <= a; ++j) r[j] = prev[j];
    /* The largest multiple of S(k) taken off: the remainder is a difference of terms that large. */
    REAL q_largest = 0;
    for (int i = a; i >= b; --i) {
      const REAL q = r[i] / cur[b];
      q_largest = fmax(q_largest, fabs(q));
      for (int j = 0; j < b; ++j) r[i - b + j] -= q * cur[j];
      r[i] = 0;
    }
    const REAL noise = sturm_remainder_noise(q_largest);
    int d = b - 1;
    while (d >= 0 && fabs(r[d]) <= noise) --d;
    if (d < 0) return; /* S(k) divides S(k-1): it is the gcd */
    /* Leading coefficients within the noise are dropped: they are as likely zero as anything, and dividing by
     * one would blow the noise up to the size of the next member. */
    REAL* next = seq + STURM_SLOT(k + 1);
    for (int j = 0; j <= d; ++j) next[j] = r[j];
    sturm_normalise(next, d, (REAL)-1);
    prev = cur;
    cur = next;
    a = b;
    b = d;
  }
}

/* The same sequence when every remainder has full degree (degrees DEGREE, DEGREE - 1, ..., 0), as for nearly
 * every ray: each division is two quotient terms, and every loop's trip count depends on the member only, so
 * all work-items run them in step. Returns 0, leaving seq half written, at the first remainder that loses a
 * degree (or vanishes), for sturm_sequence to redo in general. */
static int sturm_sequence_generic(const REAL* a1, REAL* seq) {
  if (a1[DEGREE] == 0) return 0;
  for (int j = 0; j <= DEGREE; ++j) seq[j] = a1[j];
  sturm_normalise(seq, DEGREE, (REAL)1);
  REAL* s1 = seq + STURM_SLOT(1);
  for (int j = 1; j <= DEGREE; ++j) s1[j - 1] = (REAL)j * seq[j];
  sturm_normalise(s1, DEGREE - 1, (REAL)1);
  for (int k = 1; k < DEGREE; ++k) {
    const int b = DEGREE - k; /* degree of S(k) */
    const REAL* prev = seq + STURM_SLOT(k - 1);
    const REAL* cur = seq + STURM_SLOT(k);
    REAL* next = seq + STURM_SLOT(k + 1);
    /* S(k-1) - (q1 x + q0) S(k), in the order sturm_sequence takes the terms off */
    const REAL q1 = prev[b + 1] / cur[b];
    const REAL q0 = (prev[b] - q1 * cur[b - 1]) / cur[b];
    next[0] = prev[0] - q0 * cur[0];
    for (int j = 1; j < b; ++j) next[j] = prev[j] - q1 * cur[j - 1] - q0 * cur[j];
    const REAL noise = sturm_remainder_noise(fmax(fabs(q1), fabs(q0)));
    if (!(fabs(next[b - 1]) > noise)) return 0;
    sturm_normalise(next, b - 1, (REAL)-1);
  }
  return 1;
}

/* Sign changes of the sequence at x, zeros skipped; S0(x) in *f0 and a bound on its rounding error in *noise.
 * Every slot is evaluated over its full length with a fixed trip count: the zeros past a member's degree, and
 * the members past the end, cost a few multiplications, which a generic sequence (degrees DEGREE, DEGREE - 1,
 * ..., 0) does not even have. The bound is Horner's: at most 2n roundings of eps/2 of sum |c_k| x^k, doubled. */
static int sturm_variations(const REAL* seq, REAL x, REAL* f0, REAL* noise) {
  int v = 0;
  int prev = 0; /* sign of the last nonzero member, 0 before the first */
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) {
    const REAL* c = seq + STURM_SLOT(k);
    REAL h = c[DEGREE - k];
    if (k == 0) {
      REAL m = fabs(h);
      ALGRAY_UNROLL
      for (int j = DEGREE - 1; j >= 0; --j) {
        h = h * x + c[j];
        m = m * x + fabs(c[j]);
      }
      *f0 = h;
      *noise = (REAL)(2 * DEGREE) * REAL_EPS * m;
    } else {
      ALGRAY_UNROLL
      for (int j = DEGREE - k - 1; j >= 0; --j) h = h * x + c[j];
    }
    const int s = (h > 0) - (h < 0);
    v += s * prev < 0;
    prev = s != 0 ? s : prev;
  }
  return v;
}

/* Turns a bracket found on the sequence into A1 on [iso.lo, iso.hi] (a1 holding A1 on the whole interval on
 * entry). The sequence saw a sign change between the ends; recomputed on the subinterval, an end value within
 * rounding of zero may come out with the other sign, and the refinement needs two opposite signs: then the
 * root is at that end, as far as this precision can tell, and is reported there. */
static void sturm_bracket(Isolation* iso, REAL* a1) {
  power_on_interval(a1, iso->lo, iso->hi - iso->lo, a1);
  const REAL f0 = a1[0], f1 = power_value(a1, (REAL)1);
  iso->f_lo = f0;
  iso->f_hi = f1;
  if (f0 != 0 && f1 != 0 && (f0 < 0) != (f1 < 0)) {
    iso->status = ISOLATION_BRACKET;
    return;
  }
  iso->status = ISOLATION_EXACT;
  if (f0 != 0 && (f1 == 0 || fabs(f1) < fabs(f0))) {
    iso->lo = iso->hi;
    iso->f_lo = f1; /* zero or of the sign before the root: what the hit's side is read from */
  }
}

/* p is P*(s) in the power basis, the extent interval being s in [s0, s0 + len_s]. The sequence is built once,
 * on A1 over the whole interval; then the dyadic (level, idx) pieces of [0, 1] are visited depth first, left
 * first, each needing the sequence at its right end only: its left end is its parent's, or the right end of
 * the interval examined before it. On return `a1` is A1 on [lo, hi]. */
static Isolation isolate_sturm(const REAL* p, REAL s0, REAL len_s, REAL t_in, REAL t_out, REAL* a1,
                               ProbeLog* probe_log) {
  Isolation iso = isolation_none();
  const REAL len = t_out - t_in;
  power_on_interval(p, s0, len_s, a1);
  if (a1[0] == 0) { /* also a polynomial that vanishes along the whole ray */
    iso.steps = 1;
    iso.status = ISOLATION_EXACT;
    iso.f_hi = power_value(a1, (REAL)1);
    PROBE_STEP(iso, -1, ALGRAY_STEP_EXACT_ZERO, 0);
    return iso;
  }
  REAL seq[STURM_STORE];
  if (!sturm_sequence_generic(a1, seq)) sturm_sequence(a1, seq);
  REAL f_lo, noise_lo;
  int v_lo = sturm_variations(seq, (REAL)0, &f_lo, &noise_lo);
  const int start_sign = (f_lo > 0) - (f_lo < 0);
  int level = 0;
  ulong idx = 0;

  for (;;) {
    ++iso.steps;
    const REAL width = ldexp((REAL)1, -level);
    iso.lo = (REAL)idx * width;
    iso.hi = iso.lo + width;
    REAL f_hi, noise_hi;
    const int v_hi = sturm_variations(seq, iso.hi, &f_hi, &noise_hi);
    iso.f_lo = f_lo;
    iso.f_hi = f_hi;
    if (settled_at_left_end(&iso, start_sign, level, probe_log)) return iso;
    /* Distinct roots in (lo, hi): the count is of (lo, hi], and a root exactly at hi belongs to the next
     * interval, which finds it as an exact zero at its left end. */
    const int roots = v_lo - v_hi - (f_hi == 0);
    const int crosses = f_hi != 0 && (f_lo < 0) != (f_hi < 0);
    /* An end value within its rounding error has a sign the counts agree with but the root does not: a root
     * that close to the end may be on either side of it, and may be a second one (measured: a pair 2^-20
     * apart, the larger one 2.5e-11 below a dyadic point, bracketed together, refined to the larger). */
    const int clear = fabs(f_lo) > noise_lo && fabs(f_hi) > noise_hi;
    if (roots == 1 && crosses && clear) {
      PROBE_STEP(iso, roots, ALGRAY_STEP_ISOLATED, level);
      sturm_bracket(&iso, a1);
      return iso;
    }
    /* Several roots; or one without a sign change, a root of even multiplicity or two the gcd merged; or a
     * count that rounding made disagree with the signs (negative, or none across a sign change); or an end
     * too close to a root to tell; or an exact zero at hi, where the count skips S0 and so credits the root
     * there with what may be a second root just before it (measured: the smaller of a pair 2^-20 apart,
     * lost): only halving sorts these out. */
    if (roots != 0 || crosses || f_hi == 0) {
      const int next = halve_or_settle(&iso, roots, level, width, t_in, len, probe_log);
      if (next == INTERVAL_HALVE) {
        ++level;
        idx *= 2;
        continue;
      }
      if (next == INTERVAL_SETTLED) {
        sturm_bracket(&iso, a1);
        return iso;
      }
    } else {
      PROBE_STEP(iso, roots, ALGRAY_STEP_NO_ROOT, level);
    }
    if (!next_interval(&level, &idx)) {
      /* Intervals are half open; the far end is the one point left to look at. A root within rounding of it
       * may have come out just outside, where the counts, reading the same value, agree: it is numerically
       * at 1. */
      return isolation_at_far_end(iso, fabs(f_hi) <= noise_hi, f_hi, probe_log);
    }
    f_lo = f_hi;
    noise_lo = noise_hi;
    v_lo = v_hi;
  }
}

/* The method's entry (isolate.h): P*(s) in the power basis as power_s0 and power_len_s place it. */
static Isolation isolate_method(REAL* root, REAL* root_lo, REAL t_in, REAL t_out, REAL* iso_c, RayTerms* terms,
                                ProbeLog* probe_log) {
  (void)root_lo;
  (void)terms;
  return isolate_sturm(root, power_s0(t_in), power_len_s(t_in, t_out), t_in, t_out, iso_c, probe_log);
}

#endif /* ALGRAY_STURM_H */
