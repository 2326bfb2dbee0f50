/* The paper's root isolation: power basis mapped to (0, inf), Descartes' rule of signs, left half first. */
#ifndef ALGRAY_POWER_DESCARTES_H
#define ALGRAY_POWER_DESCARTES_H

#include "methods/power_basis.h"

/* Sign variations of A2(x) = (x+1)^n A1(1/(x+1)), whose positive roots are those of A1 in (0, 1]...
 * except a root at 1, which maps to x = 0 and is not counted. */
static int descartes_unit_interval(const REAL* a1) {
  REAL a2[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) a2[k] = a1[DEGREE - k];
  taylor_shift(a2, (REAL)1);
  return sign_variations(a2);
}

/* p is P*(s) in the power basis, the extent interval being s in [s0, s0 + len_s]. Subintervals are the dyadic
 * (level, idx) pieces of that interval, visited depth first, left first. On return `a1` is A1 on [lo, hi]. */
static Isolation isolate_power(const REAL* p, REAL s0, REAL len_s, REAL t_in, REAL t_out, REAL* a1,
                               ProbeLog* probe_log) {
  Isolation iso = isolation_none();
  int level = 0;
  ulong idx = 0;
  const REAL len = t_out - t_in;
  int start_sign = 0; /* of P at t_in, set at the first interval */

  for (;;) {
    ++iso.steps;
    const REAL width = ldexp((REAL)1, -level);
    iso.lo = (REAL)idx * width;
    iso.hi = iso.lo + width;
    power_on_interval(p, s0 + iso.lo * len_s, width * len_s, a1);
    iso.f_lo = a1[0];
    iso.f_hi = power_value(a1, (REAL)1);
    if (iso.steps == 1) start_sign = (a1[0] > 0) - (a1[0] < 0);
    if (settled_at_left_end(&iso, start_sign, level, probe_log)) return iso;
    const int v = descartes_unit_interval(a1);
    if (v == 1 && iso.f_hi != 0) {
      PROBE_STEP(iso, v, ALGRAY_STEP_ISOLATED, level);
      iso.status = ISOLATION_BRACKET;
      return iso;
    }
    /* v counts roots in (lo, hi); a root exactly at hi is found as the right neighbour's EXACT case. */
    if (v >= 1) {
      const int next = halve_or_settle(&iso, v, level, width, t_in, len, probe_log);
      if (next == INTERVAL_HALVE) {
        ++level;
        idx *= 2;
        continue;
      }
      if (next == INTERVAL_SETTLED) return iso;
    } else {
      PROBE_STEP(iso, v, ALGRAY_STEP_NO_ROOT, level);
    }
    /* The last interval visited is the rightmost one, so its f_hi is P at the far end. */
    if (!next_interval(&level, &idx)) return isolation_at_far_end(iso, iso.f_hi == 0, iso.f_hi, probe_log);
  }
}

/* The method's entry (isolate.h): P*(s) in the power basis as power_s0 and power_len_s place it. */
static Isolation isolate_method(REAL* root, REAL* root_lo, REAL t_in, REAL t_out, REAL* iso_c, RayTerms* terms,
                                ProbeLog* probe_log) {
  (void)root_lo;
  (void)terms;
  return isolate_power(root, power_s0(t_in), power_len_s(t_in, t_out), t_in, t_out, iso_c, probe_log);
}

#endif /* ALGRAY_POWER_DESCARTES_H */
