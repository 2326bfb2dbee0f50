/* Restriction of P(x,y,z) to a ray: the coefficients of P*(s) in the basis the isolation method works in. */
#ifndef ALGRAY_RESTRICT_H
#define ALGRAY_RESTRICT_H

#include "algray_shared.h"
#include "real.h"

#ifndef RESTRICT_BERNSTEIN
#define RESTRICT_BERNSTEIN (ISOLATION == ALGRAY_ISOLATION_BERNSTEIN)
#endif

/* Every coordinate along the ray is a linear polynomial in s. Multiplying by linear factors and adding
 * constants builds P*(s) from the monomial list by a sparse, homogeneous Horner scheme.
 *
 * Two bases share the code; they differ only in what "one" is:
 *  - power basis: c_0 + c_1 s + ... ; a linear factor is (l0, l1) = l0 + l1*s; one = (1, 0).
 *  - scaled Bernstein basis on [0,1]: sum c_k (1-s)^(n-k) s^k ; (l0, l1) = l0*(1-s) + l1*s; one = (1, 1).
 * Homogenising with w = one makes every partial sum of a Horner level the same degree, so sums never need
 * degree elevation, and in the Bernstein basis all arithmetic stays a sum of products of nearby values. */

/* All operations run over the full NCOEF coefficients, with zeros above the current degree: fixed trip counts
 * let the compiler unroll them and keep the arrays in registers, which beats skipping the zeros. */

/* c (degree < DEGREE) times (l0 + l1 s), or times (l0 (1-s) + l1 s) in the scaled Bernstein form: same recurrence. */
void poly_mul_linear(REAL* c, REAL l0, REAL l1) {
  for (int k = DEGREE; k > 0; --k) c[k] = l0 * c[k] + l1 * c[k - 1];
  c[0] = l0 * c[0];
}

/* c times L^times for a linear factor L. */
void poly_mul_linear_pow(REAL* c, REAL l0, REAL l1, int times) {
  for (int r = 0; r < times; ++r) poly_mul_linear(c, l0, l1);
}

/* c times one^times: degree elevation in the Bernstein form; nothing to do in the power basis. */
void poly_mul_one(REAL* c, int times) {
#if RESTRICT_BERNSTEIN
  poly_mul_linear_pow(c, (REAL)1, (REAL)1, times);
#else
  (void)c;
  (void)times;
#endif
}

/* c (degree n) plus a * one^n. binomials[n * NCOEF + k] = C(n, k), zero for k > n. */
void poly_add_constant(REAL* c, int n, REAL a, __constant const REAL* binomials) {
#if RESTRICT_BERNSTEIN
  /* one^n = sum C(n,k) (1-s)^(n-k) s^k in the scaled basis. */
  __constant const REAL* row = binomials + n * NCOEF;
  for (int k = 0; k <= DEGREE; ++k) c[k] += a * row[k];
#else
  (void)n;
  (void)binomials;
  c[0] += a;
#endif
}

void poly_add(REAL* c, const REAL* other) {
  for (int k = 0; k <= DEGREE; ++k) c[k] += other[k];
}

void poly_copy(REAL* dst, const REAL* src) {
  for (int k = 0; k <= DEGREE; ++k) dst[k] = src[k];
}

void poly_set_constant(REAL* c, REAL a) {
  c[0] = a;
  for (int k = 1; k <= DEGREE; ++k) c[k] = 0;
}

/* Monomials arrive sorted by i, then j, then k, all descending, exponents packed as i | j<<8 | k<<16.
 * P = sum_i x^i sum_j y^j sum_k a_ijk z^k w^(D-i-j-k), evaluated as three nested Horner levels.
 * lx, ly, lz: the linear factors of the three coordinates. Result: out[0..DEGREE]. */
void restrict_to_ray(__global const uint* exps, __global const REAL* coefs, uint count,
                     __constant const REAL* binomials, REAL2 lx, REAL2 ly, REAL2 lz, REAL* out) {
  REAL acc_z[NCOEF], acc_y[NCOEF];
  int deg_x = -1, deg_y = -1, deg_z = -1; /* -1: level still empty */
  int cur_i = -1, cur_j = -1, cur_k = -1;
  int prev_i = -1, prev_j = -1;

  for (uint m = 0; m <= count; ++m) {
    int i = -1, j = -1, k = -1;
    REAL a = 0;
    if (m < count) {
      const uint e = exps[m];
      i = (int)(e & 0xffu);
      j = (int)((e >> 8) & 0xffu);
      k = (int)((e >> 16) & 0xffu);
      a = coefs[m];
    }
    /* Close the z-level group (cur_i, cur_j) when (i, j) changes or the list ends. */
    if (deg_z >= 0 && (i != cur_i || j != cur_j)) {
      poly_mul_linear_pow(acc_z, lz.x, lz.y, cur_k);
      deg_z += cur_k;
      const int full = DEGREE - cur_i - cur_j; /* B_ij is homogeneous of this degree */
      poly_mul_one(acc_z, full - deg_z);
      deg_z = full;
      if (deg_y < 0) {
        poly_copy(acc_y, acc_z);
        deg_y = deg_z;
      } else {
        poly_mul_linear_pow(acc_y, ly.x, ly.y, prev_j - cur_j);
        deg_y += prev_j - cur_j;
        poly_add(acc_y, acc_z);
      }
      prev_j = cur_j;
      deg_z = -1;
    }
    /* Close the y-level group cur_i when i changes or the list ends. */
    if (deg_y >= 0 && i != cur_i) {
      poly_mul_linear_pow(acc_y, ly.x, ly.y, prev_j);
      deg_y += prev_j;
      if (deg_x < 0) {
        poly_copy(out, acc_y);
        deg_x = deg_y;
      } else {
        poly_mul_linear_pow(out, lx.x, lx.y, prev_i - cur_i);
        deg_x += prev_i - cur_i;
        poly_add(out, acc_y);
      }
      prev_i = cur_i;
      deg_y = -1;
    }
    if (m == count) break;
    /* Add a_ijk to the z-level Horner sum of group (i, j). */
    if (deg_z < 0) {
      poly_set_constant(acc_z, a);
      deg_z = 0;
    } else {
      poly_mul_linear_pow(acc_z, lz.x, lz.y, cur_k - k);
      deg_z += cur_k - k;
      poly_add_constant(acc_z, deg_z, a, binomials);
    }
    cur_i = i;
    cur_j = j;
    cur_k = k;
  }
  if (deg_x < 0) { /* no monomials: the host never sends this, but stay defined */
    poly_set_constant(out, 0);
    return;
  }
  poly_mul_linear_pow(out, lx.x, lx.y, prev_i);
}

#endif /* ALGRAY_RESTRICT_H */
