// Kernel arguments set by name: one binder per kernel, over its argument list in kernels/algray_shared.h.
#pragma once

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <string>
#include <vector>

#include "algray/device/cl_runtime.h"
#include "algray/scene/camera.h"
#include "algray/scene/solver_options.h"

namespace algray {

// The names of entry's arguments in the order the kernel declares them (ALGRAY_*_ARG_NAMES); shadow_serial takes
// shadow's. Throws std::invalid_argument for an entry without a list.
const std::vector<std::string>& kernel_arg_names(const std::string& entry);

// Sets one kernel's arguments by their names in the kernel's source; REAL-typed ones follow the build's precision.
// A name the kernel does not declare is a programming error (std::logic_error), caught by the first test that
// takes that path rather than by a silent shift of every later argument.
class KernelBinder {
 public:
  KernelBinder(cl::Kernel& kernel, const std::string& entry, Precision precision);

  template <typename T>
  void plain(const std::string& name, const T& value) {
    kernel_.setArg(index(name), value);
  }
  void real(const std::string& name, double value);
  void real_vec(const std::string& name, const glm::dvec3& value);
  void real_vec4(const std::string& name, const glm::dvec4& value);
  // ray_o00 .. ray_dv, as camera_rays() takes them (kernels/ray.h).
  void ray_basis(const RayBasis& basis);
  // A __global or __constant pointer the build never reads (the screen form's rows elsewhere, `undecided` outside
  // adaptive builds): NULL, as OpenCL allows for such arguments.
  void unused_buffer(const std::string& name);

 private:
  cl_uint index(const std::string& name) const;
  cl::Kernel& kernel_;
  const std::vector<std::string>& names_;
  bool double_;
};

}  // namespace algray
