// Shading of every traced ray (Phong with area-light shadows, or a headlight), the colour its reflection and
// transmission rays bring back, and the antialiasing resolve.
#include "shade.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

#include "large_pages.h"

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
      transmits_(plan.find("transmission") != nullptr) {
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

// Colour of one traced ray that hit the surface: the side's own colour (times 1 - transparency, the rest
// coming from the transmission pass), lit by every light's points that the shadow pass left visible.
glm::dvec3 Shader::shade_hit(const HitRecord& h, int surface, const PixelRay& ray, const ShadowLookup& shadows,
                             std::size_t hit_index) const {
  const Materials& sides = scene_.surfaces[static_cast<std::size_t>(surface)].materials;
  const Material& m = (h.flags & ALGRAY_HIT_BACK) ? sides.back : sides.front;
  const glm::dvec3 n(h.normal_x, h.normal_y, h.normal_z);
  const glm::dvec3 to_eye = -glm::normalize(ray.direction);
  // Without a transmission pass (preview, max_depth = 0) nothing is seen through: the side shows opaque.
  const double own = transmits_ ? 1 - m.transparency : 1.0;
  if (lights_.empty()) {
    const double facing = std::fabs(glm::dot(n, to_eye));
    return own * m.colour * (kPreviewAmbient + (1 - kPreviewAmbient) * facing);
  }
  const glm::dvec3 point = hit_point(ray, h);
  const double highlight_cutoff =
      highlight_cutoff_[static_cast<std::size_t>(2 * surface + ((h.flags & ALGRAY_HIT_BACK) ? 1 : 0))];
  glm::dvec3 c = m.ambient * m.colour;
  for (std::size_t li = 0; li < lights_.size(); ++li) {
    const LightSamples& ls = lights_[li];
    const std::uint64_t hidden = shadows.hidden(li, hit_index);
    double diffuse = 0, specular = 0;
    for (std::size_t s = 0; s < ls.points.size(); ++s) {
      if (hidden >> s & 1u) continue;
      const glm::dvec3 l = glm::normalize(ls.points[s] - point);
      const double n_dot_l = glm::dot(n, l);
      if (n_dot_l <= 0) continue;  // behind the tangent plane: the surface hides it from itself
      diffuse += n_dot_l;
      const double r_dot_v = glm::dot(2 * n_dot_l * n - l, to_eye);
      if (r_dot_v > highlight_cutoff) specular += std::pow(r_dot_v, m.exponent);
    }
    const double share = 1.0 / static_cast<double>(ls.points.size());
    c += ls.light->intensity * ls.light->colour *
         (m.diffuse * diffuse * share * m.colour + m.specular * specular * share);
  }
  return own * c;
}

void Shader::add_batch(const SecondaryBatch& batch, std::vector<glm::dvec3>& colour, std::vector<double>& alpha) const {
  const ShadowLookup shadows(batch.shadows, batch.hits.size(), scene_.lights.size());
  const glm::dvec3 background(scene_.image.background);
  // Shaded in parallel, then added in ray order: a sample's sum must not depend on the threads.
  std::vector<glm::dvec3> seen(batch.hits.size());
  parallel_ranges(batch.hits.size(), 2048, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const HitRecord& h = batch.hits[i];
      seen[i] = (h.flags & ALGRAY_HIT_FOUND)
                    ? shade_hit(h, batch.hit_surface.empty() ? 0 : batch.hit_surface[i], batch.rays[i], shadows, i)
                    : background;
    }
  });
  const bool camera_rays = batch.pass == "antialias";
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
    for (int y = static_cast<int>(row_begin); y < static_cast<int>(row_end); ++y) {
      for (int x = 0; x < pixels_x; ++x) {
        const std::size_t i = static_cast<std::size_t>(py0 + y) * film.width + px0 + x;
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
            const PixelRay ray = pixel_ray(basis_, single_, block.x0 + bx, block.y0 + by);
            glm::dvec3 colour = shade_hit(h, block.surface ? block.surface[k] : 0, ray, *block.shadows, k);
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

glm::dvec3 pixel_direction(const RayBasis& basis, int px, int py) {
  const double fx = px + 0.5, fy = py + 0.5;
  return glm::normalize(basis.d00 + fx * basis.du + fy * basis.dv);
}

FrameImage make_film(const RenderPlan& plan) { return make_film(plan.width, plan.height, true); }

FrameImage make_film(int width, int height, bool depth_and_normal) {
  FrameImage film;
  film.width = width;
  film.height = height;
  const std::size_t n = static_cast<std::size_t>(film.width) * film.height;
  assign_on_huge_pages(film.rgba, 4 * n, 0.0f);
  if (depth_and_normal) {
    assign_on_huge_pages(film.depth, n, std::numeric_limits<float>::infinity());
    assign_on_huge_pages(film.normal, 3 * n, 0.0f);
  }
  return film;
}

FrameImage shade_frame(const Scene& scene, const RenderResult& result) {
  const HitBuffer& hits = result.hits;
  const Shader shader(scene, result.plan, result.basis, result.config.precision);
  RenderPlan plan = result.plan;
  plan.width = hits.width / std::max(plan.samples, 1);
  plan.height = hits.height / std::max(plan.samples, 1);
  FrameImage img = make_film(plan);

  // What reflection and transmission rays add to each traced camera ray: their weight times what they met.
  // Adaptive antialiasing's camera rays are such contributions too, with weights 1/n^2; they also carry alpha.
  std::vector<glm::dvec3> secondary(result.secondary.empty() ? 0 : hits.records.size(), glm::dvec3(0));
  std::vector<glm::dvec3> refined_colour(result.refined.empty() ? 0 : hits.records.size(), glm::dvec3(0));
  std::vector<double> refined_alpha(refined_colour.size(), 0.0);
  std::vector<double> no_alpha;
  for (const SecondaryBatch& batch : result.secondary) {
    if (batch.refinement)
      shader.add_batch(batch, refined_colour, refined_alpha);
    else
      shader.add_batch(batch, secondary, no_alpha);
  }
  const ShadowLookup shadows(result.shadows, hits.records.size(), scene.lights.size());
  TracedBlock block;
  block.width = hits.width;
  block.height = hits.height;
  block.hits = hits.records.data();
  block.surface = hits.surface.empty() ? nullptr : hits.surface.data();
  block.shadows = &shadows;
  block.secondary = secondary.empty() ? nullptr : secondary.data();
  shader.resolve(block, img);
  for (std::size_t k = 0; k < result.refined.size(); ++k)
    if (result.refined[k]) shader.resolve_refined(k, refined_colour[k], refined_alpha[k], img);
  return img;
}

}  // namespace algray
