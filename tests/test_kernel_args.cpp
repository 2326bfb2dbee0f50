// Each kernel's argument names, as the driver reads them from the source, against the list the host sets them by
// (kernels/algray_shared.h): a kernel that gains, loses or reorders an argument fails here, not in a render.
#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "algray/device/kernel_binder.h"
#include "algray/device/kernel_config.h"
#include "algray/device/kernel_sources.h"
#include "test_support.h"

using namespace algray;

namespace {

// The names entry's kernel declares in this build, in order (-cl-kernel-arg-info keeps them in the program).
std::vector<std::string> declared_names(ClSession& session, const KernelConfig& config) {
  cl::Program program(session.context, assemble_kernel_source(config.source_file()));
  const std::string options = config.build_options() + " -cl-kernel-arg-info";
  try {
    program.build({session.info.device}, options.c_str());
  } catch (const cl::Error&) {
    FAIL("kernel " << config.key() << " did not build with " << options << ":\n"
                   << program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(session.info.device));
  }
  cl::Kernel kernel(program, config.entry.c_str());
  std::vector<std::string> names;
  const cl_uint count = kernel.getInfo<CL_KERNEL_NUM_ARGS>();
  for (cl_uint i = 0; i < count; ++i) {
    std::string name = kernel.getArgInfo<CL_KERNEL_ARG_NAME>(i);
    name.resize(std::char_traits<char>::length(name.c_str()));  // drivers may count the terminating NUL
    names.push_back(name);
  }
  return names;
}

KernelConfig config_of(const std::string& entry, Precision precision, RayOrigin origin, int lanes) {
  KernelConfig c;
  c.entry = entry;
  c.precision = precision;
  c.degree = 2;
  c.ray_origin = origin;
  c.lanes = lanes;
  return c;
}

}  // namespace

TEST_CASE("every kernel declares the arguments the host sets by name, in every kind of build") {
  ClSession& session = testing::device_session();
  // The builds whose code paths differ most: plain, the screen form, adaptive (which alone reads `undecided`),
  // the point form of shadow rays, and lanes.
  const std::vector<KernelConfig> configs = {
      config_of("primary", Precision::Float, RayOrigin::Extent, 1),
      config_of("primary", Precision::Double, RayOrigin::Screen, 8),
      config_of("primary", Precision::Adaptive, RayOrigin::Extent, 8),
      config_of("primary", Precision::Adaptive, RayOrigin::Screen, 16),
      config_of("trace", Precision::Mixed, RayOrigin::Extent, 1),
      config_of("shadow", Precision::Adaptive, RayOrigin::Extent, 1),
      config_of("shadow", Precision::Double, RayOrigin::Point, 8),
      config_of("shadow_serial", Precision::Float, RayOrigin::Extent, 1),
      config_of("probe", Precision::Double, RayOrigin::Screen, 1),
      config_of("univariate", Precision::Float, RayOrigin::Extent, 1),
      config_of("restrict_check", Precision::Double, RayOrigin::Extent, 1),
      config_of("shade", Precision::Float, RayOrigin::Extent, 16),
      config_of("shade", Precision::Double, RayOrigin::Extent, 1),
  };
  for (const KernelConfig& config : configs) {
    INFO("kernel " << config.key());
    CHECK(declared_names(session, config) == kernel_arg_names(config.entry));
  }
}

TEST_CASE("a binder refuses a name its kernel does not declare") {
  CHECK_THROWS_AS(kernel_arg_names("no_such_kernel"), std::invalid_argument);
  ClSession& session = testing::device_session();
  const KernelConfig config = config_of("univariate", Precision::Float, RayOrigin::Extent, 1);
  cl::Program program(session.context, assemble_kernel_source(config.source_file()));
  program.build({session.info.device}, config.build_options().c_str());
  cl::Kernel kernel(program, "univariate");
  KernelBinder args(kernel, "univariate", Precision::Float);
  CHECK_NOTHROW(args.plain("count", cl_uint{1}));
  CHECK_THROWS_AS(args.plain("cuont", cl_uint{1}), std::logic_error);
}
