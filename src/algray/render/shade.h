// Shading: hit records into colours (Phong with the shadow pass's answers, or a headlight), resolved into the film.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "algray/io/image_io.h"
#include "algray/render/render_plan.h"
#include "algray/render/trace_records.h"
#include "algray/scene/camera.h"
#include "algray/scene/scene.h"

namespace algray {

// Without lights, the share of the colour that does not depend on the angle, so surfaces seen edge-on stay
// visible.
inline constexpr double kPreviewAmbient = 0.2;

// Hits shaded side by side (Shader::shade_lanes): 8 doubles are two AVX-512, four AVX or eight SSE2 registers.
inline constexpr std::size_t kShadeLanes = 8;

// A batch's shadow answers, looked up by the index of a hit in its batch.
class ShadowLookup {
 public:
  ShadowLookup(const ShadowData& data, std::size_t batch_size, std::size_t light_count);
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

// A block of whole pixels of the traced grid and what the passes found there: what the film is made of.
struct TracedBlock {
  int x0 = 0, y0 = 0, width = 0, height = 0;  // in traced rays: plan.samples per pixel side
  const HitRecord* hits = nullptr;            // width x height, row-major
  const std::uint8_t* surface = nullptr;      // which surface each hit; null when the scene has one
  const ShadowLookup* shadows = nullptr;      // of these hits
  const glm::dvec3* secondary = nullptr;      // per ray, what its bounces brought back; null without bounces
  int film_y0 = 0;                            // the image row of the film's first row (a band's film)
};

// The lights and materials of one render, shared by shade_frame, the bounces and the device's shading kernel
// (render/device_shader.h), so all shade alike.
class Shader {
 public:
  Shader(const Scene& scene, const RenderPlan& plan, const RayBasis& basis, Precision precision);
  // Adds what each ray of `batch` saw, times its weight, to colour[sample]: its hit shaded with the batch's
  // shadows, or the background. Antialias batches also add their alpha to alpha[sample].
  void add_batch(const SecondaryBatch& batch, std::vector<glm::dvec3>& colour, std::vector<double>& alpha) const;
  // RGBA, depth and normal of the block's pixels: every ray shaded, then each pixel's antialiasing samples
  // averaged (a box filter). Depth and normal are those of the pixel's nearest sample.
  void resolve(const TracedBlock& block, FrameImage& film) const;
  // Adaptive antialiasing: the colour of output pixel `pixel` becomes what its n x n rays (and their bounces)
  // saw; depth and normal stay the first ray's.
  void resolve_refined(std::size_t pixel, const glm::dvec3& colour, double alpha, FrameImage& film) const;
  // One ray that hit a surface, to be shaded: its record, which surface, the ray, and its index in the batch
  // of hits that `shadows` answers for.
  struct HitToShade {
    const HitRecord* hit;
    int surface;
    PixelRay ray;
    std::size_t hit_index;
    bool secondary = false;  // a reflected or transmitted ray, starting where an earlier one hit
  };
  // Colour of each of `count` hits: the side's own colour (times 1 - transparency, the rest coming from the
  // transmission pass), lit by every light's points that the shadow pass left visible.
  void shade_hits(const HitToShade* hits, std::size_t count, const ShadowLookup& shadows, glm::dvec3* out) const;

  // What the device's shading kernel takes of it (render/device_shader.h): each light with the points it is shaded
  // from (its centre alone in a preview), whether the colour seen through a surface is added (a transmission pass),
  // the highlight cutoff of each surface's side, the rays' precision and the samples per pixel side.
  struct LightSamples {
    const Light* light;
    std::vector<glm::dvec3> points;
  };
  const std::vector<LightSamples>& lights() const { return lights_; }
  bool transmits() const { return transmits_; }
  double highlight_cutoff(std::size_t surface, bool back) const { return highlight_cutoff_[2 * surface + back]; }
  bool single_precision_rays() const { return single_; }
  int samples() const { return samples_; }
  const RayBasis& basis() const { return basis_; }

 private:
  // shade_hits' two steps: the lit colour, then the plane sections drawn over it.
  void shade_lit(const HitToShade* hits, std::size_t count, const ShadowLookup& shadows, glm::dvec3* out) const;
  void draw_sections(const HitToShade* hits, std::size_t count, glm::dvec3* out) const;
  // At most kShadeLanes of them, side by side (count >= 1).
  void shade_lanes(const HitToShade* hits, std::size_t count, const ShadowLookup& shadows, glm::dvec3* out) const;
  struct HitLanes;  // shade_lanes' hits as arrays, one element a lane (shade.cpp)
  const Material& material_of(const HitToShade& h) const;

  const Scene& scene_;
  RayBasis basis_;
  bool single_;
  int samples_;
  bool transmits_;
  std::vector<LightSamples> lights_;
  std::vector<double> highlight_cutoff_;  // per surface, front then back: (r.v) below this adds no highlight
};

// The film with its RGBA, depth and normal channels for the plan's output size: transparent black, no depth.
FrameImage make_film(const RenderPlan& plan);
// The same for width x height pixels; without depth_and_normal only RGBA (all a PNG holds), which at 1024^2
// leaves 16 of the film's 32 MB untouched.
FrameImage make_film(int width, int height, bool depth_and_normal);

}  // namespace algray
