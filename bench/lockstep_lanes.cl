/* Lock-step lanes, a measured prototype (issue 14): the repo's Brent refinement and Bernstein isolation, one polynomial
 * per work-item, against the same steps on 8 polynomials per work-item in double8 lanes, every lane committing
 * its own state through select(). bench/lockstep_lanes.cpp times the pairs and checks that the lanes reproduce
 * the scalar results bit for bit. Temporary: it restates refine.h and bernstein.h in lanes to measure what a
 * lane-wide primary kernel would gain, and goes when that kernel lands (then the lanes are the only copy). */
#include "isolate.h"

__kernel void scalar_brent(__global const REAL* polys, __global REAL* roots, __global uint* iters, REAL tol_y,
                           __constant const REAL* binomials) {
  const uint i = get_global_id(0);
  REAL c[NCOEF];
  REAL scale = 0;
  for (int k = 0; k <= DEGREE; ++k) { c[k] = polys[(size_t)i * NCOEF + k]; scale = fmax(scale, fabs(c[k])); }
  const REAL f0 = c[0], f1 = c[DEGREE];
  prepare_isolated(c, binomials);
  uint it;
  roots[i] = refine_root(c, f0, f1, tol_y, scale, (REAL)-1, &it); /* no start: as the lanes below begin */
  iters[i] = it;
}

typedef double8 V;
typedef long8 M;
#define SEL(a, b, m) select((a), (b), (m)) /* b in the lanes where m is true (-1), a elsewhere */

/* Coefficient k of polynomials 8g .. 8g+7, stored one polynomial after another. */
V load_lanes(__global const REAL* polys, uint g, int k) {
  V v;
  REAL* lanes = (REAL*)&v;
  for (int j = 0; j < 8; ++j) lanes[j] = polys[(size_t)(g * 8 + j) * NCOEF + k];
  return v;
}
void store_lanes(__global REAL* out, uint g, V v) { vstore8(v, g, out); }
void store_lanes_int(__global int* out, uint g, long8 v) { vstore8(convert_int8(v), g, out); }
void store_lanes_uint(__global uint* out, uint g, long8 v) { vstore8(convert_uint8(v), g, out); }

ALGRAY_INLINE V vpower(V x) { V p = (V)1; for (int k = 0; k < DEGREE; ++k) p *= x; return p; }
ALGRAY_INLINE V v_value(const V* c, V y) {
  const M mir = y > (V)0.5;
  const V r = SEL(y / ((V)1 - y), ((V)1 - y) / y, mir);
  V h = SEL(c[DEGREE], c[0], mir);
  for (int k = DEGREE - 1; k >= 0; --k) h = h * r + SEL(c[k], c[DEGREE - k], mir);
  return h * vpower(SEL((V)1 - y, y, mir));
}
ALGRAY_INLINE V v_magnitude(const V* c, V y) {
  const M mir = y > (V)0.5;
  const V r = SEL(y / ((V)1 - y), ((V)1 - y) / y, mir);
  V h = 0;
  for (int k = DEGREE; k >= 0; --k) h = h * r + fabs(SEL(c[k], c[DEGREE - k], mir));
  return h * vpower(SEL((V)1 - y, y, mir));
}

__kernel void lockstep_brent(__global const REAL* polys, __global REAL* roots, __global uint* iters, REAL tol_y,
                             __constant const REAL* binomials) {
  const uint g = get_global_id(0);
  V c[NCOEF];
  V scale = 0;
  for (int k = 0; k <= DEGREE; ++k) {
    const V col = load_lanes(polys, g, k);
    c[k] = col;
    scale = fmax(scale, fabs(col));
  }
  const V f0 = c[0], f1 = c[DEGREE];
  for (int k = 0; k <= DEGREE; ++k) c[k] *= (V)binomials[DEGREE * NCOEF + k];
  V a = 0, fa = f0, b = 1, fb = f1, cp = 0, fc = f0;
  M done = (M)0;
  long8 it = (long8)0;
  for (int n = 0; n < MAX_ITERATIONS; ++n) {
    const M sw = fabs(fc) < fabs(fb);
    const V a2 = SEL(a, b, sw), fa2 = SEL(fa, fb, sw), b2 = SEL(b, cp, sw), fb2 = SEL(fb, fc, sw);
    const V cp2 = SEL(cp, a2, sw), fc2 = SEL(fc, fa2, sw);
    /* swap only lanes still running (done lanes keep their state) */
    a = SEL(a2, a, done); fa = SEL(fa2, fa, done); b = SEL(b2, b, done); fb = SEL(fb2, fb, done);
    cp = SEL(cp2, cp, done); fc = SEL(fc2, fc, done);
    M stop = fabs(cp - b) <= (V)tol_y;
    const M small = fabs(fb) <= (V)(REAL_EPS * (DEGREE + 1)) * scale;
    if (any(small & ~stop & ~done)) stop |= small & (fabs(fb) <= (V)REAL_EPS * v_magnitude(c, b));
    done |= stop;
    if (all(done)) break;
    const M iqi = (fa != fc) & (fb != fc) & (fa != fb);
    const M sec = ~iqi & (fa != fb);
    const V r = fb / fc, s = fb / fa, q = fa / fc;
    const V num = s * (q * (q - r) * (cp - b) - (r - (V)1) * (b - a));
    const V den = (q - (V)1) * (r - (V)1) * (s - (V)1);
    const V cand = SEL(SEL(b, b - fb * (b - a) / (fb - fa), sec), b - num / den, iqi);
    const V step = cand - b;
    const M accept = (iqi | sec) & isfinite(cand) & (step * (cp - b) > 0) & (fabs(step) < (V)0.75 * fabs(cp - b)) &
                     (fabs(step) < (V)0.5 * fabs(b - a));
    V next = SEL(b + (V)0.5 * (cp - b), cand, accept);
    next = SEL(next, b + copysign((V)0.5 * (V)tol_y, cp - b), fabs(next - b) < (V)0.5 * (V)tol_y);
    const V fnext = v_value(c, next);
    const M chg = (fnext > 0) == (fc > 0);
    const V na = b, nfa = fb;
    /* commit lanes still running */
    a = SEL(na, a, done); fa = SEL(nfa, fa, done);
    b = SEL(next, b, done); fb = SEL(fnext, fb, done);
    cp = SEL(SEL(cp, na, chg), cp, done); fc = SEL(SEL(fc, nfa, chg), fc, done);
    it += select((long8)1, (long8)0, done);
  }
  store_lanes(roots, g, b);
  store_lanes_uint(iters, g, it);
}

__kernel void scalar_iso(__global const REAL* polys, __global REAL* out_lo, __global REAL* out_hi, __global int* status,
                         __global uint* steps) {
  const uint i = get_global_id(0);
  REAL root[NCOEF], root_lo[NCOEF], cur[NCOEF];
  for (int k = 0; k <= DEGREE; ++k) root[k] = polys[(size_t)i * NCOEF + k];
  const Isolation iso = isolate_bernstein(root, root_lo, (REAL)0.5, (REAL)1.5, cur);
  out_lo[i] = iso.lo; out_hi[i] = iso.hi; status[i] = iso.status; steps[i] = iso.steps;
}

__kernel void lockstep_iso(__global const REAL* polys, __global REAL* out_lo, __global REAL* out_hi, __global int* status,
                           __global uint* steps) {
  const uint g = get_global_id(0);
  V root[NCOEF], cur[NCOEF], sib[NCOEF];
  for (int k = 0; k <= DEGREE; ++k) {
    const V col = load_lanes(polys, g, k);
    root[k] = col; cur[k] = col; sib[k] = col;
  }
  const REAL t_in = 0.5, len = 1.0;
  const M start_sign_pos = root[0] > 0, start_sign_neg = root[0] < 0;
  long8 level = 0, idx = 0, sib_level = -1, sib_idx = 0, st = 0;
  long8 stat = (long8)ISOLATION_NONE;
  M done = (M)0;
  V lo = 0, hi = 1;
  for (;;) {
    st += select((long8)1, (long8)0, done);
    const V width = ldexp((V)1, -convert_int8(level));
    const V ilo = convert_double8(idx) * width;
    lo = SEL(ilo, lo, done);
    hi = SEL(ilo + width, hi, done);
    const V flo = cur[0], fhi = cur[DEGREE];
    /* settled_at_left_end: exact zero, or crossed */
    const M zero = (flo == 0) & ~done;
    const M crossed = ~zero & ~done & (((flo > 0) & start_sign_neg) | ((flo < 0) & start_sign_pos));
    stat = select(stat, (long8)ISOLATION_EXACT, zero | crossed);
    done |= zero | crossed;
    /* sign variations */
    long8 v = 0, prev = 0;
    for (int k = 0; k <= DEGREE; ++k) {
      const long8 s = select((long8)0, (long8)1, cur[k] > 0) - select((long8)0, (long8)1, cur[k] < 0);
      v += select((long8)0, (long8)1, s * prev < 0);
      prev = select(prev, s, s != 0);
    }
    const M isolated = ~done & (v == 1) & (fhi != 0);
    stat = select(stat, (long8)ISOLATION_BRACKET, isolated);
    done |= isolated;
    /* v >= 1: halve unless located or at the halving limit; clusters settle or move on */
    const M located = width * (V)len <= (V)4 * (V)TOLERANCE * fmax(fabs((V)t_in + lo * (V)len), (V)1);
    const M want_split = ~done & (v >= 1);
    const M halve = want_split & ~located & (level < REAL_MAX_HALVINGS);
    const M cluster = want_split & ~halve;
    const M cl_root = cluster & ((flo < 0) != (fhi < 0));
    stat = select(stat, (long8)ISOLATION_BRACKET, cl_root);
    done |= cl_root;
    if (all(done)) break;
    if (any(halve)) {
      V t[NCOEF], left[NCOEF], right[NCOEF];
      for (int k = 0; k <= DEGREE; ++k) t[k] = cur[k];
      right[DEGREE] = t[DEGREE];
      left[0] = t[0];
      for (int r = 1; r <= DEGREE; ++r) {
        for (int k = 0; k <= DEGREE - r; ++k) t[k] = (V)0.5 * t[k] + (V)0.5 * t[k + 1];
        left[r] = t[0];
        right[DEGREE - r] = t[DEGREE - r];
      }
      for (int k = 0; k <= DEGREE; ++k) { cur[k] = SEL(cur[k], left[k], halve); sib[k] = SEL(sib[k], right[k], halve); }
      level = select(level, level + 1, halve);
      idx = select(idx, idx * 2, halve);
      sib_level = select(sib_level, level, halve);
      sib_idx = select(sib_idx, idx + 1, halve);
    }
    /* lanes moving on: no root here (v == 0), or a cluster without a sign change */
    M move = ~done & ~halve;
    if (any(move)) {
      /* next_interval per lane */
      long8 l = level, x = idx;
      for (int guard = 0; guard < 64; ++guard) {
        const M odd = move & ((x & 1) != 0);
        if (!any(odd)) break;
        x = select(x, x >> 1, odd);
        l = select(l, l - 1, odd);
      }
      const M finished = move & (l == 0);
      stat = select(stat, (long8)ISOLATION_NONE, finished); /* far-end zero ignored in the prototype */
      done |= finished;
      move &= ~finished;
      x = select(x, x + 1, move);
      level = select(level, l, move);
      idx = select(idx, x, move);
      const M from_sib = move & (sib_level == level) & (sib_idx == idx);
      const M from_root = move & ~from_sib;
      for (int k = 0; k <= DEGREE; ++k) cur[k] = SEL(cur[k], sib[k], from_sib);
      if (any(from_root)) {
        V o[NCOEF];
        for (int k = 0; k <= DEGREE; ++k) o[k] = root[k];
        const V w = ldexp((V)1, -convert_int8(level));
        const V rlo = convert_double8(idx) * w, rhi = rlo + w;
        const M kl = from_root & (rhi < (V)1);
        if (any(kl)) {
          const V x1 = (V)1 - rhi;
          V o2[NCOEF];
          for (int k = 0; k <= DEGREE; ++k) o2[k] = o[k];
          for (int r = 1; r <= DEGREE; ++r)
            for (int k = DEGREE; k >= r; --k) o2[k] = x1 * o2[k - 1] + rhi * o2[k];
          for (int k = 0; k <= DEGREE; ++k) o[k] = SEL(o[k], o2[k], kl);
        }
        const M kr = from_root & (rlo > (V)0);
        if (any(kr)) {
          const V xx = rlo / rhi, xlo = fma(-xx, rhi, rlo) / rhi;
          const V x1 = (V)1 - xx;
          V o2[NCOEF];
          for (int k = 0; k <= DEGREE; ++k) o2[k] = o[k];
          for (int r = 1; r <= DEGREE; ++r)
            for (int k = 0; k <= DEGREE - r; ++k) o2[k] = x1 * o2[k] + xx * o2[k + 1];
          for (int k = 0; k <= DEGREE; ++k) o[k] = SEL(o[k], o2[k], kr);
        }
        for (int k = 0; k <= DEGREE; ++k) cur[k] = SEL(cur[k], o[k], from_root);
      }
    }
  }
  store_lanes(out_lo, g, lo);
  store_lanes(out_hi, g, hi);
  store_lanes_int(status, g, stat);
  store_lanes_uint(steps, g, st);
}
