// The kernels' argument lists as the host reads them, from kernels/algray_shared.h, and the binder over them.
#include "algray/device/kernel_binder.h"

#include <map>
#include <stdexcept>

#include "kernels/algray_shared.h"

namespace algray {

const std::vector<std::string>& kernel_arg_names(const std::string& entry) {
#define ALGRAY_ARG_NAME(name) #name,
  static const std::map<std::string, std::vector<std::string>> lists = {
      {"primary", {ALGRAY_PRIMARY_ARG_NAMES(ALGRAY_ARG_NAME)}},
      {"trace", {ALGRAY_TRACE_ARG_NAMES(ALGRAY_ARG_NAME)}},
      {"shadow", {ALGRAY_SHADOW_ARG_NAMES(ALGRAY_ARG_NAME)}},
      {"shadow_serial", {ALGRAY_SHADOW_ARG_NAMES(ALGRAY_ARG_NAME)}},
      {"probe", {ALGRAY_PROBE_ARG_NAMES(ALGRAY_ARG_NAME)}},
      {"univariate", {ALGRAY_UNIVARIATE_ARG_NAMES(ALGRAY_ARG_NAME)}},
      {"restrict_check", {ALGRAY_RESTRICT_CHECK_ARG_NAMES(ALGRAY_ARG_NAME)}},
      {"shade", {ALGRAY_SHADE_ARG_NAMES(ALGRAY_ARG_NAME)}},
  };
#undef ALGRAY_ARG_NAME
  const auto it = lists.find(entry);
  if (it == lists.end()) throw std::invalid_argument("no argument list for kernel '" + entry + "'");
  return it->second;
}

KernelBinder::KernelBinder(cl::Kernel& kernel, const std::string& entry, Precision precision)
    : kernel_(kernel), names_(kernel_arg_names(entry)), double_(precision == Precision::Double) {}

cl_uint KernelBinder::index(const std::string& name) const {
  for (std::size_t i = 0; i < names_.size(); ++i)
    if (names_[i] == name) return static_cast<cl_uint>(i);
  throw std::logic_error("kernel argument '" + name + "' is not in this kernel's list (kernels/algray_shared.h)");
}

void KernelBinder::real(const std::string& name, double value) {
  if (double_)
    plain(name, value);
  else
    plain(name, static_cast<float>(value));
}

void KernelBinder::real_vec(const std::string& name, const glm::dvec3& v) { real_vec4(name, glm::dvec4(v, 0)); }

void KernelBinder::real_vec4(const std::string& name, const glm::dvec4& v) {
  if (double_)
    plain(name, cl_double4{{v.x, v.y, v.z, v.w}});
  else
    plain(name, cl_float4{{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z),
                           static_cast<float>(v.w)}});
}

void KernelBinder::ray_basis(const RayBasis& b) {
  real_vec("ray_o00", b.o00);
  real_vec("ray_ou", b.ou);
  real_vec("ray_ov", b.ov);
  real_vec("ray_d00", b.d00);
  real_vec("ray_du", b.du);
  real_vec("ray_dv", b.dv);
}

void KernelBinder::unused_buffer(const std::string& name) { kernel_.setArg(index(name), sizeof(cl_mem), nullptr); }

}  // namespace algray
