// Shading of every traced ray (Phong with area-light shadows, or a headlight) and the antialiasing resolve.
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
  const LightOcclusion* occlusion;  // null when the light casts no shadows or the plan traced none
};

// Colour of one traced ray that hit the surface.
glm::dvec3 shade_hit(const Scene& scene, const std::vector<LightSamples>& lights, const HitRecord& h,
                     const glm::dvec3& point, const glm::dvec3& to_eye, std::uint32_t shading_point) {
  const Material& m = (h.flags & ALGRAY_HIT_BACK) ? scene.materials.back : scene.materials.front;
  const glm::dvec3 n(h.normal_x, h.normal_y, h.normal_z);
  if (lights.empty()) {
    const double facing = std::fabs(glm::dot(n, to_eye));
    return m.colour * (kPreviewAmbient + (1 - kPreviewAmbient) * facing);
  }
  glm::dvec3 c = m.ambient * m.colour;
  for (const LightSamples& ls : lights) {
    const std::uint64_t hidden =
        ls.occlusion && shading_point != UINT32_MAX ? ls.occlusion->masks[shading_point] : std::uint64_t{0};
    double diffuse = 0, specular = 0;
    for (std::size_t s = 0; s < ls.points.size(); ++s) {
      if (hidden >> s & 1u) continue;
      const glm::dvec3 l = glm::normalize(ls.points[s] - point);
      const double n_dot_l = glm::dot(n, l);
      if (n_dot_l <= 0) continue;  // behind the tangent plane: the surface hides it from itself
      diffuse += n_dot_l;
      const glm::dvec3 mirrored = 2 * n_dot_l * n - l;
      specular += std::pow(std::max(0.0, glm::dot(mirrored, to_eye)), m.exponent);
    }
    const double share = 1.0 / static_cast<double>(ls.points.size());
    c += ls.light->intensity * ls.light->colour * (m.diffuse * diffuse * share * m.colour + m.specular * specular * share);
  }
  return c;
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
  FrameImage::UintChannel steps{"solver.isolationSteps", std::vector<std::uint32_t>(n)};
  FrameImage::UintChannel iterations{"solver.refineIterations", std::vector<std::uint32_t>(n)};
  FrameImage::UintChannel flags{"solver.flags", std::vector<std::uint32_t>(n)};

  std::vector<LightSamples> lights;
  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    LightSamples ls{&scene.lights[i], scene.lights[i].sample_points(), nullptr};
    for (const LightOcclusion& o : result.occlusion)
      if (o.light == static_cast<int>(i)) ls.occlusion = &o;
    lights.push_back(std::move(ls));
  }
  // Hit index -> shading point of the shadow pass.
  std::vector<std::uint32_t> shading_point;
  if (!result.shading_points.empty()) {
    shading_point.assign(hits.records.size(), UINT32_MAX);
    for (std::size_t k = 0; k < result.shading_points.size(); ++k)
      shading_point[result.shading_points[k]] = static_cast<std::uint32_t>(k);
  }
  const bool single = result.config.precision != Precision::Double;
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
            steps.values[i] += h.work & 0xffffu;
            iterations.values[i] += h.work >> 16;
            flags.values[i] |= h.flags;
            if (!(h.flags & ALGRAY_HIT_FOUND)) {
              sum += scene.image.background;
              continue;
            }
            const PixelRay ray = pixel_ray(result.basis, single, tx, ty);
            const glm::dvec3 to_eye = -glm::normalize(ray.direction);
            const std::uint32_t sp = shading_point.empty() ? UINT32_MAX : shading_point[k];
            sum += glm::dvec4(shade_hit(scene, lights, h, hit_point(ray, h), to_eye, sp), 1);
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
  img.uint_channels = {std::move(steps), std::move(iterations), std::move(flags)};
  return img;
}

}  // namespace algray
