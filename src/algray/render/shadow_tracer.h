// The shadow kernel on a set of surface points: which sample points of a light the surface hides from each.
#pragma once

#include <cstdint>
#include <vector>

#include "algray/device/program_cache.h"
#include "algray/render/device_surface.h"

namespace algray {

struct ShadowAnswer {
  std::vector<std::uint64_t> masks;  // per surface point: bit s set when light point s is hidden
  // Adaptive precision: per surface point, the light points whose answers the float search doubted (their bits
  // in masks mean nothing); empty in other precisions.
  std::vector<std::uint64_t> undecided;
  std::uint64_t rays_traced = 0;  // shadow rays that reached root isolation
  double kernel_ms = 0;
};

// Shadow-casting lights whose sample points share one launch of the shadow kernel: at most 64 points in all, each
// light's a run of bits in the occlusion masks. One launch per group rather than per light lets the kernel's point
// form expand P once per surface point for every light, and fill its lanes across the lights' samples.
struct LightGroup {
  std::vector<glm::dvec3> points;  // the members' sample points, one after another
  struct Member {
    std::size_t light;  // index into the list given to group_lights
    int first_bit, count;
  };
  std::vector<Member> members;
  // Member m's part of a group mask, as its own light's mask.
  std::uint64_t mask_of(const Member& m, std::uint64_t group_mask) const;
};
// Consecutive lights packed greedily; each light has 1 to 64 sample points.
std::vector<LightGroup> group_lights(const std::vector<std::vector<glm::dvec3>>& light_points);

// One batch of surface points and their normals on the device, asked about any number of lights and surfaces.
// Its buffers grow to the largest batch and are then reused, batch after batch.
class ShadowPoints {
 public:
  ShadowPoints(ClSession& session, Precision precision) : session_(session), precision_(precision) {}
  // points and normals: world-space surface points and unit normals on the side the light is looked for from.
  void upload(const std::vector<glm::dvec3>& points, const std::vector<glm::vec3>& normals);
  std::size_t size() const { return count_; }

 private:
  friend class ShadowTracer;
  ClSession& session_;
  Precision precision_;
  std::size_t count_ = 0, capacity_ = 0;
  cl::Buffer points_, normals_, masks_, undecided_;  // undecided_: adaptive precision only
  Real4Staging staging_;  // points and normals before the upload
};

// Built once per render (one program, one upload of the surface), then asked once per light and batch.
class ShadowTracer {
 public:
  // config: the shadow pass's kernel (RenderPlan); offset: how far each shadow ray's origin moves along the
  // normal, in world units.
  ShadowTracer(ClSession& session, ProgramCache& cache, const KernelConfig& config, const DeviceSurface& surface,
               double offset);
  const ProgramRecord& program() const { return record_; }
  // At most 64 light points. already_hidden (empty, or one mask per point): light points another surface
  // hides, which are not traced again and stay set in the answer. The points' precision must be the surface's.
  ShadowAnswer trace(ShadowPoints& points, const std::vector<glm::dvec3>& light_points,
                     const std::vector<std::uint64_t>& already_hidden = {});
  // The same for points given here (uploaded for this one question).
  ShadowAnswer trace(const std::vector<glm::dvec3>& points, const std::vector<glm::vec3>& normals,
                     const std::vector<glm::dvec3>& light_points,
                     const std::vector<std::uint64_t>& already_hidden = {});

 private:
  ClSession& session_;
  const DeviceSurface& surface_;
  double offset_;
  ProgramRecord record_;
  std::string entry_;  // shadow or shadow_serial: whose argument list the kernel has
  cl::Kernel kernel_;
  std::size_t largest_group_ = 1;  // the kernel's work-group limit on the device
  cl::Buffer traced_;              // the kernel's count of traced rays
};

}  // namespace algray
