// `algray batch`: a TOML list of render jobs with parameter sweeps and camera orbits, run in one process.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "algray/scene/scene.h"

namespace algray {

// One value swept over the frames of a job: a parameter (bare name) or any dotted scene key, from `from` to
// `to` in `steps` evenly spaced values, both ends included.
struct Sweep {
  std::string key;
  std::string origin;  // where the jobs file gives it, for messages
  double from = 0, to = 0;
};

// The camera orbiting its look-at point: `frames` views `degrees` apart in total about `axis` (default: the
// camera's up). With lights = camera, the lights turn with it, as when an object spins on a turntable under
// studio lights; with lights = world, they stay.
struct Orbit {
  double degrees = 360;
  std::optional<glm::dvec3> axis;
  bool lights_follow_camera = true;
};

struct BatchJob {
  std::string name;
  std::string scene;  // a path, resolved against the jobs file's directory
  std::vector<Override> overrides;
  std::vector<std::string> outputs;  // patterns, resolved like the scene
  std::string output_origin;         // where the jobs file gives them, for messages
  std::optional<std::string> stats;  // pattern of a per-frame stats file
  int frames = 1;
  std::vector<Sweep> sweeps;  // all swept together, frame by frame
  std::optional<Orbit> orbit;
  int line = 0;  // in the jobs file, for messages
};

// Reads a jobs file; errors name file:line:column (SceneError).
std::vector<BatchJob> load_jobs(const std::string& text, const std::string& source, const std::string& base_dir);

// An output pattern for one frame: {name}, {frame} (or {frame:0N}, zero-padded to N digits), {value} (the
// first swept value), {angle} (the orbit's, in degrees). Throws SceneError on an unknown placeholder.
std::string expand_pattern(const std::string& pattern, const BatchJob& job, int frame);

// The overrides of one frame: the job's own, then its swept values.
std::vector<Override> frame_overrides(const BatchJob& job, int frame);

// Turns the scene's camera (and with it, optionally, its lights) for frame `frame` of the orbit.
void apply_orbit(Scene& scene, const Orbit& orbit, int frame, int frames);

struct BatchRequest {
  std::string jobs_path;            // "-" for standard input
  std::vector<Override> overrides;  // --set and flags, applied to every job after its own
  std::string device_spec;
  bool use_cache = true;
  bool resume = false;                    // skip frames whose outputs all exist
  std::optional<std::string> log_path;    // default: beside the jobs file, <stem>.log.jsonl
  std::optional<std::string> stats_path;  // a summary of the whole batch
  bool progress = false;                  // a progress line on the terminal
};

// Runs every frame of every job, in order, on one device with one program cache. A failing frame is reported
// and logged, and the rest still run; the exit code is 1 if any failed, 2 if the jobs file itself is bad.
int run_batch(const BatchRequest& request, std::ostream& err);

}  // namespace algray
