/* The primary-ray kernel: camera rays of a tile, LANES pixels per work-item, to hit distance, normal, side and work. */
#include "algray_shared.h"
#include "isolate.h"
#include "lanes.h"
#include "ray.h"
#include "real.h"
#include "restrict.h"
#include "surface.h"

/* One tile of the image per launch: global size (ceil(tile_w / LANES), tile_h), LANES pixels of a row per work-item
 * (trace_rays): the pixels (px, py) = (tile_x0 + x, tile_y0 + gy) for x = gx * LANES .. gx * LANES + LANES - 1 within
 * the tile, with results at out[gy * tile_w + x], the tile's own buffer.
 * The polynomial is given in unit coordinates u = (p - centre) * inv_scale, with max |coefficient| = 1.
 * binomials[n * (DEGREE + 1) + k] = C(n, k) for 0 <= k <= n <= DEGREE (zero elsewhere).
 * even_axes: bit 0, 1, 2 set when every exponent of x, y, z in the polynomial is even.
 * screen_rows .. xi_offset: the image rows' polynomials of the screen form (surface.h), which other builds never
 * read. The arguments are ALGRAY_PRIMARY_ARG_NAMES (algray_shared.h), by which the host sets them. */
__kernel void primary(REAL4 ray_o00, REAL4 ray_ou, REAL4 ray_ov, REAL4 ray_d00, REAL4 ray_du, REAL4 ray_dv,
                      REAL4 extent_centre, REAL extent_inv_scale, REAL4 extent_box_half, int extent_kind,
                      __global const REAL4* clip_planes, uint clip_count, __global const uint* mono_exps, __global const REAL* mono_coefs, uint mono_count,
                      __constant const REAL* binomials, uint even_axes, __global const REAL* screen_rows,
                      uint screen_row0, REAL screen_t, REAL xi_scale, REAL xi_offset, uint tile_x0, uint tile_y0,
                      uint tile_w, uint tile_h, __global HitRecord* out) {
  const uint gx = get_global_id(0), gy = get_global_id(1);
  const uint x0 = gx * LANES;
  if (x0 >= tile_w || gy >= tile_h) return;
  const uint count = min((uint)LANES, tile_w - x0), py = tile_y0 + gy;
  const LaneRays rays = camera_rays(tile_x0 + x0, py, ray_o00, ray_ou, ray_ov, ray_d00, ray_du, ray_dv);
  HitRecord records[LANES];
  const int entered = trace_rays(count, &rays, extent_centre.xyz, extent_inv_scale, extent_box_half.xyz, extent_kind,
                                 clip_planes, clip_count, mono_exps, mono_coefs, mono_count, binomials, even_axes, records, tile_x0 + x0, py,
                                 screen_rows, screen_row0, screen_t, xi_scale, xi_offset, NO_PROBE);
  for (uint j = 0; j < count; ++j) out[(size_t)gy * tile_w + x0 + j] = entered ? records[j] : missed_record();
}
