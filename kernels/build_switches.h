/* Every -D switch of a kernel build, declared once: its default, its legal values and what it means. */
#ifndef ALGRAY_BUILD_SWITCHES_H
#define ALGRAY_BUILD_SWITCHES_H

#include "algray_shared.h"

/* ---- From the host. KernelConfig::build_options (src/algray/device/kernel_config.cpp) writes every one of these,
 * from its table kBuildSwitches, on every build; the defaults serve a kernel compiled by hand. test_config holds
 * the two lists to each other. */

/* The surface's degree, 1..32: every array and loop sized by it is fixed at build time. */
#ifndef DEGREE
#error "DEGREE must be defined (-D DEGREE=n, 1..32)"
#endif
#if DEGREE < 1 || DEGREE > 32
#error "DEGREE must be 1..32"
#endif

/* The working precision, at most one of the three set (real.h): 0/1 each.
 * ALGRAY_DOUBLE: double. ALGRAY_COMPENSATED: float, but P*(t) built in compensated (float-float) arithmetic (mixed
 * precision). ALGRAY_ESCALATE: float that marks the rays it cannot decide (adaptive precision; isolation.h).
 * None: plain float. */
#ifndef ALGRAY_DOUBLE
#define ALGRAY_DOUBLE 0
#endif
#ifndef ALGRAY_COMPENSATED
#define ALGRAY_COMPENSATED 0
#endif
#ifndef ALGRAY_ESCALATE
#define ALGRAY_ESCALATE 0
#endif
#if ALGRAY_DOUBLE + ALGRAY_COMPENSATED + ALGRAY_ESCALATE > 1
#error "at most one of ALGRAY_DOUBLE, ALGRAY_COMPENSATED and ALGRAY_ESCALATE"
#endif

/* The root isolation method, one of ALGRAY_ISOLATION_* (algray_shared.h). */
#ifndef ISOLATION
#define ISOLATION ALGRAY_ISOLATION_BERNSTEIN
#endif
#if ISOLATION < ALGRAY_ISOLATION_BERNSTEIN || ISOLATION > ALGRAY_ISOLATION_LAST
#error "ISOLATION must be one of ALGRAY_ISOLATION_*"
#endif

/* What the isolation method can do, 0/1 each, from its row of the host's one table of abilities
 * (kIsolationAbilities, src/algray/scene/solver_options.h), so that the kernels name abilities and never a method.
 * Required, like DEGREE: a default here would be a second copy of that table.
 * ISOLATION_POWER_BASIS: it isolates in the power basis (else Bernstein's, on the segment).
 * ISOLATION_ADAPTIVE: it doubts what float cannot decide (adaptive precision).
 * ISOLATION_POINT_FORM: shadow rays can be built in the point form.
 * SOLVER_LANES: the isolation and the refinement have lane builds (LANES > 1). */
#if !defined(ISOLATION_POWER_BASIS) || !defined(ISOLATION_ADAPTIVE) || !defined(ISOLATION_POINT_FORM) || \
    !defined(SOLVER_LANES)
#error "ISOLATION_POWER_BASIS, ISOLATION_ADAPTIVE, ISOLATION_POINT_FORM and SOLVER_LANES must be defined (-D ...=0/1)"
#endif

/* The root refinement method, one of ALGRAY_REFINEMENT_* (algray_shared.h). */
#ifndef REFINEMENT
#define REFINEMENT ALGRAY_REFINEMENT_BRENT
#endif
#if REFINEMENT < ALGRAY_REFINEMENT_BRENT || REFINEMENT > ALGRAY_REFINEMENT_NEWTON
#error "REFINEMENT must be one of ALGRAY_REFINEMENT_*"
#endif

/* Where P*(t) is built around, one of ALGRAY_ORIGIN_* (algray_shared.h). */
#ifndef RAY_ORIGIN
#define RAY_ORIGIN ALGRAY_ORIGIN_EXTENT
#endif
#if RAY_ORIGIN < ALGRAY_ORIGIN_EXTENT || RAY_ORIGIN > ALGRAY_ORIGIN_POINT
#error "RAY_ORIGIN must be one of ALGRAY_ORIGIN_*"
#endif

/* The refinement's stopping width (the paper's eps, refine.h) and its iteration cap. */
#ifndef TOLERANCE
#define TOLERANCE 1e-9
#endif
#ifndef MAX_ITERATIONS
#define MAX_ITERATIONS 100
#endif

/* Rays per work-item, side by side in vector lanes (lanes.h): 1, 2, 4, 8 or 16. */
#ifndef LANES
#define LANES 1
#endif
#if LANES != 1 && LANES != 2 && LANES != 4 && LANES != 8 && LANES != 16
#error "LANES must be 1, 2, 4, 8 or 16"
#endif

/* Adaptive builds only, 0/1: the float pass settles more of what it would doubt, where the second pass runs in
 * float-float or float (KernelConfig::settle_doubts): the extent form's shadow kernels by within_noise_at
 * (isolation.h) and sampled_sign_change (shadow.h), the point form's by searching its doubted rays again
 * (shadow.h, point_part_polys), the others by discards_settled (methods/bernstein.h). */
#ifndef ALGRAY_SETTLE_DOUBTS
#define ALGRAY_SETTLE_DOUBTS 0
#endif

/* The extent form's shadow kernels: 0, or how many rays one vector register holds in the kernel's precision, which
 * it then restricts side by side in the lanes of one vector per coefficient (restrict.h; KernelConfig's
 * shadow_batch, which the plan sets for devices that fuse multiply-adds). */
#ifndef ALGRAY_SHADOW_BATCH
#define ALGRAY_SHADOW_BATCH 0
#endif

/* ALGRAY_DEVICE_COPY=n (ProgramCache, for the n-th device of one name and driver in a process) is read by no
 * kernel: it only makes that device's program differ from the first one's (cl_runtime.h says why). */

/* ---- From the entry file (*.cl), defined before its includes. */

/* 1 in probe.cl: the solver's hooks record each step into the probe's log (probe_log.h); 0 compiles them away. */
#ifndef ALGRAY_PROBE
#define ALGRAY_PROBE 0
#endif

/* 1 in the shadow kernels: rays that start off the surface on purpose and ask only whether there is a root
 * (isolation.h, first_counted). */
#ifndef ALGRAY_SHADOW_RAYS
#define ALGRAY_SHADOW_RAYS 0
#endif

/* How many rays restrict_to_rays expands side by side (restrict.h); shadow.cl takes the width that measured
 * fastest for its degree. */
#ifndef RESTRICT_RAYS
#define RESTRICT_RAYS 1
#endif

/* ---- Measured constants, switches only for experiments (isolation.h says how each was chosen). */

/* Adaptive precision's noise for a coefficient: ALGRAY_DOUBT_FACTOR times the coefficients' rounding, plus
 * ALGRAY_TERMS_FACTOR times that of the terms they were summed from (DOUBT_NOISE). */
#ifndef ALGRAY_DOUBT_FACTOR
#define ALGRAY_DOUBT_FACTOR 0.5f
#endif
#ifndef ALGRAY_TERMS_FACTOR
#define ALGRAY_TERMS_FACTOR 0.25f
#endif
/* The screen form's terms (surface.h, screen_terms) count this many times the extent construction's in the noise:
 * its coefficients come through two Horner chains, in the column and then along the ray, where the extent
 * construction's come through one. */
#ifndef ALGRAY_SCREEN_TERMS_WEIGHT
#define ALGRAY_SCREEN_TERMS_WEIGHT 2
#endif
/* The noise local to an interval of a shadow ray, this many times (local_noise). */
#ifndef ALGRAY_LOCAL_FACTOR
#define ALGRAY_LOCAL_FACTOR 4
#endif

#endif
