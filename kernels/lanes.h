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
#elif LANES == 2 || LANES == 4 || LANES == 8 || LANES == 16
#define LANE_CAT(a, b) a##b
#define LANE_VEC(type, n) LANE_CAT(type, n)
typedef LANE_VEC(REAL, LANES) LREAL; /* REAL8 for LANES = 8 (real.h) */
#if ALGRAY_DOUBLE
#define LANE_INT_NAME long /* one lane of a mask: as wide as a REAL */
#else
#define LANE_INT_NAME int
#endif
#if ALGRAY_DOUBLE
#define LANE_REAL_NAME double
#else
#define LANE_REAL_NAME float
#endif
typedef LANE_INT_NAME LANE_INT;
typedef LANE_VEC(LANE_INT_NAME, LANES) LMASK;
typedef LANE_VEC(LANE_INT_NAME, LANES) LANE_INT_VEC; /* integers per lane, as wide as a REAL */
/* Lanes converted between REAL and integers (toward zero): convert_long8 and convert_double8 for LANES = 8 */
#define LANE_TO_INT(x) LANE_VEC(LANE_VEC(convert_, LANE_INT_NAME), LANES)(x)
#define LANE_TO_REAL(x) LANE_VEC(LANE_VEC(convert_, LANE_REAL_NAME), LANES)(x)
#define LANE_SEL(a, b, m) select((a), (b), (m))
#define LANE_ANY(m) lane_any(m)
#define LANE_ALL(m) (!lane_any(!(m)))
#else
#error "LANES must be 1, 2, 4, 8 or 16"
#endif

#if LANES > 1
/* Whether any lane of m is set: the halves or'ed down to one lane. PoCL's any() tests each 128-bit part's sign
 * bits in turn, branching after each; in the search's loop that was a fifth of its samples (bench/RESULTS.md). */
ALGRAY_INLINE int lane_any(LMASK m) {
#if LANES == 16
  const LANE_VEC(LANE_INT_NAME, 8) m8 = m.lo | m.hi;
#elif LANES == 8
  const LANE_VEC(LANE_INT_NAME, 8) m8 = m;
#endif
#if LANES >= 8
  const LANE_VEC(LANE_INT_NAME, 4) m4 = m8.lo | m8.hi;
#elif LANES == 4
  const LANE_VEC(LANE_INT_NAME, 4) m4 = m;
#endif
#if LANES >= 4
  const LANE_VEC(LANE_INT_NAME, 2) m2 = m4.lo | m4.hi;
#else
  const LANE_VEC(LANE_INT_NAME, 2) m2 = m;
#endif
  return (m2.s0 | m2.s1) != 0;
}
#endif

/* The vector of type T holding f(0), f(1), ..., f(LANES - 1), built in registers (lane_set goes through memory,
 * and a vector read after scalar stores stalls on them). */
#if LANES == 1
#define LANES_OF(T, f) ((T)(f(0)))
#elif LANES == 2
#define LANES_OF(T, f) ((T)(f(0), f(1)))
#elif LANES == 4
#define LANES_OF(T, f) ((T)(f(0), f(1), f(2), f(3)))
#elif LANES == 8
#define LANES_OF(T, f) ((T)(f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7)))
#else
#define LANES_OF(T, f) \
  ((T)(f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7), f(8), f(9), f(10), f(11), f(12), f(13), f(14), f(15)))
#endif

/* Bit j set for each lane j of m that is set, without a trip through memory: each lane keeps its own bit,
 * then the halves are summed. */
ALGRAY_INLINE uint lane_mask_bits(LMASK m) {
#if LANES == 1
  return m != 0;
#else
#define LANE_BIT(j) (1 << (j))
  LANE_VEC(LANE_INT_NAME, LANES) b = m & LANES_OF(LANE_VEC(LANE_INT_NAME, LANES), LANE_BIT);
#undef LANE_BIT
#if LANES == 16
  LANE_VEC(LANE_INT_NAME, 8) b8 = b.lo + b.hi;
#elif LANES == 8
  LANE_VEC(LANE_INT_NAME, 8) b8 = b;
#endif
#if LANES >= 8
  LANE_VEC(LANE_INT_NAME, 4) b4 = b8.lo + b8.hi;
#elif LANES == 4
  LANE_VEC(LANE_INT_NAME, 4) b4 = b;
#endif
#if LANES >= 4
  LANE_VEC(LANE_INT_NAME, 2) b2 = b4.lo + b4.hi;
#else
  LANE_VEC(LANE_INT_NAME, 2) b2 = b;
#endif
  return (uint)(b2.s0 + b2.s1);
#endif
}

/* Lane j set where bit j of bits is. */
ALGRAY_INLINE LMASK lanes_of_bits(uint bits) {
#if LANES == 1
  return (bits & 1u) != 0;
#else
#define LANE_BIT(j) (1 << (j))
  const LANE_VEC(LANE_INT_NAME, LANES) each = LANES_OF(LANE_VEC(LANE_INT_NAME, LANES), LANE_BIT);
#undef LANE_BIT
  return ((LANE_VEC(LANE_INT_NAME, LANES))((LANE_INT)bits) & each) != 0;
#endif
}

/* The lanes of v into a[0 .. LANES), in one store: reading many lanes of a vector one by one (lane_get) stored
 * the whole vector again for each, and the loads waited on the stores (measured: a fifth of
 * the lanes' Bernstein search in the Barth sextic's double preview). */
#if LANES == 1
#define LANES_STORE(v, a) ((a)[0] = (v))
#define LANES_LOAD(a) ((a)[0])
#else
#define LANES_STORE(v, a) LANE_VEC(vstore, LANES)((v), 0, (a))
#define LANES_LOAD(a) LANE_VEC(vload, LANES)(0, (a)) /* a[0 .. LANES) as one vector */
#endif

/* Lane j of a vector (j < LANES), read and written through its private storage. */
ALGRAY_INLINE REAL lane_get(LREAL v, uint j) { return ((REAL*)&v)[j]; }
ALGRAY_INLINE void lane_set(LREAL* v, uint j, REAL x) { ((REAL*)v)[j] = x; }
ALGRAY_INLINE long lane_get_mask(LMASK m, uint j) {
#if LANES == 1
  (void)j;
  return m;
#else
  return ((LANE_INT*)&m)[j];
#endif
}
ALGRAY_INLINE void lane_set_mask(LMASK* m, uint j, int on) {
#if LANES == 1
  (void)j;
  *m = on != 0;
#else
  ((LANE_INT*)m)[j] = on ? -1 : 0;
#endif
}

#endif /* ALGRAY_LANES_H */
