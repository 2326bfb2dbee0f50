// The shading kernel's host side: the scene's materials, lights and sections on the device, the film bound, and a
// tile's shadow answers and bounces uploaded for it.
#include "algray/render/device_shader.h"

#include <algorithm>
#include <climits>

#include "algray/device/kernel_binder.h"
#include "algray/render/device_surface.h"
#include "algray/render/render_plan.h"

namespace algray {
namespace {

// OpenCL buffers cannot be empty: a list with nothing in it still gets one element, which the kernel never reads.
template <typename T>
cl::Buffer constant_buffer(const cl::Context& context, std::vector<T> values) {
  if (values.empty()) values.resize(1);
  return cl::Buffer(context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, values.size() * sizeof(T), values.data());
}

std::size_t round_up(std::size_t n, std::size_t to) { return (n + to - 1) / to * to; }

}  // namespace

DeviceShader::DeviceShader(ClSession& session, ProgramCache& cache, const Scene& scene, const Shader& shader)
    : session_(session), samples_(shader.samples()) {
  const KernelConfig config = shading_config(session.info);
  precision_ = config.precision;
  lanes_ = config.lanes;
  kernel_ = cache.kernel(session, config, &program_);
  const Precision precision = config.precision;
  const cl::Context& context = session.context;

  std::vector<double> materials;
  for (std::size_t s = 0; s < scene.surfaces.size(); ++s)
    for (const bool back : {false, true}) {
      const Materials& sides = scene.surfaces[s].materials;
      const Material& m = back ? sides.back : sides.front;
      const double values[ALGRAY_MATERIAL_VALUES] = {
          m.colour.r, m.colour.g,  m.colour.b, m.ambient, m.diffuse, m.specular, m.exponent,
          shader.transmits() ? 1 - m.transparency : 1.0, shader.highlight_cutoff(s, back)};
      materials.insert(materials.end(), values, values + ALGRAY_MATERIAL_VALUES);
    }
  materials_ = real_buffer(context, materials, precision);

  // The shadow pass answers for the plan's shadow-casting lights, in its order (ShadowData::occlusion).
  occlusion_row_.assign(scene.lights.size(), -1);
  std::vector<double> colours, points;
  std::vector<cl_uint> first{0};
  for (const Shader::LightSamples& ls : shader.lights()) {
    const glm::dvec3 light = ls.light->intensity * ls.light->colour;
    colours.insert(colours.end(), {light.r, light.g, light.b, 0});
    for (const glm::dvec3& p : ls.points) points.insert(points.end(), {p.x, p.y, p.z, 0});
    first.push_back(static_cast<cl_uint>(first.back() + ls.points.size()));
  }
  light_colours_ = real_buffer(context, colours.empty() ? std::vector<double>(4) : colours, precision);
  light_points_ = real_buffer(context, points.empty() ? std::vector<double>(4) : points, precision);
  light_first_ = constant_buffer(context, first);
  // A tile's rows of shadow answers (per scene light, written with each tile): none until a shadow pass gives some.
  light_occlusion_ = constant_buffer(context, occlusion_row_);

  std::vector<double> planes, looks;
  std::vector<cl_int> surfaces;
  for (const Section& sec : scene.sections) {
    planes.insert(planes.end(), {sec.plane.x, sec.plane.y, sec.plane.z, sec.plane.w});
    looks.insert(looks.end(), {sec.colour.r, sec.colour.g, sec.colour.b, sec.width});
    surfaces.push_back(sec.surface);
  }
  section_planes_ = real_buffer(context, planes.empty() ? std::vector<double>(4) : planes, precision);
  section_looks_ = real_buffer(context, looks.empty() ? std::vector<double>(4) : looks, precision);
  section_surfaces_ = constant_buffer(context, surfaces);

  KernelBinder args(kernel_, "shade", precision);
  args.ray_basis(shader.basis());
  args.plain("rays_in_float", static_cast<cl_uint>(shader.single_precision_rays()));
  args.plain("samples", static_cast<cl_uint>(samples_));
  args.plain("several_surfaces", static_cast<cl_uint>(scene.surfaces.size() > 1));
  args.plain("materials", materials_);
  args.plain("light_colours", light_colours_);
  args.plain("light_first", light_first_);
  args.plain("light_occlusion", light_occlusion_);
  args.plain("light_count", static_cast<cl_uint>(shader.lights().size()));
  args.real("headlight_ambient", kPreviewAmbient);
  args.plain("light_points", light_points_);
  args.plain("section_planes", section_planes_);
  args.plain("section_looks", section_looks_);
  args.plain("section_surfaces", section_surfaces_);
  args.plain("section_count", static_cast<cl_uint>(scene.sections.size()));
  const glm::dvec4& background = scene.image.background;
  args.real_vec4("background", background);
}

void DeviceShader::ensure(cl::Buffer& buffer, std::size_t& capacity, std::size_t bytes, cl_mem_flags flags) {
  bytes = std::max<std::size_t>(bytes, 16);
  if (capacity >= bytes) return;
  buffer = cl::Buffer(session_.context, flags, bytes);
  capacity = bytes;
}

void DeviceShader::bind_film(FrameImage& film, int film_y0, bool alone) {
  film_ = &film;
  film_y0_ = film_y0;
  alone_ = alone;
  const std::size_t pixels = static_cast<std::size_t>(film.width) * film.height;
  const bool depth_and_normal = !film.depth.empty();
  if (alone) {
    // The film's own memory: on a CPU the kernel writes it in place.
    film_rgba_ = cl::Buffer(session_.context, CL_MEM_WRITE_ONLY | CL_MEM_USE_HOST_PTR, film.rgba.size() * sizeof(float),
                            film.rgba.data());
    film_rgba_bytes_ = 0;
    if (depth_and_normal) {
      film_depth_ = cl::Buffer(session_.context, CL_MEM_WRITE_ONLY | CL_MEM_USE_HOST_PTR,
                               film.depth.size() * sizeof(float), film.depth.data());
      film_normal_ = cl::Buffer(session_.context, CL_MEM_WRITE_ONLY | CL_MEM_USE_HOST_PTR,
                                film.normal.size() * sizeof(float), film.normal.data());
      film_depth_bytes_ = film_normal_bytes_ = 0;
    }
  } else {
    ensure(film_rgba_, film_rgba_bytes_, 4 * pixels * sizeof(float), CL_MEM_WRITE_ONLY);
    if (depth_and_normal) {
      ensure(film_depth_, film_depth_bytes_, pixels * sizeof(float), CL_MEM_WRITE_ONLY);
      ensure(film_normal_, film_normal_bytes_, 3 * pixels * sizeof(float), CL_MEM_WRITE_ONLY);
    }
  }
  if (!depth_and_normal) {
    // Never written: the kernel is told the film has no depth and normal.
    ensure(film_depth_, film_depth_bytes_, 0, CL_MEM_WRITE_ONLY);
    ensure(film_normal_, film_normal_bytes_, 0, CL_MEM_WRITE_ONLY);
  }
  KernelBinder args(kernel_, "shade", precision_);
  args.plain("film_rgba", film_rgba_);
  args.plain("film_depth", film_depth_);
  args.plain("film_normal", film_normal_);
  args.plain("film_depth_and_normal", static_cast<cl_uint>(depth_and_normal));
  args.plain("film_width", static_cast<cl_uint>(film.width));
  args.plain("film_y0", static_cast<cl_uint>(film_y0));
}

void DeviceShader::upload_shadows(const ShadeTile& tile) {
  const std::size_t rays = static_cast<std::size_t>(tile.trace_w) * tile.trace_h;
  const ShadowData* data = tile.shadows;
  std::fill(occlusion_row_.begin(), occlusion_row_.end(), -1);
  const std::size_t points = data ? data->points.size() : 0;
  if (points > 0) {
    point_of_hit_staging_.assign(rays, UINT32_MAX);
    for (std::size_t k = 0; k < points; ++k) point_of_hit_staging_[data->points[k]] = static_cast<std::uint32_t>(k);
    masks_staging_.resize(data->occlusion.size() * points);
    for (std::size_t row = 0; row < data->occlusion.size(); ++row) {
      occlusion_row_[static_cast<std::size_t>(data->occlusion[row].light)] = static_cast<int>(row);
      std::copy(data->occlusion[row].masks.begin(), data->occlusion[row].masks.end(),
                masks_staging_.begin() + static_cast<std::ptrdiff_t>(row * points));
    }
    ensure(point_of_hit_, point_of_hit_bytes_, rays * sizeof(std::uint32_t), CL_MEM_READ_ONLY);
    ensure(masks_, masks_bytes_, masks_staging_.size() * sizeof(std::uint64_t), CL_MEM_READ_ONLY);
    session_.queue.enqueueWriteBuffer(point_of_hit_, CL_FALSE, 0, rays * sizeof(std::uint32_t),
                                      point_of_hit_staging_.data());
    session_.queue.enqueueWriteBuffer(masks_, CL_FALSE, 0, masks_staging_.size() * sizeof(std::uint64_t),
                                      masks_staging_.data());
  } else {
    ensure(point_of_hit_, point_of_hit_bytes_, 0, CL_MEM_READ_ONLY);
    ensure(masks_, masks_bytes_, 0, CL_MEM_READ_ONLY);
  }
  if (!occlusion_row_.empty())
    session_.queue.enqueueWriteBuffer(light_occlusion_, CL_FALSE, 0, occlusion_row_.size() * sizeof(cl_int),
                                      occlusion_row_.data());
  KernelBinder args(kernel_, "shade", precision_);
  args.plain("point_of_hit", point_of_hit_);
  args.plain("occlusion_masks", masks_);
  args.plain("occlusion_stride", static_cast<cl_uint>(points));
}

void DeviceShader::read_back_tile(const ShadeTile& tile) {
  // The tile's pixels, rows of the film: one rectangular read per channel.
  const std::size_t x0 = static_cast<std::size_t>(tile.trace_x0 / samples_);
  const std::size_t y0 = static_cast<std::size_t>(tile.trace_y0 / samples_ - film_y0_);
  const std::size_t w = static_cast<std::size_t>(tile.trace_w / samples_), h = static_cast<std::size_t>(tile.trace_h / samples_);
  const std::size_t row = static_cast<std::size_t>(film_->width);
  auto read = [&](const cl::Buffer& buffer, float* host, std::size_t per_pixel) {
    const std::size_t pixel_bytes = per_pixel * sizeof(float);
    const cl::array<cl::size_type, 3> origin{x0 * pixel_bytes, y0, 0}, region{w * pixel_bytes, h, 1};
    session_.queue.enqueueReadBufferRect(buffer, CL_TRUE, origin, origin, region, row * pixel_bytes, 0,
                                         row * pixel_bytes, 0, host);
  };
  read(film_rgba_, film_->rgba.data(), 4);
  if (!film_->depth.empty()) {
    read(film_depth_, film_->depth.data(), 1);
    read(film_normal_, film_->normal.data(), 3);
  }
}

PrimarySummary DeviceShader::shade(const ShadeTile& tile, double& kernel_ms) {
  const std::size_t rays = static_cast<std::size_t>(tile.trace_w) * tile.trace_h;
  const std::size_t pixels_x = static_cast<std::size_t>(tile.trace_w / samples_),
                    pixels_y = static_cast<std::size_t>(tile.trace_h / samples_);
  const std::size_t side = ALGRAY_SHADE_GROUP_SIDE;
  // LANES pixels of a row per work-item, in square groups.
  const std::size_t items_x = (pixels_x + static_cast<std::size_t>(lanes_) - 1) / static_cast<std::size_t>(lanes_);
  const std::size_t groups = round_up(items_x, side) / side * (round_up(pixels_y, side) / side);
  KernelBinder args(kernel_, "shade", precision_);
  args.plain("tile_x0", static_cast<cl_uint>(tile.trace_x0));
  args.plain("tile_y0", static_cast<cl_uint>(tile.trace_y0));
  args.plain("tile_w", static_cast<cl_uint>(tile.trace_w));
  args.plain("tile_h", static_cast<cl_uint>(tile.trace_h));
  args.plain("hits", *tile.hits);
  ensure(surface_, surface_bytes_, tile.surface ? rays : 0, CL_MEM_READ_ONLY);
  if (tile.surface) session_.queue.enqueueWriteBuffer(surface_, CL_FALSE, 0, rays, tile.surface);
  args.plain("hit_surface", surface_);
  upload_shadows(tile);
  if (tile.secondary) {
    secondary_staging_.pack(rays, precision_ == Precision::Double, [&](std::size_t k) { return tile.secondary[k]; });
    ensure(secondary_, secondary_bytes_, secondary_staging_.bytes(), CL_MEM_READ_ONLY);
    secondary_staging_.write(session_.queue, secondary_);
  } else {
    ensure(secondary_, secondary_bytes_, 0, CL_MEM_READ_ONLY);
  }
  args.plain("secondary", secondary_);
  args.plain("has_secondary", static_cast<cl_uint>(tile.secondary != nullptr));
  args.plain("kept_first", static_cast<cl_uint>(std::max(tile.kept_first, 0)));
  args.plain("kept_end", static_cast<cl_uint>(std::max(tile.kept_end, 0)));
  ensure(summary_, summary_bytes_, groups * ALGRAY_SUMMARY_VALUES * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
  args.plain("summary", summary_);

  cl::Event done;
  session_.queue.enqueueNDRangeKernel(kernel_, cl::NullRange, cl::NDRange(round_up(items_x, side), round_up(pixels_y, side)),
                                      cl::NDRange(side, side), nullptr, &done);
  summary_staging_.resize(groups * ALGRAY_SUMMARY_VALUES);
  session_.queue.enqueueReadBuffer(summary_, CL_TRUE, 0, summary_staging_.size() * sizeof(cl_uint),
                                   summary_staging_.data());
  kernel_ms += ms_between(done);
  if (!alone_) read_back_tile(tile);

  PrimarySummary sum;
  for (std::size_t g = 0; g < groups; ++g) {
    const cl_uint* c = &summary_staging_[g * ALGRAY_SUMMARY_VALUES];
    sum.rays += c[ALGRAY_SUMMARY_RAYS];
    sum.hits += c[ALGRAY_SUMMARY_HITS];
    sum.depth_limited += c[ALGRAY_SUMMARY_DEPTH_LIMITED];
    sum.isolation_steps += c[ALGRAY_SUMMARY_ISOLATION_STEPS];
    sum.refine_iterations += c[ALGRAY_SUMMARY_REFINE_ITERATIONS];
    sum.pixels += c[ALGRAY_SUMMARY_PIXELS];
    sum.pixels_hit += c[ALGRAY_SUMMARY_PIXELS_HIT];
  }
  return sum;
}

void DeviceShader::finish_film() {
  if (!film_) return;
  if (alone_) {
    // Mapping brings a device's copy back into the film's memory (on a CPU it is that memory already).
    auto sync = [&](const cl::Buffer& buffer, std::size_t bytes) {
      void* mapped = session_.queue.enqueueMapBuffer(buffer, CL_TRUE, CL_MAP_READ, 0, bytes);
      session_.queue.enqueueUnmapMemObject(buffer, mapped);
    };
    sync(film_rgba_, film_->rgba.size() * sizeof(float));
    if (!film_->depth.empty()) {
      sync(film_depth_, film_->depth.size() * sizeof(float));
      sync(film_normal_, film_->normal.size() * sizeof(float));
    }
    session_.queue.finish();
    // The film's memory is the caller's again: its buffers go (the next band's film is another).
    film_rgba_ = cl::Buffer();
    film_depth_ = cl::Buffer();
    film_normal_ = cl::Buffer();
    film_depth_bytes_ = film_normal_bytes_ = 0;
  }
  film_ = nullptr;
}

}  // namespace algray
