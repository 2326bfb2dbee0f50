// Scene: the surface, extent, camera, image, colours and render settings read from a TOML file and overrides.
#pragma once

#include <glm/glm.hpp>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "camera.h"
#include "kernel_config.h"
#include "polynomial.h"

namespace algray {

// Bad input. `where` is "file:line:column" (or "--set key=value"), `excerpt` the offending line with a caret.
struct SceneError : std::runtime_error {
  SceneError(std::string where, std::string message, std::string excerpt = {});
  std::string where, message, excerpt;
};

enum class ExtentKind { Sphere, Box };

struct Extent {
  ExtentKind kind = ExtentKind::Sphere;
  glm::dvec3 centre{0};  // sphere
  double radius = 1;
  glm::dvec3 min{-1}, max{1};  // box

  // The kernels work in u = (p - unit_centre()) / unit_scale(), where the extent fits in |u| <= 1.
  glm::dvec3 unit_centre() const;
  double unit_scale() const;
  glm::dvec3 unit_box_half() const;  // box half-sizes in unit coordinates
};

struct ImageSpec {
  int width = 800;
  int height = 600;
  glm::dvec4 background{1, 1, 1, 1};  // linear RGBA
};

struct Colours {
  glm::dvec3 front{0.95, 0.65, 0.15};  // where the ray arrives from P > 0 (outside)
  glm::dvec3 back{0.25, 0.45, 0.9};    // where it arrives from P < 0 (inside)
};

struct RenderSettings {
  std::optional<Precision> precision;  // unset: double where the device has fp64, else float
  double tolerance = 1e-9;
  Isolation isolation = Isolation::Bernstein;
  Refinement refinement = Refinement::Brent;
  RayOrigin ray_origin = RayOrigin::Extent;
  int max_iterations = 0;  // 0: the refinement's default (default_max_iterations)
  int tile_size = 0;  // pixels per side of a dispatched tile; 0 chooses by device type
};

struct Scene {
  std::string source;    // the scene file's path, or "<built-in default scene>"
  std::string name;      // surface.name, else the file stem
  std::string equation;  // as written, or generated from the term list
  std::map<std::string, double> parameters;
  Polynomial polynomial;
  Extent extent;
  CameraSpec camera;
  ImageSpec image;
  Colours colours;
  RenderSettings render;
};

// "key=value" from --set (or a flag such as --width): key is a dotted scene key; a key without a dot names a
// parameter. The value is read as TOML, or as a string when it is not valid TOML.
struct Override {
  std::string key;
  std::string value;
};

Scene load_scene_file(const std::string& path, const std::vector<Override>& overrides = {});
Scene load_scene_text(const std::string& text, const std::string& source_name,
                      const std::vector<Override>& overrides = {});
Scene default_scene(const std::vector<Override>& overrides = {});

}  // namespace algray
