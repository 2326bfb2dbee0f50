/* The interface every root-isolation method implements, the method this build is specialised for (-D ISOLATION=...),
 * and the refinement after it. */
#ifndef ALGRAY_ISOLATE_H
#define ALGRAY_ISOLATE_H

#include "algray_shared.h"
#include "isolation.h"
#include "lanes.h"
#include "probe_log.h"
#include "real.h"
#include "restrict.h"

/* An isolation method is one file in kernels/methods/ that defines the functions declared here; the declarations
 * make the compiler hold each method to them. */

/* The smallest root of P*(t) on [t_in, t_out], from the coefficients the restriction left in the method's basis
 * (root, with root_lo the low parts in mixed precision; both may be consumed). iso_c gets the polynomial on the
 * isolating interval, in the form the functions below take after prepare_isolated. terms: the ray's terms, which
 * adaptive builds measure their noise by (restrict.h); unread elsewhere. */
static Isolation isolate_method(REAL* root, REAL* root_lo, REAL t_in, REAL t_out, REAL* iso_c, RayTerms* terms,
                                ProbeLog* probe_log);
/* For the refinement (refine.h), of one ray or of lanes, on the isolating interval y in [0, 1]: a first estimate of
 * the root, or -1 for none; the coefficients made ready for the others; P's value, its value and slope, and the
 * size of the terms its value sums (whose rounding the value carries). */
static LREAL isolated_start(const LREAL* c);
static void prepare_isolated(LREAL* c, __constant const REAL* binomials);
static LREAL isolated_value(const LREAL* c, LREAL y);
static LREAL isolated_value_slope(const LREAL* c, LREAL y, LREAL* slope);
static LREAL isolated_magnitude(const LREAL* c, LREAL y);

#if ISOLATION == ALGRAY_ISOLATION_BERNSTEIN
#include "methods/bernstein.h"
#elif ISOLATION == ALGRAY_ISOLATION_POWER
#include "methods/power_descartes.h"
#elif ISOLATION == ALGRAY_ISOLATION_STURM
#include "methods/sturm.h"
#elif ISOLATION == ALGRAY_ISOLATION_DERIVATIVE_CHAIN
#include "methods/derivative_chain.h"
#endif
#include "refine.h"

#endif /* ALGRAY_ISOLATE_H */
