// Derives the render plan from a scene: passes, their kernels and their buffers.
#include "algray/render/render_plan.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "algray/render/screen_form.h"
#include "algray/util/host_memory.h"
#include "kernels/algray_shared.h"

namespace algray {

bool screen_form_applies(const Scene& scene, Precision precision) {
  if (precision != Precision::Double && precision != Precision::Adaptive) return false;
  const RayBasis basis = make_ray_basis(scene.camera, scene.image.width, scene.image.height);
  return screen_geometry(basis, scene.image.width, scene.image.height, scene.extent).well_placed;
}

bool point_form_applies(const KernelConfig& shadow) {
  return (shadow.precision == Precision::Double || shadow.precision == Precision::Adaptive) &&
         abilities(shadow.isolation).point_form && shadow.degree <= kMaxPointFormDegree;
}

KernelConfig primary_config(const Scene& scene, Precision precision, std::size_t surface) {
  KernelConfig config;
  config.entry = "primary";
  config.degree = scene.surfaces.at(surface).polynomial.degree();
  config.precision = precision;
  config.isolation = scene.render.isolation;
  config.refinement = scene.render.refinement;
  config.ray_origin = scene.render.ray_origin;
  if (config.ray_origin == RayOrigin::Auto)
    config.ray_origin = screen_form_applies(scene, precision) ? RayOrigin::Screen : RayOrigin::Extent;
  // Below a few units of roundoff the stopping rule can never trigger.
  const double eps =
      precision == Precision::Double ? std::numeric_limits<double>::epsilon() : std::numeric_limits<float>::epsilon();
  config.tolerance = std::max(scene.render.tolerance, 2 * eps);
  config.max_iterations =
      scene.render.max_iterations > 0 ? scene.render.max_iterations : default_max_iterations(scene.render.refinement);
  return config;
}

void escalate_in(RenderPlan& plan, Precision precision) {
  const PlannedPass* primary = plan.find(PassKind::Primary);
  for (PlannedPass& pass : plan.passes)
    for (std::size_t i = 0; i < pass.escalation.size(); ++i) {
      KernelConfig& c = pass.escalation[i];
      c.precision = precision;
      // Doubted shadow rays again in double go through the point form, as auto's double shadow pass does: one
      // expansion per surface point serves its few doubted samples (Barth decic, one ray per pixel: 321 k doubted
      // rays, their pass 132 -> 66 ms).
      if (pass.kind == PassKind::Shadow && c.ray_origin == RayOrigin::Extent && point_form_applies(c)) {
        c.ray_origin = RayOrigin::Point;
        c.lanes = shadow_lanes(primary->kernels.at(i).lanes, c.precision);
      }
      // The first pass's settling costs about what double's second pass saves, or more (Barth decic: sign
      // sampling 1.28x -> 1.30x float's time, 1.69x -> 1.55x where the second pass is float-float; each interval's
      // own noise 1.24x either way, 1.45x -> 1.32x where it is float-float; Kummer shell, discard doubts settled
      // in float-float: 2.2x -> 2.7x, 4.1x -> 3.9x).
      // A float second pass (plain float's, make_render_plan) costs less still, but for the point form's doubted
      // shadow rays, which its own search again by each part's noise (kernels/shadow.h, point_part_polys) settles
      // for less than float's extent construction (Barth decic, 1024x768 full: 2.76 -> 2.61 s; with a double
      // second pass it saved nothing: 2.58 -> 2.60 s).
      const bool point_form_again = precision == Precision::Float && pass.kind == PassKind::Shadow &&
                                    pass.kernels.at(i).ray_origin == RayOrigin::Point;
      if (precision != Precision::Mixed && !point_form_again) pass.kernels.at(i).settle_doubts = false;
    }
}

namespace {

// The trace kernel's second pass (doubted camera rays, antialiasing samples and bounces) in as many lanes as one of
// every device's vector registers holds in its precision (escalation_lanes).
void narrow_escalation_lanes(RenderPlan& plan, const std::vector<PlanDevice>& devices) {
  for (PlannedPass& pass : plan.passes)
    for (KernelConfig& c : pass.escalation) {
      if (c.entry != "trace" || c.lanes == 1) continue;
      for (const PlanDevice& device : devices)
        c.lanes = escalation_lanes(c.lanes, c.precision == Precision::Double ? device.info.native_double_width
                                                                             : device.info.native_float_width);
    }
}

}  // namespace

int shadow_batch_on(const DeviceInfo& device, Precision precision) {
  if (precision == Precision::Mixed) return 0;
  const bool in_double = precision == Precision::Double;
  return shadow_batch_width(in_double ? device.native_double_width : device.native_float_width,
                            in_double ? device.double_fma : device.float_fma);
}

namespace {

// The extent form's shadow kernels (first passes where the point form does not apply, and the float second passes
// of the point form's doubted rays) restrict a vector register's rays side by side where every device's registers
// and fused multiply-adds allow it (shadow_batch_width); mixed precision's float-float accumulators keep theirs.
void batch_extent_shadows(RenderPlan& plan, const std::vector<PlanDevice>& devices) {
  auto batch = [&devices](KernelConfig& c) {
    if (c.entry != "shadow" || c.ray_origin != RayOrigin::Extent) return;
    // Several devices: the narrowest batch (0 where any device takes none), which every device's compiler builds
    int width = devices.empty() ? 0 : 16;
    for (const PlanDevice& device : devices) width = std::min(width, shadow_batch_on(device.info, c.precision));
    c.shadow_batch = width;
  };
  for (PlannedPass& pass : plan.passes) {
    if (pass.kind != PassKind::Shadow) continue;
    for (KernelConfig& c : pass.kernels) batch(c);
    for (KernelConfig& c : pass.escalation) batch(c);
    for (std::optional<KernelConfig>& c : pass.float_escalation)
      if (c) batch(*c);
  }
}

// Adaptive precision with a float-float second pass: the point form's doubted shadow rays through float's extent
// construction first (PlannedPass::float_escalation). Its first pass settles doubts only by searching its doubted
// rays again by each part's noise (kernels/shadow.h, point_part_polys; Barth decic, 1024x768, no fp64: 3.30 ->
// 2.94 s): the float extent pass settles the rest for less than the first pass's other checks (bench/history/
// 2026-12.md, "Doubted shadow rays in float first").
void escalate_point_form_in_float(RenderPlan& plan) {
  for (PlannedPass& pass : plan.passes) {
    if (pass.kind != PassKind::Shadow || pass.escalation.empty()) continue;
    pass.float_escalation.assign(pass.kernels.size(), std::nullopt);
    for (std::size_t i = 0; i < pass.kernels.size(); ++i) {
      KernelConfig& first = pass.kernels[i];
      if (first.ray_origin != RayOrigin::Point || pass.escalation[i].precision != Precision::Mixed) continue;
      KernelConfig in_float = first;
      in_float.ray_origin = RayOrigin::Extent;
      if (!lanes_apply(in_float)) in_float.lanes = 1;
      in_float.settle_doubts = true;  // what it leaves goes to float-float
      pass.float_escalation[i] = in_float;  // the first pass keeps settle_doubts: its own search again
    }
  }
}

}  // namespace

double shadow_offset_unit(Precision precision) { return precision == Precision::Double ? 1e-6 : 1e-3; }

std::string to_string(PassKind kind) {
  switch (kind) {
    case PassKind::Primary:
      return "primary";
    case PassKind::Shadow:
      return "shadow";
    case PassKind::Reflection:
      return "reflection";
    case PassKind::Transmission:
      return "transmission";
    case PassKind::Antialias:
      return "antialias";
  }
  return "?";
}

const PlannedPass* RenderPlan::find(PassKind kind) const {
  for (const PlannedPass& p : passes)
    if (p.kind == kind) return &p;
  return nullptr;
}

namespace {

// The primary kernels' configurations for another entry: the shadow kernel batches its rays its own way
// (kernels/shadow.cl) where lanes do not apply, and the screen form is camera rays' alone.
std::vector<KernelConfig> kernels_for(const std::vector<KernelConfig>& primary, const std::string& entry) {
  std::vector<KernelConfig> configs = primary;
  for (KernelConfig& c : configs) {
    c.entry = entry;
    if (!lanes_apply(c)) c.lanes = 1;
    if (c.ray_origin == RayOrigin::Screen) c.ray_origin = RayOrigin::Extent;
  }
  return configs;
}

// The shadow pass, when a light casts shadows and the scene is not a preview; else why not, in plan.skipped.
void plan_shadows(RenderPlan& plan, const Scene& scene, const std::vector<KernelConfig>& primary, std::size_t rays,
                  std::size_t real_size, int float_shadow_lanes) {
  for (std::size_t i = 0; i < scene.lights.size(); ++i)
    if (scene.lights[i].shadows) plan.shadow_lights.push_back(static_cast<int>(i));
  if (scene.render.preview) {
    plan.shadow_lights.clear();
    plan.skipped.push_back("shadow: preview mode traces primary rays only");
  } else if (scene.lights.empty()) {
    plan.skipped.push_back("shadow: no lights (a headlight shades the surface)");
  } else if (plan.shadow_lights.empty()) {
    plan.skipped.push_back("shadow: no light casts shadows");
  }
  if (plan.shadow_lights.empty()) return;
  // The shadow kernel isolates roots and never refines them: the refinement is not part of its code.
  std::vector<KernelConfig> shadow = kernels_for(primary, "shadow");
  for (std::size_t i = 0; i < shadow.size(); ++i) {
    KernelConfig& c = shadow[i];
    c.refinement = Refinement::Brent;
    c.max_iterations = default_max_iterations(Refinement::Brent);
    // Its batched search restricts P on segments (kernels/shadow.cl): the paper's construction about the ray's
    // origin is camera and secondary rays' alone, and a shadow ray's origin is the surface point anyway.
    if (c.ray_origin == RayOrigin::Eye) c.ray_origin = RayOrigin::Extent;
    if (scene.render.ray_origin == RayOrigin::Auto && point_form_applies(c)) {
      c.ray_origin = RayOrigin::Point;
      c.lanes = shadow_lanes(primary[i].lanes, c.precision, float_shadow_lanes);
    }
  }
  std::size_t points = 0;
  for (int i : plan.shadow_lights) points += scene.lights[static_cast<std::size_t>(i)].sample_points().size();
  plan.passes.push_back({PassKind::Shadow,
                         std::to_string(plan.shadow_lights.size()) + " shadow-casting light(s), " +
                             std::to_string(points) + " sample point(s) per lit surface point",
                         shadow,
                         {},
                         {}});
  // A batch of surface points at a time, asked about each light in turn.
  const std::size_t batch = std::min(rays, kBatchRays);
  plan.buffers.push_back({"shading points (per batch)", batch * 4 * real_size});
  plan.buffers.push_back({"shading normals (per batch)", batch * 4 * sizeof(float)});
  plan.buffers.push_back({"light sample points", points * 4 * real_size});
  plan.buffers.push_back({"occlusion masks (per batch)", batch * sizeof(cl_ulong)});
}

// Secondary rays: one pass per effect a material asks for, sharing the one "trace" kernel.
void plan_bounces(RenderPlan& plan, const Scene& scene, const std::vector<KernelConfig>& trace, std::size_t rays,
                  std::size_t real_size) {
  bool reflective = false, transparent = false;
  for (const SceneSurface& s : scene.surfaces) {
    reflective |= s.materials.front.reflectivity > 0 || s.materials.back.reflectivity > 0;
    transparent |= s.materials.front.transparency > 0 || s.materials.back.transparency > 0;
  }
  const struct {
    PassKind kind;
    bool wanted;
    const char* why;
  } effects[] = {
      {PassKind::Reflection, reflective, "mirror rays of reflective sides"},
      {PassKind::Transmission, transparent, "rays continued through transparent sides to the next root"},
  };
  for (const auto& effect : effects) {
    const std::string name = to_string(effect.kind);
    if (!effect.wanted)
      plan.skipped.push_back(name + ": no material asks for it");
    else if (scene.render.preview)
      plan.skipped.push_back(name + ": preview mode traces primary rays only");
    else if (scene.render.max_depth == 0)
      plan.skipped.push_back(name + ": render.max_depth is 0");
    else {
      plan.passes.push_back({effect.kind,
                             std::string(effect.why) + ", up to depth " + std::to_string(scene.render.max_depth),
                             trace,
                             {},
                             {}});
      // Each bounce can double a tile's rays; they are traced in batches of at most kBatchRays.
      const std::size_t batch = rays << std::min(scene.render.max_depth - 1, 8) < kBatchRays
                                    ? rays << std::min(scene.render.max_depth - 1, 8)
                                    : kBatchRays;
      plan.buffers.push_back({name + " rays (per batch)", batch * 8 * real_size});
      plan.buffers.push_back({name + " hits (per batch)", batch * sizeof(HitRecord)});
    }
  }
}

// Adaptive antialiasing's pass, or why there is none.
void plan_antialias(RenderPlan& plan, const Scene& scene, const std::vector<KernelConfig>& trace, std::size_t rays,
                    std::size_t real_size) {
  if (plan.refine_samples > 0) {
    const std::string n = std::to_string(plan.refine_samples);
    plan.passes.push_back({PassKind::Antialias,
                           n + "x" + n + " camera rays in pixels whose colour differs from a neighbour's",
                           trace,
                           {},
                           {}});
    const std::size_t batch =
        std::min(rays * static_cast<std::size_t>(plan.refine_samples * plan.refine_samples), kBatchRays);
    plan.buffers.push_back({"antialias rays (per batch)", batch * 8 * real_size});
    plan.buffers.push_back({"antialias hits (per batch)", batch * sizeof(HitRecord)});
  } else {
    plan.skipped.push_back("antialias: " + std::string(scene.render.preview && scene.antialias.samples > 1
                                                           ? "preview mode traces one camera ray per pixel"
                                                       : scene.antialias.samples > 1 ? "uniform supersampling"
                                                                                     : "off (one ray per pixel)"));
  }
}

// Adaptive precision: every pass's kernels settle what they can, and the rays they doubt go again through mixed
// precision's own kernels (or double's: escalate_in), a batch at a time.
void plan_escalation(RenderPlan& plan, Precision precision, const std::vector<KernelConfig>& primary,
                     std::size_t rays) {
  if (precision != Precision::Adaptive) {
    plan.skipped.push_back("escalation: only adaptive precision traces doubted rays again in float-float");
    return;
  }
  for (PlannedPass& pass : plan.passes) {
    pass.escalation = pass.kind == PassKind::Primary ? kernels_for(primary, "trace") : pass.kernels;
    for (KernelConfig& c : pass.escalation) {
      c.precision = Precision::Mixed;
      // The point form has no float-float build: mixed precision takes doubted shadow rays in the extent
      // construction (escalate_in turns them back to the point form where the second pass is double).
      if (c.ray_origin == RayOrigin::Point) {
        c.ray_origin = RayOrigin::Extent;
        if (!lanes_apply(c)) c.lanes = 1;
      }
    }
    // Rays the float pass can settle after all need no float-float pass (escalate_in undoes it for double).
    for (KernelConfig& c : pass.kernels) c.settle_doubts = true;
  }
  const std::size_t batch = std::min(rays, kBatchRays);
  // Sized for double, which escalate_in may choose.
  plan.buffers.push_back({"escalated rays (per batch)", batch * (8 * sizeof(double) + sizeof(HitRecord))});
}

// The host's share of one tile's work, per camera ray of the tile: its hit record (twice, and which surface, with
// several), the shadow answers (an index each way, a mask per light), what its bounces bring back; and per ray of
// the batch in flight (rays, hits, weights, staging, the rays waiting for the next bounce), about 100 bytes for
// shadow rays alone and 600 with bounces.
std::uint64_t host_bytes_per_tile(const RenderPlan& plan, const Scene& scene, std::size_t rays) {
  const bool adaptive = plan.refine_samples > 0;
  const bool several = scene.surfaces.size() > 1;
  const bool shadows = plan.find(PassKind::Shadow) != nullptr;
  const bool bounces = plan.find(PassKind::Reflection) || plan.find(PassKind::Transmission);
  std::uint64_t per_ray = sizeof(HitRecord) * (several ? 2 : 1) + (several ? 1 : 0);
  if (shadows) per_ray += 8 + 8 * plan.shadow_lights.size();
  if (bounces) per_ray += 3 * sizeof(double);
  if (adaptive) per_ray += 4 * sizeof(double);  // a refined pixel's colour and alpha
  const std::uint64_t batch = std::min<std::uint64_t>(
      kBatchRays, static_cast<std::uint64_t>(rays) * (adaptive ? plan.refine_samples * plan.refine_samples : 1) *
                      (bounces ? 2 : 1));
  const std::uint64_t per_batch_ray = bounces || adaptive ? 600 : shadows ? 100 : 0;
  return rays * per_ray + batch * per_batch_ray;
}

}  // namespace

int default_tile_size(const DeviceInfo& device) { return device.type == "GPU" ? kGpuTileSize : kCpuTileSize; }

bool float_measures_noise(const Scene& scene) {
  // Any degree: adaptive's limit of 15 is its mixed-precision second pass's, and float's second pass is float.
  return scene.render.ray_origin == RayOrigin::Auto && abilities(scene.render.isolation).adaptive;
}

RenderPlan make_render_plan(const Scene& scene, Precision precision, int tile_size, int lanes,
                            int float_shadow_lanes) {
  if (precision == Precision::Float && float_measures_noise(scene)) {
    RenderPlan plan = make_render_plan(scene, Precision::Adaptive, tile_size, lanes, float_shadow_lanes);
    escalate_in(plan, Precision::Float);
    return plan;
  }
  RenderPlan plan;
  plan.width = scene.image.width;
  plan.height = scene.image.height;
  plan.clip_planes = scene.extent.clips;
  if (scene.extent.gate) plan.gate = {true, scene.extent.unit_centre(), scene.extent.unit_scale(), scene.extent.reach};
  plan.tile_size = tile_size > 0                ? tile_size
                   : scene.render.tile_size > 0 ? scene.render.tile_size
                                                : default_tile_size(DeviceInfo{});  // a device of no kind: a CPU's
  // Preview mode is the paper's quick look: one camera ray per pixel, whatever the scene's antialiasing.
  const int samples = scene.render.preview ? 1 : scene.antialias.samples;
  const bool adaptive = scene.antialias.adaptive && samples > 1;
  plan.samples = adaptive ? 1 : samples;
  if (adaptive) {
    plan.refine_samples = scene.antialias.samples;
    plan.refine_threshold = scene.antialias.threshold;
  }
  // The device holds one tile's camera rays, and one batch of other rays at a time.
  const std::size_t rays = plan.tile_rays();
  const std::size_t real_size = precision == Precision::Double ? sizeof(double) : sizeof(float);

  // Every pass has one kernel per surface: each surface's degree specialises its own.
  std::vector<KernelConfig> primary;
  for (std::size_t i = 0; i < scene.surfaces.size(); ++i) {
    primary.push_back(primary_config(scene, precision, i));
    if (lanes_apply(primary.back())) primary.back().lanes = scene.render.lanes > 0 ? scene.render.lanes : lanes;
  }
  plan.passes.push_back({PassKind::Primary,
                         plan.samples > 1 ? "camera rays, " + std::to_string(plan.samples) + "x" +
                                                std::to_string(plan.samples) + " per pixel"
                                          : "camera rays, one per pixel",
                         primary,
                         {},
                         {}});
  plan.buffers.push_back({"primary hits", rays * sizeof(HitRecord)});
  plan_shadows(plan, scene, primary, rays, real_size, float_shadow_lanes);
  const std::vector<KernelConfig> trace = kernels_for(primary, "trace");
  plan_bounces(plan, scene, trace, rays, real_size);
  plan_antialias(plan, scene, trace, rays, real_size);
  plan_escalation(plan, precision, primary, rays);
  plan.tile_host_bytes = host_bytes_per_tile(plan, scene, rays);
  return plan;
}

KernelConfig shading_config(const DeviceInfo& device) {
  KernelConfig config;
  config.entry = "shade";
  config.precision = device.fp64 ? Precision::Double : Precision::Float;
  // As many pixels as the host's shading takes side by side in double (8), twice that in float.
  config.lanes = std::min(default_lanes(device.type), device.fp64 ? 8 : 16);
  return config;
}

namespace {

// The shading kernel of the first device (each device builds its own, alike but for precision and lanes), what it
// draws, and its buffers: a tile's shadow answers and bounces' colours, and with several devices a film of each
// device's own, whose tiles are read back as they are shaded.
void plan_shading(RenderPlan& plan, const Scene& scene, const std::vector<PlanDevice>& devices) {
  plan.shading = shading_config(devices.front().info);
  std::string what = scene.lights.empty() ? "the headlight" : std::to_string(scene.lights.size()) + " light(s)";
  if (plan.find(PassKind::Shadow)) what += " with their shadows";
  if (!scene.sections.empty()) what += ", " + std::to_string(scene.sections.size()) + " section(s)";
  const bool bounces = plan.find(PassKind::Reflection) || plan.find(PassKind::Transmission);
  if (bounces) what += ", the bounces' colour";
  what += ", the background, " + std::to_string(plan.samples) + "x" + std::to_string(plan.samples) +
          " samples per pixel averaged";
  if (plan.refine_samples > 1) what += " (refined pixels on the host)";
  plan.shading_purpose = what;
  const std::size_t real = plan.shading.precision == Precision::Double ? sizeof(double) : sizeof(float);
  const std::size_t per_ray =
      (plan.find(PassKind::Shadow) ? sizeof(std::uint32_t) + sizeof(std::uint64_t) * plan.shadow_lights.size() : 0) +
      (bounces ? 4 * real : 0);
  if (per_ray > 0) plan.buffers.push_back({"shading: a tile's shadow answers and bounces' colours", per_ray * plan.tile_rays()});
  if (devices.size() > 1)
    plan.buffers.push_back({"shading: the film of each device", devices.size() * plan.film_bytes()});
}

}  // namespace

RenderPlan make_render_plan(const Scene& scene, Precision precision, const std::vector<PlanDevice>& devices) {
  if (devices.empty()) throw std::invalid_argument("a render plan needs at least one device");
  const int lanes = default_lanes(devices.front().info.type);
  int float_lanes = kMaxFloatShadowLanes;  // what every device's registers hold
  for (const PlanDevice& device : devices) float_lanes = std::min(float_lanes, float_shadow_lanes(device.info.native_float_width));
  RenderPlan plan;
  if (scene.render.tile_size > 0) {
    plan = make_render_plan(scene, precision, scene.render.tile_size, lanes, float_lanes);
    plan.tile_choice = "the scene's render.tile_size";
  } else {
    int side = default_tile_size(devices.front().info);
    for (const PlanDevice& device : devices) side = std::min(side, default_tile_size(device.info));
    plan = make_render_plan(scene, precision, side, lanes, float_lanes);
    plan.tile_choice = side == kGpuTileSize ? "a GPU's: as many camera rays as fill it in one launch per pass"
                                            : "a CPU's: few large launches";
    // Several devices take tiles from one queue: with about 8 tiles each, a device that finds its tiles cheaper
    // takes more of them, and none idles long at the end. The tile size changes no pixel (test_multi_device).
    const std::size_t wanted = devices.size() > 1 ? 8 * devices.size() : 1;
    auto tiles = [](const RenderPlan& p) {
      const std::size_t side_pixels = static_cast<std::size_t>(p.tile_pixels());
      return ((static_cast<std::size_t>(p.width) + side_pixels - 1) / side_pixels) *
             ((static_cast<std::size_t>(p.height) + side_pixels - 1) / side_pixels);
    };
    const std::string choice = plan.tile_choice;
    while (tiles(plan) < wanted && plan.tile_size / 2 >= 16 * plan.samples)
      plan = make_render_plan(scene, precision, plan.tile_size / 2, lanes, float_lanes);
    plan.tile_choice = choice;
    if (plan.tile_size != side)
      plan.tile_choice += ", halved to " + std::to_string(plan.tile_size) + " for about 8 tiles per device";
  }
  if (precision == Precision::Adaptive) {
    const bool all_fast = std::all_of(devices.begin(), devices.end(),
                                      [](const PlanDevice& d) { return d.escalation == Precision::Double; });
    escalate_in(plan, all_fast ? Precision::Double : Precision::Mixed);
    if (!all_fast) escalate_point_form_in_float(plan);
  }
  narrow_escalation_lanes(plan, devices);
  batch_extent_shadows(plan, devices);
  plan_shading(plan, scene, devices);
  return plan;
}

nlohmann::json RenderPlan::json() const {
  nlohmann::json j;
  j["image"] = {{"width", width}, {"height", height}};
  j["antialias_samples"] = samples;
  j["adaptive_antialias_samples"] = refine_samples;
  j["traced"] = {{"width", trace_width()}, {"height", trace_height()}};
  j["tile"] = {{"size", tile_size}, {"pixels", tile_pixels()}, {"rays", tile_rays()}, {"choice", tile_choice}};
  j["film_bytes"] = film_bytes();
  j["tile_host_bytes"] = tile_host_bytes;
  for (const PlannedPass& p : passes) {
    nlohmann::json kernels = nlohmann::json::array();
    for (const KernelConfig& k : p.kernels) kernels.push_back(k.key());
    nlohmann::json pass = {{"name", to_string(p.kind)}, {"purpose", p.purpose}, {"kernels", kernels}};
    if (!p.escalation.empty()) {
      pass["escalation"] = nlohmann::json::array();
      for (const KernelConfig& k : p.escalation) pass["escalation"].push_back(k.key());
    }
    for (const std::optional<KernelConfig>& k : p.float_escalation)
      if (k) pass["float_escalation"].push_back(k->key());
    j["passes"].push_back(pass);
  }
  for (const PlannedBuffer& b : buffers) j["buffers"].push_back({{"name", b.name}, {"bytes", b.bytes}});
  j["shading"] = {{"kernel", shading.key()}, {"purpose", shading_purpose}};
  j["shadow_lights"] = shadow_lights;
  j["clip_planes"] = nlohmann::json::array();
  for (const glm::dvec4& p : clip_planes) j["clip_planes"].push_back({p.x, p.y, p.z, p.w});
  j["extent_gate"] = nullptr;
  if (gate.on)
    j["extent_gate"] = {
        {"reach", gate.reach},
        {"far_sphere",
         {{"centre", {gate.far_centre.x, gate.far_centre.y, gate.far_centre.z}}, {"radius", gate.far_radius}}}};
  j["skipped"] = skipped;
  j["estimated_memory_bytes"] = estimated_memory_bytes();
  return j;
}

std::uint64_t RenderPlan::buffer_bytes() const {
  std::uint64_t sum = 0;
  for (const PlannedBuffer& b : buffers) sum += b.bytes;
  return sum;
}

std::uint64_t RenderPlan::film_bytes() const {
  const std::uint64_t pixels = static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height);
  // RGBA, depth and normal in float; adaptive antialiasing's choice of pixels, a byte each.
  return pixels * (kFilmBytesPerPixel + (refine_samples > 1 ? 1 : 0));
}

std::uint64_t RenderPlan::estimated_memory_bytes() const {
  constexpr std::uint64_t kBase = 128ull << 20;    // the process, the OpenCL runtime and its compiler
  constexpr std::uint64_t kWriters = 32ull << 20;  // the image writers convert and compress a strip of lines at a time
  return kBase + kWriters + film_bytes() + tile_host_bytes + buffer_bytes();
}

namespace {

std::string gigabytes(std::uint64_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f GB", static_cast<double>(bytes) / 1e9);
  return buf;
}

}  // namespace

void check_plan_fits(const RenderPlan& plan, const DeviceInfo& device) {
  const std::string what = "a " + std::to_string(plan.width) + "x" + std::to_string(plan.height) + " render with " +
                           std::to_string(plan.samples) + "x" + std::to_string(plan.samples) +
                           " samples per pixel needs about ";
  const std::string advice = ": render a smaller image (or with a smaller render.tile_size)";
  const std::uint64_t need = plan.estimated_memory_bytes();
  HostMemory available;
  try {
    available = available_host_memory();
  } catch (const std::invalid_argument& e) {
    throw DeviceError(e.what());
  }
  if (available.bytes && need > available.bytes)
    throw DeviceError(what + gigabytes(need) + " of memory, and " + gigabytes(available.bytes) +
                      " are available to this process (" + available.limited_by + ")" + advice);
  if (device.type == "CPU") return;  // its buffers are in the memory counted above
  if (device.global_mem_bytes && plan.buffer_bytes() > device.global_mem_bytes)
    throw DeviceError(what + gigabytes(plan.buffer_bytes()) + " of device memory, and " + device.name + " has " +
                      gigabytes(device.global_mem_bytes) + advice);
  for (const PlannedBuffer& b : plan.buffers)
    if (device.max_alloc_bytes && b.bytes > device.max_alloc_bytes)
      throw DeviceError(what + "a buffer of " + gigabytes(b.bytes) + " (" + b.name + "), and " + device.name +
                        " allocates at most " + gigabytes(device.max_alloc_bytes) + " at once" + advice);
}

}  // namespace algray
