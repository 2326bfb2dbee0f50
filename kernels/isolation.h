/* What every root-isolation method returns, and the sign-variation count they share. */
#ifndef ALGRAY_ISOLATION_H
#define ALGRAY_ISOLATION_H

#include "probe_log.h"
#include "real.h"
#include "restrict.h"

#define ISOLATION_NONE ALGRAY_ISOLATED_NONE
#define ISOLATION_BRACKET ALGRAY_ISOLATED_BRACKET
#define ISOLATION_EXACT ALGRAY_ISOLATED_EXACT

/* lo, hi are fractions of [t_in, t_out]; f_lo, f_hi the polynomial's values there in the method's scaling. */
typedef struct {
  int status;
  int budget;  /* 1 when some interval hit the halving limit before reaching the tolerance */
  int cluster; /* 1 when the bracket is an interval that still held several roots (settle_cluster) */
  uint steps;  /* intervals examined */
  REAL lo, hi;
  REAL f_lo, f_hi;
} Isolation;

Isolation isolation_none(void) {
  Isolation iso;
  iso.status = ISOLATION_NONE;
  iso.budget = 0;
  iso.cluster = 0;
  iso.steps = 0;
  iso.lo = 0;
  iso.hi = 1;
  iso.f_lo = 0;
  iso.f_hi = 0;
  return iso;
}

/* Whether an interval `width` (a fraction of [t_in, t_out], starting at fraction lo) is down to the stopping
 * width: then it is located, however many roots Descartes' rule still allows in it. */
int interval_located(REAL width, REAL lo, REAL t_in, REAL len) { return width * len <= stop_width(t_in + lo * len); }

/* An interval still holding several roots, or a complex pair, once it is located or at the halving limit: a
 * sign change between its ends is a root; without one it counts as no root. So a root of even multiplicity is
 * invisible, as on the true surface (an isolated point, a tangent ray), and a rounded double root that became
 * a complex pair is never reported. Returns 1 when it settled iso->status. */
int settle_cluster(Isolation* iso, int located) {
  if (!located) iso->budget = 1;
  if ((iso->f_lo < 0) != (iso->f_hi < 0)) {
    iso->status = ISOLATION_BRACKET;
    iso->cluster = 1;
    return 1;
  }
  return 0;
}

/* Every interval before this one was root-free or without a sign change, so P should still have the sign it had
 * at t_in. If this interval starts with the other sign, P changed sign where two subdivisions meet, within
 * their rounding noise: that point is the root. Returns 1 when it settled iso->status. */
int crossed_at_left_end(Isolation* iso, int start_sign) {
  const int s = (iso->f_lo > 0) - (iso->f_lo < 0);
  if (s == 0 || s == start_sign) return 0;
  iso->status = ISOLATION_EXACT;
  return 1;
}

/* The checks every subdividing method makes first on an interval (iso.lo, iso.f_lo set): P exactly zero at its
 * left end, or of the other sign there than at t_in. Returns 1 when it settled iso->status. */
int settled_at_left_end(Isolation* iso, int start_sign, int level PROBE_PARAM) {
  if (iso->f_lo == 0) {
    PROBE_STEP(*iso, -1, ALGRAY_STEP_EXACT_ZERO, level);
    iso->status = ISOLATION_EXACT;
    return 1;
  }
  if (crossed_at_left_end(iso, start_sign)) {
    PROBE_STEP(*iso, -1, ALGRAY_STEP_CROSSED, level);
    return 1;
  }
  return 0;
}

/* What to do with an interval that may hold several roots (`count` of them, as the method counts). */
#define INTERVAL_HALVE 0   /* halve it: go one level down, left half first */
#define INTERVAL_SETTLED 1 /* a cluster with a sign change: iso->status is set */
#define INTERVAL_NEXT 2    /* a cluster without one: go on to the next interval */
int halve_or_settle(Isolation* iso, int count, int level, REAL width, REAL t_in, REAL len PROBE_PARAM) {
  const int located = interval_located(width, iso->lo, t_in, len);
  if (!located && level < REAL_MAX_HALVINGS) {
    PROBE_STEP(*iso, count, ALGRAY_STEP_SPLIT, level);
    return INTERVAL_HALVE;
  }
  if (settle_cluster(iso, located)) {
    PROBE_STEP(*iso, count, ALGRAY_STEP_CLUSTER_ROOT, level);
    return INTERVAL_SETTLED;
  }
  PROBE_STEP(*iso, count, ALGRAY_STEP_CLUSTER_SKIP, level);
  return INTERVAL_NEXT;
}

/* Every interval has been searched. They are half open, so the far end is the one point left: a root when
 * `zero` (P there is f_end). */
Isolation isolation_at_far_end(Isolation iso, int zero, REAL f_end PROBE_PARAM) {
  iso.status = zero ? ISOLATION_EXACT : ISOLATION_NONE;
  PROBE(ALGRAY_EVENT_STEP, -1, zero ? ALGRAY_STEP_END_ZERO : ALGRAY_STEP_END_NONE, 0u, (REAL)1, (REAL)1, f_end, f_end);
  iso.lo = iso.hi = 1;
  iso.f_lo = iso.f_hi = 0;
  return iso;
}

/* The next dyadic interval (level, idx) in depth-first, left-first order: climb while a right child, then
 * step right. Returns 0 when the whole interval has been searched. */
int next_interval(int* level, ulong* idx) {
  while (*idx & 1) {
    *idx >>= 1;
    --*level;
  }
  if (*level == 0) return 0;
  ++*idx;
  return 1;
}

/* Sign changes between consecutive nonzero coefficients. Branch-free: a zero keeps the previous sign, and a
 * change is a product of signs below zero (the first nonzero sign never counts, as prev starts at 0). */
int sign_variations(const REAL* c) {
  int v = 0;
  int prev = 0; /* sign of the last nonzero coefficient, 0 before the first */
  ALGRAY_UNROLL
  for (int k = 0; k <= DEGREE; ++k) {
    const int s = (c[k] > 0) - (c[k] < 0);
    v += s * prev < 0;
    prev = s != 0 ? s : prev;
  }
  return v;
}

#endif /* ALGRAY_ISOLATION_H */
