/* The root-isolation method this build is specialised for (-D ISOLATION=...), and the refinement after it. */
#ifndef ALGRAY_ISOLATE_H
#define ALGRAY_ISOLATE_H

#include "algray_shared.h"

/* Bernstein isolation works on P*(s) in the Bernstein basis of the segment; the others in its power basis, and
 * name their entry point isolate_power_basis(p, s0, len_s, t_in, t_out, a1) (see power_descartes.h). Each
 * provides prepare_isolated, isolated_value, isolated_value_slope and isolated_magnitude for refine.h. */
#if ISOLATION == ALGRAY_ISOLATION_BERNSTEIN
#include "bernstein.h"
#elif ISOLATION == ALGRAY_ISOLATION_POWER
#include "power_descartes.h"
#elif ISOLATION == ALGRAY_ISOLATION_STURM
#include "sturm.h"
#elif ISOLATION == ALGRAY_ISOLATION_DERIVATIVE_CHAIN
#include "derivative_chain.h"
#else
#error "ISOLATION must name an isolation method"
#endif
#include "refine.h"

#endif /* ALGRAY_ISOLATE_H */
