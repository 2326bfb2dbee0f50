/* The paper's root isolation: power basis mapped to (0, inf), Descartes' rule of signs, left half first. */
#ifndef ALGRAY_POWER_DESCARTES_H
#define ALGRAY_POWER_DESCARTES_H

#include "power_basis.h"

/* Sign variations of A2(x) = (x+1)^n A1(1/(x+1)), whose positive roots are those of A1 in (0, 1]...
 * except a root at 1, which maps to x = 0 and is not counted. */
int descartes_unit_interval(const REAL* a1) {
  REAL a2[NCOEF];
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) a2[k] = a1[DEGREE - k];
  taylor_shift(a2, (REAL)1);
  return sign_variations(a2);
}

/* p is P*(s) in the power basis, the extent interval being s in [s0, s0 + len_s]. Subintervals are the dyadic
 * (level, idx) pieces of that interval, visited depth first, left first. On return `a1` is A1 on [lo, hi]. */
Isolation isolate_power(const REAL* p, REAL s0, REAL len_s, REAL t_in, REAL t_out, REAL* a1 PROBE_PARAM) {
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
    if (a1[0] == 0) {
      PROBE_STEP(iso, -1, ALGRAY_STEP_EXACT_ZERO, level);
      iso.status = ISOLATION_EXACT;
      return iso;
    }
    if (iso.steps == 1) start_sign = (a1[0] > 0) - (a1[0] < 0);
    if (crossed_at_left_end(&iso, start_sign)) {
      PROBE_STEP(iso, -1, ALGRAY_STEP_CROSSED, level);
      return iso;
    }
    const int v = descartes_unit_interval(a1);
    if (v == 1 && iso.f_hi != 0) {
      PROBE_STEP(iso, v, ALGRAY_STEP_ISOLATED, level);
      iso.status = ISOLATION_BRACKET;
      return iso;
    }
    /* v counts roots in (lo, hi); a root exactly at hi is found as the right neighbour's EXACT case. */
    if (v >= 1) {
      const int located = interval_located(width, iso.lo, t_in, len);
      if (!located && level < REAL_MAX_HALVINGS) {
        PROBE_STEP(iso, v, ALGRAY_STEP_SPLIT, level);
        ++level;
        idx *= 2;
        continue;
      }
      if (settle_cluster(&iso, located)) {
        PROBE_STEP(iso, v, ALGRAY_STEP_CLUSTER_ROOT, level);
        return iso;
      }
      PROBE_STEP(iso, v, ALGRAY_STEP_CLUSTER_SKIP, level);
    } else {
      PROBE_STEP(iso, v, ALGRAY_STEP_NO_ROOT, level);
    }
    if (!next_interval(&level, &idx)) {
      /* The last interval visited is the rightmost one: a root exactly at its far end is the one point left. */
      iso.status = iso.f_hi == 0 ? ISOLATION_EXACT : ISOLATION_NONE;
      PROBE(ALGRAY_EVENT_STEP, -1, iso.status == ISOLATION_EXACT ? ALGRAY_STEP_END_ZERO : ALGRAY_STEP_END_NONE, 0u,
            (REAL)1, (REAL)1, iso.f_hi, iso.f_hi);
      iso.lo = iso.hi = 1;
      iso.f_lo = iso.f_hi = 0;
      return iso;
    }
  }
}

#define isolate_power_basis isolate_power

#endif /* ALGRAY_POWER_DESCARTES_H */
