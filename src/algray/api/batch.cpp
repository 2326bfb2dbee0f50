// Batches: jobs file, frames, resume, JSON-lines log; the renders share one device and program cache.
#include "algray/api/batch.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <variant>

#include "algray/io/image_io.h"
#include "algray/io/video_writer.h"
#include "algray/api/render_job.h"
#include "algray/scene/toml_reader.h"
#include "algray/util/file_names.h"
#include "algray/util/json_text.h"
#include "algray/util/version.h"

namespace algray {
namespace {

namespace fs = std::filesystem;

const std::set<std::string> kBatchTopKeys{"defaults", "job"};
const std::set<std::string> kJobKeys{"name",  "scene", "set",   "output",  "stats",
                                     "frames", "sweep", "orbit", "seconds", "fps"};
// What every job may share; frames, sweeps and orbits belong to one job.
const std::set<std::string> kDefaultsKeys{"scene", "set", "output", "stats"};
const std::set<std::string> kSweepKeys{"from", "to", "steps"};
const std::set<std::string> kOrbitKeys{"frames", "degrees", "axis", "lights"};

// A TOML value as the text of an override's value, which apply_override reads back as TOML.
std::string toml_text(const TomlReader& r, const toml::node& n) {
  if (auto i = n.value_exact<std::int64_t>()) return std::to_string(*i);
  if (auto d = n.value_exact<double>()) return toml_number(*d);
  if (auto b = n.value_exact<bool>()) return *b ? "true" : "false";
  if (auto s = n.value_exact<std::string>()) return toml_quoted(*s);
  if (const toml::array* a = n.as_array()) {
    std::string out = "[";
    for (std::size_t k = 0; k < a->size(); ++k) out += (k ? ", " : "") + toml_text(r, *a->get(k));
    return out + "]";
  }
  r.fail(n.source(), "a set value must be a number, string, boolean or array");
}

// set = { mu = 1, image = { width = 512 }, "light.0.intensity" = 0.5 }: nested tables become dotted keys.
// "jobs.toml:7:9": where a node of the jobs file is, for the messages of what it causes later.
std::string origin_of(const TomlReader& r, const toml::node& n) {
  return r.source() + ":" + std::to_string(n.source().begin.line) + ":" + std::to_string(n.source().begin.column);
}

void collect_sets(const TomlReader& r, const toml::table& t, const std::string& prefix, std::vector<Override>& out) {
  for (auto&& [key, node] : t) {
    const std::string k = prefix + std::string(key.str());
    if (const toml::table* sub = node.as_table())
      collect_sets(r, *sub, k + ".", out);
    else
      out.push_back({k, toml_text(r, node), origin_of(r, node)});
  }
}

std::vector<std::string> string_or_list(const TomlReader& r, const toml::node& n, const std::string& what) {
  if (n.is_string()) return {r.string(n, what)};
  const toml::array* a = n.as_array();
  if (!a || a->empty()) r.fail(n.source(), what + " must be a string or a non-empty array of strings");
  std::vector<std::string> out;
  for (const toml::node& e : *a) out.push_back(r.string(e, what));
  return out;
}

std::string resolve(const std::string& base_dir, const std::string& path) {
  if (path.empty() || path == "-" || fs::path(path).is_absolute() || base_dir.empty()) return path;
  return (fs::path(base_dir) / path).lexically_normal().string();
}

// A job's tables: its own, and [defaults] for what it leaves out.
struct JobTables {
  const toml::table& job;
  const toml::table* defaults;
  const toml::node* get(const char* key) const {
    if (const toml::node* n = job.get(key)) return n;
    return defaults ? defaults->get(key) : nullptr;
  }
};

// The scene, and the name, which defaults to the scene's stem and the job's index.
void read_job_scene(const TomlReader& r, const JobTables& tables, std::size_t index, const std::string& base_dir,
                    BatchJob& job) {
  const toml::node* scene = tables.get("scene");
  if (!scene) r.fail(tables.job.source(), "job " + std::to_string(index) + " needs a scene (a .toml or .jsurf path)");
  job.scene = r.string(*scene, "job.scene");
  if (job.scene == "-") r.fail(scene->source(), "a batch job cannot read its scene from standard input");
  job.scene = resolve(base_dir, job.scene);
  job.name = tables.get("name") ? r.string(*tables.get("name"), "job.name")
                                : fs::path(job.scene).stem().string() + "_" + std::to_string(index);
}

// [defaults]' set first, then the job's, so that the job's own values win.
void read_job_sets(const TomlReader& r, const JobTables& tables, BatchJob& job) {
  for (const toml::table* table : {tables.defaults, &tables.job})
    if (const toml::node* n = table ? table->get("set") : nullptr) {
      if (!n->is_table()) r.fail(n->source(), "set must be a table of scene keys and values");
      collect_sets(r, *n->as_table(), "", job.overrides);
    }
}

// Returns the output node, which later messages about the patterns point at.
const toml::node* read_job_outputs(const TomlReader& r, const JobTables& tables, const std::string& base_dir,
                                   BatchJob& job) {
  // Without an output, the frames go only into the batch's --video (plan_batch checks there is one).
  const toml::node* output = tables.get("output");
  if (output)
    for (const std::string& o : string_or_list(r, *output, "job.output")) job.outputs.push_back(resolve(base_dir, o));
  if (const toml::node* n = tables.get("stats")) job.stats = resolve(base_dir, r.string(*n, "job.stats"));
  return output;
}

// The frame count as the job's frames, seconds x fps, sweeps' steps and orbit frames give it: each that gives
// one must agree with those before it.
struct FrameCount {
  const TomlReader& r;
  std::optional<int> frames;
  void agree(int n, const toml::node& where, const std::string& what) {
    if (frames && *frames != n)
      r.fail(where.source(), what + " gives " + std::to_string(n) + " frames but the job has " +
                                 std::to_string(*frames) + " (all sweeps and the orbit step together)");
    frames = n;
  }
};

// A duration and a frame rate: seconds x fps frames (a sweep or orbit then needs no steps or frames).
void read_job_duration(const TomlReader& r, const toml::table& t, FrameCount& count, BatchJob& job) {
  if (const toml::node* n = t.get("fps")) {
    job.fps = r.number(*n, "job.fps");
    if (!(job.fps > 0 && job.fps <= 1000)) r.fail(n->source(), "job.fps must be above 0 and at most 1000");
  }
  if (const toml::node* n = t.get("seconds")) {
    const double seconds = r.number(*n, "job.seconds");
    const double frames = std::round(seconds * job.fps);
    if (!(seconds > 0) || !(frames >= 1 && frames <= 1000000))
      r.fail(n->source(), "job.seconds x fps must make 1 to 1000000 frames");
    count.agree(static_cast<int>(frames), *n, "seconds x fps");
  }
}

Sweep read_sweep(const TomlReader& r, const toml::key& key, const toml::node& node, FrameCount& count) {
  const std::string what = "sweep." + std::string(key.str());
  const toml::table* s = node.as_table();
  if (!s) r.fail(node.source(), what + " must be { from = ..., to = ..., steps = ... }");
  r.check_keys(*s, what, kSweepKeys);
  for (const char* k : {"from", "to"})
    if (!s->get(k)) r.fail(node.source(), what + " needs '" + k + "'");
  if (!s->get("steps") && !count.frames)
    r.fail(node.source(), what + " needs 'steps', or the job frames or seconds (and fps)");
  Sweep sweep;
  sweep.key = std::string(key.str());
  sweep.origin = origin_of(r, node);
  sweep.from = r.number(*s->get("from"), what + ".from");
  sweep.to = r.number(*s->get("to"), what + ".to");
  if (const toml::node* steps = s->get("steps"))
    count.agree(static_cast<int>(r.integer(*steps, what + ".steps", 1, 1000000)), node, what);
  return sweep;
}

std::vector<Sweep> read_sweeps(const TomlReader& r, const toml::node& n, FrameCount& count) {
  const toml::table* sweeps = n.as_table();
  if (!sweeps || sweeps->empty())
    r.fail(n.source(), "sweep must be a table of keys, each { from = ..., to = ..., steps = ... }");
  std::vector<Sweep> out;
  for (auto&& [key, node] : *sweeps) out.push_back(read_sweep(r, key, node, count));
  return out;
}

Orbit read_orbit(const TomlReader& r, const toml::node& n, FrameCount& count) {
  const toml::table* o = n.as_table();
  if (!o) r.fail(n.source(), "orbit must be a table { frames, degrees, axis, lights }");
  r.check_keys(*o, "orbit", kOrbitKeys);
  Orbit orbit;
  if (const toml::node* d = o->get("degrees")) orbit.degrees = r.number(*d, "orbit.degrees");
  if (const toml::node* a = o->get("axis")) {
    orbit.axis = r.vec3(*a, "orbit.axis");
    if (!(glm::length(*orbit.axis) > 0)) r.fail(a->source(), "orbit.axis must not be zero");
  }
  if (const toml::node* l = o->get("lights")) {
    const std::string mode = r.string(*l, "orbit.lights");
    if (mode != "camera" && mode != "world") r.fail(l->source(), "orbit.lights must be \"camera\" or \"world\"");
    orbit.lights_follow_camera = mode == "camera";
  }
  if (const toml::node* f = o->get("frames"))
    count.agree(static_cast<int>(r.integer(*f, "orbit.frames", 1, 1000000)), *f, "orbit.frames");
  else if (!count.frames)
    r.fail(n.source(), "orbit needs frames (or a sweep's steps) to know how many views to render");
  return orbit;
}

// Frames, sweeps and orbits belong to the job alone, never to [defaults].
void read_job_frames(const TomlReader& r, const toml::table& t, BatchJob& job) {
  FrameCount count{r, std::nullopt};
  if (const toml::node* n = t.get("frames")) count.frames = static_cast<int>(r.integer(*n, "job.frames", 1, 1000000));
  read_job_duration(r, t, count, job);
  if (const toml::node* n = t.get("sweep")) job.sweeps = read_sweeps(r, *n, count);
  if (const toml::node* n = t.get("orbit")) job.orbit = read_orbit(r, *n, count);
  job.frames = count.frames.value_or(1);
}

// Patterns are checked now, so that a typo fails the whole batch before any rendering.
void check_job_patterns(const TomlReader& r, const BatchJob& job, const toml::node* output, const toml::node* stats) {
  // Every frame must write its own files: a pattern without {frame}, {value} or {angle} would overwrite itself.
  if (job.frames > 1)
    for (const std::string& o : job.outputs)
      if (o.find("{frame") == std::string::npos && o.find("{value}") == std::string::npos &&
          o.find("{angle}") == std::string::npos)
        r.fail(output->source(), "job '" + job.name + "' has " + std::to_string(job.frames) + " frames but output '" +
                                     o + "' has no {frame} (or {value}, {angle}) to tell them apart");
  for (const std::string& o : job.outputs) {
    try {
      expand_pattern(o, job, 0);
      format_from_extension(o);
    } catch (const SceneError& e) {
      r.fail(output->source(), e.message);
    } catch (const OutputError& e) {
      r.fail(output->source(), e.what());
    }
  }
  if (job.stats) {
    try {
      expand_pattern(*job.stats, job, 0);
    } catch (const SceneError& e) {
      r.fail(stats->source(), e.message);
    }
  }
}

// Reads one [[job]] on top of [defaults].
BatchJob read_job(const TomlReader& r, const toml::table* defaults, const toml::table& t, std::size_t index,
                  const std::string& base_dir) {
  r.check_keys(t, "job", kJobKeys);
  const JobTables tables{t, defaults};
  BatchJob job;
  job.line = static_cast<int>(t.source().begin.line);
  job.origin = origin_of(r, t);
  read_job_scene(r, tables, index, base_dir, job);
  read_job_sets(r, tables, job);
  const toml::node* output = read_job_outputs(r, tables, base_dir, job);
  read_job_frames(r, t, job);
  check_job_patterns(r, job, output, tables.get("stats"));
  job.output_origin = output ? origin_of(r, *output) : job.origin;
  return job;
}

// The shortest text that reads back as v: 0.3, not 0.29999999999999999; 180, not 1.8e+02.
std::string shortest_text(double v) {
  char buf[40];
  const auto end = std::to_chars(buf, buf + sizeof buf, v).ptr;
  return std::string(buf, end);
}

double sweep_value(const Sweep& s, int frame, int frames) {
  if (frames == 1) return s.from;
  const double t = static_cast<double>(frame) / (frames - 1);
  // to - from overflows for ends near +-DBL_MAX; the weighted form stays between the ends.
  const double span = s.to - s.from;
  return std::isfinite(span) ? s.from + span * frame / (frames - 1) : s.from * (1 - t) + s.to * t;
}

double orbit_angle(const Orbit& o, int frame, int frames) { return o.degrees * frame / frames; }

// v rotated by `radians` about the unit axis k (Rodrigues).
glm::dvec3 rotated(const glm::dvec3& v, const glm::dvec3& k, double radians) {
  const double c = std::cos(radians), s = std::sin(radians);
  return v * c + glm::cross(k, v) * s + k * glm::dot(k, v) * (1 - c);
}

bool file_exists(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

// The log gets one line per frame, flushed as written, so a crash loses at most the frame it was on. It is the
// one file written in place, not through a temporary: it grows while the batch runs, and --resume appends.
class JsonLinesLog {
 public:
  // Failing to write a line (a full disk) stops the batch: later frames would fail alike, and --resume needs
  // to know what was done.
  struct WriteFailed : std::runtime_error {
    using std::runtime_error::runtime_error;
  };

  JsonLinesLog(const std::string& path, bool append) : path_(path) {
    // A run killed mid-line (or a disk that filled) leaves a last line with no newline; appending to it would
    // glue the next entry on and lose both as JSON. The torn line stays, for whoever wants to look at it, and
    // the new entries start on a line of their own.
    if (append) torn_line_ = torn_last_line(path);
    out_.open(path, append ? std::ios::app : std::ios::trunc);
    if (!out_) throw OutputError("cannot write the batch log " + path);
    if (torn_line_) out_ << "\n";
  }
  // The number of the last line, where it was torn (no newline) before this run appended.
  std::optional<int> torn_line() const { return torn_line_; }
  void write(const nlohmann::json& j) {
    errno = 0;
    out_ << dump_json(j) << "\n";
    out_.flush();
    if (!out_)
      throw WriteFailed("cannot write the batch log " + path_ + ": " +
                        (errno ? std::error_code(errno, std::generic_category()).message() : "write failed"));
  }

 private:
  static std::optional<int> torn_last_line(const std::string& path) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in || in.tellg() <= 0) return std::nullopt;
    in.seekg(-1, std::ios::end);
    char last = '\n';
    if (!in.get(last) || last == '\n') return std::nullopt;
    in.seekg(0);
    const auto newlines = std::count(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>(), '\n');
    return static_cast<int>(newlines) + 1;
  }

  std::string path_;
  std::ofstream out_;
  std::optional<int> torn_line_;
};

}  // namespace

std::vector<BatchJob> load_jobs(const std::string& text, const std::string& source, const std::string& base_dir) {
  TomlReader r(source, text);
  check_toml_shape(text, source);
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    r.fail(e.source(), std::string(e.description()));
  }
  r.check_keys(root, "", kBatchTopKeys);
  const toml::table* defaults = r.subtable(root, "defaults");
  if (defaults) r.check_keys(*defaults, "defaults", kDefaultsKeys);
  const toml::node* jobs = root.get("job");
  if (!jobs) r.fail(root.source(), "no jobs: add [[job]] tables, each with a scene and an output");
  const toml::array* list = jobs->as_array();
  if (!list || !list->is_array_of_tables()) r.fail(jobs->source(), "'job' must be a list of [[job]] tables");
  std::vector<BatchJob> out;
  for (std::size_t i = 0; i < list->size(); ++i)
    out.push_back(read_job(r, defaults, *list->get(i)->as_table(), i, base_dir));
  // Two frames writing one file would leave only the last: a pattern whose {value} or {angle} repeats, or two
  // jobs with the same pattern.
  std::map<std::string, std::string> writer;  // file -> "job frame"
  for (const BatchJob& job : out)
    for (int frame = 0; frame < job.frames; ++frame) {
      std::vector<std::string> files;
      for (const std::string& o : job.outputs) files.push_back(expand_pattern(o, job, frame));
      if (job.stats) files.push_back(expand_pattern(*job.stats, job, frame));
      for (const std::string& f : files) {
        const std::string who = "job " + job.name + " frame " + std::to_string(frame);
        const auto [it, fresh] = writer.emplace(f, who);
        if (!fresh)
          throw SceneError(job.output_origin, who + " would write " + f + ", which " + it->second +
                                                  " writes too: give each frame its own file name");
      }
    }
  return out;
}

std::string expand_pattern(const std::string& pattern, const BatchJob& job, int frame) {
  std::string out;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '{') {
      out += pattern[i];
      continue;
    }
    const std::size_t close = pattern.find('}', i);
    if (close == std::string::npos) throw SceneError(job.name, "unclosed '{' in output pattern '" + pattern + "'");
    const std::string field = pattern.substr(i + 1, close - i - 1);
    char buf[64];
    if (field == "name") {
      out += job.name;
    } else if (field == "frame") {
      out += std::to_string(frame);
    } else if (field.rfind("frame:0", 0) == 0 && field.size() > 7 && field.size() <= 9 &&
               field.find_first_not_of("0123456789", 7) == std::string::npos) {
      std::snprintf(buf, sizeof buf, "%0*d", std::stoi(field.substr(7)), frame);
      out += buf;
    } else if (field == "value" && !job.sweeps.empty()) {
      out += shortest_text(sweep_value(job.sweeps.front(), frame, job.frames));
    } else if (field == "angle" && job.orbit) {
      out += shortest_text(orbit_angle(*job.orbit, frame, job.frames));
    } else {
      throw SceneError(job.name, "unknown placeholder {" + field + "} in output pattern '" + pattern +
                                     "': use {name}, {frame}, {frame:03}" + (job.sweeps.empty() ? "" : ", {value}") +
                                     (job.orbit ? ", {angle}" : ""));
    }
    i = close;
  }
  return out;
}

std::vector<Override> frame_overrides(const BatchJob& job, int frame) {
  std::vector<Override> out = job.overrides;
  for (const Sweep& s : job.sweeps) out.push_back({s.key, toml_number(sweep_value(s, frame, job.frames)), s.origin});
  return out;
}

void apply_orbit(Scene& scene, const Orbit& orbit, int frame, int frames) {
  CameraSpec& cam = scene.camera;
  // A camera placed by angles turns about the up it was given (its `up` is the image's, tilted with the view).
  const glm::dvec3 axis = glm::normalize(orbit.axis.value_or(cam.angles ? cam.written_up : cam.up));
  const double radians = orbit_angle(orbit, frame, frames) * 3.14159265358979323846 / 180;
  const glm::dvec3 pivot = cam.look_at;
  cam.eye = pivot + rotated(cam.eye - pivot, axis, radians);
  cam.up = rotated(cam.up, axis, radians);
  cam.angles.reset();  // the eye is placed now, not by the scene's angles
  for (Light& l : scene.lights) {
    // A light attached to the camera follows it by being placed again in the camera's frame, as reading the
    // frame's scene (its PNG) places it; with lights = world it stays where it was, a world light now.
    if (l.in_camera) {
      if (orbit.lights_follow_camera) {
        std::vector<Light> one{l};
        place_camera_lights(one, cam);
        l = one.front();
      } else {
        l.in_camera.reset();
      }
      continue;
    }
    if (!orbit.lights_follow_camera) continue;
    l.position = pivot + rotated(l.position - pivot, axis, radians);
    l.edge_u = rotated(l.edge_u, axis, radians);
    l.edge_v = rotated(l.edge_v, axis, radians);
    l.normal = rotated(l.normal, axis, radians);
  }
}

BatchOutcome run_batch(const BatchRequest& req, const BatchCallbacks& callbacks) {
  if (req.distribute) return req.distribute(req, callbacks);
  RenderContext context(req.device_spec, req.use_cache);
  return run_batch(req, callbacks, context);
}

namespace {

// The whole of `text` as a decimal int: no sign but '-', no spaces, no trailing characters.
bool whole_number(std::string_view text, int& value) {
  const char* end = text.data() + text.size();
  return !text.empty() && std::from_chars(text.data(), end, value).ptr == end;
}

// Lines for the person running the batch, through its callback; a refusal before any frame, as its outcome.
struct BatchReporter {
  const BatchCallbacks& callbacks;
  void operator()(const std::string& text) const {
    if (callbacks.on_message) callbacks.on_message(text);
  }
  BatchOutcome refused(const std::exception& e) const {
    const ErrorReport report = describe_error(e);
    (*this)(report.text);
    return report.bad_input ? BatchOutcome::BadInput : BatchOutcome::Stopped;
  }
};

constexpr const char* kShardExpected = "expected K/N with 0 <= K < N, such as 0/4 for the first of four shards";

}  // namespace

bool check_shard(const BatchShard& shard, std::string& error) {
  if (shard.count >= 1 && shard.index >= 0 && shard.index < shard.count) return true;
  error = kShardExpected;
  return false;
}

bool parse_shard(const std::string& text, BatchShard& out, std::string& error) {
  const std::size_t slash = text.find('/');
  BatchShard shard{-1, 0};
  const std::string_view view(text);
  if (slash == std::string::npos || !whole_number(view.substr(0, slash), shard.index) ||
      !whole_number(view.substr(slash + 1), shard.count)) {
    error = kShardExpected;
    return false;
  }
  if (!check_shard(shard, error)) return false;
  out = shard;
  return true;
}

std::optional<BatchShard> shard_from_slurm_environment() {
  const auto variable = [](const char* name) -> std::optional<int> {
    const char* text = std::getenv(name);
    if (!text || !*text) return std::nullopt;
    int value = 0;
    if (!whole_number(text, value)) throw SceneError(name, std::string("not a whole number: '") + text + "'");
    return value;
  };
  const std::optional<int> id = variable("SLURM_ARRAY_TASK_ID");
  if (!id) return std::nullopt;
  const std::optional<int> count = variable("SLURM_ARRAY_TASK_COUNT");
  const std::optional<int> min = variable("SLURM_ARRAY_TASK_MIN"), max = variable("SLURM_ARRAY_TASK_MAX");
  BatchShard shard;
  if (min && max) {
    // An array's task ids run from MIN to MAX (--array=1-4): ids, not counts, say where a task stands.
    shard = {*id - *min, *max - *min + 1};
  } else if (count) {
    shard = {*id, *count};
  } else {
    throw SceneError("SLURM_ARRAY_TASK_ID", "set without SLURM_ARRAY_TASK_COUNT or SLURM_ARRAY_TASK_MIN/MAX");
  }
  if (shard.count < 1 || shard.index < 0 || shard.index >= shard.count)
    throw SceneError("SLURM_ARRAY_TASK_ID", "task " + std::to_string(*id) + " is outside its array of " +
                                                std::to_string(shard.count) + " tasks");
  return shard;
}

std::string shard_file(const std::string& path, const BatchShard& shard) {
  const fs::path p(path);
  const std::string tag = ".shard-" + std::to_string(shard.index) + "-of-" + std::to_string(shard.count);
  return (p.parent_path() / (p.stem().string() + tag + p.extension().string())).string();
}

namespace {

// Whether frame `number` of the whole batch (every job's frames in order) is this request's to render.
bool in_shard(const BatchRequest& req, int number) {
  return !req.shard || number % req.shard->count == req.shard->index;
}

// The batch's log before sharding: as given, else beside the jobs file as <stem>.log.jsonl.
std::string batch_log_path(const BatchRequest& req, const std::string& base_dir) {
  if (req.log_path) return *req.log_path;
  if (req.jobs_path == "-") return "batch.log.jsonl";
  return (fs::path(base_dir) / (fs::path(req.jobs_path).stem().string() + ".log.jsonl")).string();
}

// Makes `dir` and its missing parents, each recorded in `made`; OutputError when one cannot be made.
void make_folders(const fs::path& dir, std::vector<fs::path>& made) {
  if (dir.empty()) return;
  std::error_code ec;
  if (fs::exists(dir, ec)) return;
  make_folders(dir.parent_path(), made);
  if (!fs::create_directory(dir, ec) && ec)
    throw OutputError("cannot make the folder '" + dir.string() + "' an output pattern names: " + ec.message());
  made.push_back(dir);
}

std::string shard_text(const BatchShard& shard) {
  return std::to_string(shard.index) + "/" + std::to_string(shard.count);
}

}  // namespace

BatchPlan plan_batch(const BatchRequest& req) {
  BatchPlan plan;
  std::string text, base_dir;
  if (req.jobs_path == "-") {
    text = read_input_stream(std::cin, "<stdin>", "jobs file");
  } else {
    text = read_input_file(req.jobs_path, "jobs file");
    base_dir = fs::path(req.jobs_path).parent_path().string();
  }
  plan.jobs = load_jobs(text, req.jobs_path == "-" ? "<stdin>" : req.jobs_path, base_dir);
  if (!req.video_path)
    for (const BatchJob& job : plan.jobs)
      if (job.outputs.empty())
        throw SceneError(job.origin, "job '" + job.name +
                                         "' needs an output (a file name pattern, or a list of them), or the batch a "
                                         "--video to put its frames in");
  if (req.video_path) {
    // One writer takes every frame in order: a shard has only some, and --resume renders only some.
    if (req.shard)
      throw OutputError("--video needs every frame in one process: run the shards without it, then `algray batch "
                        "JOBS --merge-logs --video OUT` encodes their images in order");
    if (req.resume) throw OutputError("--video renders every frame; it does not combine with --resume");
    if (!video_format_of(*req.video_path))
      throw OutputError("cannot write '" + *req.video_path + "': --video takes " + video_extensions());
    for (const BatchJob& job : plan.jobs)
      if (job.fps != plan.jobs.front().fps)
        throw SceneError(job.origin, "job '" + job.name + "' has fps " + toml_number(job.fps) + ", the first job " +
                                         toml_number(plan.jobs.front().fps) + ": one --video has one frame rate");
    check_output_writable(*req.video_path);
  }
  plan.log_path = batch_log_path(req, base_dir);
  if (req.shard) plan.log_path = shard_file(plan.log_path, *req.shard);
  if (req.stats_path) plan.stats_path = req.shard ? shard_file(*req.stats_path, *req.shard) : *req.stats_path;
  check_output_writable(plan.log_path);
  if (plan.stats_path) check_output_writable(*plan.stats_path);
  // No file the batch writes may be one it reads, or another it writes, by any name.
  std::vector<RoleAndPath> inputs{{"jobs file", req.jobs_path}}, outputs{{"--log", plan.log_path}};
  if (plan.stats_path) outputs.push_back({"--stats", *plan.stats_path});
  if (req.video_path) outputs.push_back({"--video", *req.video_path});
  int number = 0;  // of each frame in the whole batch, which decides its shard
  for (const BatchJob& job : plan.jobs) {
    inputs.push_back({"scene of job " + job.name, job.scene});
    for (int frame = 0; frame < job.frames; ++frame, ++number) {
      if (!in_shard(req, number)) continue;
      const std::string who = "job " + job.name + " frame " + std::to_string(frame);
      for (const std::string& o : job.outputs) outputs.push_back({who + " output", expand_pattern(o, job, frame)});
      if (job.stats) outputs.push_back({who + " stats", expand_pattern(*job.stats, job, frame)});
      ++plan.total_frames;
    }
  }
  plan.numbered_frames = number;
  check_distinct_files(inputs, outputs);
  // Folders that output patterns name with placeholders ("out/{name}/f{frame}.png") are made now; the rest must
  // exist. Should a path still be bad, the folders made for it are taken away again: bad input writes nothing.
  std::vector<fs::path> made;
  try {
    for (const BatchJob& job : plan.jobs) {
      std::vector<std::string> patterns = job.outputs;
      if (job.stats) patterns.push_back(*job.stats);
      for (const std::string& pattern : patterns) {
        if (fs::path(pattern).parent_path().string().find('{') == std::string::npos) continue;
        for (int frame = 0; frame < job.frames; ++frame)
          make_folders(fs::path(expand_pattern(pattern, job, frame)).parent_path(), made);
      }
    }
    // Every frame's paths are checked now, as render checks its own, so that a bad one is bad input (exit 2)
    // before anything renders rather than a failure of each frame.
    for (const RoleAndPath& o : outputs) check_output_writable(o.path);
  } catch (...) {
    for (auto it = made.rbegin(); it != made.rend(); ++it) {
      std::error_code ignored;
      fs::remove(*it, ignored);  // only if still empty
    }
    throw;
  }
  return plan;
}

namespace {

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

// Frame counts of one job, and the wall time of each frame that ran.
struct JobTally {
  int ok = 0, failed = 0, skipped = 0;
  std::vector<double> frame_ms;

  nlohmann::json json(const BatchJob& job) const {
    nlohmann::json j = {{"name", job.name}, {"frames", job.frames}, {"ok", ok}, {"failed", failed}, {"skipped", skipped}};
    if (!frame_ms.empty()) {
      std::vector<double> sorted = frame_ms;
      std::sort(sorted.begin(), sorted.end());
      j["median_frame_ms"] = sorted[sorted.size() / 2];
      double sum = 0;
      for (double v : frame_ms) sum += v;
      j["total_ms"] = sum;
    }
    return j;
  }
};

// Which job frame `number` of the whole batch belongs to, and its frame within the job.
std::pair<std::size_t, int> place_of(const BatchPlan& plan, int number) {
  for (std::size_t j = 0; j < plan.jobs.size(); ++j) {
    if (number < plan.jobs[j].frames) return {j, number};
    number -= plan.jobs[j].frames;
  }
  throw std::out_of_range("frame number beyond the batch's frames");
}

// Renders (or, with --resume, skips) one frame into its report. Nothing is written but the frame's own files:
// the log and the messages are the recorder's, perhaps in another process.
class FrameRenderer {
 public:
  FrameRenderer(const BatchRequest& req, RenderContext& context) : req_(req), context_(context) {}

  FrameReport render(const BatchJob& job, int frame, int number) {
    const auto start = std::chrono::steady_clock::now();
    FrameReport report;
    report.number = number;
    nlohmann::json& entry = report.entry;
    entry = {{"version", version_string()}, {"job", job.name}, {"frame", frame}, {"frames", job.frames}};
    put_path(entry, "scene", job.scene);
    if (req_.shard) entry["shard"] = shard_text(*req_.shard);
    try {
      std::vector<std::string> outputs;
      for (const std::string& o : job.outputs) outputs.push_back(expand_pattern(o, job, frame));
      std::optional<std::string> stats;
      if (job.stats) stats = expand_pattern(*job.stats, job, frame);
      put_paths(entry, "outputs", outputs);
      std::vector<Override> overrides = frame_overrides(job, frame);
      overrides.insert(overrides.end(), req_.overrides.begin(), req_.overrides.end());
      nlohmann::json set = nlohmann::json::object();
      for (const Override& o : overrides) set[utf8_for_json(o.key)] = utf8_for_json(o.value);
      entry["set"] = set;
      const bool complete =
          std::all_of(outputs.begin(), outputs.end(), file_exists) && (!stats || file_exists(*stats));
      if (req_.resume && complete) {
        entry["status"] = "skipped";
        entry["reason"] = "--resume: every output exists";
        return report;
      }
      Scene scene = load_scene_file(job.scene, overrides);
      report.warnings = warning_text(scene, "job " + job.name + ": ");
      if (job.orbit) {
        apply_orbit(scene, *job.orbit, frame, job.frames);
        entry["camera"] = {{"eye", {scene.camera.eye.x, scene.camera.eye.y, scene.camera.eye.z}},
                           {"up", {scene.camera.up.x, scene.camera.up.y, scene.camera.up.z}},
                           {"angle", orbit_angle(*job.orbit, frame, job.frames)}};
      }
      RenderOutputs render;
      render.images = outputs;
      render.stats_path = stats;
      if (req_.video_path)
        render.keep_image = [&report](FrameImage&& image) {
          report.image = std::make_shared<const FrameImage>(std::move(image));
        };
      check_outputs(scene, render);
      entry["stats"] = render_scene(scene, render, context_, {}, start);
      entry["status"] = "ok";
    } catch (const DeviceError& e) {
      report.message = std::string("algray: ") + e.what() + "\n";
      entry["status"] = "failed";
      entry["error"] = utf8_for_json(e.what());
      report.device_lost = true;
      return report;
    } catch (const std::exception& e) {
      const std::string why = describe_error(e).text;
      report.message = "algray: job " + job.name + " frame " + std::to_string(frame) + " failed:\n" + why;
      entry["status"] = "failed";
      entry["error"] = utf8_for_json(why);
    }
    entry["ms"] = ms_since(start);
    return report;
  }

 private:
  const BatchRequest& req_;
  RenderContext& context_;
};

}  // namespace

void render_dealt_frames(const BatchRequest& req, const BatchPlan& plan, RenderContext& context,
                         FrameDealer& dealer) {
  FrameRenderer renderer(req, context);
  while (const std::optional<int> number = dealer.next_frame()) {
    const auto [job, frame] = place_of(plan, *number);
    FrameReport report = renderer.render(plan.jobs[job], frame, *number);
    // No frame can run without the device: this renderer stops rather than fail every frame it would get alike.
    const bool device_lost = report.device_lost;
    dealer.finished(std::move(report));
    if (device_lost) return;
  }
}

struct BatchRecorder::State {
  const BatchRequest& req;
  const BatchPlan& plan;
  const BatchCallbacks& callbacks;
  BatchReporter message{callbacks};
  JsonLinesLog log;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  int done = 0, ok = 0, failed = 0, skipped = 0, devices_lost = 0;
  bool stopped = false;
  std::vector<JobTally> tallies;
  // A job's warnings are shown once, from the first of its frames that read the scene.
  std::vector<bool> warned;
  // --video: opened at the first frame (which gives the size) and fed every frame in the batch's order, however
  // the frames arrive (MPI ranks finish them out of order: those ahead wait here). The first frame that cannot
  // go in (failed, skipped, another size) abandons it, with the reason said once.
  std::unique_ptr<VideoWriter> video;
  std::optional<std::string> video_lost;
  std::map<int, std::pair<std::shared_ptr<const FrameImage>, std::string>> video_waiting;  // number -> image, why not
  int video_next = 0;

  void add_to_video(const FrameReport& report, const std::string& status, const BatchJob& job, int frame) {
    if (!req.video_path || video_lost) return;
    const std::string why = status == "ok" && report.image
                                ? std::string()
                                : "job " + job.name + " frame " + std::to_string(frame) + " " +
                                      (status.empty() ? "failed" : status);
    video_waiting[report.number] = {report.image, why};
    for (auto it = video_waiting.find(video_next); it != video_waiting.end() && !video_lost;
         it = video_waiting.find(video_next)) {
      const auto [image, problem] = it->second;
      video_waiting.erase(it);
      ++video_next;
      try {
        if (!problem.empty()) throw std::runtime_error(problem);
        if (!video)
          video = std::make_unique<VideoWriter>(*req.video_path, image->width, image->height, plan.jobs.front().fps);
        video->add(*image);
      } catch (const std::exception& e) {
        video.reset();
        video_waiting.clear();
        video_lost = e.what();
        message("algray: the video " + *req.video_path + " will not be written: " + *video_lost + "\n");
      }
    }
  }

  State(const BatchRequest& r, const BatchPlan& p, const BatchCallbacks& c)
      : req(r), plan(p), callbacks(c), log(p.log_path, r.resume), tallies(p.jobs.size()), warned(p.jobs.size()) {
    if (const std::optional<int> torn = log.torn_line())
      message("algray: warning: " + p.log_path + ":" + std::to_string(*torn) +
              ": the last entry is torn (no newline: an earlier run stopped mid-write); it is left as it is and "
              "the new entries start on the next line\n");
  }
};

BatchRecorder::BatchRecorder(const BatchRequest& request, const BatchPlan& plan, const BatchCallbacks& callbacks)
    : state_(std::make_unique<State>(request, plan, callbacks)) {}

BatchRecorder::~BatchRecorder() = default;

bool BatchRecorder::stopped() const { return state_->stopped; }

bool BatchRecorder::cancel_requested() {
  State& s = *state_;
  if (s.stopped) return true;
  if (!s.callbacks.cancelled || !s.callbacks.cancelled()) return false;
  s.message("algray: cancelled after " + std::to_string(s.done) + " of " + std::to_string(s.plan.total_frames) +
            " frames; --resume continues where the images end\n");
  s.stopped = true;
  return true;
}

void BatchRecorder::record(const FrameReport& report) {
  State& s = *state_;
  if (s.stopped) return;
  const auto [job_index, frame] = place_of(s.plan, report.number);
  const BatchJob& job = s.plan.jobs[job_index];
  if (report.warnings && !s.warned[job_index]) {
    s.warned[job_index] = true;
    if (!report.warnings->empty()) s.message(*report.warnings);
  }
  if (!report.message.empty()) s.message(report.message);
  try {
    s.log.write(report.entry);
  } catch (const JsonLinesLog::WriteFailed& e) {
    s.message(std::string("algray: ") + e.what() + "\nalgray: stopped after " + std::to_string(s.done) + " of " +
              std::to_string(s.plan.total_frames) + " frames (" + std::to_string(s.ok) + " rendered, " +
              std::to_string(s.failed) + " failed); --resume continues where the images end\n");
    s.stopped = true;
    return;
  }
  ++s.done;
  JobTally& tally = s.tallies[job_index];
  const std::string status = report.entry.value("status", "");
  s.add_to_video(report, status, job, frame);
  if (report.device_lost) {
    ++s.devices_lost;
    ++s.failed;
    ++tally.failed;
    return;
  }
  if (status == "skipped") {
    ++s.skipped;
    ++tally.skipped;
    return;
  }
  if (status == "ok") {
    ++s.ok;
    ++tally.ok;
  } else {
    ++s.failed;
    ++tally.failed;
  }
  const double ms = report.entry.value("ms", 0.0);
  tally.frame_ms.push_back(ms);
  if (s.callbacks.on_frame) {
    const int total = s.plan.total_frames;
    const double elapsed = ms_since(s.start);
    s.callbacks.on_frame({s.done, total, &job, frame, status, ms, elapsed, elapsed / s.done * (total - s.done)});
  }
}

BatchOutcome BatchRecorder::finish(int renderers) {
  State& s = *state_;
  if (s.stopped) return BatchOutcome::Stopped;
  // The device's message is out already; as in one process, where the first failure of the device ends the batch.
  if (s.devices_lost >= renderers) return BatchOutcome::BadInput;
  const int total = s.plan.total_frames;
  nlohmann::json summary_jobs = nlohmann::json::array();
  for (std::size_t j = 0; j < s.plan.jobs.size(); ++j) summary_jobs.push_back(s.tallies[j].json(s.plan.jobs[j]));
  nlohmann::json summary = {
      {"version", version_string()},
      {"shard", s.req.shard ? nlohmann::json(shard_text(*s.req.shard)) : nlohmann::json()},
      {"frames", {{"total", total}, {"ok", s.ok}, {"failed", s.failed}, {"skipped", s.skipped}}},
      {"jobs", summary_jobs},
      {"total_ms", ms_since(s.start)}};
  put_path(summary, "jobs_file", s.req.jobs_path);
  put_path(summary, "log", s.plan.log_path);
  if (s.plan.stats_path) {
    try {
      write_text_file(*s.plan.stats_path, dump_json(summary, 2) + "\n");
    } catch (const std::exception& e) {
      // After the frames: a failure to write, not bad input.
      s.message(std::string("algray: the frames are done, but the batch stats were not written: ") + e.what() +
                "\n");
      return BatchOutcome::Stopped;
    }
  }
  if (s.failed)
    s.message("algray: " + std::to_string(s.failed) + " of " + std::to_string(total) + " frames failed (see " +
              s.plan.log_path + ")\n");
  if (s.req.video_path && s.video) {
    try {
      s.video->finish();
      s.message("algray: wrote " + *s.req.video_path + " (" + std::to_string(s.video->frames()) + " frames, " +
                std::to_string(s.video->width()) + "x" + std::to_string(s.video->height()) + ")\n");
    } catch (const std::exception& e) {
      s.message(std::string("algray: ") + e.what() + "\n");
      s.video.reset();
      return BatchOutcome::Stopped;
    }
    s.video.reset();
  } else if (s.req.video_path && !s.video_lost) {
    s.message("algray: the video " + *s.req.video_path + " was not written: no frame was rendered\n");
    return BatchOutcome::Stopped;
  }
  if (s.video_lost && !s.failed) return BatchOutcome::Stopped;
  return s.failed ? BatchOutcome::FramesFailed : BatchOutcome::Done;
}

BatchOutcome refuse_batch(const std::exception& error, const BatchCallbacks& callbacks) {
  return BatchReporter{callbacks}.refused(error);
}

BatchOutcome run_batch(const BatchRequest& req, const BatchCallbacks& callbacks, RenderContext& context) {
  BatchPlan plan;
  std::optional<BatchRecorder> recorder;
  try {
    plan = plan_batch(req);
    recorder.emplace(req, plan, callbacks);
  } catch (const std::exception& e) {
    return refuse_batch(e, callbacks);
  }
  // One process deals itself its shard's frames in order, each recorded as soon as it is done.
  class OwnFrames : public FrameDealer {
   public:
    OwnFrames(const BatchRequest& req, const BatchPlan& plan, BatchRecorder& recorder)
        : req_(req), plan_(plan), recorder_(recorder) {}
    std::optional<int> next_frame() override {
      while (next_ < plan_.numbered_frames && !in_shard(req_, next_)) ++next_;
      if (next_ >= plan_.numbered_frames || recorder_.cancel_requested()) return std::nullopt;
      return next_++;
    }
    void finished(FrameReport report) override { recorder_.record(report); }

   private:
    const BatchRequest& req_;
    const BatchPlan& plan_;
    BatchRecorder& recorder_;
    int next_ = 0;
  } own(req, plan, *recorder);
  render_dealt_frames(req, plan, context, own);
  return recorder->finish(1);
}

namespace {

// Moves aside a log at `path` that a merge did not write (some line lacks "merged_from"), to the first free
// <stem>.before-merge[-N]<ext>, and returns that name; "" where there is none or it is a merge's own.
std::string keep_unmerged_log(const std::string& path) {
  std::ifstream in(path);
  if (!in) return "";
  bool ours = true;
  for (std::string line; ours && std::getline(in, line);) {
    if (line.empty()) continue;
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    ours = j.is_object() && j.contains("merged_from");
  }
  in.close();
  if (ours) return "";
  const fs::path p(path);
  for (int n = 0; n < 1000; ++n) {
    const std::string suffix = n ? "-" + std::to_string(n) : "";
    const fs::path aside = p.parent_path() / (p.stem().string() + ".before-merge" + suffix + p.extension().string());
    if (fs::exists(aside)) continue;
    fs::rename(p, aside);
    return aside.string();
  }
  throw OutputError("cannot keep " + path + " aside: every " + p.stem().string() + ".before-merge-N name is taken");
}

}  // namespace

namespace {

// The image of a frame that a video can be made from: its first PNG or EXR output.
std::optional<std::string> frame_image_pattern(const BatchJob& job) {
  for (const std::string& o : job.outputs)
    if (lowercase_extension(o) == ".png" || lowercase_extension(o) == ".exr") return o;
  return std::nullopt;
}

// Slurm shards render in separate processes: once their logs are merged, one writer reads every frame's image in
// the batch's order and encodes the video.
BatchOutcome encode_shards_video(const BatchRequest& req, const BatchPlan& plan, const BatchReporter& message) {
  try {
    std::unique_ptr<VideoWriter> video;
    for (const BatchJob& job : plan.jobs)
      for (int frame = 0; frame < job.frames; ++frame) {
        const std::string path = expand_pattern(*frame_image_pattern(job), job, frame);
        const FrameImage image = lowercase_extension(path) == ".png" ? read_png_pixels(path) : read_exr(path);
        if (!video) video = std::make_unique<VideoWriter>(*req.video_path, image.width, image.height, job.fps);
        video->add(image);
      }
    video->finish();
    message("algray: wrote " + *req.video_path + " (" + std::to_string(video->frames()) + " frames, " +
            std::to_string(video->width()) + "x" + std::to_string(video->height()) + ") from the shards' images\n");
    return BatchOutcome::Done;
  } catch (const std::exception& e) {
    message(std::string("algray: the video was not written: ") + e.what() + "\n");
    return BatchOutcome::Stopped;
  }
}

// The batch's plan without the shard, checked for what a merge needs; a refusal is the outcome to return.
std::variant<BatchPlan, BatchOutcome> plan_merge(const BatchRequest& req, const BatchReporter& message) {
  BatchRequest whole = req;
  whole.shard.reset();
  try {
    BatchPlan plan = plan_batch(whole);
    if (req.video_path)
      for (const BatchJob& job : plan.jobs)
        if (!frame_image_pattern(job))
          throw SceneError(job.origin, "--merge-logs --video makes the video from the shards' images: job '" +
                                           job.name + "' needs a .png or .exr output");
    return plan;
  } catch (const std::exception& e) {
    return message.refused(e);
  }
}

// The shard logs beside the batch's log: <stem>.shard-K-of-N<extension>, whatever the shard count.
struct ShardLogs {
  std::vector<fs::path> paths;                               // sorted
  std::map<std::string, std::vector<std::string>> by_count;  // shard count -> its logs' names
};

ShardLogs find_shard_logs(const fs::path& log) {
  const fs::path dir = log.parent_path().empty() ? fs::path(".") : log.parent_path();
  const auto literal = [](const std::string& text) {
    return std::regex_replace(text, std::regex(R"([.^$|()\[\]{}*+?\\])"), R"(\$&)");
  };
  const std::regex shard_name(literal(log.stem().string()) + R"(\.shard-[0-9]+-of-([0-9]+))" +
                              literal(log.extension().string()));
  ShardLogs found;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    std::smatch m;
    if (!std::regex_match(name, m, shard_name)) continue;
    found.paths.push_back(log.parent_path() / name);  // named as the batch's log is, without a "./"
    found.by_count[m[1].str()].push_back(name);
  }
  std::sort(found.paths.begin(), found.paths.end());
  return found;
}

// "\n  4 shards: a, b\n  8 shards: c": the logs of each shard count, for the message that refuses to mix them.
std::string shard_counts_text(std::map<std::string, std::vector<std::string>>& by_count) {
  std::string counts;
  for (auto& [count, names] : by_count) {
    std::sort(names.begin(), names.end());
    counts += "\n  " + count + " shards: ";
    for (std::size_t i = 0; i < names.size(); ++i) counts += (i ? ", " : "") + names[i];
  }
  return counts;
}

// Each frame's last entry: a later line of a shard's log is a later attempt (--resume appends). Across logs, a
// frame one shard rendered and another failed is a conflict: reported, and the rendered one kept.
struct ShardEntries {
  struct Kept {
    nlohmann::json entry;
    std::string where;  // file:line
    std::string file;
  };
  std::map<std::pair<std::string, int>, Kept> last;
  std::vector<std::string> conflicts;

  void add(nlohmann::json j, const fs::path& p, const std::string& where) {
    std::pair<std::string, int> key{j.at("job").get<std::string>(), j.at("frame").get<int>()};
    const auto it = last.find(key);
    if (it != last.end() && it->second.file != p.string()) {
      const std::string was = it->second.entry.value("status", ""), now = j.value("status", "");
      if ((was == "ok" && now == "failed") || (was == "failed" && now == "ok")) {
        conflicts.push_back("job " + key.first + " frame " + std::to_string(key.second) + ": " + was + " in " +
                            it->second.where + ", " + now + " in " + where + "; the ok entry is kept");
        if (now == "failed") return;
      }
    }
    put_path(j, "merged_from", p.filename());
    last[std::move(key)] = Kept{std::move(j), where, p.string()};
  }
};

ShardEntries read_shard_entries(const std::vector<fs::path>& shard_logs, const BatchReporter& message) {
  ShardEntries entries;
  for (const fs::path& p : shard_logs) {
    std::ifstream in(p);
    int line_number = 0;
    for (std::string line; std::getline(in, line);) {
      ++line_number;
      const std::string where = p.string() + ":" + std::to_string(line_number);
      try {
        entries.add(nlohmann::json::parse(line), p, where);
      } catch (const std::exception& e) {
        message("algray: warning: " + where + ": not a log entry (" + e.what() + "), ignored\n");
      }
    }
  }
  return entries;
}

// The merged log's text, in the batch's frame order, and what it lacks.
struct MergedLog {
  std::string text;
  int missing = 0, failed = 0, total = 0;
  std::string missing_names;  // the first 10
};

MergedLog merge_entries(const BatchPlan& plan, const ShardEntries& entries) {
  MergedLog merged;
  for (const BatchJob& job : plan.jobs)
    for (int frame = 0; frame < job.frames; ++frame, ++merged.total) {
      const auto it = entries.last.find({job.name, frame});
      if (it == entries.last.end()) {
        if (merged.missing++ < 10)
          merged.missing_names += (merged.missing_names.empty() ? "" : ", ") + job.name + "/" + std::to_string(frame);
        continue;
      }
      merged.failed += it->second.entry.value("status", "") == "failed";
      merged.text += dump_json(it->second.entry) + "\n";
    }
  return merged;
}

// Writes the merged log over the batch's, keeping aside a log that no merge wrote; false when that failed.
bool write_merged_log(const BatchPlan& plan, const std::string& text, const BatchReporter& message) {
  std::string kept_as;
  try {
    kept_as = keep_unmerged_log(plan.log_path);
    write_text_file(plan.log_path, text);
  } catch (const std::exception& e) {
    message(describe_error(e).text);
    return false;
  }
  if (!kept_as.empty())
    message("algray: " + plan.log_path + " held entries that no merge wrote (a run's log and its --resume " +
            "history); it is kept as " + kept_as + "\n");
  return true;
}

}  // namespace

BatchOutcome merge_shard_logs(const BatchRequest& req, const BatchCallbacks& callbacks) {
  const BatchReporter message{callbacks};
  std::variant<BatchPlan, BatchOutcome> planned = plan_merge(req, message);
  if (const BatchOutcome* refused = std::get_if<BatchOutcome>(&planned)) return *refused;
  const BatchPlan& plan = std::get<BatchPlan>(planned);
  const fs::path log(plan.log_path);
  ShardLogs shard_logs = find_shard_logs(log);
  if (shard_logs.paths.empty()) {
    message("algray: no shard logs beside " + plan.log_path + " (" + log.stem().string() + ".shard-K-of-N" +
            log.extension().string() + "): nothing to merge\n");
    return BatchOutcome::BadInput;
  }
  // Two shard counts side by side are two runs, one of them stale: which frames came from which is the user's
  // call, not ours.
  if (shard_logs.by_count.size() > 1 && !req.merge_mixed_counts) {
    message("algray: the shard logs beside " + plan.log_path + " are of different shard counts:" +
            shard_counts_text(shard_logs.by_count) +
            "\nalgray: remove the stale ones, or pass --mixed-shard-counts to merge them all; nothing merged\n");
    return BatchOutcome::BadInput;
  }
  const ShardEntries entries = read_shard_entries(shard_logs.paths, message);
  for (const std::string& c : entries.conflicts) message("algray: warning: conflicting shard logs: " + c + "\n");
  const MergedLog merged = merge_entries(plan, entries);
  if (!write_merged_log(plan, merged.text, message)) return BatchOutcome::Stopped;
  const std::size_t conflicts = entries.conflicts.size();
  message("algray: merged " + std::to_string(shard_logs.paths.size()) + " shard logs into " + plan.log_path + ": " +
          std::to_string(merged.total) + " frames, " + std::to_string(merged.failed) + " failed, " +
          std::to_string(merged.missing) + " in no log" +
          (merged.missing ? " (" + merged.missing_names + (merged.missing > 10 ? ", ..." : "") + ")" : "") +
          (conflicts ? ", " + std::to_string(conflicts) + " in conflict" : "") + "\n");
  if (merged.missing || merged.failed) {
    if (req.video_path) message("algray: the video " + *req.video_path + " was not written: frames are missing\n");
    return BatchOutcome::FramesFailed;
  }
  if (req.video_path) return encode_shards_video(req, plan, message);
  return BatchOutcome::Done;
}

}  // namespace algray
