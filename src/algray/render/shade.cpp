// Shading of every traced ray (Phong with area-light shadows, or a headlight), the colour its reflection and
// transmission rays bring back, and the antialiasing resolve.
#include "algray/render/shade.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

namespace algray {
namespace {

// Runs work(begin, end) over [0, count) in parts of `grain` items, which the cores take in turn as they finish
// one: a tile's rows differ widely in how many hits they hold, so equal halves would leave a core idle. Below
// two parts a thread costs more than it saves (starting one is ~50 us), so small counts run here.
template <typename Work>
void parallel_ranges(std::size_t count, std::size_t grain, const Work& work) {
  const std::size_t cores = std::clamp(std::thread::hardware_concurrency(), 1u, 16u);
  const std::size_t parts = (count + grain - 1) / grain;
  if (cores <= 1 || parts <= 1) {
    work(std::size_t{0}, count);
    return;
  }
  std::atomic<std::size_t> next{0};
  auto run = [&] {
    for (std::size_t part = next++; part < parts; part = next++)
      work(part * grain, std::min(count, (part + 1) * grain));
  };
  std::vector<std::thread> workers;
  for (std::size_t t = 1; t < std::min(cores, parts); ++t) workers.emplace_back(run);
  run();
  for (std::thread& w : workers) w.join();
}

}  // namespace

ShadowLookup::ShadowLookup(const ShadowData& data, std::size_t batch_size, std::size_t light_count)
    : by_light_(light_count, nullptr) {
  if (data.points.empty()) return;
  point_of_hit_.assign(batch_size, UINT32_MAX);
  for (std::size_t k = 0; k < data.points.size(); ++k) point_of_hit_[data.points[k]] = static_cast<std::uint32_t>(k);
  for (const LightOcclusion& o : data.occlusion) by_light_[static_cast<std::size_t>(o.light)] = &o;
}

Shader::Shader(const Scene& scene, const RenderPlan& plan, const RayBasis& basis, Precision precision)
    : scene_(scene),
      basis_(basis),
      single_(precision != Precision::Double),
      samples_(std::max(plan.samples, 1)),
      transmits_(plan.find(PassKind::Transmission) != nullptr) {
  // Highlights below 1/4096 of full strength are skipped: they cannot show, and pow() dominates shading.
  for (const SceneSurface& surface : scene.surfaces)
    for (const Material* m : {&surface.materials.front, &surface.materials.back})
      highlight_cutoff_.push_back(std::pow(1.0 / 4096, 1 / m->exponent));
  for (const Light& light : scene.lights) {
    // Preview shades without shadows, so the sample points of an area light differ only in their angles: the
    // grid's centre stands for them (the grid is symmetric about it, so the mean of n.l over the points
    // matches it to first order in the light's size over its distance). Full mode shades every point.
    if (scene.render.preview)
      lights_.push_back({&light, {light.position}});
    else
      lights_.push_back({&light, light.sample_points()});
  }
}

const Material& Shader::material_of(const HitToShade& h) const {
  const Materials& sides = scene_.surfaces[static_cast<std::size_t>(h.surface)].materials;
  return (h.hit->flags & ALGRAY_HIT_BACK) ? sides.back : sides.front;
}

void Shader::shade_hits(const HitToShade* hits, std::size_t count, const ShadowLookup& shadows, glm::dvec3* out) const {
  shade_lit(hits, count, shadows, out);
  if (!scene_.sections.empty()) draw_sections(hits, count, out);
}

// A hit whose pixel the section's curve passes through takes the section's colour: |s(p)| within half the change
// of s(p) = n.p + d from one pixel to the next along x or y (whichever is larger), which draws the curve as an
// unbroken line one pixel wide, as a digital line is; a section `width` pixels wide takes `width` times that band.
// A section of one surface marks that surface's hits only. Moving to the next pixel moves the ray by e = ou + t*du
// (or ov + t*dv) times the samples per pixel at parameter t (docs/outputs.md), and its hit along the tangent
// plane by e - d (N.e)/(N.d). A reflected or transmitted ray starts where an earlier one hit: its t counts from
// there, so the distance back to the eye is added (exactly so along a transmitted ray, which keeps the camera
// ray's direction; the straight distance to a mirror's hit for a reflected one).
void Shader::draw_sections(const HitToShade* hits, std::size_t count, glm::dvec3* out) const {
  for (std::size_t i = 0; i < count; ++i) {
    const HitRecord& h = *hits[i].hit;
    const double t = static_cast<double>(h.t_hi) + static_cast<double>(h.t_lo);
    const glm::dvec3 d = hits[i].ray.direction, p = hits[i].ray.origin + t * d;
    const glm::dvec3 normal(h.normal_x, h.normal_y, h.normal_z);
    const double from_eye =
        hits[i].secondary ? t + glm::length(hits[i].ray.origin - basis_.o00) / glm::length(d) : t;
    glm::dvec3 ex = double(samples_) * (basis_.ou + from_eye * basis_.du),
               ey = double(samples_) * (basis_.ov + from_eye * basis_.dv);
    const double facing = glm::dot(normal, d);
    // At the silhouette the hit runs off along the ray; the move across the image stands for it there.
    if (std::fabs(facing) > 1e-3 * glm::length(d)) {
      ex -= d * (glm::dot(normal, ex) / facing);
      ey -= d * (glm::dot(normal, ey) / facing);
    }
    for (const Section& sec : scene_.sections) {
      if (sec.surface >= 0 && sec.surface != hits[i].surface) continue;
      const glm::dvec3 n(sec.plane);
      const double band = 0.5 * sec.width * std::max(std::fabs(glm::dot(n, ex)), std::fabs(glm::dot(n, ey)));
      if (std::fabs(glm::dot(n, p) + sec.plane.w) <= band) {
        out[i] = sec.colour;
        break;
      }
    }
  }
}

void Shader::shade_lit(const HitToShade* hits, std::size_t count, const ShadowLookup& shadows, glm::dvec3* out) const {
  if (lights_.empty()) {
    // The headlight: no lights, nothing to hide, the colour by how squarely the surface faces the eye.
    for (std::size_t i = 0; i < count; ++i) {
      const Material& m = material_of(hits[i]);
      const HitRecord& h = *hits[i].hit;
      const glm::dvec3 n(h.normal_x, h.normal_y, h.normal_z);
      const glm::dvec3 to_eye = -glm::normalize(hits[i].ray.direction);
      const double own = transmits_ ? 1 - m.transparency : 1.0;
      const double facing = std::fabs(glm::dot(n, to_eye));
      out[i] = own * m.colour * (kPreviewAmbient + (1 - kPreviewAmbient) * facing);
    }
    return;
  }
  for (std::size_t first = 0; first < count; first += kShadeLanes)
    shade_lanes(hits + first, std::min(kShadeLanes, count - first), shadows, out + first);
}

// Phong per light point, kShadeLanes hits at a time in arrays: the loops over lanes have no branches, so the
// compiler runs them in SIMD registers and one hit's square roots and divisions no longer wait on the last
// one's (they were most of a preview's shading time). Each lane does the scalar formula's operations in its
// order (glm's normalize is v * (1 / sqrt(v.v)), its dot ((x + y) + z)); with no contraction into fused
// multiply-adds (-ffp-contract=off) the colours are the scalar code's bit for bit, whatever the vector width.
struct Shader::HitLanes {
  using Lanes = double[kShadeLanes];
  Lanes nx, ny, nz, ex, ey, ez, px, py, pz, cr, cg, cb, own, amb, kd, ks, cutoff, mr, mg, mb;
  const Material* material[kShadeLanes];
  // One light's sums over its points, and a point's reflection term and highlight test. Kept here beside the
  // rest, where the compiler sees that no two arrays overlap.
  Lanes diffuse, specular, r_dot_v;
  bool highlight[kShadeLanes];

  HitLanes(const Shader& shader, const HitToShade* hits, std::size_t count);
  void start_at_ambient();
  void add_light(const LightSamples& ls, const std::uint64_t* hidden, std::size_t count);
  void add_light_point(const glm::dvec3& at, std::size_t s, const std::uint64_t* hidden, std::size_t count);
  void write(std::size_t count, glm::dvec3* out) const;
};

Shader::HitLanes::HitLanes(const Shader& shader, const HitToShade* hits, std::size_t count) {
  for (std::size_t j = 0; j < kShadeLanes; ++j) {
    // Lanes past `count` repeat the first hit, so that every lane computes on ordinary numbers.
    const HitToShade& q = hits[j < count ? j : 0];
    const HitRecord& h = *q.hit;
    const Material& m = shader.material_of(q);
    material[j] = &m;
    nx[j] = h.normal_x;
    ny[j] = h.normal_y;
    nz[j] = h.normal_z;
    const glm::dvec3& d = q.ray.direction;
    ex[j] = d.x;
    ey[j] = d.y;
    ez[j] = d.z;
    const glm::dvec3 point = hit_point(q.ray, h);
    px[j] = point.x;
    py[j] = point.y;
    pz[j] = point.z;
    own[j] = shader.transmits_ ? 1 - m.transparency : 1.0;
    amb[j] = m.ambient;
    kd[j] = m.diffuse;
    ks[j] = m.specular;
    mr[j] = m.colour.r;
    mg[j] = m.colour.g;
    mb[j] = m.colour.b;
    cutoff[j] =
        shader.highlight_cutoff_[static_cast<std::size_t>(2 * q.surface + ((h.flags & ALGRAY_HIT_BACK) ? 1 : 0))];
  }
}

// The direction to the eye in place of the ray's, and the colour at the ambient term.
void Shader::HitLanes::start_at_ambient() {
  for (std::size_t j = 0; j < kShadeLanes; ++j) {
    const double inv = 1.0 / std::sqrt(ex[j] * ex[j] + ey[j] * ey[j] + ez[j] * ez[j]);
    ex[j] = -(ex[j] * inv);
    ey[j] = -(ey[j] * inv);
    ez[j] = -(ez[j] * inv);
    cr[j] = amb[j] * mr[j];
    cg[j] = amb[j] * mg[j];
    cb[j] = amb[j] * mb[j];
  }
}

// hidden[j]: the shadow pass's bits of this light's points for lane j.
void Shader::HitLanes::add_light(const LightSamples& ls, const std::uint64_t* hidden, std::size_t count) {
  for (std::size_t j = 0; j < kShadeLanes; ++j) diffuse[j] = specular[j] = 0;
  for (std::size_t s = 0; s < ls.points.size(); ++s) add_light_point(ls.points[s], s, hidden, count);
  const double share = 1.0 / static_cast<double>(ls.points.size());
  const glm::dvec3 light = ls.light->intensity * ls.light->colour;
  for (std::size_t j = 0; j < kShadeLanes; ++j) {
    const double d = kd[j] * diffuse[j] * share, sp = ks[j] * specular[j] * share;
    cr[j] += light.r * (d * mr[j] + sp);
    cg[j] += light.g * (d * mg[j] + sp);
    cb[j] += light.b * (d * mb[j] + sp);
  }
}

void Shader::HitLanes::add_light_point(const glm::dvec3& at, std::size_t s, const std::uint64_t* hidden,
                                       std::size_t count) {
  // The square roots and divisions first, in a loop of arithmetic alone (which vectorises), then the tests.
  Lanes lx, ly, lz, n_dot_l;
  for (std::size_t j = 0; j < kShadeLanes; ++j) {
    lx[j] = at.x - px[j];
    ly[j] = at.y - py[j];
    lz[j] = at.z - pz[j];
    const double inv = 1.0 / std::sqrt(lx[j] * lx[j] + ly[j] * ly[j] + lz[j] * lz[j]);
    lx[j] *= inv;
    ly[j] *= inv;
    lz[j] *= inv;
    n_dot_l[j] = nx[j] * lx[j] + ny[j] * ly[j] + nz[j] * lz[j];
    const double twice = 2 * n_dot_l[j];
    r_dot_v[j] = (twice * nx[j] - lx[j]) * ex[j] + (twice * ny[j] - ly[j]) * ey[j] + (twice * nz[j] - lz[j]) * ez[j];
  }
  bool any_highlight = false;
  for (std::size_t j = 0; j < kShadeLanes; ++j) {
    // Not hidden by the shadow pass, and in front of the tangent plane (the surface hides it from itself).
    const bool lit = !(hidden[j] >> s & 1u) && !(n_dot_l[j] <= 0);
    if (lit) diffuse[j] += n_dot_l[j];
    highlight[j] = lit && r_dot_v[j] > cutoff[j];
    any_highlight |= highlight[j];
  }
  // pow() only where a highlight can show; below the cutoff it is under 1/4096 of full strength.
  if (any_highlight)
    for (std::size_t j = 0; j < count; ++j)
      if (highlight[j]) specular[j] += std::pow(r_dot_v[j], material[j]->exponent);
}

void Shader::HitLanes::write(std::size_t count, glm::dvec3* out) const {
  for (std::size_t j = 0; j < count; ++j) out[j] = glm::dvec3(own[j] * cr[j], own[j] * cg[j], own[j] * cb[j]);
}

void Shader::shade_lanes(const HitToShade* hits, std::size_t count, const ShadowLookup& shadows,
                         glm::dvec3* out) const {
  HitLanes lanes(*this, hits, count);
  lanes.start_at_ambient();
  for (std::size_t li = 0; li < lights_.size(); ++li) {
    std::uint64_t hidden[kShadeLanes];
    for (std::size_t j = 0; j < kShadeLanes; ++j) hidden[j] = j < count ? shadows.hidden(li, hits[j].hit_index) : 0;
    lanes.add_light(lights_[li], hidden, count);
  }
  lanes.write(count, out);
}

void Shader::add_batch(const SecondaryBatch& batch, std::vector<glm::dvec3>& colour, std::vector<double>& alpha) const {
  const ShadowLookup shadows(batch.shadows, batch.hits.size(), scene_.lights.size());
  const glm::dvec3 background(scene_.image.background);
  // Shaded in parallel, then added in ray order: a sample's sum must not depend on the threads.
  std::vector<glm::dvec3> seen(batch.hits.size(), background);
  parallel_ranges(batch.hits.size(), 2048, [&](std::size_t begin, std::size_t end) {
    std::vector<HitToShade> found;
    std::vector<glm::dvec3> shaded;
    for (std::size_t i = begin; i < end; ++i)
      if (batch.hits[i].flags & ALGRAY_HIT_FOUND)
        found.push_back({&batch.hits[i], batch.hit_surface.empty() ? 0 : batch.hit_surface[i], batch.rays[i], i,
                         batch.pass != PassKind::Antialias});
    shaded.resize(found.size());
    shade_hits(found.data(), found.size(), shadows, shaded.data());
    for (std::size_t f = 0; f < found.size(); ++f) seen[found[f].hit_index] = shaded[f];
  });
  const bool camera_rays = batch.pass == PassKind::Antialias;
  for (std::size_t i = 0; i < batch.hits.size(); ++i) {
    colour[batch.sample[i]] += batch.weight[i] * seen[i];
    if (camera_rays)
      alpha[batch.sample[i]] +=
          batch.weight[i] * ((batch.hits[i].flags & ALGRAY_HIT_FOUND) ? 1.0 : scene_.image.background.a);
  }
}

void Shader::resolve(const TracedBlock& block, FrameImage& film) const {
  const int samples = samples_;
  const double weight = 1.0 / (samples * samples);
  const int px0 = block.x0 / samples, py0 = block.y0 / samples;
  const int pixels_x = block.width / samples, pixels_y = block.height / samples;
  // Rows are independent; shading a 1024x768 frame on one core costs as much as a fifth of the kernel.
  parallel_ranges(static_cast<std::size_t>(pixels_y), 8, [&](std::size_t row_begin, std::size_t row_end) {
    // A row of pixels' traced rays (samples rows of them) are shaded together first, then summed per pixel.
    std::vector<HitToShade> found;
    std::vector<glm::dvec3> shaded;
    std::vector<std::uint32_t> shaded_at(static_cast<std::size_t>(block.width) * samples);
    for (int y = static_cast<int>(row_begin); y < static_cast<int>(row_end); ++y) {
      found.clear();
      for (int sy = 0; sy < samples; ++sy)
        for (int bx = 0; bx < block.width; ++bx) {
          const int by = y * samples + sy;
          const std::size_t k = static_cast<std::size_t>(by) * block.width + bx;
          if (!(block.hits[k].flags & ALGRAY_HIT_FOUND)) continue;
          shaded_at[static_cast<std::size_t>(sy) * block.width + bx] = static_cast<std::uint32_t>(found.size());
          found.push_back({&block.hits[k], block.surface ? block.surface[k] : 0,
                           pixel_ray(basis_, single_, block.x0 + bx, block.y0 + by), k});
        }
      shaded.resize(found.size());
      shade_hits(found.data(), found.size(), *block.shadows, shaded.data());
      for (int x = 0; x < pixels_x; ++x) {
        const std::size_t i = static_cast<std::size_t>(py0 + y - block.film_y0) * film.width + px0 + x;
        float depth = std::numeric_limits<float>::infinity();
        float normal[3] = {0, 0, 0};
        glm::dvec4 sum(0);
        for (int sy = 0; sy < samples; ++sy) {
          for (int sx = 0; sx < samples; ++sx) {
            const int bx = x * samples + sx, by = y * samples + sy;
            const std::size_t k = static_cast<std::size_t>(by) * block.width + bx;
            const HitRecord& h = block.hits[k];
            if (!(h.flags & ALGRAY_HIT_FOUND)) {
              sum += scene_.image.background;
              continue;
            }
            glm::dvec3 colour = shaded[shaded_at[static_cast<std::size_t>(sy) * block.width + bx]];
            if (block.secondary) colour += block.secondary[k];
            sum += glm::dvec4(colour, 1);
            if (h.depth < depth) {
              depth = h.depth;
              normal[0] = h.normal_x;
              normal[1] = h.normal_y;
              normal[2] = h.normal_z;
            }
          }
        }
        for (int c = 0; c < 4; ++c) film.rgba[4 * i + c] = static_cast<float>(sum[c] * weight);
        if (film.depth.empty()) continue;  // a film for PNG outputs only
        film.depth[i] = depth;
        for (int c = 0; c < 3; ++c) film.normal[3 * i + c] = normal[c];
      }
    }
  });
}

void Shader::resolve_refined(std::size_t pixel, const glm::dvec3& colour, double alpha, FrameImage& film) const {
  // Refinement runs with one first ray per pixel, so the weight of the box filter is 1.
  const double weight = 1.0 / (samples_ * samples_);
  glm::dvec4 sum(0);
  sum += glm::dvec4(colour, alpha);
  for (int c = 0; c < 4; ++c) film.rgba[4 * pixel + c] = static_cast<float>(sum[c] * weight);
}

FrameImage make_film(const RenderPlan& plan) { return make_film(plan.width, plan.height, true); }

FrameImage make_film(int width, int height, bool depth_and_normal) {
  FrameImage film;
  film.width = width;
  film.height = height;
  const std::size_t n = static_cast<std::size_t>(film.width) * film.height;
  film.rgba.assign(4 * n, 0.0f);
  if (depth_and_normal) {
    film.depth.assign(n, std::numeric_limits<float>::infinity());
    film.normal.assign(3 * n, 0.0f);
  }
  return film;
}

}  // namespace algray
