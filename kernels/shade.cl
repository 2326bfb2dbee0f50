/* The shading kernel: a tile's camera-ray hit records into the film's pixels (Phong with the shadow pass's answers
 * or a headlight, plane sections, the bounces' colour, the background, the box filter), as the host's Shader does. */
#include "algray_shared.h"
#include "lanes.h"
#include "ray.h"
#include "real.h"

/* Built in double where the device has fp64, else in float (the host's DeviceShader picks it): the host shades in
 * double, and a hit point o + t*d rounded in float can move a section's line by a pixel where |o| is large.
 * LANES pixels of a row per work-item, as the host shades 8 hits side by side: PoCL runs work-items one after
 * another and cannot merge this kernel's loops over samples and lights, so one pixel per work-item ran at a third of
 * the host's speed. Each lane does one pixel's operations in the host's order (no fused multiply-adds). */

/* a.b summed as the host's glm::dot sums it: ((x + y) + z) */
#define SHADE_DOT(ax, ay, az, bx, by, bz) (((ax) * (bx) + (ay) * (by)) + (az) * (bz))

/* One lane's camera ray component rounded in float (a single-precision render's rays), as the host's pixel_ray
 * rebuilds it, whatever REAL is. */
static REAL float_camera_axis(uint px, uint py, REAL base, REAL along_x, REAL along_y) {
#pragma OPENCL FP_CONTRACT OFF
  const float fx = (float)px + 0.5f, fy = (float)py + 0.5f;
  return (REAL)CAMERA_AXIS(fx, fy, (float)base, (float)along_x, (float)along_y);
}

/* Those components of the lanes' rays, pixel columns px0, px0 + step, ... */
static LREAL float_camera_axes(uint px0, uint step, uint py, REAL base, REAL along_x, REAL along_y) {
#define FLOAT_AXIS(j) float_camera_axis(px0 + (j)*step, py, base, along_x, along_y)
  return LANES_OF(LREAL, FLOAT_AXIS);
#undef FLOAT_AXIS
}

/* The camera rays of pixel columns px0, px0 + step, ... (one per lane) of row py, as the primary kernel traced them. */
ALGRAY_INLINE LaneRays shade_camera_rays(uint px0, uint step, uint py, uint in_float, REAL4 o00, REAL4 ou, REAL4 ov,
                                         REAL4 d00, REAL4 du, REAL4 dv) {
#pragma OPENCL FP_CONTRACT OFF
  LaneRays r;
  if (in_float) {
    r.ox = float_camera_axes(px0, step, py, o00.x, ou.x, ov.x);
    r.oy = float_camera_axes(px0, step, py, o00.y, ou.y, ov.y);
    r.oz = float_camera_axes(px0, step, py, o00.z, ou.z, ov.z);
    r.dx = float_camera_axes(px0, step, py, d00.x, du.x, dv.x);
    r.dy = float_camera_axes(px0, step, py, d00.y, du.y, dv.y);
    r.dz = float_camera_axes(px0, step, py, d00.z, du.z, dv.z);
    return r;
  }
#define PIXEL_CENTRE(j) ((REAL)(px0 + (j)*step) + (REAL)0.5)
  const LREAL fx = LANES_OF(LREAL, PIXEL_CENTRE);
#undef PIXEL_CENTRE
  return camera_rays_through(fx, (REAL)py + (REAL)0.5, o00, ou, ov, d00, du, dv);
}

/* The lanes' hits as the shading needs them: point, normal, material values, and which surface and side. */
typedef struct {
  LREAL px, py, pz, nx, ny, nz, t;
  LREAL m[ALGRAY_MATERIAL_VALUES];
  LANE_INT_VEC surface;
} LaneHits;

/* What the lights see of the lanes' hits, Shader::shade_lit's two cases: without lights the headlight (the colour by
 * how squarely the surface faces the eye); else Phong per light point that the shadow pass left visible (lane j's
 * masks at point[j] of the light's row of occlusion_masks, see the kernel) and that lies in front of the tangent
 * plane, each light's sums shared among its points. */
ALGRAY_INLINE void shade_lit(const LaneHits* h, const LaneRays* ray, LMASK found, uint light_count,
                             REAL headlight_ambient, __global const REAL4* light_colours,
                             __global const uint* light_first, __global const REAL4* light_points,
                             __global const int* light_occlusion, const uint point[LANES],
                             __global const ulong* occlusion_masks, uint occlusion_stride, LREAL* cr, LREAL* cg,
                             LREAL* cb) {
#pragma OPENCL FP_CONTRACT OFF
  const LREAL mr = h->m[ALGRAY_MATERIAL_RED], mg = h->m[ALGRAY_MATERIAL_GREEN], mb = h->m[ALGRAY_MATERIAL_BLUE];
  const LREAL own = h->m[ALGRAY_MATERIAL_OWN];
  const LREAL inv = (REAL)1 / sqrt(SHADE_DOT(ray->dx, ray->dy, ray->dz, ray->dx, ray->dy, ray->dz));
  const LREAL ex = -(ray->dx * inv), ey = -(ray->dy * inv), ez = -(ray->dz * inv);
  if (light_count == 0) {
    const LREAL facing = fabs(SHADE_DOT(h->nx, h->ny, h->nz, ex, ey, ez));
    const LREAL lit = headlight_ambient + ((REAL)1 - headlight_ambient) * facing;
    *cr = own * mr * lit;
    *cg = own * mg * lit;
    *cb = own * mb * lit;
    return;
  }
  const LREAL kd = h->m[ALGRAY_MATERIAL_DIFFUSE], ks = h->m[ALGRAY_MATERIAL_SPECULAR];
  const LREAL exponent = h->m[ALGRAY_MATERIAL_EXPONENT], cutoff = h->m[ALGRAY_MATERIAL_CUTOFF];
  const LREAL ambient = h->m[ALGRAY_MATERIAL_AMBIENT];
  LREAL r = ambient * mr, g = ambient * mg, b = ambient * mb;
  for (uint li = 0; li < light_count; ++li) {
    const int row = light_occlusion[li];
    /* each lane's mask in two halves of 32 bits, as lane integers (which are 32 bits wide in float builds) */
    ulong hidden[LANES];
    for (uint j = 0; j < LANES; ++j)
      hidden[j] = row < 0 || point[j] == UINT_MAX ? 0 : occlusion_masks[(size_t)row * occlusion_stride + point[j]];
#define HIDDEN_LOW(j) ((LANE_INT)(uint)hidden[j])
#define HIDDEN_HIGH(j) ((LANE_INT)(uint)(hidden[j] >> 32))
    const LANE_INT_VEC hidden_low = LANES_OF(LANE_INT_VEC, HIDDEN_LOW), hidden_high = LANES_OF(LANE_INT_VEC, HIDDEN_HIGH);
#undef HIDDEN_LOW
#undef HIDDEN_HIGH
    LREAL diffuse = 0, specular = 0;
    const uint first = light_first[li], end = light_first[li + 1];
    for (uint s = first; s < end; ++s) {
      const REAL4 at = light_points[s];
      LREAL lx = at.x - h->px, ly = at.y - h->py, lz = at.z - h->pz;
      const LREAL to_light = (REAL)1 / sqrt(SHADE_DOT(lx, ly, lz, lx, ly, lz));
      lx *= to_light;
      ly *= to_light;
      lz *= to_light;
      const LREAL n_dot_l = SHADE_DOT(h->nx, h->ny, h->nz, lx, ly, lz);
      const LREAL twice = 2 * n_dot_l;
      const LREAL r_dot_v = SHADE_DOT(twice * h->nx - lx, twice * h->ny - ly, twice * h->nz - lz, ex, ey, ez);
      const uint bit = s - first;
      const LMASK shadowed = (((bit < 32 ? hidden_low : hidden_high) >> (LANE_INT)(bit & 31)) & (LANE_INT)1) != 0;
      const LMASK lit = found && !shadowed && !(n_dot_l <= 0);
      diffuse = LANE_SEL(diffuse, diffuse + n_dot_l, lit);
      /* Below the cutoff a highlight is under 1/4096 of full strength: its power only where it can show. There
       * r.v > 0, and exp2(e log2 x) costs half of what PoCL's vector pow() does, with an error far below what
       * shows (the host's pow's images in 8-bit and half-float channels bit for bit on the shipped scenes). */
      const LMASK highlight = lit && r_dot_v > cutoff;
      if (LANE_ANY(highlight))
        specular = LANE_SEL(specular, specular + exp2(exponent * log2(r_dot_v)), highlight);
    }
    const REAL share = (REAL)1 / (REAL)(end - first);
    const REAL4 light = light_colours[li];
    const LREAL d = kd * diffuse * share, sp = ks * specular * share;
    r += light.x * (d * mr + sp);
    g += light.y * (d * mg + sp);
    b += light.z * (d * mb + sp);
  }
  *cr = own * r;
  *cg = own * g;
  *cb = own * b;
}

/* Shader::draw_sections for camera rays: where the first section whose curve passes through a lane's pixel gives
 * its colour. The band is half the change of n.p + d from one pixel to the next, times the section's width. */
ALGRAY_INLINE void draw_sections(const LaneHits* h, const LaneRays* ray, LMASK found, REAL samples, REAL4 ou,
                                 REAL4 ov, REAL4 du, REAL4 dv, __global const REAL4* section_planes,
                                 __global const REAL4* section_looks, __global const int* section_surfaces,
                                 uint section_count, LREAL* cr, LREAL* cg, LREAL* cb) {
#pragma OPENCL FP_CONTRACT OFF
  const LREAL t = h->t;
  LREAL exx = samples * (ou.x + t * du.x), exy = samples * (ou.y + t * du.y), exz = samples * (ou.z + t * du.z);
  LREAL eyx = samples * (ov.x + t * dv.x), eyy = samples * (ov.y + t * dv.y), eyz = samples * (ov.z + t * dv.z);
  const LREAL facing = SHADE_DOT(h->nx, h->ny, h->nz, ray->dx, ray->dy, ray->dz);
  const LREAL length_d = sqrt(SHADE_DOT(ray->dx, ray->dy, ray->dz, ray->dx, ray->dy, ray->dz));
  /* at the silhouette the hit runs off along the ray; the move across the image stands for it there */
  const LMASK across = fabs(facing) > (REAL)1 / (REAL)1000 * length_d;
  const LREAL along_x = SHADE_DOT(h->nx, h->ny, h->nz, exx, exy, exz) / facing;
  const LREAL along_y = SHADE_DOT(h->nx, h->ny, h->nz, eyx, eyy, eyz) / facing;
  exx = LANE_SEL(exx, exx - ray->dx * along_x, across);
  exy = LANE_SEL(exy, exy - ray->dy * along_x, across);
  exz = LANE_SEL(exz, exz - ray->dz * along_x, across);
  eyx = LANE_SEL(eyx, eyx - ray->dx * along_y, across);
  eyy = LANE_SEL(eyy, eyy - ray->dy * along_y, across);
  eyz = LANE_SEL(eyz, eyz - ray->dz * along_y, across);
  LMASK open = found; /* lanes no section has taken yet */
  for (uint k = 0; k < section_count; ++k) {
    const REAL4 plane = section_planes[k], look = section_looks[k];
    const LREAL band = (REAL)0.5 * look.w *
                       fmax(fabs(SHADE_DOT(plane.x, plane.y, plane.z, exx, exy, exz)),
                            fabs(SHADE_DOT(plane.x, plane.y, plane.z, eyx, eyy, eyz)));
    const LMASK on_surface = (LMASK)(section_surfaces[k] < 0) || h->surface == (LANE_INT_VEC)section_surfaces[k];
    const LMASK on = open && on_surface &&
                     fabs(SHADE_DOT(plane.x, plane.y, plane.z, h->px, h->py, h->pz) + plane.w) <= band;
    *cr = LANE_SEL(*cr, (LREAL)look.x, on);
    *cg = LANE_SEL(*cg, (LREAL)look.y, on);
    *cb = LANE_SEL(*cb, (LREAL)look.z, on);
    open = open && !on;
  }
}

/* The lanes' hits of one sample as the shading needs them: t, normal, surface, point on the ray, material. */
ALGRAY_INLINE LaneHits lane_hits(const HitRecord rec[LANES], const size_t at[LANES], const LaneRays* ray,
                                 __global const uchar* hit_surface, uint several_surfaces,
                                 __global const REAL* materials) {
#pragma OPENCL FP_CONTRACT OFF
  LaneHits h;
  uint surface[LANES]; /* which surface each lane's hit is on */
  for (uint j = 0; j < LANES; ++j) surface[j] = several_surfaces ? (uint)hit_surface[at[j]] : 0u;
#define REC_T(j) ((REAL)rec[j].t_hi + (REAL)rec[j].t_lo)
#define REC_NX(j) ((REAL)rec[j].normal_x)
#define REC_NY(j) ((REAL)rec[j].normal_y)
#define REC_NZ(j) ((REAL)rec[j].normal_z)
#define REC_SURFACE(j) ((LANE_INT)surface[j])
  h.t = LANES_OF(LREAL, REC_T);
  h.nx = LANES_OF(LREAL, REC_NX);
  h.ny = LANES_OF(LREAL, REC_NY);
  h.nz = LANES_OF(LREAL, REC_NZ);
  h.surface = LANES_OF(LANE_INT_VEC, REC_SURFACE);
#undef REC_T
#undef REC_NX
#undef REC_NY
#undef REC_NZ
#undef REC_SURFACE
  h.px = ray->ox + h.t * ray->dx;
  h.py = ray->oy + h.t * ray->dy;
  h.pz = ray->oz + h.t * ray->dz;
  /* each lane's material: its surface's front or back; read once where every lane has the same (most groups) */
  uint material[LANES];
  uint mixed = 0;
  for (uint j = 0; j < LANES; ++j) {
    material[j] = (2 * surface[j] + ((rec[j].flags & ALGRAY_HIT_BACK) ? 1u : 0u)) * ALGRAY_MATERIAL_VALUES;
    mixed |= material[j] ^ material[0];
  }
  for (uint v = 0; v < ALGRAY_MATERIAL_VALUES; ++v) {
#define MATERIAL_VALUE(j) (materials[material[j] + v])
    h.m[v] = mixed ? LANES_OF(LREAL, MATERIAL_VALUE) : (LREAL)materials[material[0] + v];
#undef MATERIAL_VALUE
  }
  return h;
}

/* What each lane's bounces brought back, added to its colour. */
ALGRAY_INLINE void add_secondary(__global const REAL4* secondary, const size_t at[LANES], LREAL* cr, LREAL* cg,
                                 LREAL* cb) {
#pragma OPENCL FP_CONTRACT OFF
#define MORE_R(j) (secondary[at[j]].x)
#define MORE_G(j) (secondary[at[j]].y)
#define MORE_B(j) (secondary[at[j]].z)
  *cr += LANES_OF(LREAL, MORE_R);
  *cg += LANES_OF(LREAL, MORE_G);
  *cb += LANES_OF(LREAL, MORE_B);
#undef MORE_R
#undef MORE_G
#undef MORE_B
}

/* The records of sample (sx, sy) of the lanes' `count` pixels from x0 in tile row y, at[j] where lane j's lies
 * (lanes past the tile's edge repeat the first lane's, and are never written), counted into the totals. */
ALGRAY_INLINE void load_records(__global const HitRecord* hits, uint tile_w, uint samples, uint x0, uint y, uint sx,
                                uint sy, uint count, HitRecord rec[LANES], size_t at[LANES],
                                uint counts[ALGRAY_SUMMARY_VALUES], uint* any_found) {
  for (uint j = 0; j < LANES; ++j) {
    at[j] = (size_t)(y * samples + sy) * tile_w + (x0 + (j < count ? j : 0)) * samples + sx;
    rec[j] = hits[at[j]];
    const uint flags = rec[j].flags;
    if (j < count) {
      counts[ALGRAY_SUMMARY_HITS] += (flags & ALGRAY_HIT_FOUND) != 0;
      counts[ALGRAY_SUMMARY_DEPTH_LIMITED] += (flags & ALGRAY_HIT_BUDGET) != 0;
      counts[ALGRAY_SUMMARY_ISOLATION_STEPS] += ALGRAY_WORK_ISOLATION_STEPS(rec[j].work);
      counts[ALGRAY_SUMMARY_REFINE_ITERATIONS] += ALGRAY_WORK_REFINE_ITERATIONS(rec[j].work);
      *any_found |= (flags & ALGRAY_HIT_FOUND) ? 1u << j : 0u;
    }
  }
}

/* The lanes' first `count` pixels into the film from index `at`: the samples' sums times `weight`, and where the
 * film has them the nearest sample's depth and normal. Each vector goes to private storage in one store and the
 * pixels read it from there: read lane by lane (lane_get), the vectors were stored again for every pixel, a fifth
 * of the shading kernel's time in a preview (bench/history/2026-12.md, "Shading stores"). */
ALGRAY_INLINE void store_pixels(size_t at, uint count, REAL weight, LREAL r, LREAL g, LREAL b, LREAL a, LREAL depth,
                                LREAL nx, LREAL ny, LREAL nz, __global float4* film_rgba, __global float* film_depth,
                                __global float* film_normal, uint film_depth_and_normal) {
  REAL red[LANES], green[LANES], blue[LANES], alpha[LANES];
  LANES_STORE(r * weight, red);
  LANES_STORE(g * weight, green);
  LANES_STORE(b * weight, blue);
  LANES_STORE(a * weight, alpha);
  for (uint j = 0; j < count; ++j)
    film_rgba[at + j] = (float4)((float)red[j], (float)green[j], (float)blue[j], (float)alpha[j]);
  if (!film_depth_and_normal) return;
  REAL d[LANES], x[LANES], y[LANES], z[LANES];
  LANES_STORE(depth, d);
  LANES_STORE(nx, x);
  LANES_STORE(ny, y);
  LANES_STORE(nz, z);
  for (uint j = 0; j < count; ++j) {
    film_depth[at + j] = (float)d[j];
    film_normal[3 * (at + j)] = (float)x[j];
    film_normal[3 * (at + j) + 1] = (float)y[j];
    film_normal[3 * (at + j) + 2] = (float)z[j];
  }
}

/* The work-group's totals of every work-item's counts into its ALGRAY_SUMMARY_VALUES numbers of summary: integer
 * sums, the same in any order. Every work-item of the group calls it (a barrier). */
ALGRAY_INLINE void store_group_totals(const uint counts[ALGRAY_SUMMARY_VALUES], __local uint* group_counts,
                                      __global uint* summary) {
  const uint items = ALGRAY_SHADE_GROUP_SIDE * ALGRAY_SHADE_GROUP_SIDE;
  const uint me = get_local_id(1) * ALGRAY_SHADE_GROUP_SIDE + get_local_id(0);
  for (int i = 0; i < ALGRAY_SUMMARY_VALUES; ++i) group_counts[i * items + me] = counts[i];
  barrier(CLK_LOCAL_MEM_FENCE);
  if (me < ALGRAY_SUMMARY_VALUES) {
    uint total = 0;
    for (uint j = 0; j < items; ++j) total += group_counts[me * items + j];
    const size_t group = (size_t)get_group_id(1) * get_num_groups(0) + get_group_id(0);
    summary[group * ALGRAY_SUMMARY_VALUES + me] = total;
  }
}

/* Pixels x0 .. x0 + LANES - 1 (x0 = LANES * global id 0) of tile row y (global id 1), each from its samples x samples
 * camera rays at hits[(y * samples + sy) * tile_w + x * samples + sx] (the primary kernel's records, tile_w x tile_h
 * of them; tile_x0, tile_y0, tile_w and tile_h count traced rays). A pixel's RGBA (and, where film_depth_and_normal,
 * its nearest sample's depth and normal) goes to the film's pixel (tile_x0 / samples + x, tile_y0 / samples + y -
 * film_y0), film_width wide. The camera rays' totals over the image rows [kept_first, kept_end) go to summary,
 * ALGRAY_SUMMARY_VALUES per work-group in the order of ALGRAY_SUMMARY_*. Materials are ALGRAY_MATERIAL_VALUES each,
 * per surface front then back. Light li has the points [light_first[li], light_first[li + 1]) and, where
 * light_occlusion[li] >= 0, the shadow pass's masks in that row of occlusion_masks (occlusion_stride per row),
 * indexed by point_of_hit of the ray; without lights, the headlight. The arguments are ALGRAY_SHADE_ARG_NAMES. */
__kernel __attribute__((reqd_work_group_size(ALGRAY_SHADE_GROUP_SIDE, ALGRAY_SHADE_GROUP_SIDE, 1))) void shade(
    REAL4 ray_o00, REAL4 ray_ou, REAL4 ray_ov, REAL4 ray_d00, REAL4 ray_du, REAL4 ray_dv, uint rays_in_float,
    uint samples, uint tile_x0, uint tile_y0, uint tile_w, uint tile_h, __global const HitRecord* hits,
    __global const uchar* hit_surface, uint several_surfaces, __global const REAL* materials,
    __global const REAL4* light_colours, __global const uint* light_first, __global const int* light_occlusion,
    uint light_count, REAL headlight_ambient, __global const REAL4* light_points, __global const uint* point_of_hit,
    __global const ulong* occlusion_masks, uint occlusion_stride, __global const REAL4* section_planes,
    __global const REAL4* section_looks, __global const int* section_surfaces, uint section_count,
    __global const REAL4* secondary, uint has_secondary, REAL4 background, __global float4* film_rgba,
    __global float* film_depth, __global float* film_normal, uint film_depth_and_normal, uint film_width, uint film_y0,
    uint kept_first, uint kept_end, __global uint* summary) {
#pragma OPENCL FP_CONTRACT OFF
  const uint x0 = get_global_id(0) * LANES, y = get_global_id(1);
  const uint pixels_x = tile_w / samples, pixels_y = tile_h / samples;
  const uint count = y < pixels_y && x0 < pixels_x ? min((uint)LANES, pixels_x - x0) : 0;
  const uint image_y = tile_y0 / samples + y;
  const int kept = image_y >= kept_first && image_y < kept_end;
  uint counts[ALGRAY_SUMMARY_VALUES] = {0, 0, 0, 0, 0, 0, 0};
  if (count > 0) {
    LREAL sum_r = 0, sum_g = 0, sum_b = 0, sum_a = 0;
    LREAL depth = INFINITY, normal_x = 0, normal_y = 0, normal_z = 0;
    uint any_found = 0; /* bit j: some sample of lane j's pixel hit */
    for (uint sy = 0; sy < samples; ++sy)
      for (uint sx = 0; sx < samples; ++sx) {
        HitRecord rec[LANES];
        size_t at[LANES];
        load_records(hits, tile_w, samples, x0, y, sx, sy, count, rec, at, counts, &any_found);
#define REC_FLAG(j) ((LANE_INT)((rec[j].flags & ALGRAY_HIT_FOUND) != 0))
        const LMASK found = LANES_OF(LANE_INT_VEC, REC_FLAG) != 0;
#undef REC_FLAG
        LREAL cr = 0, cg = 0, cb = 0;
        if (LANE_ANY(found)) {
          const LaneRays ray = shade_camera_rays(tile_x0 + x0 * samples + sx, samples, tile_y0 + y * samples + sy,
                                                 rays_in_float, ray_o00, ray_ou, ray_ov, ray_d00, ray_du, ray_dv);
          const LaneHits h = lane_hits(rec, at, &ray, hit_surface, several_surfaces, materials);
          /* where each lane's hit is among the points the shadow pass traced from */
          uint point[LANES];
          for (uint j = 0; j < LANES; ++j) point[j] = occlusion_stride > 0 ? point_of_hit[at[j]] : UINT_MAX;
          shade_lit(&h, &ray, found, light_count, headlight_ambient, light_colours, light_first, light_points,
                    light_occlusion, point, occlusion_masks, occlusion_stride, &cr, &cg, &cb);
          if (section_count > 0)
            draw_sections(&h, &ray, found, (REAL)samples, ray_ou, ray_ov, ray_du, ray_dv, section_planes,
                          section_looks, section_surfaces, section_count, &cr, &cg, &cb);
          if (has_secondary) add_secondary(secondary, at, &cr, &cg, &cb);
#define REC_DEPTH(j) ((REAL)rec[j].depth)
          const LREAL d = LANES_OF(LREAL, REC_DEPTH);
#undef REC_DEPTH
          const LMASK nearer = found && d < depth;
          depth = LANE_SEL(depth, d, nearer);
          normal_x = LANE_SEL(normal_x, h.nx, nearer);
          normal_y = LANE_SEL(normal_y, h.ny, nearer);
          normal_z = LANE_SEL(normal_z, h.nz, nearer);
        }
        sum_r += LANE_SEL((LREAL)background.x, cr, found);
        sum_g += LANE_SEL((LREAL)background.y, cg, found);
        sum_b += LANE_SEL((LREAL)background.z, cb, found);
        sum_a += LANE_SEL((LREAL)background.w, (LREAL)1, found);
      }
    store_pixels((size_t)(image_y - film_y0) * film_width + tile_x0 / samples + x0, count,
                 (REAL)1 / (REAL)(samples * samples), sum_r, sum_g, sum_b, sum_a, depth, normal_x, normal_y, normal_z,
                 film_rgba, film_depth, film_normal, film_depth_and_normal);
    counts[ALGRAY_SUMMARY_RAYS] = count * samples * samples;
    counts[ALGRAY_SUMMARY_PIXELS] = count;
    counts[ALGRAY_SUMMARY_PIXELS_HIT] = popcount(any_found);
    /* a band's extra rows (adaptive antialiasing's neighbours) are counted by the band they belong to */
    if (!kept)
      for (int i = 0; i < ALGRAY_SUMMARY_VALUES; ++i) counts[i] = 0;
  }
  __local uint group_counts[ALGRAY_SUMMARY_VALUES * ALGRAY_SHADE_GROUP_SIDE * ALGRAY_SHADE_GROUP_SIDE];
  store_group_totals(counts, group_counts, summary);
}
