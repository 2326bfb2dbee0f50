/* The working precision REAL of a kernel build (-D ALGRAY_DOUBLE=1 selects double) and its constants. */
#ifndef ALGRAY_REAL_H
#define ALGRAY_REAL_H

#include "build_switches.h"

#if ALGRAY_DOUBLE
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double REAL;
typedef double2 REAL2;
typedef double3 REAL3;
typedef double4 REAL4;
typedef double8 REAL8;
typedef double16 REAL16;
#define REAL_EPS DBL_EPSILON
#define REAL_MAX DBL_MAX
#define REAL_MAX_HALVINGS 52   /* dyadic subintervals of [0,1] stay exact down to this level */
#define FINEST_UNITS (1L << REAL_MAX_HALVINGS) /* the finest subintervals in [0, 1]; an integer of LANE_INT */
#else
typedef float REAL;
typedef float2 REAL2;
typedef float3 REAL3;
typedef float4 REAL4;
typedef float8 REAL8;
typedef float16 REAL16;
#define REAL_EPS FLT_EPSILON
#define REAL_MAX FLT_MAX
#define REAL_MAX_HALVINGS 23
#define FINEST_UNITS (1 << REAL_MAX_HALVINGS)
#endif

/* The kernel is specialised by degree; everything sized by it lives in private arrays. */
#define NCOEF (DEGREE + 1)

/* The polynomial loops run over DEGREE + 1 coefficients, a compile-time constant: fully unrolled and inlined
 * they keep the coefficients in registers (measured: 30% fewer instructions in the restriction). */
#define ALGRAY_UNROLL _Pragma("unroll")
/* Every helper is static: a program's module then holds only what its kernels call, and PoCL, which reads the whole
 * module back on every load of a cached binary, loads a render's programs about 35% faster (bench/history/2026-12.md,
 * "Static kernel helpers"). */
#define ALGRAY_INLINE static inline __attribute__((always_inline))
/* Kept out of line: large bodies whose every call inlined made the degree-16 shadow kernel 18% slower (static
 * functions with one caller are inlined by default; bench/history/2026-12.md, "Static kernel helpers"). */
#define ALGRAY_NOINLINE __attribute__((noinline))

/* The paper's stopping width: a root is located once its bracket is at most 4*eps*max(|t|, 1) wide in t; of one t
 * or of lanes (lanes.h). */
#define STOP_WIDTH(t) ((REAL)4 * (REAL)TOLERANCE * fmax(fabs(t), (REAL)1))
static REAL stop_width(REAL t) { return STOP_WIDTH(t); }

#endif /* ALGRAY_REAL_H */
