// Reads scene TOML into a Scene, checking every key and value and naming file, line and column on error.
#include "algray/scene/scene.h"

#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "algray/scene/expression.h"
#include "algray/scene/jsurf.h"
#include "algray/scene/povray.h"
#include "algray/scene/scene_formats.h"
#include "algray/scene/surf_script.h"
#include "algray/scene/toml_reader.h"
#include "algray/util/embedded_files.h"

namespace algray {
namespace {

constexpr int kMaxImageSide = 32768;

std::string format_what(const std::string& where, const std::string& message, const std::string& excerpt) {
  std::string s = where + ": error: " + message;
  if (!excerpt.empty()) s += "\n" + excerpt;
  return s;
}

const std::set<std::string> kTopKeys{"surface", "parameters", "extent",  "camera", "image", "material",
                                     "light",   "antialias",  "render",  "section", "clip"};
const std::set<std::string> kSectionKeys{"plane", "colour", "surface", "width"};
const std::set<std::string> kClipKeys{"plane"};
const std::set<std::string> kSurfaceKeys{"name", "equation", "terms", "material"};
// The keys of every kind: type, and the gate's two (Extent::gate, Extent::reach).
const std::set<std::string> kExtentKeys = [] {
  std::set<std::string> keys{"type", "gate", "reach"};
  for (const ExtentKindInfo& k : extent_kinds()) keys.insert(k.keys.begin(), k.keys.end());
  return keys;
}();
// The eye, or the angles about look_at (camera.h's CameraAngles): one or the other.
const std::set<std::string> kCameraAngleKeys{"azimuth", "elevation", "distance"};
const std::set<std::string> kCameraKeys{"projection", "eye",     "look_at",   "up",      "fov_y",
                                        "height",     "azimuth", "elevation", "distance", "shift"};
const std::set<std::string> kImageKeys{"width", "height", "background"};
const std::set<std::string> kMaterialKeys{"front", "back"};
const std::set<std::string> kMaterialSideKeys{"colour",   "ambient",      "diffuse",     "specular",
                                              "exponent", "reflectivity", "transparency"};
const std::set<std::string> kLightKeys{"type",    "position", "edge_u",    "edge_v",  "normal", "radius",
                                       "samples", "colour",   "intensity", "shadows", "frame"};
const std::set<std::string> kAntialiasKeys{"samples", "adaptive", "threshold"};
const std::set<std::string> kRenderKeys{"precision",      "tolerance", "isolation", "refinement", "ray_origin",
                                        "max_iterations", "tile_size", "lanes",     "preview",    "max_depth"};

// Merges `from` into `into`; tables merge key by key, anything else replaces.
void merge_tables(toml::table& into, toml::table&& from) {
  for (auto&& [key, node] : from) {
    toml::node* existing = into.get(key.str());
    if (existing && existing->is_table() && node.is_table())
      merge_tables(*existing->as_table(), std::move(*node.as_table()));
    else
      into.insert_or_assign(key.str(), std::move(node));
  }
}

bool is_index(const std::string& s) {
  return !s.empty() && s.size() <= 6 &&
         std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
}

// A vector of three numbers in `node`, or nothing: for the exchanges below, which leave checking to the reader.
std::optional<glm::dvec3> loose_vec3(const toml::node* node) {
  const toml::array* a = node ? node->as_array() : nullptr;
  if (!a || a->size() != 3) return std::nullopt;
  glm::dvec3 v;
  for (int i = 0; i < 3; ++i) {
    const toml::node* x = a->get(static_cast<std::size_t>(i));
    if (auto d = x->value<double>())
      v[i] = *d;
    else
      return std::nullopt;
  }
  return v;
}

toml::array toml_array(const glm::dvec3& v) { return toml::array{v.x, v.y, v.z}; }

// The extent's centre as the [extent] table gives it (before it is checked), for a camera's default look_at.
glm::dvec3 loose_extent_centre(const toml::table& root) {
  const toml::table* extent = root["extent"].as_table();
  if (!extent) return glm::dvec3(0);
  if (const auto mn = loose_vec3(extent->get("min")), mx = loose_vec3(extent->get("max")); mn && mx)
    return (*mn + *mx) * 0.5;
  return loose_vec3(extent->get("centre")).value_or(glm::dvec3(0));
}

// --set camera.azimuth (or elevation, distance) on a camera placed by its eye: the eye becomes the three angles
// first, so that the keys not set keep the view; --set camera.eye drops the angles. Nothing is lost either way.
void exchange_camera_keys(toml::table& root, const std::string& key) {
  toml::table* camera = root["camera"].as_table();
  if (!camera) return;
  if (key == "eye") {
    for (const std::string& k : kCameraAngleKeys) camera->erase(k);
    return;
  }
  if (!kCameraAngleKeys.count(key) || !camera->get("eye")) return;
  const auto eye = loose_vec3(camera->get("eye"));
  if (!eye) return;  // the reader reports it
  CameraSpec c;
  c.eye = *eye;
  c.look_at = camera->get("look_at") ? loose_vec3(camera->get("look_at")).value_or(glm::dvec3(0))
                                     : loose_extent_centre(root);
  c.up = loose_vec3(camera->get("up")).value_or(glm::dvec3(0, 1, 0));
  if (!(glm::length(c.up) > 0) || !(glm::length(c.eye - c.look_at) > 0)) return;
  const CameraAngles a = camera_angles(c);
  camera->erase("eye");
  camera->insert("azimuth", a.azimuth);
  camera->insert("elevation", a.elevation);
  camera->insert("distance", a.distance);
}

// --set extent.type=KIND: the keys of the other kinds are dropped, with a note, and the new kind's keys that are
// missing are made from the old ones so that the same part of space stays in view: a sphere of radius R becomes
// the cube of side 2R about its centre, a box the sphere inscribed in its largest side, a sphere the cylinder
// about z of the same radius and half_height R, a box the cylinder about z inscribed in its x and y sides with its
// caps on the box's, and a cylinder the box around it.
void switch_extent_kind(toml::table& root, const std::string& label, std::vector<std::string>& notes) {
  toml::table* extent = root["extent"].as_table();
  if (!extent) return;
  const auto type = extent->get("type") ? extent->get("type")->value<std::string>() : std::nullopt;
  const auto to = std::find_if(extent_kinds().begin(), extent_kinds().end(),
                               [&](const ExtentKindInfo& k) { return type && *type == k.name; });
  if (to == extent_kinds().end()) return;  // the reader names the kinds
  std::vector<std::string> dropped;  // each once: a sphere and a cylinder share centre and radius
  for (const ExtentKindInfo& k : extent_kinds())
    for (const std::string& key : k.keys)
      if (std::find(to->keys.begin(), to->keys.end(), key) == to->keys.end() && extent->get(key) &&
          std::find(dropped.begin(), dropped.end(), key) == dropped.end())
        dropped.push_back(key);
  std::string made;
  const auto centre = loose_vec3(extent->get("centre")).value_or(glm::dvec3(0));
  const auto radius = extent->get("radius") ? extent->get("radius")->value<double>() : std::nullopt;
  const auto half_height = extent->get("half_height") ? extent->get("half_height")->value<double>() : std::nullopt;
  const auto axis_name = extent->get("axis") ? extent->get("axis")->value<std::string>() : std::nullopt;
  const auto mn = loose_vec3(extent->get("min")), mx = loose_vec3(extent->get("max"));
  if (to->kind == ExtentKind::Box && radius && !extent->get("min") && !extent->get("max")) {
    glm::dvec3 half(*radius);
    const int axis = axis_name && axis_name->size() == 1 && (*axis_name)[0] >= 'x' && (*axis_name)[0] <= 'z'
                         ? (*axis_name)[0] - 'x'
                         : 2;
    // read from the node: through the optional above, GCC 12 warns falsely (-Wmaybe-uninitialized) once this file
    // is compiled in a unity batch
    if (const toml::node* h = extent->get("half_height")) half[axis] = h->value_or(half[axis]);
    extent->insert("min", toml_array(centre - half));
    extent->insert("max", toml_array(centre + half));
    made = std::string("; the box is the ") + (half_height ? "box around the cylinder" : "cube about the sphere") +
           ", min = " + toml_vector(centre - half) + ", max = " + toml_vector(centre + half);
  } else if (to->kind == ExtentKind::Sphere && mn && mx && !extent->get("radius")) {
    const glm::dvec3 half = (*mx - *mn) * 0.5;
    const double r = std::max({half.x, half.y, half.z});
    extent->insert_or_assign("centre", toml_array((*mn + *mx) * 0.5));
    extent->insert("radius", r);
    made = "; the sphere is centre = " + toml_vector((*mn + *mx) * 0.5) + ", radius = " + toml_number(r);
    dropped.erase(std::remove(dropped.begin(), dropped.end(), "centre"), dropped.end());
  } else if (to->kind == ExtentKind::Cylinder && !extent->get("half_height")) {
    if (mn && mx && !extent->get("radius")) {
      const glm::dvec3 half = (*mx - *mn) * 0.5;
      extent->insert_or_assign("centre", toml_array((*mn + *mx) * 0.5));
      extent->insert("radius", std::max(half.x, half.y));
      extent->insert("half_height", half.z);
      made = "; the cylinder is centre = " + toml_vector((*mn + *mx) * 0.5) +
             ", radius = " + toml_number(std::max(half.x, half.y)) +
             ", axis = \"z\", half_height = " + toml_number(half.z);
      dropped.erase(std::remove(dropped.begin(), dropped.end(), "centre"), dropped.end());
    } else if (radius) {
      extent->insert("half_height", *radius);
      made = "; the cylinder is about " + std::string(axis_name ? *axis_name : "z") +
             " with half_height = " + toml_number(*radius);
    }
  }
  if (dropped.empty()) {
    if (!made.empty()) notes.push_back(label + ": " + made.substr(2));
    return;
  }
  std::string names;
  for (const std::string& key : dropped) {
    extent->erase(key);
    names += (names.empty() ? "extent." : " and extent.") + key;
  }
  notes.push_back(label + ": " + names + " do" + (dropped.size() == 1 ? "es" : "") + " not apply to a " + to->name +
                  " extent and " + (dropped.size() == 1 ? "was" : "were") + " dropped" + made);
}

// The list of [[name]] tables (section, clip), made where there is none, for a new table to be appended.
toml::array& table_list(toml::table& root, const char* name) {
  toml::node* at = root.get(name);
  if (!at || !at->is_array()) {
    root.insert_or_assign(name, toml::array{});
    at = root.get(name);
  }
  return *at->as_array();
}

// A plane given as text on the command line: --section's equation or --clip's inequality, its errors naming the
// text's character under `label`.
struct PlaneText {
  const std::string& text;
  const std::string& label;
  const char* noun;      // "section", "clip"
  const char* relation;  // "equation", "inequality"
  const char* example;   // "z=0.5", "z<0.5"
  [[noreturn]] void fail_at(std::size_t offset, const std::string& message) const {
    throw SceneError(label, message + " (at character " + std::to_string(offset + 1) + " of the plane)",
                     "  " + text + "\n  " + std::string(std::min(offset, text.size()), ' ') + "^");
  }
  // One side of the relation, text[from, from + length), as a polynomial in x, y, z with the scene's parameters;
  // `related`: the text has a relation sign (an empty side is the left or the right one).
  Polynomial side(const toml::table& root, std::size_t from, std::size_t length, bool related) const;
  // (a, b, c, d) of `poly`, which must be of degree 1.
  std::array<double, 4> coefficients(const Polynomial& poly) const;
};

Polynomial PlaneText::side(const toml::table& root, std::size_t from, std::size_t length, bool related) const {
  std::map<std::string, double> parameters;
  if (const toml::table* p = root["parameters"].as_table())
    for (auto&& [name, node] : *p)
      if (const auto v = node.value<double>()) parameters[std::string(name.str())] = *v;
  const std::string part = text.substr(from, length);
  if (part.find_first_not_of(" \t") == std::string::npos) {
    if (!related) fail_at(from, std::string("--") + noun + " takes a plane, as " + example + " or x+y=1");
    fail_at(from, std::string("the ") + (from == 0 ? "left" : "right") + " side of the plane is empty");
  }
  try {
    return parse_equation(part, parameters);
  } catch (const EquationError& e) {
    fail_at(from + e.position, e.what());
  }
}

std::array<double, 4> PlaneText::coefficients(const Polynomial& p) const {
  if (p.degree() != 1)
    fail_at(0, p.degree() < 1 ? std::string("the plane has no x, y or z: a ") + noun + " is a plane such as " + example
                              : std::string("a ") + noun + " is a plane, of degree 1 in x, y and z; this " +
                                    relation + " has degree " + std::to_string(p.degree()));
  std::array<double, 4> plane = {0, 0, 0, 0};
  for (const auto& [e, c] : p.terms()) plane[e[0] ? 0 : e[1] ? 1 : e[2] ? 2 : 3] = nearest_double(c);
  for (const double c : plane)
    if (!std::isfinite(c)) fail_at(0, "the plane's coefficients do not fit a double");
  return plane;
}

// --section EQUATION: a plane as a linear equation in x, y and z ("z=0.5", "x+y=1", "x-2*z", the last = 0), with
// the scene's parameters, appended as a [[section]] table. Errors name the character of the equation.
void add_section(toml::table& root, const std::string& text, const std::string& label) {
  const PlaneText plane{text, label, "section", "equation", "z=0.5"};
  const std::size_t eq = text.find('=');
  if (eq != std::string::npos && text.find('=', eq + 1) != std::string::npos)
    plane.fail_at(text.find('=', eq + 1), "a plane is one equation, as z=0.5 or x+y=1: it has one '='");
  const Polynomial p = eq == std::string::npos
                           ? plane.side(root, 0, std::string::npos, false)
                           : plane.side(root, 0, eq, true) - plane.side(root, eq + 1, std::string::npos, true);
  const std::array<double, 4> c = plane.coefficients(p);
  toml::table section;
  section.insert("plane", toml::array{c[0], c[1], c[2], c[3]});
  table_list(root, "section").push_back(std::move(section));
}

// --clip INEQUALITY: the half-space kept, as a linear inequality in x, y and z with <, <=, > or >= ("z<0.5",
// "x+y>=1"; < and <= alike, as the plane itself is drawn either way), with the scene's parameters, appended as a
// [[clip]] table whose plane keeps a*x + b*y + c*z + d <= 0. Errors name the character of the inequality.
void add_clip(toml::table& root, const std::string& text, const std::string& label) {
  const PlaneText plane{text, label, "clip", "inequality", "z<0.5"};
  toml::array& clips = table_list(root, "clip");
  if (clips.size() >= kMaxClipPlanes)
    plane.fail_at(0, "at most " + std::to_string(kMaxClipPlanes) + " clipping planes cut a scene, and it has " +
                         std::to_string(clips.size()) + " already");
  const std::size_t op = text.find_first_of("<>");
  if (op == std::string::npos) {
    const std::size_t eq = text.find('=');
    if (eq != std::string::npos)
      plane.fail_at(eq, "a clip keeps one side of a plane: write an inequality such as z<0.5 or z>0.5, not an '='");
    plane.fail_at(0, "--clip takes a half-space, the side of a plane to keep, as z<0.5 or x+y>=1");
  }
  const std::size_t width = op + 1 < text.size() && text[op + 1] == '=' ? 2 : 1;
  const std::size_t rest = op + width;
  if (const std::size_t again = text.find_first_of("<>=", rest); again != std::string::npos)
    plane.fail_at(again, "a half-space is one inequality, as z<0.5 or x+y>=1: it has one '<' or '>'");
  const Polynomial lhs_minus_rhs = plane.side(root, 0, op, true) - plane.side(root, rest, std::string::npos, true);
  // lhs < rhs keeps lhs - rhs <= 0; lhs > rhs keeps rhs - lhs <= 0.
  std::array<double, 4> c = plane.coefficients(lhs_minus_rhs);
  if (text[op] == '>')
    for (double& v : c) v = v == 0 ? 0.0 : -v;
  toml::table clip;
  clip.insert("plane", toml::array{c[0], c[1], c[2], c[3]});
  clips.push_back(std::move(clip));
}

// Why LIST.INDEX names nothing: the scene has no [[LIST]] tables, and what adds one.
std::string no_list_message(const std::string& list, const std::string& index) {
  std::string m = "the scene has no [[" + list + "]] tables, so there is no " + list + "." + index;
  if (list == "section") m += "; --section adds one, as --section z=0.5";
  if (list == "clip") m += "; --clip adds one, as --clip 'z<0.5'";
  if (list == "light")
    m += "; it is lit by a headlight at the eye (a scene that places camera.eye); [[light]] tables give it lights";
  return m;
}

// A hostile key or value may be megabytes long: messages show its start.
std::string shown(const std::string& t) {
  return t.size() <= 120 ? t : t.substr(0, 100) + "...(" + std::to_string(t.size()) + " characters)";
}

// --section or --clip given as an override: the plane as written, or as a TOML string (Python's Scene.set and a
// job's set table quote it).
void apply_plane_override(toml::table& root, const Override& o) {
  std::string plane = o.value;
  if (!plane.empty() && (plane.front() == '"' || plane.front() == '\'')) try {
      plane = toml::parse("v = " + plane)["v"].value_or(plane);
    } catch (const toml::parse_error&) {
      // not a TOML string after all: the plane's own reading says what is wrong
    }
  const bool clip = o.key == kClipOverrideKey;
  const std::string noun = clip ? "clip " : "section ";
  const std::string label = (o.origin.empty() ? "--" + noun : o.origin + ": " + noun) + shown(plane);
  if (clip)
    add_clip(root, plane, label);
  else
    add_section(root, plane, label);
}

// A bare name must be one of the scene's parameters, so that a typo is not a new parameter nothing uses.
void check_parameter_exists(const toml::table* params, const std::string& name, const std::string& label) {
  if (params && params->get(name)) return;
  std::string names;
  if (params)
    for (auto&& [param, node] : *params) names += (names.empty() ? "" : ", ") + std::string(param.str());
  throw SceneError(label, "the scene has no parameter '" + name + "'; " +
                              (names.empty() ? "it has no parameters" : "its parameters: " + names) +
                              " (--set parameters." + name + "=VALUE adds one)");
}

std::vector<std::string> key_parts(const std::string& key, const std::string& label) {
  std::vector<std::string> parts;
  for (std::size_t start = 0;;) {
    const std::size_t dot = key.find('.', start);
    parts.push_back(key.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  if (parts.size() > kMaxTomlKeyParts)
    throw SceneError(label, "the key has " + std::to_string(parts.size()) + " parts; at most " +
                                std::to_string(kMaxTomlKeyParts) + " are allowed");
  return parts;
}

// An override's key on its way down the scene's tables, and the override's words for its messages.
struct KeyWalk {
  const std::vector<std::string>& parts;
  const std::string& written_key;
  const std::string& label;
  toml::table* target;
  std::size_t i = 0;  // parts[i] is the first part below target

  void check_identifier(const std::string& part) const {
    if (!is_identifier(part))
      throw SceneError(
          label, "'" + shown(written_key) + "' is not a dotted scene key such as camera.fov_y or light.0.intensity");
  }
  // Down the existing tables to the last part's, or to where they end.
  void descend() {
    while (i + 1 < parts.size())
      if (!step()) return;
  }
  bool step();
  void step_into_list(toml::node& at);
};

// One step down: into a table, or into one table of a list by its index; false where the existing tables end.
bool KeyWalk::step() {
  check_identifier(parts[i]);
  toml::node* at = target->get(parts[i]);
  if (at && at->is_table()) {
    if (is_index(parts[i + 1]))
      throw SceneError(label, "'" + parts[i] + "' is a single [" + parts[i] + "] table, not a list: leave out the " +
                                  "index, as in " + parts[i] + "." + (i + 2 < parts.size() ? parts[i + 2] : "KEY"));
    target = at->as_table();
    ++i;
    return true;
  }
  if (!at || !at->is_array_of_tables()) {
    if (is_index(parts[i + 1]) && (!at || (at->is_array() && at->as_array()->empty())))
      throw SceneError(label, no_list_message(parts[i], parts[i + 1]));
    return false;
  }
  step_into_list(*at);
  return true;
}

void KeyWalk::step_into_list(toml::node& at) {
  const std::string& list_name = parts[i];
  toml::array& list = *at.as_array();
  if (!is_index(parts[i + 1]))
    throw SceneError(label, "'" + list_name + "' is a list of [[" + list_name +
                                "]] tables: name one by its index from 0, as in " + list_name + ".0." + parts[i + 1]);
  const std::size_t index = std::stoul(parts[i + 1]);
  if (index >= list.size())
    throw SceneError(label, "the scene has " + std::to_string(list.size()) + " [[" + list_name + "]] table" +
                                (list.size() == 1 ? "" : "s") + ", indexed from 0: there is no " + list_name + "." +
                                parts[i + 1]);
  if (i + 2 == parts.size())
    throw SceneError(label,
                     "'" + shown(written_key) + "' names a whole [[" + list_name + "]] table; set one of its keys");
  target = list.get(index)->as_table();
  i += 2;
}

// Parsed as the TOML line `key = value`, every node it creates carries the override as its source, so errors
// name it. A value that is not TOML (render.precision=float) is taken as a string.
toml::table parse_override_value(const std::string& rest, const std::string& value, const std::string& label) {
  try {
    check_toml_shape(rest + " = " + value, label);
  } catch (const SceneError& e) {
    throw SceneError(label, e.message);  // the line and column are of a line the user never wrote
  }
  try {
    return toml::parse(rest + " = " + value, label);
  } catch (const toml::parse_error&) {
    // As a literal string it must still be TOML: no quote, no line break, no control character, valid UTF-8.
    try {
      if (value.find_first_of("'\n") != std::string::npos) throw std::invalid_argument("quote or line break");
      return toml::parse(rest + " = '" + value + "'", label);
    } catch (const std::exception&) {
      throw SceneError(label, "value is neither valid TOML nor a plain string");
    }
  }
}

void apply_override(toml::table& root, const Override& o, std::vector<std::string>& notes) {
  // A scene without [extent] has algray's sphere of radius kDefaultExtentRadius: extent.KEY changes that one.
  if (o.key.rfind("extent.", 0) == 0 && !root.get("extent"))
    root.insert("extent", toml::table{{"radius", kDefaultExtentRadius}});
  if (o.key == kSectionOverrideKey || o.key == kClipOverrideKey) return apply_plane_override(root, o);
  const std::string label = (o.origin.empty() ? "--set " : o.origin + ": set ") + shown(o.key) + "=" + shown(o.value);
  // A bare name is a parameter; any other key is a dotted path into the scene; parameters.NAME adds a parameter.
  // A bare name that is no parameter but a top-level table of the scene is that table: --set 'section=[]' drops
  // the sections.
  const bool bare = o.key.find('.') == std::string::npos;
  const toml::table* params = root["parameters"].as_table();
  const bool top_table = bare && (!params || !params->get(o.key)) && kTopKeys.count(o.key) && o.key != "parameters";
  if (bare && is_identifier(o.key) && !top_table) check_parameter_exists(params, o.key, label);
  const std::string key = bare && !top_table ? "parameters." + o.key : o.key;
  const std::vector<std::string> parts = key_parts(key, label);
  // Walk down the existing tables. A list of tables ([[surface]], [[light]]) is reached by index, as in
  // light.0.intensity, and the override applies inside that one table: merging at the list would replace the
  // whole list with a single table.
  KeyWalk walk{parts, o.key, label, &root};
  walk.descend();
  const std::size_t i = walk.i;
  if (!top_table && i + 1 == parts.size() && walk.target->get(parts[i]) &&
      walk.target->get(parts[i])->is_array_of_tables())
    throw SceneError(label, "'" + parts[i] + "' is a list of [[" + parts[i] +
                                "]] tables: name one by its index from 0, as in " + parts[i] + ".0.KEY");
  std::string rest;
  for (std::size_t k = i; k < parts.size(); ++k) {
    walk.check_identifier(parts[k]);
    rest += (k > i ? "." : "") + parts[k];
  }
  toml::table parsed = parse_override_value(rest, o.value, label);
  if (parts.size() == 2 && parts[0] == "camera") exchange_camera_keys(root, parts[1]);
  merge_tables(*walk.target, std::move(parsed));
  if (key == "extent.type") switch_extent_kind(root, label, notes);
}

Polynomial polynomial_from_terms(const TomlReader& r, const toml::node& terms_node) {
  const toml::array* terms = terms_node.as_array();
  if (!terms || terms->empty()) r.fail(terms_node.source(), "surface.terms must be a non-empty array of [i, j, k, a]");
  Polynomial p;
  for (const toml::node& t : *terms) {
    const toml::array* a = t.as_array();
    if (!a || a->size() != 4)
      r.fail(t.source(), "each term must be [i, j, k, a]: exponents of x, y, z and the coefficient");
    const int i = static_cast<int>(r.integer(*a->get(0), "exponent i", 0, 1000));
    const int j = static_cast<int>(r.integer(*a->get(1), "exponent j", 0, 1000));
    const int k = static_cast<int>(r.integer(*a->get(2), "exponent k", 0, 1000));
    p.add_term(i, j, k, exact_rational(r.number(*a->get(3), "coefficient")));
  }
  return p;
}

void read_material(const TomlReader& r, const toml::table& t, const std::string& name, Material& m) {
  r.check_keys(t, name, kMaterialSideKeys);
  if (const toml::node* n = t.get("colour")) m.colour = glm::dvec3(r.colour(*n, name + ".colour", false));
  if (const toml::node* n = t.get("ambient")) m.ambient = r.number_in(*n, name + ".ambient", 0, 1);
  if (const toml::node* n = t.get("diffuse")) m.diffuse = r.number_in(*n, name + ".diffuse", 0, 1);
  if (const toml::node* n = t.get("specular")) m.specular = r.number_in(*n, name + ".specular", 0, 1);
  if (const toml::node* n = t.get("exponent")) m.exponent = r.number_in(*n, name + ".exponent", 1, 10000);
  if (const toml::node* n = t.get("reflectivity")) m.reflectivity = r.number_in(*n, name + ".reflectivity", 0, 1);
  if (const toml::node* n = t.get("transparency")) m.transparency = r.number_in(*n, name + ".transparency", 0, 1);
}

void read_materials(const TomlReader& r, const toml::table& t, const std::string& name, Materials& m) {
  r.check_keys(t, name, kMaterialKeys);
  for (const char* side : {"front", "back"})
    if (const toml::table* st = r.subtable(t, side))
      read_material(r, *st, name + "." + side, std::string(side) == "front" ? m.front : m.back);
}

SceneSurface read_surface(const TomlReader& r, const toml::table& surface,
                          const std::map<std::string, double>& parameters) {
  SceneSurface out;
  r.check_keys(surface, "surface", kSurfaceKeys);
  const toml::node* equation = surface.get("equation");
  const toml::node* terms = surface.get("terms");
  if (equation && terms) r.fail(terms->source(), "give surface.equation or surface.terms, not both");
  const toml::node& anchor = equation ? *equation : terms ? *terms : static_cast<const toml::node&>(surface);
  if (equation) {
    out.equation = r.string(*equation, "surface.equation");
    try {
      out.polynomial = parse_equation(out.equation, parameters, kMaxDegree);
    } catch (const EquationError& e) {
      r.fail(equation->source(),
             std::string(e.what()) + " (at character " + std::to_string(e.position + 1) + " of the equation)",
             r.string_column_offset(*equation, e.position));
    }
  } else if (terms) {
    out.polynomial = polynomial_from_terms(r, *terms);
    out.from_terms = true;
    out.equation = out.polynomial.to_string();
  } else {
    r.fail(surface.source(), "[surface] needs an equation or a list of terms");
  }
  const int degree = out.polynomial.degree();
  if (degree < 0) r.fail(anchor.source(), "the polynomial is identically zero after expansion");
  if (degree == 0) r.fail(anchor.source(), "the polynomial is a nonzero constant: it has no points");
  if (degree > kMaxDegree)
    r.fail(anchor.source(),
           "degree " + std::to_string(degree) + " exceeds the supported maximum " + std::to_string(kMaxDegree));
  if (const toml::node* n = surface.get("name")) out.name = r.string(*n, "surface.name");
  return out;
}

// `index`: the light's place in the [[light]] list, as --set light.N.KEY names it in an unknown key's message.
Light read_light(const TomlReader& r, const toml::table& t, const CameraSpec& camera, std::size_t index) {
  r.check_keys(t, "light." + std::to_string(index), kLightKeys);
  Light light;
  const std::string type = t.get("type") ? r.string(*t.get("type"), "light.type") : "point";
  if (type == "point")
    light.kind = LightKind::Point;
  else if (type == "rectangle")
    light.kind = LightKind::Rectangle;
  else if (type == "disc")
    light.kind = LightKind::Disc;
  else
    r.fail(t.get("type")->source(), "light.type must be \"point\", \"rectangle\" or \"disc\"");
  const toml::node* position = t.get("position");
  if (!position) r.fail(t.source(), "a light needs a position (the centre of an area light)");
  light.position = r.vec3(*position, "light.position");
  // Keys that belong to another kind of light are mistakes, not things to ignore.
  const std::set<std::string> own =
      light.kind == LightKind::Rectangle ? std::set<std::string>{"edge_u", "edge_v", "samples"}
      : light.kind == LightKind::Disc    ? std::set<std::string>{"normal", "radius", "samples"}
                                         : std::set<std::string>{};
  for (const char* key : {"edge_u", "edge_v", "normal", "radius", "samples"})
    if (const toml::node* n = t.get(key); n && !own.count(key))
      r.fail(n->source(), std::string("light.") + key + " does not apply to a " + type + " light");
  if (light.kind == LightKind::Rectangle) {
    if (!t.get("edge_u") || !t.get("edge_v")) r.fail(t.source(), "a rectangle light needs edge_u and edge_v");
    light.edge_u = r.vec3(*t.get("edge_u"), "light.edge_u");
    light.edge_v = r.vec3(*t.get("edge_v"), "light.edge_v");
    if (glm::length(glm::cross(light.edge_u, light.edge_v)) <= 0)
      r.fail(t.get("edge_v")->source(), "the rectangle is degenerate: edge_u and edge_v must span an area");
  }
  if (light.kind == LightKind::Disc) {
    if (!t.get("radius")) r.fail(t.source(), "a disc light needs a radius");
    light.radius = r.coordinate(*t.get("radius"), "light.radius");
    if (!(light.radius > 0)) r.fail(t.get("radius")->source(), "light.radius must be positive");
    if (const toml::node* n = t.get("normal")) {
      light.normal = r.vec3(*n, "light.normal");
      // Kept as written (normalised where it is used), so that scene_to_toml writes back what was read.
      if (!(glm::length(light.normal) > 0)) r.fail(n->source(), "light.normal must not be zero");
    }
  }
  if (light.kind != LightKind::Point) {
    light.samples = 5;  // the paper's 25 points per area light
    if (const toml::node* n = t.get("samples"))
      light.samples = static_cast<int>(r.integer(*n, "light.samples", 1, kMaxLightSamplesPerSide));
  }
  if (const toml::node* n = t.get("colour")) light.colour = glm::dvec3(r.colour(*n, "light.colour", false));
  if (const toml::node* n = t.get("intensity")) {
    light.intensity = r.coordinate(*n, "light.intensity");
    if (light.intensity < 0) r.fail(n->source(), "light.intensity must not be negative");
  }
  if (const toml::node* n = t.get("shadows")) light.shadows = r.boolean(*n, "light.shadows");
  if (const toml::node* n = t.get("frame")) {
    const std::string frame = r.string(*n, "light.frame");
    if (frame == "camera")
      light.in_camera = Light::CameraFrame{light.position, light.edge_u, light.edge_v, light.normal};
    else if (frame != "world")
      r.fail(n->source(), "light.frame must be \"world\" or \"camera\" (attached to the camera, following it)");
  }
  if (light.in_camera) {
    std::vector<Light> one{light};
    place_camera_lights(one, camera);
    light = one.front();
  }
  return light;
}

// Parameters come first: the equations refer to them.
void read_parameters(const TomlReader& r, const toml::table& root, std::map<std::string, double>& parameters) {
  const toml::table* params = r.subtable(root, "parameters");
  if (!params) return;
  for (auto&& [key, node] : *params) {
    const std::string name(key.str());
    if (!is_identifier(name) || is_reserved_name(name))
      r.fail(key.source(), "parameter name '" + name +
                               "' must be an identifier other than x, y, z and the function names (sqrt, sin, ...)");
    parameters[name] = r.number(node, "parameter '" + name + "'");
  }
}

// One [surface] table, or several [[surface]] tables: the nearest hit among them wins. Returns the tables, in
// the order of scene.surfaces, for their own materials.
std::vector<const toml::table*> read_surfaces(const TomlReader& r, const toml::table& root, Scene& scene) {
  const toml::node* surface_node = root.get("surface");
  if (!surface_node) r.fail(root.source(), "missing [surface] table with an equation or a list of terms");
  std::vector<const toml::table*> surface_tables;
  if (const toml::table* t = surface_node->as_table()) {
    surface_tables.push_back(t);
  } else if (const toml::array* list = surface_node->as_array(); list && list->is_array_of_tables() && !list->empty()) {
    if (list->size() > kMaxSurfaces)
      r.fail(surface_node->source(), "at most " + std::to_string(kMaxSurfaces) + " surfaces per scene");
    for (const toml::node& n : *list) surface_tables.push_back(n.as_table());
  } else {
    r.fail(surface_node->source(), "'surface' must be a [surface] table or [[surface]] tables");
  }
  for (const toml::table* t : surface_tables) scene.surfaces.push_back(read_surface(r, *t, scene.parameters));
  if (!scene.surfaces.front().name.empty()) scene.name = scene.surfaces.front().name;
  return surface_tables;
}

// A key of another kind (extent_kinds()) is refused, naming the first kind it belongs to.
void refuse_other_kinds_keys(const TomlReader& r, const toml::table& extent, ExtentKind kind) {
  const auto own = std::find_if(extent_kinds().begin(), extent_kinds().end(),
                                [&](const ExtentKindInfo& k) { return k.kind == kind; });
  for (const ExtentKindInfo& k : extent_kinds())
    for (const std::string& key : k.keys)
      if (const toml::node* n = extent.get(key);
          n && std::find(own->keys.begin(), own->keys.end(), key) == own->keys.end())
        r.fail(n->source(), "extent." + key + " belongs to a " + k.name + " extent");
}

// The centre and radius a sphere and a cylinder share.
void read_round_extent(const TomlReader& r, const toml::table& extent, Extent& out) {
  refuse_other_kinds_keys(r, extent, out.kind);
  if (const toml::node* n = extent.get("centre")) out.centre = r.vec3(*n, "extent.centre");
  const toml::node* radius = extent.get("radius");
  if (!radius)
    r.fail(extent.source(),
           std::string("a ") + (out.kind == ExtentKind::Sphere ? "sphere" : "cylinder") + " extent needs a radius");
  out.radius = r.coordinate(*radius, "extent.radius");
  if (out.radius <= 0) r.fail(radius->source(), "the extent is empty: radius must be positive");
  if (out.radius < 1 / kMaxCoordinate)
    r.fail(radius->source(), "the extent is too small to render: its radius must be at least 1e-18");
}

void read_sphere_extent(const TomlReader& r, const toml::table& extent, Extent& out) {
  out.kind = ExtentKind::Sphere;
  read_round_extent(r, extent, out);
}

// A cylinder: a sphere's centre and radius, an axis "x", "y" or "z" (z unless given) and the caps' half_height.
void read_cylinder_extent(const TomlReader& r, const toml::table& extent, Extent& out) {
  out.kind = ExtentKind::Cylinder;
  read_round_extent(r, extent, out);
  out.axis = 2;
  if (const toml::node* n = extent.get("axis")) {
    const std::string axis = r.string(*n, "extent.axis");
    if (axis != "x" && axis != "y" && axis != "z") r.fail(n->source(), "extent.axis must be \"x\", \"y\" or \"z\"");
    out.axis = axis[0] - 'x';
  }
  const toml::node* half = extent.get("half_height");
  if (!half) r.fail(extent.source(), "a cylinder extent needs a half_height");
  out.half_height = r.coordinate(*half, "extent.half_height");
  if (out.half_height <= 0) r.fail(half->source(), "the extent is empty: half_height must be positive");
  if (out.half_height < 1 / kMaxCoordinate)
    r.fail(half->source(), "the extent is too small to render: its half_height must be at least 1e-18");
}

void read_box_extent(const TomlReader& r, const toml::table& extent, Extent& out) {
  out.kind = ExtentKind::Box;
  refuse_other_kinds_keys(r, extent, out.kind);
  const toml::node* mn = extent.get("min");
  const toml::node* mx = extent.get("max");
  if (!mn || !mx) r.fail(extent.source(), "a box extent needs min and max");
  out.min = r.vec3(*mn, "extent.min");
  out.max = r.vec3(*mx, "extent.max");
  for (int i = 0; i < 3; ++i)
    if (!(out.min[i] < out.max[i]))
      r.fail(mx->source(), std::string("the extent is empty: max.") + "xyz"[i] + " must exceed min." + "xyz"[i]);
  if (out.shape_scale() < 1 / kMaxCoordinate)
    r.fail(mx->source(), "the extent is too small to render: its half-diagonal must be at least 1e-18");
}

// gate = true makes the shape a ray gate; reach (only with a gate) sets its far sphere.
void read_gate(const TomlReader& r, const toml::table& extent, Extent& out) {
  if (const toml::node* n = extent.get("gate")) out.gate = r.boolean(*n, "extent.gate");
  const toml::node* reach = extent.get("reach");
  if (!reach) return;
  if (!out.gate)
    r.fail(reach->source(), "extent.reach is the far limit of a gate: it needs extent.gate = true");
  out.reach = r.number_in(*reach, "extent.reach", 1, kMaxGateReach);
}

// "\"sphere\" or \"box\"", from extent_kinds().
std::string extent_kind_choices() {
  std::string out;
  const auto& kinds = extent_kinds();
  for (std::size_t i = 0; i < kinds.size(); ++i)
    out += std::string(i == 0 ? "" : i + 1 == kinds.size() ? " or " : ", ") + "\"" + kinds[i].name + "\"";
  return out;
}

void read_extent(const TomlReader& r, const toml::table& root, Extent& out) {
  const toml::table* extent = r.subtable(root, "extent");
  if (!extent) {  // algray's default: a sphere about the origin
    out.kind = ExtentKind::Sphere;
    out.radius = kDefaultExtentRadius;
    return;
  }
  r.check_keys(*extent, "extent", kExtentKeys);
  const std::string type = extent->get("type") ? r.string(*extent->get("type"), "extent.type") : "sphere";
  if (type == "sphere")
    read_sphere_extent(r, *extent, out);
  else if (type == "box")
    read_box_extent(r, *extent, out);
  else if (type == "cylinder")
    read_cylinder_extent(r, *extent, out);
  else
    r.fail(extent->get("type")->source(), "extent.type must be " + extent_kind_choices());
  read_gate(r, *extent, out);
}

// The camera: by its eye, or by angles about look_at (CameraAngles), which is algray's framing when the scene
// gives neither: look_at the extent's centre, up +y, kFramingDistance times the extent's radius away.
void read_camera(const TomlReader& r, const toml::table& root, const Extent& extent, CameraSpec& cam) {
  static const toml::table none;
  const toml::table* given = r.subtable(root, "camera");
  const toml::table* camera = given ? given : &none;
  r.check_keys(*camera, "camera", kCameraKeys);
  if (const toml::node* n = camera->get("projection")) {
    const std::string p = r.string(*n, "camera.projection");
    if (p == "perspective")
      cam.projection = Projection::Perspective;
    else if (p == "orthographic")
      cam.projection = Projection::Orthographic;
    else
      r.fail(n->source(), "camera.projection must be \"perspective\" or \"orthographic\"");
  }
  // Where it looks from and to, and which way is up.
  cam.look_at = camera->get("look_at") ? r.vec3(*camera->get("look_at"), "camera.look_at") : extent.unit_centre();
  cam.up = camera->get("up") ? r.vec3(*camera->get("up"), "camera.up") : glm::dvec3(0, 1, 0);
  if (const toml::node* eye = camera->get("eye")) {
    for (const std::string& k : kCameraAngleKeys)
      if (const toml::node* n = camera->get(k))
        r.fail(n->source(), "camera." + k + " places the eye by angles: give camera.eye or the angles (azimuth, " +
                                "elevation, distance), not both");
    cam.eye = r.vec3(*eye, "camera.eye");
    const glm::dvec3 view = cam.look_at - cam.eye;
    const toml::node* look_at = camera->get("look_at");
    if (glm::length(view) <= 1e-12 * std::max(1.0, glm::length(cam.eye)))
      r.fail((look_at ? look_at : eye)->source(), "degenerate camera: look_at coincides with eye");
    const toml::node* up = camera->get("up");
    if (glm::length(glm::cross(glm::normalize(view), cam.up)) <= 1e-9 * glm::length(cam.up) ||
        glm::length(cam.up) == 0)
      r.fail((up ? up : eye)->source(), "degenerate camera: up is zero or parallel to the viewing direction");
  } else {
    CameraAngles a;
    a.distance = kFramingDistance * extent.shape_scale();
    if (const toml::node* n = camera->get("azimuth")) a.azimuth = r.number_in(*n, "camera.azimuth", -3600, 3600);
    if (const toml::node* n = camera->get("elevation")) a.elevation = r.number_in(*n, "camera.elevation", -90, 90);
    if (const toml::node* n = camera->get("distance")) {
      a.distance = r.coordinate(*n, "camera.distance");
      if (!(a.distance > 1 / kMaxCoordinate)) r.fail(n->source(), "degenerate camera: distance must be positive");
    }
    if (!(glm::length(cam.up) > 0)) r.fail(camera->get("up")->source(), "degenerate camera: up is zero");
    place_camera_by_angles(cam, a, cam.up);
  }
  // How much it sees: an angle for a perspective camera, a height for an orthographic one.
  if (const toml::node* n = camera->get("fov_y")) {
    if (cam.projection != Projection::Perspective) r.fail(n->source(), "camera.fov_y applies to perspective cameras");
    cam.fov_y_degrees = r.number(*n, "camera.fov_y");
    if (!(cam.fov_y_degrees > 0 && cam.fov_y_degrees < 180))
      r.fail(n->source(), "degenerate camera: fov_y must be between 0 and 180 degrees, exclusive");
  }
  if (const toml::node* n = camera->get("height")) {
    if (cam.projection != Projection::Orthographic)
      r.fail(n->source(), "camera.height applies to orthographic cameras");
    cam.ortho_height = r.coordinate(*n, "camera.height");
    if (!(cam.ortho_height > 0)) r.fail(n->source(), "degenerate camera: height must be positive");
  } else if (cam.projection == Projection::Orthographic) {
    r.fail(camera->get("projection")->source(),
           "an orthographic camera needs camera.height (the view height in world units)");
  }
  // An off-axis view: the image's centre moved across the image plane, in image widths and heights.
  if (const toml::node* n = camera->get("shift")) {
    const toml::array* a = n->as_array();
    if (!a || a->size() != 2)
      r.fail(n->source(), "camera.shift must be an array of 2 numbers [x, y] (image widths right, heights up)");
    for (int i = 0; i < 2; ++i)
      cam.shift[i] = r.number_in(*a->get(static_cast<std::size_t>(i)), "camera.shift[" + std::to_string(i) + "]",
                                 -kMaxCameraShift, kMaxCameraShift);
  }
}

void read_image(const TomlReader& r, const toml::table& root, ImageSpec& out) {
  const toml::table* image = r.subtable(root, "image");
  if (!image) return;
  r.check_keys(*image, "image", kImageKeys);
  if (const toml::node* n = image->get("width"))
    out.width = static_cast<int>(r.integer(*n, "image.width", 1, kMaxImageSide));
  if (const toml::node* n = image->get("height"))
    out.height = static_cast<int>(r.integer(*n, "image.height", 1, kMaxImageSide));
  if (const toml::node* n = image->get("background")) out.background = r.colour(*n, "image.background", true);
}

// [material] sets every surface's sides; a surface's own [surface.material] then changes its keys.
void read_surface_materials(const TomlReader& r, const toml::table& root,
                            const std::vector<const toml::table*>& surface_tables,
                            std::vector<SceneSurface>& surfaces) {
  Materials defaults;
  if (const toml::table* material = r.subtable(root, "material")) read_materials(r, *material, "material", defaults);
  for (std::size_t i = 0; i < surfaces.size(); ++i) {
    Materials own = defaults;
    if (const toml::table* material = r.subtable(*surface_tables[i], "material"))
      read_materials(r, *material, "surface.material", own);
    surfaces[i].materials = own;
  }
}

// The key and fill light of a scene that leaves its view to algray: the shipped scenes' two rectangle lights of 5x5
// points, attached to the camera (so that they follow it), in units of the extent's radius R: the key above and
// to the left of the eye, the fill to its right.
struct FramingLight {
  glm::dvec3 position, edge_u, edge_v;
  double intensity;
};
const FramingLight kFramingLights[] = {{{-2.4, 2.6, 0}, {0.47, 0, 0.375}, {0.21, 0.5, -0.26}, 0.8},
                                       {{2.2, 0.2, 0}, {0.48, 0, -0.355}, {-0.02, 0.6, -0.03}, 0.3}};

std::vector<Light> framing_lights(double radius, const CameraSpec& camera) {
  std::vector<Light> out;
  for (const FramingLight& f : kFramingLights) {
    Light l;
    l.kind = LightKind::Rectangle;
    l.samples = 5;
    l.intensity = f.intensity;
    l.in_camera = Light::CameraFrame{f.position * radius, f.edge_u * radius, f.edge_v * radius, glm::dvec3(0, 0, 1)};
    out.push_back(l);
  }
  place_camera_lights(out, camera);
  return out;
}

// The framing lights as [[light]] tables of `root`, sized by its extent as read now: for a --set light.N.KEY on a
// scene that leaves its lights to algray (load_scene_text), which then changes one of them. They read back to
// framing_lights' own values.
void write_framing_lights(const TomlReader& r, toml::table& root) {
  Extent extent;
  read_extent(r, root, extent);
  const double radius = extent.shape_scale();
  toml::array lights;
  for (const FramingLight& f : kFramingLights) {
    toml::table t;
    t.insert("type", "rectangle");
    t.insert("frame", "camera");
    t.insert("position", toml_array(f.position * radius));
    t.insert("edge_u", toml_array(f.edge_u * radius));
    t.insert("edge_v", toml_array(f.edge_v * radius));
    t.insert("samples", 5);
    t.insert("intensity", f.intensity);
    lights.push_back(std::move(t));
  }
  root.insert_or_assign("light", std::move(lights));
}

// The [[key]] tables of root; none where it is absent or `key = []`. Anything else is a located error, `written`.
const toml::array* table_list(const TomlReader& r, const toml::table& root, const char* key, const char* written) {
  const toml::node* node = root.get(key);
  if (!node) return nullptr;
  const toml::array* list = node->as_array();
  if (list && list->empty()) return nullptr;
  if (!list || !list->is_array_of_tables()) r.fail(node->source(), written);
  return list;
}

void read_lights(const TomlReader& r, const toml::table& root, const CameraSpec& camera, std::vector<Light>& out) {
  // light = []: the headlight
  const toml::array* list = table_list(r, root, "light", "lights are written as [[light]] tables, one per light");
  if (!list) return;
  for (const toml::node& node : *list) out.push_back(read_light(r, *node.as_table(), camera, out.size()));
}

// A [[section]] or [[clip]] table's plane = [a, b, c, d], (a, b, c) not zero; `meaning` says what the plane does.
glm::dvec4 read_plane(const TomlReader& r, const toml::table& t, const std::string& name, const std::string& meaning) {
  const toml::node* plane = t.get("plane");
  if (!plane) r.fail(t.source(), "a " + name + " needs plane = [a, b, c, d] (" + meaning + ")");
  const toml::array* a = plane->as_array();
  if (!a || a->size() != 4) r.fail(plane->source(), name + ".plane must be an array of 4 numbers [a, b, c, d]");
  glm::dvec4 p;
  for (int i = 0; i < 4; ++i)
    p[i] = r.coordinate(*a->get(static_cast<std::size_t>(i)), name + ".plane[" + std::to_string(i) + "]");
  if (p.x == 0 && p.y == 0 && p.z == 0) r.fail(plane->source(), name + ".plane is no plane: a, b and c are all 0");
  return p;
}

// [[section]] tables: plane = [a, b, c, d] (a plane: (a, b, c) not zero), an optional colour, width in pixels and
// surface (the index of the one surface it cuts, from 0 as --set counts them; every surface without it).
void read_sections(const TomlReader& r, const toml::table& root, std::size_t surfaces, std::vector<Section>& out) {
  const toml::array* list =
      table_list(r, root, "section", "plane sections are written as [[section]] tables, one per plane");
  if (!list) return;
  for (const toml::node& node : *list) {
    const toml::table& t = *node.as_table();
    r.check_keys(t, "section." + std::to_string(out.size()), kSectionKeys);
    Section s;
    s.plane = read_plane(r, t, "section", "the plane a*x + b*y + c*z + d = 0");
    if (const toml::node* c = t.get("colour")) s.colour = glm::dvec3(r.colour(*c, "section.colour", false));
    if (const toml::node* w = t.get("width")) {
      s.width = r.number_in(*w, "section.width", 0, kMaxSectionWidth);
      if (s.width == 0) r.fail(w->source(), "section.width must be above 0 (pixels)");
    }
    if (const toml::node* n = t.get("surface"))
      s.surface = static_cast<int>(r.integer(*n, "section.surface (the surface's index, from 0)", 0,
                                             static_cast<long long>(surfaces) - 1));
    out.push_back(s);
  }
}

// [[clip]] tables: plane = [a, b, c, d], the half-space a*x + b*y + c*z + d <= 0 kept ((a, b, c) not zero); at
// most kMaxClipPlanes of them.
void read_clips(const TomlReader& r, const toml::table& root, std::vector<glm::dvec4>& out) {
  const toml::array* list = table_list(r, root, "clip", "clipping planes are written as [[clip]] tables, one per plane");
  if (!list) return;
  for (const toml::node& node : *list) {
    const toml::table& t = *node.as_table();
    if (out.size() == kMaxClipPlanes)
      r.fail(t.source(), "at most " + std::to_string(kMaxClipPlanes) + " clipping planes ([[clip]] tables) cut a " +
                             "scene; this is clip." + std::to_string(out.size()));
    r.check_keys(t, "clip." + std::to_string(out.size()), kClipKeys);
    out.push_back(read_plane(r, t, "clip", "the half-space a*x + b*y + c*z + d <= 0 is kept"));
  }
}

void read_antialias(const TomlReader& r, const toml::table& root, Antialias& out) {
  const toml::table* aa = r.subtable(root, "antialias");
  if (!aa) return;
  r.check_keys(*aa, "antialias", kAntialiasKeys);
  if (const toml::node* n = aa->get("samples"))
    out.samples = static_cast<int>(r.integer(*n, "antialias.samples", 1, 16));
  if (const toml::node* n = aa->get("adaptive")) out.adaptive = r.boolean(*n, "antialias.adaptive");
  if (const toml::node* n = aa->get("threshold")) out.threshold = r.number_in(*n, "antialias.threshold", 0, 1);
}

// `degree` is the scene's highest, which mixed precision is held to.
void read_render(const TomlReader& r, const toml::table& root, int degree, RenderSettings& rs) {
  const toml::table* render = r.subtable(root, "render");
  if (!render) return;
  r.check_keys(*render, "render", kRenderKeys);
  // The solver: precision, tolerance, methods and the point P*(t) is built around.
  if (const toml::node* n = render->get("precision")) {
    const std::string p = r.string(*n, "render.precision");
    Precision value;
    if (p == "auto")
      rs.precision.reset();
    else if (parse_precision(p, value))
      rs.precision = value;
    else
      r.fail(n->source(), "render.precision must be auto, " + precision_choices());
    if (rs.precision == Precision::Mixed && degree > kMaxMixedDegree)
      r.fail(n->source(), "mixed precision supports degrees up to " + std::to_string(kMaxMixedDegree) +
                              "; this surface has degree " + std::to_string(degree));
  }
  if (const toml::node* n = render->get("tolerance")) {
    rs.tolerance = r.number(*n, "render.tolerance");
    if (!(rs.tolerance > 0 && rs.tolerance <= 0.1)) r.fail(n->source(), "render.tolerance must be in (0, 0.1]");
  }
  if (const toml::node* n = render->get("isolation"))
    if (!parse_isolation(r.string(*n, "render.isolation"), rs.isolation))
      r.fail(n->source(), "render.isolation must be one of " + isolation_choices());
  if (const toml::node* n = render->get("refinement"))
    if (!parse_refinement(r.string(*n, "render.refinement"), rs.refinement))
      r.fail(n->source(), "render.refinement must be one of " + refinement_choices());
  if (rs.precision == Precision::Adaptive)
    if (const std::string why = adaptive_unsupported(degree, rs.isolation); !why.empty())
      r.fail(render->get("precision")->source(), why + "; use mixed or double");
  if (const toml::node* n = render->get("ray_origin")) {
    if (!parse_ray_origin(r.string(*n, "render.ray_origin"), rs.ray_origin))
      r.fail(n->source(), "render.ray_origin must be one of " + ray_origin_choices());
    if (rs.ray_origin == RayOrigin::Eye && !isolates_in_power_basis(rs.isolation))
      r.fail(n->source(),
             "render.ray_origin = \"eye\" needs a power-basis isolation (" + power_basis_isolation_choices("or") + ")");
    if (rs.ray_origin == RayOrigin::Screen && (rs.precision == Precision::Mixed || rs.precision == Precision::Adaptive))
      r.fail(n->source(), "render.ray_origin = \"screen\" is built in float or double, not " +
                              to_string(*rs.precision) + " precision");
  }
  if (const toml::node* n = render->get("max_iterations"))
    rs.max_iterations = static_cast<int>(r.integer(*n, "render.max_iterations", 1, 1000000));
  // How the kernels run and what they trace.
  if (const toml::node* n = render->get("tile_size"))
    rs.tile_size = static_cast<int>(r.integer(*n, "render.tile_size", 8, 16384));
  if (const toml::node* n = render->get("lanes")) {
    rs.lanes = static_cast<int>(r.integer(*n, "render.lanes", 1, 16));
    if (!valid_lanes(rs.lanes)) r.fail(n->source(), "render.lanes must be " + lanes_choices());
    if (rs.lanes > 1 && !lanes_supported(rs.isolation, rs.refinement))
      r.fail(n->source(), "render.lanes > 1 needs " + lanes_methods());
  }
  if (const toml::node* n = render->get("preview")) rs.preview = r.boolean(*n, "render.preview");
  if (const toml::node* n = render->get("max_depth"))
    rs.max_depth = static_cast<int>(r.integer(*n, "render.max_depth", 0, 64));
}

// Table by table, in a fixed order: where several are wrong, the first of them in this order is reported.
// `framed`: the scene as written leaves its view to algray (it gives no camera.eye), so that a scene without
// [[light]] or [antialias] gets the shipped scenes' key and fill light and 2x2 antialiasing; a scene that places
// its eye keeps a headlight and one ray per pixel there, as scenes always did.
Scene interpret(const TomlReader& r, const toml::table& root, const std::string& source, bool framed) {
  Scene scene;
  scene.source = source;
  r.check_keys(root, "", kTopKeys);
  read_parameters(r, root, scene.parameters);
  const std::vector<const toml::table*> surface_tables = read_surfaces(r, root, scene);
  int degree = 0;
  for (const SceneSurface& s : scene.surfaces) degree = std::max(degree, s.polynomial.degree());
  read_extent(r, root, scene.extent);
  read_clips(r, root, scene.extent.clips);
  read_camera(r, root, scene.extent, scene.camera);
  read_image(r, root, scene.image);
  read_surface_materials(r, root, surface_tables, scene.surfaces);
  read_lights(r, root, scene.camera, scene.lights);
  read_sections(r, root, scene.surfaces.size(), scene.sections);
  if (framed && !root.get("light")) scene.lights = framing_lights(scene.extent.shape_scale(), scene.camera);
  // 2x2 unless the scene gives antialias.samples (a --set antialias.adaptive=true alone keeps the 2x2).
  const toml::table* aa = root["antialias"].as_table();
  if (framed && (!aa || !aa->get("samples"))) scene.antialias.samples = 2;
  read_antialias(r, root, scene.antialias);
  read_render(r, root, degree, scene.render);
  return scene;
}

}  // namespace

SceneError::SceneError(std::string where_, std::string message_, std::string excerpt_)
    : std::runtime_error(format_what(where_, message_, excerpt_)),
      where(std::move(where_)),
      message(std::move(message_)),
      excerpt(std::move(excerpt_)) {}

glm::dvec3 Extent::unit_centre() const { return kind == ExtentKind::Box ? (min + max) * 0.5 : centre; }

// a.p + d <= 0 with p = centre + scale * u is a.u + (a.centre + d) / scale <= 0, divided by |a|.
std::vector<glm::dvec4> Extent::unit_clips() const {
  std::vector<glm::dvec4> out;
  const glm::dvec3 c = unit_centre();
  const double s = unit_scale();
  for (const glm::dvec4& p : clips) {
    const glm::dvec3 a(p);
    const double length = glm::length(a);
    out.emplace_back(a / length, (glm::dot(a, c) + p.w) / (s * length));
  }
  return out;
}

// A cylinder's scale is the distance from its centre to a cap's rim, so that it fits in |u| <= 1.
double Extent::shape_scale() const {
  switch (kind) {
    case ExtentKind::Sphere:
      return radius;
    case ExtentKind::Box:
      return glm::length(max - min) * 0.5;
    case ExtentKind::Cylinder:
      break;
  }
  return std::hypot(radius, half_height);
}

double Extent::unit_scale() const { return gate ? shape_scale() * reach : shape_scale(); }

glm::dvec3 Extent::unit_box_half() const {
  if (kind == ExtentKind::Box) return (max - min) * 0.5 / unit_scale();
  if (kind == ExtentKind::Sphere) return glm::dvec3(gate ? radius / unit_scale() : 1);
  glm::dvec3 half(radius / unit_scale());
  half[axis] = half_height / unit_scale();
  return half;
}

std::vector<glm::dvec3> Light::sample_points() const {
  if (kind == LightKind::Point) return {position};
  std::vector<glm::dvec3> points;
  const int n = samples;
  // An orthonormal frame of the disc's plane.
  const glm::dvec3 unit = glm::normalize(normal);
  const glm::dvec3 a = std::fabs(unit.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  const glm::dvec3 e1 = glm::normalize(glm::cross(unit, a)), e2 = glm::cross(unit, e1);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double u = (i + 0.5) / n * 2 - 1, v = (j + 0.5) / n * 2 - 1;  // cell centres in [-1, 1]^2
      if (kind == LightKind::Rectangle) {
        points.push_back(position + 0.5 * u * edge_u + 0.5 * v * edge_v);
        continue;
      }
      // Shirley and Chiu's concentric map: squares around the centre go to rings of equal area.
      const double pi = 3.14159265358979323846;
      double r = 0, phi = 0;
      if (std::fabs(u) > std::fabs(v)) {
        r = u;
        phi = pi / 4 * (v / u);
      } else if (v != 0) {
        r = v;
        phi = pi / 2 - pi / 4 * (u / v);
      }
      points.push_back(position + radius * r * (std::cos(phi) * e1 + std::sin(phi) * e2));
    }
  }
  return points;
}

void place_camera_lights(std::vector<Light>& lights, const CameraSpec& camera) {
  for (Light& l : lights) {
    if (!l.in_camera) continue;
    l.position = camera_point_to_world(camera, l.in_camera->position);
    l.edge_u = camera_vector_to_world(camera, l.in_camera->edge_u);
    l.edge_v = camera_vector_to_world(camera, l.in_camera->edge_v);
    l.normal = camera_vector_to_world(camera, l.in_camera->normal);
  }
}

Scene load_scene_text(const std::string& text, const std::string& source_name, const std::vector<Override>& overrides) {
  TomlReader reader(source_name, text);
  check_toml_shape(text, source_name);
  toml::table root;
  try {
    root = toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    reader.fail(e.source(), std::string(e.description()));
  }
  const toml::table* written_camera = root["camera"].as_table();
  const bool framed = !written_camera || !written_camera->get("eye");
  std::vector<std::string> notes;
  // A scene that leaves its lights to algray gets them from its camera and extent as it is read: a --set
  // light.N.KEY there waits for the other overrides (--radius, extent.*), then the default lights are written in
  // as [[light]] tables, and it changes one of them.
  std::vector<const Override*> to_default_lights;
  for (const Override& o : overrides) {
    if (framed && !root.get("light") && o.key.rfind("light.", 0) == 0)
      to_default_lights.push_back(&o);
    else
      apply_override(root, o, notes);
  }
  if (!to_default_lights.empty()) {
    if (!root.get("light")) write_framing_lights(reader, root);
    for (const Override* o : to_default_lights) apply_override(root, *o, notes);
  }
  Scene scene = interpret(reader, root, source_name, framed);
  scene.warnings.insert(scene.warnings.end(), notes.begin(), notes.end());
  if (scene.name.empty()) {
    const auto slash = source_name.find_last_of('/');
    std::string stem = source_name.substr(slash == std::string::npos ? 0 : slash + 1);
    scene.name = stem.substr(0, stem.rfind('.'));
  }
  return scene;
}

Scene load_jsurf_text(const std::string& text, const std::string& source_name, const std::vector<Override>& overrides) {
  std::vector<std::string> warnings;
  std::map<int, JsurfOrigin> origins;
  const std::string toml = jsurf_to_toml(text, source_name, warnings, &origins);
  const std::string translated = source_name + " (translated to TOML)";
  Scene scene;
  try {
    scene = load_scene_text(toml, translated, overrides);
  } catch (const SceneError& e) {
    // An override's error names the override; any other names a line of the translation, which the user never
    // saw: point at the .jsurf property that line came from instead.
    if (e.where.compare(0, translated.size(), translated) != 0) throw;
    int line = 0;
    if (e.where.size() > translated.size() + 1 && e.where[translated.size()] == ':')
      line = std::atoi(e.where.c_str() + translated.size() + 1);
    if (const auto it = origins.find(line); it != origins.end())
      throw SceneError(it->second.where, it->second.key + ": " + e.message, it->second.excerpt);
    throw SceneError(source_name, e.message);
  }
  scene.source = source_name;
  scene.warnings.insert(scene.warnings.begin(), warnings.begin(), warnings.end());
  return scene;
}

namespace {

// The image size that overrides set, 0 where none does: the surf and POV-Ray framings depend on it.
std::array<int, 2> overridden_size(const std::vector<Override>& overrides) {
  std::array<int, 2> size = {0, 0};
  for (const Override& o : overrides)
    if (o.key == "image.width" || o.key == "image.height") {
      char* end = nullptr;
      const long v = std::strtol(o.value.c_str(), &end, 10);
      if (end && *end == '\0' && v > 0 && v <= 1 << 20) size[o.key == "image.height"] = static_cast<int>(v);
    }
  return size;
}

// A translated scene read as TOML; an error in the translation, which the user never saw, is put at `at`.
Scene load_translation(const std::string& toml, const std::string& source_name, const std::vector<Override>& overrides,
                       const std::string& at, const std::string& excerpt, const std::string& what,
                       std::vector<std::string> warnings) {
  const std::string translated = source_name + " (translated to TOML)";
  Scene scene;
  try {
    scene = load_scene_text(toml, translated, overrides);
  } catch (const SceneError& e) {
    if (e.where.compare(0, translated.size(), translated) != 0) throw;
    throw SceneError(at, what + ": " + e.message, excerpt);
  }
  scene.source = source_name;
  scene.warnings = std::move(warnings);
  return scene;
}

}  // namespace

Scene load_povray_text(const std::string& text, const std::string& source_name,
                       const std::vector<Override>& overrides) {
  const std::array<int, 2> size = overridden_size(overrides);
  std::vector<std::string> warnings;
  const PovTranslation pov = povray_to_toml(text, source_name, warnings, size[0], size[1]);
  return load_translation(pov.toml, source_name, overrides, pov.first_object_at, pov.first_object_excerpt,
                          "the scene of the object here", std::move(warnings));
}

Scene load_surf_script_text(const std::string& text, const std::string& source_name,
                            const std::vector<Override>& overrides) {
  // surf frames by the shorter side, so the translation needs the size the image will have.
  const std::array<int, 2> size = overridden_size(overrides);
  std::vector<std::string> warnings;
  const SurfTranslation surf = surf_script_to_toml(text, source_name, warnings, size[0], size[1]);
  // The translation's values are computed by the script; the drawing statement is where they take effect.
  return load_translation(surf.toml, source_name, overrides, surf.drawn_at, surf.drawn_excerpt,
                          "the surface drawn here", std::move(warnings));
}

namespace {

void write_material(std::ostringstream& out, const std::string& table, const Material& m) {
  out << "\n[" << table << "]\ncolour = " << toml_vector(m.colour) << "\nambient = " << toml_number(m.ambient)
      << "\ndiffuse = " << toml_number(m.diffuse) << "\nspecular = " << toml_number(m.specular)
      << "\nexponent = " << toml_number(m.exponent) << "\nreflectivity = " << toml_number(m.reflectivity)
      << "\ntransparency = " << toml_number(m.transparency) << "\n";
}

const char* light_type(LightKind k) {
  switch (k) {
    case LightKind::Rectangle:
      return "rectangle";
    case LightKind::Disc:
      return "disc";
    case LightKind::Point:
      break;
  }
  return "point";
}

void write_surfaces(std::ostringstream& out, const std::vector<SceneSurface>& surfaces) {
  const bool several = surfaces.size() > 1;
  for (const SceneSurface& s : surfaces) {
    out << (several ? "\n[[surface]]\n" : "\n[surface]\n");
    if (!s.name.empty()) out << "name = " << toml_quoted(s.name) << "\n";
    if (s.from_terms) {
      // Each coefficient as the double it was read as: the equation text made from them rounds.
      out << "terms = [";
      const char* sep = "";
      for (const auto& [e, c] : s.polynomial.terms()) {
        out << sep << "[" << e[0] << ", " << e[1] << ", " << e[2] << ", " << toml_number(nearest_double(c)) << "]";
        sep = ", ";
      }
      out << "]\n";
    } else {
      out << "equation = " << toml_quoted(s.equation) << "\n";
    }
    write_material(out, "surface.material.front", s.materials.front);
    write_material(out, "surface.material.back", s.materials.back);
  }
}

void write_extent(std::ostringstream& out, const Extent& e) {
  if (e.kind == ExtentKind::Sphere)
    out << "\n[extent]\ntype = \"sphere\"\ncentre = " << toml_vector(e.centre) << "\nradius = " << toml_number(e.radius)
        << "\n";
  else if (e.kind == ExtentKind::Box)
    out << "\n[extent]\ntype = \"box\"\nmin = " << toml_vector(e.min) << "\nmax = " << toml_vector(e.max) << "\n";
  else
    out << "\n[extent]\ntype = \"cylinder\"\ncentre = " << toml_vector(e.centre)
        << "\nradius = " << toml_number(e.radius) << "\naxis = \""
        << "xyz"[e.axis] << "\"\nhalf_height = " << toml_number(e.half_height) << "\n";
  if (e.gate) out << "gate = true\nreach = " << toml_number(e.reach) << "\n";
}

void write_camera(std::ostringstream& out, const CameraSpec& c) {
  const bool perspective = c.projection == Projection::Perspective;
  out << "\n[camera]\n";
  // The eye as placed, which reads back to the same rays; the angles it was placed by, for people.
  if (c.angles)
    out << "# placed by angles about look_at: azimuth = " << toml_number(c.angles->azimuth)
        << ", elevation = " << toml_number(c.angles->elevation) << ", distance = " << toml_number(c.angles->distance)
        << ", up = " << toml_vector(c.written_up) << "\n";
  out << "projection = \"" << (perspective ? "perspective" : "orthographic")
      << "\"\neye = " << toml_vector(c.eye) << "\nlook_at = " << toml_vector(c.look_at)
      << "\nup = " << toml_vector(c.up) << "\n"
      << (perspective ? "fov_y = " + toml_number(c.fov_y_degrees) : "height = " + toml_number(c.ortho_height)) << "\n";
  if (c.shift != glm::dvec2(0))
    out << "shift = [" << toml_number(c.shift.x) << ", " << toml_number(c.shift.y) << "]\n";
}

void write_lights(std::ostringstream& out, const std::vector<Light>& lights) {
  for (const Light& world : lights) {
    // A light attached to the camera is written in the camera's frame, as it was given, so that it still follows.
    const Light::CameraFrame l = world.in_camera.value_or(
        Light::CameraFrame{world.position, world.edge_u, world.edge_v, world.normal});
    out << "\n[[light]]\ntype = \"" << light_type(world.kind) << "\"\n"
        << (world.in_camera ? "frame = \"camera\"\n" : "") << "position = " << toml_vector(l.position) << "\n";
    if (world.kind == LightKind::Rectangle)
      out << "edge_u = " << toml_vector(l.edge_u) << "\nedge_v = " << toml_vector(l.edge_v) << "\n";
    if (world.kind == LightKind::Disc)
      out << "normal = " << toml_vector(l.normal) << "\nradius = " << toml_number(world.radius) << "\n";
    if (world.kind != LightKind::Point) out << "samples = " << world.samples << "\n";
    out << "colour = " << toml_vector(world.colour) << "\nintensity = " << toml_number(world.intensity)
        << "\nshadows = " << (world.shadows ? "true" : "false") << "\n";
  }
}

void write_render(std::ostringstream& out, const RenderSettings& rs) {
  out << "\n[render]\nprecision = \"" << (rs.precision ? to_string(*rs.precision) : std::string("auto"))
      << "\"\ntolerance = " << toml_number(rs.tolerance) << "\nisolation = \"" << to_string(rs.isolation)
      << "\"\nrefinement = \"" << to_string(rs.refinement) << "\"\nray_origin = \"" << to_string(rs.ray_origin)
      << "\"\npreview = " << (rs.preview ? "true" : "false") << "\nmax_depth = " << rs.max_depth << "\n";
  if (rs.max_iterations) out << "max_iterations = " << rs.max_iterations << "\n";
  if (rs.tile_size) out << "tile_size = " << rs.tile_size << "\n";
  if (rs.lanes) out << "lanes = " << rs.lanes << "\n";
}

}  // namespace

std::string scene_to_toml(const Scene& scene) {
  std::ostringstream out;
  std::string origin = scene.name + ", as algray rendered it (from " + scene.source + ")";
  for (char& ch : origin)
    // A comment ends at the line's end, and TOML text must be UTF-8, which a file name need not be.
    if (static_cast<unsigned char>(ch) < 0x20 || static_cast<unsigned char>(ch) >= 0x7f) ch = '?';
  out << "# " << origin << "\n";
  if (!scene.parameters.empty()) {
    out << "\n[parameters]\n";
    for (const auto& [name, value] : scene.parameters) out << name << " = " << toml_number(value) << "\n";
  }
  write_surfaces(out, scene.surfaces);
  write_extent(out, scene.extent);
  write_camera(out, scene.camera);
  const glm::dvec4& bg = scene.image.background;
  out << "\n[image]\nwidth = " << scene.image.width << "\nheight = " << scene.image.height << "\nbackground = ["
      << toml_number(bg.r) << ", " << toml_number(bg.g) << ", " << toml_number(bg.b) << ", " << toml_number(bg.a)
      << "]\n";
  write_lights(out, scene.lights);
  for (const Section& sec : scene.sections)
    out << "\n[[section]]\nplane = [" << toml_number(sec.plane.x) << ", " << toml_number(sec.plane.y) << ", "
        << toml_number(sec.plane.z) << ", " << toml_number(sec.plane.w) << "]\ncolour = " << toml_vector(sec.colour)
        << "\n" << (sec.surface >= 0 ? "surface = " + std::to_string(sec.surface) + "\n" : "")
        << (sec.width != 1 ? "width = " + toml_number(sec.width) + "\n" : "");
  for (const glm::dvec4& c : scene.extent.clips)
    out << "\n[[clip]]\nplane = [" << toml_number(c.x) << ", " << toml_number(c.y) << ", " << toml_number(c.z) << ", "
        << toml_number(c.w) << "]\n";
  const Antialias& aa = scene.antialias;
  out << "\n[antialias]\nsamples = " << aa.samples << "\nadaptive = " << (aa.adaptive ? "true" : "false")
      << "\nthreshold = " << toml_number(aa.threshold) << "\n";
  write_render(out, scene.render);
  return out.str();
}

std::string read_input_stream(std::istream& in, const std::string& source, const std::string& what) {
  std::string text;
  char buf[65536];
  while (in) {
    in.read(buf, sizeof buf);
    text.append(buf, static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxInputBytes)
      throw SceneError(source, "the " + what + " is larger than " + std::to_string(kMaxInputBytes >> 20) + " MiB; " +
                                   what + "s are small text files");
  }
  if (in.bad()) throw SceneError(source, "cannot read the " + what);
  return text;
}

std::string read_input_file(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw SceneError(path, "is a directory, not a " + what);
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const bool exists = std::filesystem::exists(path, ec);
    throw SceneError(path, "cannot read the " + what + (exists ? "" : ": no such file"));
  }
  try {
    return read_input_stream(in, path, what);
  } catch (const std::ios_base::failure&) {
    throw SceneError(path, "cannot read the " + what);
  }
}

Scene load_scene_file(const std::string& path, const std::vector<Override>& overrides) {
  const std::optional<SceneFormat> format = scene_format_of(path);
  if (!format) throw SceneError(path, unknown_scene_type_message(path));
  const std::string text = read_input_file(path, "scene file");  // a missing file is said so first
  if (*format == SceneFormat::Png)
    throw SceneError(path, "is not a PNG file (it does not start with PNG's signature), so it carries no scene");
  if (*format == SceneFormat::Jsurf) return load_jsurf_text(text, path, overrides);
  if (*format == SceneFormat::SurfScript) return load_surf_script_text(text, path, overrides);
  if (*format == SceneFormat::PovRay) return load_povray_text(text, path, overrides);
  return load_scene_text(text, path, overrides);
}

Scene load_equation(const std::string& equation, const std::vector<Override>& overrides) {
  // One line, `surface.equation = "..."`: a column of it is a character of the equation, shifted by the key.
  static const std::string source = "--equation", key = "surface.equation = ";
  const std::string quoted = toml_quoted(equation);
  try {
    return load_scene_text(key + quoted + "\n", source, overrides);
  } catch (const SceneError& e) {
    // An error in the equation names its character in the equation as given, with the equation as the excerpt.
    const std::string prefix = source + ":1:";
    if (e.where.compare(0, prefix.size(), prefix) != 0 || quoted != "\"" + equation + "\"") throw;
    const long column = std::atol(e.where.c_str() + prefix.size()) - static_cast<long>(key.size() + 1);
    if (column < 1 || column > static_cast<long>(equation.size()) + 1) throw;
    throw SceneError(source + ":1:" + std::to_string(column), e.message,
                     "  " + equation + "\n  " + std::string(static_cast<std::size_t>(column - 1), ' ') + "^");
  }
}

Scene default_scene(const std::vector<Override>& overrides) {
  for (const EmbeddedFile& f : embedded_scene_files())
    if (std::string(f.name) == "barth_sextic.toml")
      return load_scene_text(f.text, "<built-in default scene>", overrides);
  throw std::logic_error("the default scene was not embedded");
}

}  // namespace algray
