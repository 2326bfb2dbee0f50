// The surface on the device as every kernel takes it, and the helpers that set kernel arguments.
#pragma once

#include <memory>
#include <vector>

#include "algray/device/cl_runtime.h"
#include "algray/device/kernel_binder.h"
#include "algray/device/kernel_config.h"
#include "algray/scene/scene.h"

namespace algray {

// The polynomial as the kernels see it: in unit coordinates of the extent, scaled to max |coefficient| = 1.
struct SurfaceData {
  int degree = 0;
  std::vector<cl_uint> exponents;  // i | j << 8 | k << 16, sorted by i, j, k descending
  std::vector<double> coefficients;
  cl_uint even_axes = 0;  // bit a set when every exponent of axis a is even (the kernels then step by squares)
};
SurfaceData prepare_surface(const Scene& scene, std::size_t surface = 0);

// Device time of a finished command, in milliseconds (the queue has profiling on).
double ms_between(const cl::Event& e);

// A launch of one work-item per ray for `count` rays, in work-groups of a fixed size and rows of a fixed width
// (kernels/ray.h launch_item_index numbers them); the kernels skip the items past `count`. The driver's own choice
// would follow each count, and PoCL compiles a work-group function for every group size it meets: a render's batches
// come in many sizes, and each new one cost a second or more. `largest_group` is the kernel's CL_KERNEL_WORK_GROUP_SIZE
// on the device.
struct RayLaunch {
  cl::NDRange global, local;
};
RayLaunch ray_launch(std::size_t count, std::size_t largest_group);
// The launch that covers a width x height tile of camera rays, `lanes` pixels of a row per work-item
// (kernels/primary.cl), in work-groups of a fixed shape for the same reason: tiles at the image's right and
// bottom edges are narrower and shorter.
RayLaunch primary_launch(int lanes, int width, int height, std::size_t largest_group);
std::size_t largest_group(const cl::Kernel& kernel, const cl::Device& device);

// Buffer of REAL values (double, or float for float and mixed precision) from doubles.
cl::Buffer real_buffer(const cl::Context& ctx, const std::vector<double>& values, Precision precision);
// Buffer of REAL4 values (x, y, z, 0) from points or directions.
cl::Buffer real4_buffer(const cl::Context& ctx, const std::vector<glm::dvec3>& values, Precision precision);

// REAL4 values (x, y, z, 0) on their way to a device, in double or in float: each component rounded to the
// kernel's REAL on its own. Kept by a tracer between batches, so that its uploads allocate nothing.
class Real4Staging {
 public:
  // vector_of(i) for i < count, packed in double (in_double) or float.
  template <typename VectorOf>
  void pack(std::size_t count, bool in_double, VectorOf vector_of) {
    in_double_ = in_double;
    count_ = count;
    if (in_double)
      fill(doubles_, vector_of);
    else
      fill(floats_, vector_of);
  }
  // Writes what pack() holds to the start of `buffer`, blocking.
  void write(cl::CommandQueue& queue, const cl::Buffer& buffer) const;
  const void* data() const { return in_double_ ? static_cast<const void*>(doubles_.data()) : floats_.data(); }
  std::size_t bytes() const { return 4 * count_ * (in_double_ ? sizeof(double) : sizeof(float)); }

 private:
  template <typename T, typename VectorOf>
  void fill(std::vector<T>& out, VectorOf vector_of) {
    out.resize(4 * count_);
    for (std::size_t i = 0; i < count_; ++i) {
      const glm::dvec3 v = vector_of(i);
      out[4 * i] = static_cast<T>(v.x);
      out[4 * i + 1] = static_cast<T>(v.y);
      out[4 * i + 2] = static_cast<T>(v.z);
      out[4 * i + 3] = 0;
    }
  }
  bool in_double_ = true;
  std::size_t count_ = 0;
  std::vector<double> doubles_;
  std::vector<float> floats_;
};

// One surface's buffers in one precision, shared by every pass's kernel.
class DeviceSurface {
 public:
  DeviceSurface(const cl::Context& ctx, const Scene& scene, Precision precision, std::size_t surface = 0);
  Precision precision() const { return precision_; }
  const SurfaceData& data() const { return data_; }
  // The extent's and the surface's arguments of every kernel (ALGRAY_EXTENT_ARGS, ALGRAY_SURFACE_ARGS); the
  // extent's include its clipping planes, a count of 0 where there are none.
  void set_extent_args(KernelBinder& args) const;
  void set_surface_args(KernelBinder& args) const;
  // The screen form's arguments of the primary and probe kernels (ALGRAY_SCREEN_ARGS): rows row0 .. row0 + rows - 1
  // of the width x height camera image of `basis`; unused values for other builds. The kernel reads the returned
  // buffer: keep it until the launches are done.
  cl::Buffer set_screen_args(KernelBinder& args, const cl::Context& ctx, const KernelConfig& config,
                             const RayBasis& basis, int width, int height, int row0, int rows) const;

 private:
  Precision precision_;
  Extent extent_;
  SurfaceData data_;
  cl::Buffer exps_, coefs_, binomials_;
  cl::Buffer clips_;  // the extent's clipping planes in unit coordinates (REAL4 each); none without planes
  // The screen form of the last camera set_screen_args saw: a render asks for it band by band, and expanding P
  // along the rays again for each band would repeat the costliest step.
  struct ScreenCache;
  mutable std::shared_ptr<const ScreenCache> screen_;
};

}  // namespace algray
