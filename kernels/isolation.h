/* What every root-isolation method returns, and the sign-variation count they share. */
#ifndef ALGRAY_ISOLATION_H
#define ALGRAY_ISOLATION_H

#include "real.h"
#include "restrict.h"

#define ISOLATION_NONE 0     /* certified: no root in [t_in, t_out] (up to the tolerance) */
#define ISOLATION_BRACKET 1  /* one root (or an odd cluster) bracketed by a sign change on [lo, hi] */
#define ISOLATION_EXACT 2    /* the polynomial is exactly zero at lo */
#define ISOLATION_TANGENT 3  /* no sign change, but |P| within noise on a tolerance-wide interval */

/* lo, hi are fractions of [t_in, t_out]; f_lo, f_hi the polynomial's values there in the method's scaling. */
typedef struct {
  int status;
  int budget;  /* 1 when some interval hit the halving limit before reaching the tolerance */
  uint steps;  /* intervals examined */
  REAL lo, hi;
  REAL f_lo, f_hi;
} Isolation;

Isolation isolation_none(void) {
  Isolation iso;
  iso.status = ISOLATION_NONE;
  iso.budget = 0;
  iso.steps = 0;
  iso.lo = 0;
  iso.hi = 1;
  iso.f_lo = 0;
  iso.f_hi = 0;
  return iso;
}

Isolation iso_finish_none(Isolation iso) {
  iso.status = ISOLATION_NONE;
  return iso;
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
