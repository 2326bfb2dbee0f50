// Scene: the surface, extent, camera, image, colours and render settings read from a TOML file and overrides.
#pragma once

#include <glm/glm.hpp>
#include <istream>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "algray/scene/camera.h"
#include "algray/scene/solver_options.h"
#include "algray/math/polynomial.h"

namespace algray {

// Bad input. `where` is "file:line:column" (or "--set key=value"), `excerpt` the offending line with a caret.
struct SceneError : std::runtime_error {
  SceneError(std::string where, std::string message, std::string excerpt = {});
  std::string where, message, excerpt;
};

enum class ExtentKind { Sphere, Box, Cylinder };

// The extent kinds: the name extent.type takes and the keys that belong to each, besides those every kind has
// (type, gate, reach: scene.cpp's kExtentKeys). One row per kind, read by the scene reader and by --set
// extent.type, which drops the keys of the other kinds (with a note).
struct ExtentKindInfo {
  ExtentKind kind;
  const char* name;
  std::vector<std::string> keys;
};
inline const std::vector<ExtentKindInfo>& extent_kinds() {
  static const std::vector<ExtentKindInfo> kinds{
      {ExtentKind::Sphere, "sphere", {"centre", "radius"}},
      {ExtentKind::Box, "box", {"min", "max"}},
      {ExtentKind::Cylinder, "cylinder", {"centre", "radius", "axis", "half_height"}}};
  return kinds;
}

// A scene that gives no [extent] is a sphere of this radius about the origin (`algray render -e ... --radius R`).
inline constexpr double kDefaultExtentRadius = 2;

// A gate's far sphere is this many times the radius of the sphere around the gate, unless extent.reach says
// otherwise (1 to kMaxGateReach). POV-Ray looks along a ray that passes its bound without end, but root isolation
// needs a finite interval, and the farther it reaches, the more digits the surface near the gate loses in the
// kernels' unit coordinates (the far sphere's). Measured: in POV-Ray's quartic samples that have bounded_by alone,
// all that POV-Ray shows through the bound lies within 1.86 of its radii of its centre (quarcyl; hyptorus 1.60),
// so 4 holds it with room to spare. The Kummer surface gated by a sphere of radius 1.2 (test_reference_agree,
// 64x48) has in float a worst relative depth error of 4.4e-6 at reach 2, 9.7e-5 at 4, 4.1e-4 at 8, 6.3e-4 at 16
// and 1.3e-3 at 64, past float's line of 1e-3 (in double about 1e-9 at every reach up to 1000). The POV-Ray reader
// raises it where its own rays see farther (povray.cpp, gate_reach).
inline constexpr double kDefaultGateReach = 4;
inline constexpr double kMaxGateReach = 1000;

struct Extent {
  ExtentKind kind = ExtentKind::Sphere;
  glm::dvec3 centre{0};  // sphere
  double radius = 1;
  glm::dvec3 min{-1}, max{1};  // box
  // cylinder: centre and radius as a sphere's, about the coordinate axis `axis` (0 x, 1 y, 2 z; "z" unless given),
  // its caps half_height either side of the centre along that axis
  int axis = 2;
  double half_height = 1;
  // gate = true: the shape above is a ray gate (POV-Ray's bounded_by), not a cut. A ray that does not meet it sees
  // nothing of the surface; a ray that does sees the surface all along it, within the far sphere: about the
  // shape's centre, `reach` times the radius of the sphere around the shape (shape_scale()). Root isolation needs
  // a finite interval, and the far sphere is it; kDefaultGateReach says why its default is what it is.
  bool gate = false;
  double reach = kDefaultGateReach;

  // The radius of the sphere about unit_centre() that holds the shape (a box's half-diagonal, a cylinder's distance
  // from its centre to a cap's rim): what the camera is framed by.
  double shape_scale() const;
  // The kernels work in u = (p - unit_centre()) / unit_scale(), where the extent fits in |u| <= 1: the shape, or
  // with a gate, the far sphere (the unit sphere), which holds the gate.
  glm::dvec3 unit_centre() const;
  double unit_scale() const;
  // Box half-sizes in unit coordinates; for a cylinder, those of the box around it (radius across, half_height
  // along its axis), from which the kernels take the cylinder (kernels/ray.h); for a sphere, its radius in each
  // (1 without a gate).
  glm::dvec3 unit_box_half() const;

  // Clipping planes ([[clip]] tables, --clip) that cut the surface open: each keeps the half-space
  // a*x + b*y + c*z + d <= 0 of its (a, b, c, d), (a, b, c) not zero, and what is drawn is the part of the surface
  // inside the extent and every one of them. At most kMaxClipPlanes; none cuts nothing.
  std::vector<glm::dvec4> clips;
  // The planes in unit coordinates, as the kernels take them: (n, e) with n unit and n.u + e <= 0 kept.
  std::vector<glm::dvec4> unit_clips() const;
};

// How many clipping planes a scene may have: the kernels loop over as many as are given (kernels/ray.h), and a
// few planes are what users cut a surface open with (a slab, a wedge, a corner).
inline constexpr std::size_t kMaxClipPlanes = 4;

// A plane section, surf's cut_with_plane: the curve where the plane a*x + b*y + c*z + d = 0 meets the surface,
// drawn over the shading in `colour` as a line `width` pixels wide (shade.cpp), on every surface or on one.
struct Section {
  glm::dvec4 plane{0, 0, 1, 0};  // a, b, c, d
  glm::dvec3 colour{0.05, 0.05, 0.05};
  int surface = -1;    // the index in Scene::surfaces of the one surface it cuts; -1: every surface
  double width = 1;    // in pixels
};
inline constexpr double kMaxSectionWidth = 64;

struct ImageSpec {
  int width = 800;
  int height = 600;
  glm::dvec4 background{1, 1, 1, 1};  // linear RGBA
};

// How a side of the surface reflects light (Phong), plus what it passes on to secondary rays.
struct Material {
  glm::dvec3 colour{0.95, 0.65, 0.15};
  double ambient = 0.15;   // share of the colour lit by the ambient light, shadow or not
  double diffuse = 0.75;   // Lambertian share per light
  double specular = 0.35;  // highlight strength per light, in the light's colour
  double exponent = 40;    // Phong exponent: larger is a smaller, sharper highlight
  // Share of the mirror ray's colour added to the surface's own (a reflection pass traces the mirror rays).
  double reflectivity = 0;
  // Share of the colour seen through the surface, the ray continuing to the next root as in surf and SURFER;
  // the surface's own colour keeps 1 - transparency (a transmission pass traces the continued rays).
  double transparency = 0;
};

// Front: where the ray arrives from P > 0 (outside); back: from P < 0 (inside).
struct Materials {
  Material front;
  Material back = [] {
    Material m;
    m.colour = {0.25, 0.45, 0.9};
    return m;
  }();
};

enum class LightKind { Point, Rectangle, Disc };

// A light; area lights are sampled as samples x samples points spread uniformly over their area.
struct Light {
  LightKind kind = LightKind::Point;
  glm::dvec3 position{0};           // the point, or the area's centre
  glm::dvec3 edge_u{0}, edge_v{0};  // rectangle: its two edges (full length), centred on position
  glm::dvec3 normal{0, 0, 1};       // disc: its plane's normal, as written (not necessarily unit)
  double radius = 0;                // disc
  int samples = 1;                  // n: n x n points for an area light; 1 for a point light
  glm::dvec3 colour{1};
  double intensity = 1;
  bool shadows = true;
  // A light attached to the camera (light.frame = "camera"), so that it follows the camera: its position, edges
  // and normal as written, in the camera's frame (camera_point_to_world). The world fields above are placed
  // from them whenever the scene is read.
  struct CameraFrame {
    glm::dvec3 position{0}, edge_u{0}, edge_v{0}, normal{0, 0, 1};
  };
  std::optional<CameraFrame> in_camera;

  // The light's sample points: cell centres of an n x n grid over the rectangle, or the same grid mapped to
  // the disc by an area-preserving (concentric) map.
  std::vector<glm::dvec3> sample_points() const;
};

// The most points one area light may have: a shadow pass keeps one visibility bit per point in 64 bits.
inline constexpr int kMaxLightSamplesPerSide = 8;

struct Antialias {
  int samples = 1;  // n x n supersampling; 1 is off
  // Adaptive: one ray per pixel first, then n x n only in pixels whose colour differs from a neighbour's by
  // more than `threshold` in some channel (the antialiasing refinement pass).
  bool adaptive = false;
  double threshold = 0.1;
};

struct RenderSettings {
  std::optional<Precision> precision;  // unset: double where the device has fp64, else float
  double tolerance = 1e-9;
  Isolation isolation = Isolation::Bernstein;
  Refinement refinement = Refinement::Brent;
  RayOrigin ray_origin = RayOrigin::Auto;
  int max_iterations = 0;  // 0: the refinement's default (default_max_iterations)
  int tile_size = 0;       // pixels per side of a dispatched tile; 0 chooses by device type
  int lanes = 0;           // rays per work-item of camera and secondary rays (kernels/lanes.h); 0: by device type
  bool preview = false;    // primary rays only: lights shade, but cast no shadows (the paper's preview mode)
  // Secondary bounces after the camera ray: reflection and transmission rays stop after this many.
  int max_depth = 5;
};

// Places the lights attached to the camera (Light::in_camera) in the world, from the scene's camera: after the
// camera moved (a batch's orbit), so that they follow it.
void place_camera_lights(std::vector<Light>& lights, const CameraSpec& camera);

// One surface of a scene: its polynomial and how its two sides look.
struct SceneSurface {
  std::string name;
  std::string equation;  // as written, or generated from the term list
  bool from_terms = false;  // given as surface.terms: exact doubles, which the generated equation may round
  Polynomial polynomial;
  Materials materials;
};

// Surfaces one scene may hold; each is traced by its own kernel specialisation.
inline constexpr std::size_t kMaxSurfaces = 8;

struct Scene {
  std::string source;  // the scene file's path, or "<built-in default scene>"
  std::string name;    // the first surface's name, else the file stem
  std::map<std::string, double> parameters;
  std::vector<SceneSurface> surfaces;  // at least one; where several meet a ray, the nearest hit wins
  Extent extent;
  CameraSpec camera;
  ImageSpec image;
  std::vector<Light> lights;  // none: a headlight at the eye shades the surface, without shadows
  std::vector<Section> sections;  // plane sections drawn on the surface ([[section]])
  // (the clipping planes, [[clip]], are the extent's: extent.clips)
  Antialias antialias;
  RenderSettings render;
  // What the scene's reader could not render as written (a .jsurf feature algray draws differently, an unknown
  // key it ignored, a surf statement outside the subset); commands print them as warnings.
  std::vector<std::string> warnings;

  // The first surface: the one single-surface tools (the reference solver, the solver benchmarks) work on.
  const SceneSurface& surface() const { return surfaces.front(); }
};

// "key=value" from --set (or a flag such as --width): key is a dotted scene key; a key without a dot names a
// parameter, or else a top-level table (--set 'section=[]'). The value is read as TOML, or as a string when it is
// not valid TOML. The key kSectionOverrideKey is --section: its value, a plane as a linear equation in x, y, z
// ("z=0.5", "x+y=1"), is appended as a [[section]] table. The key kClipOverrideKey is --clip: its value, a
// half-space as a linear inequality in x, y, z ("z<0.5", "x+y>=1": the side kept), is appended as a [[clip]] table.
inline constexpr const char* kSectionOverrideKey = "--section";
inline constexpr const char* kClipOverrideKey = "--clip";
struct Override {
  std::string key;
  std::string value;
  // Where it was written, for messages ("jobs.toml:7:9"); empty for the command line's --set.
  std::string origin = {};
};

// A scene file by its extension (any case, scene_formats.h): a .toml scene (also a path without an extension),
// a SURFER/jsurf .jsurf file translated with jsurf's framing, a surf script (.pic) with surf's, or a POV-Ray
// scene (.pov) as POV-Ray shows it. Any other
// extension is a SceneError listing the types algray reads, before the file is opened. (PNGs that carry a
// scene are read a layer up, where the PNG reader is: api's SceneLoader.)
Scene load_scene_file(const std::string& path, const std::vector<Override>& overrides = {});
Scene load_scene_text(const std::string& text, const std::string& source_name,
                      const std::vector<Override>& overrides = {});
Scene load_jsurf_text(const std::string& text, const std::string& source_name,
                      const std::vector<Override>& overrides = {});
Scene load_surf_script_text(const std::string& text, const std::string& source_name,
                            const std::vector<Override>& overrides = {});
Scene load_povray_text(const std::string& text, const std::string& source_name,
                       const std::vector<Override>& overrides = {});
Scene default_scene(const std::vector<Override>& overrides = {});
// An equation alone as a scene (`algray render -e`): "[surface] equation" and algray's defaults for the rest, as a
// TOML file holding only that table gets. Errors in the equation name "--equation:1:COLUMN".
Scene load_equation(const std::string& equation, const std::vector<Override>& overrides = {});

// The scene as TOML that reads back to the same Scene, value for value (floats to 17 digits, the equations as
// written with their parameters): what PNG files embed so that `algray render image.png` renders them again, and
// what holds a scene after --set, an orbit or a .jsurf translation. Comments and the source's layout are lost.
std::string scene_to_toml(const Scene& scene);

// Scenes and jobs files are small text; a larger input is refused after reading one byte past this, so that
// `algray render /dev/zero` or a mistyped path to a video fails at once instead of filling the memory.
inline constexpr std::size_t kMaxInputBytes = std::size_t{4} << 20;

// The whole of a text input (`what`: "scene file", "jobs file"); SceneError naming `path` when it is missing, a
// directory, unreadable or larger than kMaxInputBytes.
std::string read_input_file(const std::string& path, const std::string& what);
// The same from a stream such as standard input, named `source` in messages.
std::string read_input_stream(std::istream& in, const std::string& source, const std::string& what);

}  // namespace algray
