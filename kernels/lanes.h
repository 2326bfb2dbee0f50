/* Lanes: LANES rays side by side in one work-item's vector registers (-D LANES=n), and the scalar case n = 1. */
#ifndef ALGRAY_LANES_H
#define ALGRAY_LANES_H

#include "real.h"

/* PoCL runs a CPU work-group's work-items one after another, and the solver's loops keep its vectoriser from
 * merging them, so each ray's divisions and Horner chains wait on one another. Code written over LREAL runs
 * LANES rays at once instead: every lane takes the same steps, a lane that has finished keeps its state
 * through LANE_SEL, and a loop ends when every lane has. Each lane's arithmetic is one ray's, operation for
 * operation, so a lane's result is the LANES = 1 build's bit for bit (tests/test_lanes). With LANES = 1 the same
 * code is the one-ray build: GPUs, the probe, and the other kernels.
 *
 * LMASK is what a comparison of LREALs gives: 0 or 1 for scalars, 0 or -1 (all bits) per lane for vectors. So
 * masks combine with !, && and ||, never ~, and count with LANE_SEL((LMASK)0, (LMASK)1, m). */
#if LANES == 1
typedef REAL LREAL;
typedef int LMASK;
typedef int LANE_INT;     /* one lane's integer */
typedef int LANE_INT_VEC; /* integers per lane */
#define LANE_TO_INT(x) ((LANE_INT)(x))
#define LANE_TO_REAL(x) ((REAL)(x))
#define LANE_SEL(a, b, m) ((m) ? (b) : (a))
#define LANE_ANY(m) (m)
#define LANE_ALL(m) (m)
#define LANES_OF(T, f) ((T)(f(0)))
#define LANES_STORE(v, a) ((a)[0] = (v))
#define LANES_LOAD(a) ((a)[0])

ALGRAY_INLINE uint lane_mask_bits(LMASK m) { return m != 0; }
ALGRAY_INLINE LMASK lanes_of_bits(uint bits) { return (bits & 1u) != 0; }
ALGRAY_INLINE long lane_get_mask(LMASK m, uint j) {
  (void)j;
  return m;
}
ALGRAY_INLINE void lane_set_mask(LMASK* m, uint j, int on) {
  (void)j;
  *m = on != 0;
}

#else /* 2, 4, 8 or 16 lanes (build_switches.h) */
#define LANE_CAT(a, b) a##b
#define LANE_VEC(type, n) LANE_CAT(type, n)
#if ALGRAY_DOUBLE
#define LANE_INT_NAME long /* one lane of a mask: as wide as a REAL */
#define LANE_REAL_NAME double
#else
#define LANE_INT_NAME int
#define LANE_REAL_NAME float
#endif
typedef LANE_VEC(REAL, LANES) LREAL; /* REAL8 for LANES = 8 (real.h) */
typedef LANE_INT_NAME LANE_INT;
typedef LANE_VEC(LANE_INT_NAME, LANES) LMASK;
typedef LANE_VEC(LANE_INT_NAME, LANES) LANE_INT_VEC; /* integers per lane, as wide as a REAL */
/* Lanes converted between REAL and integers (toward zero): convert_long8 and convert_double8 for LANES = 8 */
#define LANE_TO_INT(x) LANE_VEC(LANE_VEC(convert_, LANE_INT_NAME), LANES)(x)
#define LANE_TO_REAL(x) LANE_VEC(LANE_VEC(convert_, LANE_REAL_NAME), LANES)(x)
#define LANE_SEL(a, b, m) select((a), (b), (m))
#define LANE_ANY(m) (lane_or(m) != 0)
#define LANE_ALL(m) (lane_or(!(m)) == 0)

/* The vector of type T holding f(0), f(1), ..., f(LANES - 1), built in registers (lane_set goes through memory,
 * and a vector read after scalar stores stalls on them). */
#if LANES == 2
#define LANES_OF(T, f) ((T)(f(0), f(1)))
#elif LANES == 4
#define LANES_OF(T, f) ((T)(f(0), f(1), f(2), f(3)))
#elif LANES == 8
#define LANES_OF(T, f) ((T)(f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7)))
#else
#define LANES_OF(T, f) \
  ((T)(f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7), f(8), f(9), f(10), f(11), f(12), f(13), f(14), f(15)))
#endif

/* The lanes of v or'ed together, the halves folded down to one lane. PoCL's any() tests each 128-bit part's
 * sign bits in turn, branching after each; in the search's loop that was a fifth of its samples
 * (bench/RESULTS.md). */
ALGRAY_INLINE LANE_INT lane_or(LANE_INT_VEC v) {
#if LANES == 16
  const LANE_VEC(LANE_INT_NAME, 8) v8 = v.lo | v.hi;
#elif LANES == 8
  const LANE_VEC(LANE_INT_NAME, 8) v8 = v;
#endif
#if LANES >= 8
  const LANE_VEC(LANE_INT_NAME, 4) v4 = v8.lo | v8.hi;
#elif LANES == 4
  const LANE_VEC(LANE_INT_NAME, 4) v4 = v;
#endif
#if LANES >= 4
  const LANE_VEC(LANE_INT_NAME, 2) v2 = v4.lo | v4.hi;
#else
  const LANE_VEC(LANE_INT_NAME, 2) v2 = v;
#endif
  return v2.s0 | v2.s1;
}

#define LANE_BIT(j) (1 << (j))
/* Bit j set for each lane j of m that is set, without a trip through memory: each lane keeps its own bit. */
ALGRAY_INLINE uint lane_mask_bits(LMASK m) { return (uint)lane_or(m & LANES_OF(LANE_INT_VEC, LANE_BIT)); }
/* Lane j set where bit j of bits is. */
ALGRAY_INLINE LMASK lanes_of_bits(uint bits) {
  return ((LANE_INT_VEC)((LANE_INT)bits) & LANES_OF(LANE_INT_VEC, LANE_BIT)) != 0;
}
#undef LANE_BIT

/* The lanes of v into a[0 .. LANES), in one store: reading many lanes of a vector one by one (lane_get) stored
 * the whole vector again for each, and the loads waited on the stores (measured: a fifth of
 * the lanes' Bernstein search in the Barth sextic's double preview). */
#define LANES_STORE(v, a) LANE_VEC(vstore, LANES)((v), 0, (a))
#define LANES_LOAD(a) LANE_VEC(vload, LANES)(0, (a)) /* a[0 .. LANES) as one vector */

ALGRAY_INLINE long lane_get_mask(LMASK m, uint j) { return ((LANE_INT*)&m)[j]; }
ALGRAY_INLINE void lane_set_mask(LMASK* m, uint j, int on) { ((LANE_INT*)m)[j] = on ? -1 : 0; }
#endif

/* Lane j of a vector (j < LANES), read and written through its private storage. */
ALGRAY_INLINE REAL lane_get(LREAL v, uint j) { return ((REAL*)&v)[j]; }
ALGRAY_INLINE void lane_set(LREAL* v, uint j, REAL x) { ((REAL*)v)[j] = x; }

#endif /* ALGRAY_LANES_H */
