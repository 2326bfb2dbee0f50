// Batches: a TOML list of render jobs with parameter sweeps and camera orbits, run in one process.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "algray/api/render_job.h"
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

// A deterministic share of a batch's frames, for Slurm job arrays: numbering every frame of every job in order
// from 0, shard `index` of `count` renders the frames whose number is index modulo count.
struct BatchShard {
  int index = 0, count = 1;
};

// Whether 0 <= index < count; false with a message otherwise.
bool check_shard(const BatchShard& shard, std::string& error);
// "K/N" with 0 <= K < N; false with a message otherwise.
bool parse_shard(const std::string& text, BatchShard& out, std::string& error);
// The shard of a Slurm array task: SLURM_ARRAY_TASK_ID with SLURM_ARRAY_TASK_COUNT, or with
// SLURM_ARRAY_TASK_MIN and _MAX (an array 1-4 is shards 0/4 to 3/4). Unset outside an array job; throws
// SceneError on values that make no shard.
std::optional<BatchShard> shard_from_slurm_environment();
// A shard's own file beside `path`: "jobs.log.jsonl" -> "jobs.log.shard-2-of-4.jsonl".
std::string shard_file(const std::string& path, const BatchShard& shard);

struct BatchRequest {
  std::string jobs_path;            // "-" for standard input
  std::vector<Override> overrides;  // --set and flags, applied to every job after its own
  std::string device_spec;
  bool use_cache = true;
  bool resume = false;                    // skip frames whose outputs all exist
  std::optional<std::string> log_path;    // default: beside the jobs file, <stem>.log.jsonl
  std::optional<std::string> stats_path;  // a summary of the whole batch
  // Only this share of the frames; the log and the stats become the shard's own (shard_file).
  std::optional<BatchShard> shard;
};

// One frame finished (rendered, failed or skipped), for a progress display.
struct BatchProgress {
  int done = 0, total = 0;  // frames finished so far, this one included, of all jobs
  const BatchJob* job = nullptr;
  int frame = 0;
  std::string status;  // "ok", "failed" or "skipped"
  double frame_ms = 0, elapsed_ms = 0, eta_ms = 0;
};

struct BatchCallbacks {
  std::function<void(const BatchProgress&)> on_frame;
  // Lines for the person running the batch: warnings and failures, each ending in a newline.
  std::function<void(const std::string&)> on_message;
};

// How a batch ended: every frame done (or skipped), some frames failed (each reported and logged, the rest
// rendered), the jobs file or its outputs were bad input (nothing rendered), or it stopped early (the device or
// the log failed).
enum class BatchOutcome { Done, FramesFailed, BadInput, Stopped };

// Joins the shard logs of a batch (shard_file of its log, any shard count) into its log: each frame's last entry,
// in job and frame order. Frames no shard rendered or skipped are reported (FramesFailed), as is a bad jobs file.
BatchOutcome merge_shard_logs(const BatchRequest& request, const BatchCallbacks& callbacks);

// Runs every frame of every job, in order, on one device with one program cache. A failing frame is reported
// and logged, and the rest still run.
BatchOutcome run_batch(const BatchRequest& request, const BatchCallbacks& callbacks);
// The same on a device already open (its device_spec and use_cache are then the context's).
BatchOutcome run_batch(const BatchRequest& request, const BatchCallbacks& callbacks, RenderContext& context);

}  // namespace algray
