// The .jsurf importer: Java properties parsed with positions, checked, and written out as an algray scene.
#include "algray/scene/jsurf.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "algray/scene/expression.h"
#include "algray/math/colour.h"
#include "algray/scene/scene.h"
#include "algray/scene/toml_reader.h"

namespace algray {
namespace {

// Where a character of the file is: 1-based line and column.
struct Position {
  int line = 0, column = 0;
};

// One property's value, with the position of each of its characters (after continuation lines are joined and
// escapes resolved), so that an error anywhere inside it points at the right line and column.
struct Property {
  std::string value;
  std::vector<Position> positions;  // one per character of value, plus one past the end
};

class Properties {
 public:
  Properties(const std::string& text, std::string source) : source_(std::move(source)) {
    std::istringstream in(text);
    for (std::string l; std::getline(in, l);) {
      if (!l.empty() && l.back() == '\r') l.pop_back();
      lines_.push_back(l);
    }
    parse();
  }

  const Property* get(const std::string& key) const {
    const auto it = values_.find(key);
    if (it == values_.end()) return nullptr;
    used_.insert(key);
    return &it->second;
  }
  // An error at character `offset` of the value.
  [[noreturn]] void fail(const Property& p, const std::string& key, const std::string& message,
                         std::size_t offset = 0) const {
    const Position at = p.positions[std::min(offset, p.positions.size() - 1)];
    const std::string caret = std::string(static_cast<std::size_t>(std::max(at.column - 1, 0)), ' ') + "^";
    throw SceneError(source_ + ":" + std::to_string(at.line) + ":" + std::to_string(at.column), key + ": " + message,
                     line_text(at.line) + "\n" + caret);
  }
  [[noreturn]] void fail_missing(const std::string& key, const std::string& message) const {
    throw SceneError(source_, key + ": " + message);
  }
  // Where the value of `p` starts, for the translated TOML's lines made from it.
  JsurfOrigin origin(const Property& p, const std::string& key) const {
    const Position at = p.positions.front();
    const std::string caret = std::string(static_cast<std::size_t>(std::max(at.column - 1, 0)), ' ') + "^";
    return {source_ + ":" + std::to_string(at.line) + ":" + std::to_string(at.column), key,
            line_text(at.line) + "\n" + caret};
  }
  int line_of(const Property& p) const { return p.positions.front().line; }
  std::vector<std::string> unused() const {
    std::vector<std::string> keys;
    for (const auto& [key, p] : values_)
      if (!used_.count(key)) keys.push_back(key);
    return keys;
  }
  std::vector<std::string> keys_with_prefix(const std::string& prefix) const {
    std::vector<std::string> keys;
    for (const auto& [key, p] : values_)
      if (key.compare(0, prefix.size(), prefix) == 0) keys.push_back(key);
    return keys;
  }
  const std::string& source() const { return source_; }

 private:
  const std::string& line_text(int line) const {
    static const std::string none;
    return line >= 1 && static_cast<std::size_t>(line) <= lines_.size() ? lines_[static_cast<std::size_t>(line - 1)]
                                                                        : none;
  }

  // java.util.Properties rules: # and ! comments, a trailing odd backslash continues the line (leading blanks of
  // the next one dropped), the key ends at an unescaped '=', ':' or blank, and \t \n \r \f \uXXXX escapes.
  void parse() {
    for (std::size_t i = 0; i < lines_.size(); ++i) {
      const std::string& first = lines_[i];
      const std::size_t start = first.find_first_not_of(" \t\f");
      if (start == std::string::npos || first[start] == '#' || first[start] == '!') continue;
      // The logical line, each character with its place in the file.
      std::string logical;
      std::vector<Position> where;
      auto append = [&](std::size_t line, std::size_t from) {
        for (std::size_t c = from; c < lines_[line].size(); ++c) {
          logical += lines_[line][c];
          where.push_back({static_cast<int>(line) + 1, static_cast<int>(c) + 1});
        }
      };
      append(i, start);
      while (ends_in_continuation(logical) && i + 1 < lines_.size()) {
        logical.pop_back();
        where.pop_back();
        ++i;
        const std::size_t s = lines_[i].find_first_not_of(" \t\f");
        if (s != std::string::npos) append(i, s);
      }
      const Position end =
          where.empty() ? Position{static_cast<int>(i) + 1, 1} : Position{where.back().line, where.back().column + 1};
      std::size_t k = 0;
      std::string key;
      while (k < logical.size() && logical[k] != '=' && logical[k] != ':' && logical[k] != ' ' && logical[k] != '\t') {
        if (logical[k] == '\\' && k + 1 < logical.size()) ++k;
        key += logical[k++];
      }
      while (k < logical.size() && (logical[k] == ' ' || logical[k] == '\t')) ++k;
      if (k < logical.size() && (logical[k] == '=' || logical[k] == ':')) ++k;
      while (k < logical.size() && (logical[k] == ' ' || logical[k] == '\t')) ++k;
      values_[key] = unescape(logical, where, k, end);  // the last occurrence wins, as in Java
    }
  }
  static bool ends_in_continuation(const std::string& s) {
    std::size_t backslashes = 0;
    for (auto it = s.rbegin(); it != s.rend() && *it == '\\'; ++it) ++backslashes;
    return backslashes % 2 == 1;
  }
  static Property unescape(const std::string& s, const std::vector<Position>& where, std::size_t from, Position end) {
    Property p;
    for (std::size_t i = from; i < s.size(); ++i) {
      p.positions.push_back(where[i]);
      if (s[i] != '\\' || i + 1 == s.size()) {
        p.value += s[i];
        continue;
      }
      const char c = s[++i];
      if (c == 't') {
        p.value += '\t';
      } else if (c == 'n') {
        p.value += '\n';
      } else if (c == 'r') {
        p.value += '\r';
      } else if (c == 'f') {
        p.value += '\f';
      } else if (c == 'u' && i + 4 < s.size() && s.find_first_not_of("0123456789abcdefABCDEF", i + 1) >= i + 5) {
        const unsigned code = static_cast<unsigned>(std::stoul(s.substr(i + 1, 4), nullptr, 16));
        i += 4;
        p.value += code < 0x80 ? static_cast<char>(code) : '?';  // equations and numbers are ASCII
      } else {
        p.value += c;
      }
    }
    p.positions.push_back(end);
    return p;
  }

  std::string source_;
  std::vector<std::string> lines_;
  std::map<std::string, Property> values_;
  mutable std::set<std::string> used_;
};

std::vector<double> numbers(const Properties& props, const std::string& key, const Property& p, std::size_t count) {
  std::istringstream in(p.value);
  in.imbue(std::locale::classic());
  std::vector<double> out;
  std::string word;
  while (in >> word) {
    try {
      std::size_t used = 0;
      const double v = std::stod(word, &used);
      if (used != word.size() || !std::isfinite(v)) throw std::invalid_argument(word);
      out.push_back(v);
    } catch (const std::exception&) {
      props.fail(p, key, "'" + word + "' is not a number");
    }
  }
  if (out.size() != count)
    props.fail(p, key,
               "expected " + std::to_string(count) + " number" + (count == 1 ? "" : "s") + ", found " +
                   std::to_string(out.size()));
  return out;
}

double number_or(const Properties& props, const std::string& key, double fallback) {
  const Property* p = props.get(key);
  return p ? numbers(props, key, *p, 1)[0] : fallback;
}

glm::dvec3 vector_or(const Properties& props, const std::string& key, glm::dvec3 fallback) {
  const Property* p = props.get(key);
  if (!p) return fallback;
  const std::vector<double> v = numbers(props, key, *p, 3);
  return {v[0], v[1], v[2]};
}

// Row-major 16 numbers (m00 m01 m02 m03 m10 ...), applied to column vectors, into glm's column-major matrix.
glm::dmat4 matrix_or_identity(const Properties& props, const std::string& key, const Property** where = nullptr) {
  const Property* p = props.get(key);
  if (where) *where = p;
  if (!p) return glm::dmat4(1.0);
  const std::vector<double> v = numbers(props, key, *p, 16);
  glm::dmat4 m;
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) m[col][row] = v[static_cast<std::size_t>(row * 4 + col)];
  return m;
}

bool is_identity(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (std::fabs(m[c][r] - (c == r ? 1.0 : 0.0)) > 1e-9) return false;
  return true;
}

// Files store 7-8 digits, so an orthonormal matrix is orthonormal to about 1e-7; 1e-4 tells those from real
// scaling or shear, which algray cannot apply to a camera.
bool is_rotation(const glm::dmat3& m) {
  const glm::dmat3 should_be_identity = glm::transpose(m) * m;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (std::fabs(should_be_identity[c][r] - (c == r ? 1.0 : 0.0)) > 1e-4) return false;
  return glm::determinant(m) > 0;
}

bool is_affine(const glm::dmat4& m) {
  return std::fabs(m[0][3]) + std::fabs(m[1][3]) + std::fabs(m[2][3]) + std::fabs(m[3][3] - 1) < 1e-9;
}

// jsurf's colours are display values in 0..1, shaded without gamma; algray's are linear.
glm::dvec3 colour_or(const Properties& props, const std::string& key, glm::dvec3 fallback) {
  const Property* p = props.get(key);
  glm::dvec3 c = fallback;
  if (p) {
    c = vector_or(props, key, fallback);
    for (int i = 0; i < 3; ++i)
      if (c[i] < 0 || c[i] > 1) props.fail(*p, key, "colour components are between 0 and 1");
  }
  return {srgb_to_linear(c.x), srgb_to_linear(c.y), srgb_to_linear(c.z)};
}

// A [0, 1] material factor; jsurf allows more, algray's materials do not.
double factor_or(const Properties& props, const std::string& key, double fallback, std::vector<std::string>& warnings) {
  const double v = number_or(props, key, fallback);
  if (v >= 0 && v <= 1) return v;
  const Property* p = props.get(key);
  if (v < 0) props.fail(*p, key, "must not be negative");
  warnings.push_back(props.source() + ":" + std::to_string(props.line_of(*p)) + ": " + key + " = " + p->value +
                     " is above 1; algray's materials stop at 1, so it renders as 1");
  return 1;
}

// The surface's equation and parameters, checked here so that an error points into the .jsurf file, not into
// the TOML made from it.
struct JsurfSurface {
  const Property* equation = nullptr;
  std::map<std::string, double> parameters;
};

JsurfSurface read_surface(const Properties& props) {
  JsurfSurface surface;
  surface.equation = props.get("surface_equation");
  if (!surface.equation) props.fail_missing("surface_equation", "a .jsurf file must give the surface's equation");
  for (const std::string& key : props.keys_with_prefix("surface_parameter_")) {
    const Property* p = props.get(key);
    const std::string name = key.substr(std::string("surface_parameter_").size());
    if (!is_identifier(name))
      props.fail(*p, key, "'" + name + "' is not a parameter name (a letter or _, then letters, digits or _)");
    if (is_reserved_name(name)) props.fail(*p, key, "'" + name + "' is reserved: x, y, z and function names");
    surface.parameters[name] = numbers(props, key, *p, 1)[0];
  }
  try {
    parse_equation(surface.equation->value, surface.parameters);
  } catch (const EquationError& e) {
    props.fail(*surface.equation, "surface_equation", e.what(), e.position);
  }
  return surface;
}

// Frames. jsurf clips to the unit sphere of its clip space and evaluates the equation at 10^scale_factor times
// the clip-space point, after rotation_matrix; the camera sits in clip space through camera_transform
// (world-to-camera). algray keeps the equation's own coordinates as the world, so the camera and lights move
// instead: camera point p maps to 10^s R C^-1 p.
struct Framing {
  double scale = 1;  // 10^scale_factor: the clip sphere's radius in the world
  glm::dmat4 camera_to_world{1.0};
};

Framing read_framing(const Properties& props, std::vector<std::string>& warnings) {
  const double scale = std::pow(10.0, number_or(props, "scale_factor", 0.0));
  if (!(scale > 0 && std::isfinite(scale) && std::isfinite(1 / scale)))
    props.fail(*props.get("scale_factor"), "scale_factor", "10^scale_factor must be a finite, nonzero radius");
  const Property* rotation_at = nullptr;
  const glm::dmat4 rotation = matrix_or_identity(props, "rotation_matrix", &rotation_at);
  if (rotation_at &&
      (!is_affine(rotation) || !is_rotation(glm::dmat3(rotation)) || glm::length(glm::dvec3(rotation[3])) > 1e-9))
    props.fail(*rotation_at, "rotation_matrix",
               "algray supports a pure rotation here (no scaling, shear, translation)");
  const Property* camera_at = nullptr;
  const glm::dmat4 camera_transform = matrix_or_identity(props, "camera_transform", &camera_at);
  if (camera_at && (!is_affine(camera_transform) || !is_rotation(glm::dmat3(camera_transform))))
    props.fail(*camera_at, "camera_transform",
               "algray supports a rotation and a translation here (no scaling or shear)");
  for (const char* ignored : {"transform_matrix", "surface_transform_matrix"}) {
    const Property* where = nullptr;
    if (!is_identity(matrix_or_identity(props, ignored, &where)))
      warnings.push_back(props.source() + ":" + std::to_string(props.line_of(*where)) + ": " + ignored +
                         " is ignored, as SURFER ignores it (jsurf would apply it on top of rotation_matrix and "
                         "scale_factor, which SURFER also writes)");
  }
  for (const char* unused : {"transform", "surface_transform"}) props.get(unused);  // written by SURFER, read by none
  return {scale, glm::dmat4(glm::dmat3(scale)) * rotation * glm::inverse(camera_transform)};
}

struct JsurfCamera {
  std::string projection = "orthographic";
  double fov_y = 60, height = 2;  // height in clip space
};

JsurfCamera read_camera(const Properties& props) {
  JsurfCamera camera;
  if (const Property* p = props.get("camera_type")) {
    if (p->value == "PERSPECTIVE_CAMERA")
      camera.projection = "perspective";
    else if (p->value != "ORTHOGRAPHIC_CAMERA")
      props.fail(*p, "camera_type", "expected ORTHOGRAPHIC_CAMERA or PERSPECTIVE_CAMERA");
  }
  camera.fov_y = number_or(props, "camera_fov_y", camera.fov_y);
  camera.height = number_or(props, "camera_height", camera.height);
  if (!(camera.fov_y > 0 && camera.fov_y < 180))
    props.fail(*props.get("camera_fov_y"), "camera_fov_y", "must be between 0 and 180 degrees");
  if (!(camera.height > 0)) props.fail(*props.get("camera_height"), "camera_height", "must be positive");
  return camera;
}

// The translated TOML. Each line that carries a value from the file records the property it came from, so that
// an error the scene reader finds in it (a radius of 1e308, say) points into the .jsurf, not into text the user
// never saw.
class TranslatedToml {
 public:
  TranslatedToml(const Properties& props, std::map<int, JsurfOrigin>* origins) : props_(props), origins_(origins) {}

  // `lines` come from the first of `keys` the file gives.
  void emit(const std::string& lines, std::initializer_list<std::string> keys = {}) {
    for (const std::string& key : keys)
      if (const Property* p = props_.get(key); p && origins_) {
        (*origins_)[line_] = props_.origin(*p, key);
        break;
      }
    toml_ << lines;
    line_ += static_cast<int>(std::count(lines.begin(), lines.end(), '\n'));
  }
  std::string str() const { return toml_.str(); }

 private:
  const Properties& props_;
  std::map<int, JsurfOrigin>* origins_;
  std::ostringstream toml_;
  int line_ = 1;
};

void write_surface(TranslatedToml& toml, const std::string& source, const JsurfSurface& surface) {
  const std::size_t slash = source.find_last_of('/');
  const std::string file_name = source.substr(slash == std::string::npos ? 0 : slash + 1);
  toml.emit("# Translated from " + source + " (SURFER/jsurf)\n\n[surface]\nname = " + toml_quoted(file_name) + "\n");
  toml.emit("equation = " + toml_quoted(surface.equation->value) + "\n", {"surface_equation"});
  if (!surface.parameters.empty()) {
    toml.emit("\n[parameters]\n");
    for (const auto& [name, value] : surface.parameters)
      toml.emit(name + " = " + toml_number(value) + "\n", {"surface_parameter_" + name});
  }
}

void write_extent(TranslatedToml& toml, const Framing& framing) {
  toml.emit("\n[extent]  # jsurf's clip sphere: radius 1 in clip space\ntype = \"sphere\"\ncentre = [0.0, 0.0, 0.0]\n");
  toml.emit("radius = " + toml_number(framing.scale) + "\n", {"scale_factor"});
}

void write_camera(TranslatedToml& toml, const JsurfCamera& camera, const Framing& framing) {
  const glm::dvec3 eye = glm::dvec3(framing.camera_to_world * glm::dvec4(0, 0, 0, 1));
  const glm::dvec3 forward = glm::normalize(glm::dvec3(framing.camera_to_world * glm::dvec4(0, 0, -1, 0)));
  const glm::dvec3 up = glm::normalize(glm::dvec3(framing.camera_to_world * glm::dvec4(0, 1, 0, 0)));
  // The camera and everything placed in camera space depend on all three framing properties.
  const std::initializer_list<std::string> framing_keys = {"scale_factor", "rotation_matrix", "camera_transform"};
  toml.emit("\n[camera]\nprojection = \"" + camera.projection + "\"\n", {"camera_type"});
  toml.emit("eye = " + toml_vector(eye) + "\n", framing_keys);
  toml.emit("look_at = " + toml_vector(eye + forward) + "\n", framing_keys);
  toml.emit("up = " + toml_vector(up) + "\n", framing_keys);
  if (camera.projection == "perspective")
    toml.emit("fov_y = " + toml_number(camera.fov_y) + "\n", {"camera_fov_y"});
  else
    toml.emit("height = " + toml_number(camera.height * framing.scale) + "\n", {"camera_height", "scale_factor"});
}

// jsurf renders square images, 512 pixels by default; a background is required by jsurf, white here.
void write_image(TranslatedToml& toml, const Properties& props) {
  toml.emit("\n[image]\nwidth = 512\nheight = 512\n");
  const glm::dvec3 background = colour_or(props, "background_color", glm::dvec3(1));
  toml.emit("background = " + toml_vector(background) + "\n", {"background_color"});
}

// jsurf's default quality: one ray per pixel, more where neighbouring colours differ.
void write_antialias(TranslatedToml& toml) {
  toml.emit("\n[antialias]\nsamples = 2\nadaptive = true\nthreshold = 0.3\n");
}

// jsurf shades with Blinn's half vector, algray with Phong's mirror vector: a Blinn exponent of 4n gives about
// the highlight of a Phong exponent n.
void write_materials(TranslatedToml& toml, const Properties& props, std::vector<std::string>& warnings) {
  for (const char* side : {"front", "back"}) {
    const std::string prefix = std::string(side) + "_material_";
    toml.emit("\n[material." + std::string(side) + "]\n");
    const glm::dvec3 colour = colour_or(props, prefix + "color", glm::dvec3(0.5));
    // 2011 files spell the key specular_iIntensity; the SURFER that wrote them meant the specular intensity.
    const double specular_typo = number_or(props, prefix + "specular_iIntensity", 0.9);
    const double specular = props.get(prefix + "specular_intensity")
                                ? factor_or(props, prefix + "specular_intensity", 0.9, warnings)
                                : std::clamp(specular_typo, 0.0, 1.0);
    toml.emit("colour = " + toml_vector(colour) + "\n", {prefix + "color"});
    toml.emit("ambient = " + toml_number(factor_or(props, prefix + "ambient_intensity", 0.1, warnings)) + "\n",
              {prefix + "ambient_intensity"});
    toml.emit("diffuse = " + toml_number(factor_or(props, prefix + "diffuse_intensity", 0.23232, warnings)) + "\n",
              {prefix + "diffuse_intensity"});
    toml.emit("specular = " + toml_number(specular) + "\n",
              {prefix + "specular_intensity", prefix + "specular_iIntensity"});
    toml.emit(
        "exponent = " + toml_number(std::clamp(number_or(props, prefix + "shininess", 1.0) / 4, 1.0, 10000.0)) + "\n",
        {prefix + "shininess"});
  }
}

// Camera-space points, so they keep their place relative to the viewer; no shadows in jsurf.
void write_lights(TranslatedToml& toml, const Properties& props, const Framing& framing,
                  std::vector<std::string>& warnings) {
  int lights = 0;
  for (int n = 0; n < 8; ++n) {
    const std::string i = std::to_string(n);
    const Property* status = props.get("light_status_" + i);
    const glm::dvec3 position = vector_or(props, "light_position_" + i, glm::dvec3(0));
    const glm::dvec3 colour = colour_or(props, "light_color_" + i, glm::dvec3(1));
    const double intensity = number_or(props, "light_intensity_" + i, 1.0);
    if (!status) continue;  // jsurf switches every light off before reading the file
    if (status->value == "OFF") continue;
    if (status->value != "ON") props.fail(*status, "light_status_" + i, "expected ON or OFF");
    if (intensity < 0) props.fail(*props.get("light_intensity_" + i), "light_intensity_" + i, "must not be negative");
    ++lights;
    toml.emit("\n[[light]]  # light_" + i + "\ntype = \"point\"\n", {"light_status_" + i});
    toml.emit("position = " + toml_vector(glm::dvec3(framing.camera_to_world * glm::dvec4(position, 1))) + "\n",
              {"light_position_" + i, "scale_factor", "rotation_matrix", "camera_transform"});
    toml.emit("colour = " + toml_vector(colour) + "\n", {"light_color_" + i});
    toml.emit("intensity = " + toml_number(intensity) + "\nshadows = false\n", {"light_intensity_" + i});
  }
  if (lights == 0)
    warnings.push_back(
        props.source() +
        ": no light is ON: jsurf shows only the ambient term, algray lights the surface with a headlight");
}

void warn_unused_keys(const Properties& props, std::vector<std::string>& warnings) {
  for (const std::string& key : props.unused())
    warnings.push_back(props.source() + ":" + std::to_string(props.line_of(*props.get(key))) + ": unknown key " + key +
                       " is ignored");
}

}  // namespace

bool looks_like_jsurf(const std::string& text) {
  static const std::regex key(R"((^|\n)[ \t\f]*surface_equation[ \t\f]*[=:])");
  return std::regex_search(text, key);
}

// The surface, framing and camera are read and checked first; the image, materials and lights are checked as
// they are written. Where several properties are wrong, the first in this order is the one reported.
std::string jsurf_to_toml(const std::string& text, const std::string& source, std::vector<std::string>& warnings,
                          std::map<int, JsurfOrigin>* origins) {
  const Properties props(text, source);
  const JsurfSurface surface = read_surface(props);
  const Framing framing = read_framing(props, warnings);
  const JsurfCamera camera = read_camera(props);
  TranslatedToml toml(props, origins);
  write_surface(toml, source, surface);
  write_extent(toml, framing);
  write_camera(toml, camera, framing);
  write_image(toml, props);
  write_antialias(toml);
  write_materials(toml, props, warnings);
  write_lights(toml, props, framing, warnings);
  warn_unused_keys(props, warnings);
  return toml.str();
}

}  // namespace algray
