// Shading of every traced ray (Phong with area-light shadows, or a headlight), the colour its reflection and
// transmission rays bring back, and the antialiasing resolve.
#include "shade.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

namespace algray {
namespace {

struct LightSamples {
  const Light* light;
  std::vector<glm::dvec3> points;
};

// A batch's shadow answers, looked up by the index of a hit in its batch.
class ShadowLookup {
 public:
  ShadowLookup(const ShadowData& data, std::size_t batch_size, const std::vector<Light>& lights)
      : by_light_(lights.size(), nullptr) {
    if (data.points.empty()) return;
    point_of_hit_.assign(batch_size, UINT32_MAX);
    for (std::size_t k = 0; k < data.points.size(); ++k) point_of_hit_[data.points[k]] = static_cast<std::uint32_t>(k);
    for (const LightOcclusion& o : data.occlusion) by_light_[static_cast<std::size_t>(o.light)] = &o;
  }
  // Bit s set when the shadow pass found light point s of light `light` hidden from hit `hit`.
  std::uint64_t hidden(std::size_t light, std::size_t hit) const {
    const LightOcclusion* o = by_light_[light];
    if (!o || point_of_hit_.empty() || point_of_hit_[hit] == UINT32_MAX) return 0;
    return o->masks[point_of_hit_[hit]];
  }

 private:
  std::vector<const LightOcclusion*> by_light_;
  std::vector<std::uint32_t> point_of_hit_;
};

// Colour of one traced ray that hit the surface: the side's own colour (times 1 - transparency, the rest
// coming from the transmission pass), lit by every light's points that the shadow pass left visible.
glm::dvec3 shade_hit(const Scene& scene, const std::vector<LightSamples>& lights, const HitRecord& h, int surface,
                     const glm::dvec3& point, const glm::dvec3& to_eye, const ShadowLookup& shadows,
                     std::size_t hit_index, bool transmits) {
  const Materials& sides = scene.surfaces[static_cast<std::size_t>(surface)].materials;
  const Material& m = (h.flags & ALGRAY_HIT_BACK) ? sides.back : sides.front;
  const glm::dvec3 n(h.normal_x, h.normal_y, h.normal_z);
  // Without a transmission pass (preview, max_depth = 0) nothing is seen through: the side shows opaque.
  const double own = transmits ? 1 - m.transparency : 1.0;
  if (lights.empty()) {
    const double facing = std::fabs(glm::dot(n, to_eye));
    return own * m.colour * (kPreviewAmbient + (1 - kPreviewAmbient) * facing);
  }
  // Highlights below 1/4096 of full strength are skipped: they cannot show, and pow() dominates shading.
  const double highlight_cutoff = std::pow(1.0 / 4096, 1 / m.exponent);
  glm::dvec3 c = m.ambient * m.colour;
  for (std::size_t li = 0; li < lights.size(); ++li) {
    const LightSamples& ls = lights[li];
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

}  // namespace

glm::dvec3 pixel_direction(const RayBasis& basis, int px, int py) {
  const double fx = px + 0.5, fy = py + 0.5;
  return glm::normalize(basis.d00 + fx * basis.du + fy * basis.dv);
}

FrameImage shade_frame(const Scene& scene, const RenderResult& result) {
  const HitBuffer& hits = result.hits;
  const int samples = result.plan.samples;
  FrameImage img;
  img.width = hits.width / samples;
  img.height = hits.height / samples;
  const std::size_t n = static_cast<std::size_t>(img.width) * img.height;
  img.rgba.assign(4 * n, 0.0f);
  img.depth.assign(n, std::numeric_limits<float>::infinity());
  img.normal.assign(3 * n, 0.0f);

  std::vector<LightSamples> lights;
  for (const Light& light : scene.lights) lights.push_back({&light, light.sample_points()});
  const ShadowLookup primary_shadows(result.shadows, hits.records.size(), scene.lights);
  const bool single = result.config.precision != Precision::Double;
  const bool transmits = result.plan.find("transmission") != nullptr;

  // What reflection and transmission rays add to each traced camera ray: their weight times what they met.
  // Adaptive antialiasing's camera rays are such contributions too, with weights 1/n^2; they also carry alpha.
  std::vector<glm::dvec3> secondary(result.secondary.empty() ? 0 : hits.records.size(), glm::dvec3(0));
  std::vector<glm::dvec3> refined_colour(result.refined.empty() ? 0 : hits.records.size(), glm::dvec3(0));
  std::vector<double> refined_alpha(refined_colour.size(), 0.0);
  for (const SecondaryBatch& batch : result.secondary) {
    const ShadowLookup batch_shadows(batch.shadows, batch.hits.size(), scene.lights);
    for (std::size_t i = 0; i < batch.hits.size(); ++i) {
      const HitRecord& h = batch.hits[i];
      const glm::dvec3 seen = (h.flags & ALGRAY_HIT_FOUND)
                                  ? shade_hit(scene, lights, h, batch.hit_surface.empty() ? 0 : batch.hit_surface[i],
                                              hit_point(batch.rays[i], h), -glm::normalize(batch.rays[i].direction),
                                              batch_shadows, i, transmits)
                                  : glm::dvec3(scene.image.background);
      (batch.refinement ? refined_colour : secondary)[batch.sample[i]] += batch.weight[i] * seen;
      if (batch.pass == "antialias")
        refined_alpha[batch.sample[i]] +=
            batch.weight[i] * ((h.flags & ALGRAY_HIT_FOUND) ? 1.0 : scene.image.background.a);
    }
  }
  const double weight = 1.0 / (samples * samples);

  // Rows are independent; shading a 1024x768 frame on one core costs as much as a fifth of the kernel.
  auto shade_rows = [&](int y_begin, int y_end) {
    for (int y = y_begin; y < y_end; ++y) {
      for (int x = 0; x < img.width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * img.width + x;
        glm::dvec4 sum(0);
        for (int sy = 0; sy < samples; ++sy) {
          for (int sx = 0; sx < samples; ++sx) {
            const int tx = x * samples + sx, ty = y * samples + sy;
            const std::size_t k = static_cast<std::size_t>(ty) * hits.width + tx;
            const HitRecord& h = hits.records[k];
            if (!result.refined.empty() && result.refined[k]) {
              // Its colour is what the antialias batch's n x n rays (and their bounces) saw.
              sum += glm::dvec4(refined_colour[k], refined_alpha[k]);
              if (h.flags & ALGRAY_HIT_FOUND) {
                img.depth[i] = h.depth;
                img.normal[3 * i] = h.normal_x;
                img.normal[3 * i + 1] = h.normal_y;
                img.normal[3 * i + 2] = h.normal_z;
              }
              continue;
            }
            if (!(h.flags & ALGRAY_HIT_FOUND)) {
              sum += scene.image.background;
              continue;
            }
            const PixelRay ray = pixel_ray(result.basis, single, tx, ty);
            const glm::dvec3 to_eye = -glm::normalize(ray.direction);
            glm::dvec3 colour = shade_hit(scene, lights, h, hits.surface_of(k), hit_point(ray, h), to_eye,
                                          primary_shadows, k, transmits);
            if (!secondary.empty()) colour += secondary[k];
            sum += glm::dvec4(colour, 1);
            if (h.depth < img.depth[i]) {
              img.depth[i] = h.depth;
              img.normal[3 * i] = h.normal_x;
              img.normal[3 * i + 1] = h.normal_y;
              img.normal[3 * i + 2] = h.normal_z;
            }
          }
        }
        for (int c = 0; c < 4; ++c) img.rgba[4 * i + c] = static_cast<float>(sum[c] * weight);
      }
    }
  };
  const int threads = static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 16u));
  std::vector<std::thread> workers;
  for (int t = 1; t < threads; ++t)
    workers.emplace_back(shade_rows, img.height * t / threads, img.height * (t + 1) / threads);
  shade_rows(0, img.height / threads);
  for (std::thread& w : workers) w.join();
  return img;
}

}  // namespace algray
