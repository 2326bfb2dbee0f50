// Batches: a TOML list of render jobs with parameter sweeps and camera orbits, run in one process.
#pragma once

#include <exception>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "algray/api/render_job.h"
#include "algray/scene/scene.h"

namespace algray {

struct BatchCallbacks;

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
  double fps = 30;  // frames per second of a --video; `seconds` in the jobs file times this gives the frames
  int line = 0;     // in the jobs file, for messages
  std::string origin;  // "file:line:column" of the job's table, for messages
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

// How a batch ended: every frame done (or skipped), some frames failed (each reported and logged, the rest
// rendered), the jobs file or its outputs were bad input (nothing rendered), or it stopped early (the device or
// the log failed).
enum class BatchOutcome { Done, FramesFailed, BadInput, Stopped };

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
  // --merge-logs only: join shard logs of different shard counts too (by default refused: one count is a stale run).
  bool merge_mixed_counts = false;
  // --video: every frame of every job, in order, encoded into this .mp4, .webm or .gif as it is rendered
  // (io/video_writer.h), at the first job's fps. Jobs may then have no output of their own.
  std::optional<std::string> video_path;
  // Runs the batch in place of this process alone, from the same request and callbacks: set by the command line
  // under an MPI launcher (cluster/mpi_batch.h), which sits above this layer. run_batch calls it when set.
  std::function<BatchOutcome(const BatchRequest&, const BatchCallbacks&)> distribute;
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
  // Asked before each frame; true stops the batch there (Stopped), as RenderCallbacks::cancelled stops a render
  // before a tile. A frame under way is finished and logged, so --resume picks up after it.
  std::function<bool()> cancelled;
};

// Joins the shard logs of a batch (shard_file of its log) into its log: each frame's last entry, in job and frame
// order, each with the shard log it came from ("merged_from"). Frames no shard rendered or skipped are reported
// (FramesFailed), as is a bad jobs file. Logs of different shard counts are refused (BadInput, nothing written)
// unless request.merge_mixed_counts; a frame logged ok by one shard and failed by another is reported, and the ok
// entry kept. An existing log that holds entries no merge wrote (an unsharded run's, with its --resume history) is
// kept under a new name, never replaced.
BatchOutcome merge_shard_logs(const BatchRequest& request, const BatchCallbacks& callbacks);

// Runs every frame of every job, in order, on one device with one program cache. A failing frame is reported
// and logged, and the rest still run. With request.distribute set, that runs the batch instead.
BatchOutcome run_batch(const BatchRequest& request, const BatchCallbacks& callbacks);
// The same in this process, on a device already open (its device_spec and use_cache are then the context's).
BatchOutcome run_batch(const BatchRequest& request, const BatchCallbacks& callbacks, RenderContext& context);

// The pieces run_batch is made of, for a batch whose frames are rendered by several processes (cluster/): one
// plans and records, every one renders the frames a FrameDealer hands it.

// The jobs file read and every path the batch will write checked, before anything renders.
struct BatchPlan {
  std::vector<BatchJob> jobs;
  std::string log_path;
  std::optional<std::string> stats_path;
  int total_frames = 0;     // of this shard
  int numbered_frames = 0;  // of every job: frame numbers run from 0 to this, shard or not
};
// Throws SceneError or OutputError on bad input: a bad jobs file, or an output that cannot be written or is
// another input or output by some other name.
BatchPlan plan_batch(const BatchRequest& request);

// A frame finished (rendered, failed or skipped) by whichever process rendered it.
struct FrameReport {
  int number = 0;        // in the numbering of the whole batch that shards use
  std::shared_ptr<const FrameImage> image;  // the frame's pixels, kept for a --video
  nlohmann::json entry;  // its log line
  std::string message;   // why it failed, for the person running the batch; empty when it did not
  std::optional<std::string> warnings;  // the scene's warning lines, once the frame has read its scene
  bool device_lost = false;             // the device failed: the process that rendered it renders no more
};

// Where a renderer's frames come from and where what became of them goes.
class FrameDealer {
 public:
  virtual ~FrameDealer() = default;
  // The number of the next frame to render, or none when there are no more for this renderer.
  virtual std::optional<int> next_frame() = 0;
  virtual void finished(FrameReport report) = 0;
};

// Renders (or, with --resume, skips) the frames `dealer` deals, one at a time, until it deals no more or the
// device fails. Writes nothing but the frames' own files.
void render_dealt_frames(const BatchRequest& request, const BatchPlan& plan, RenderContext& context,
                         FrameDealer& dealer);

// The log, the messages, the progress and the summary of a batch, from its frames' reports in the order they
// finish. One thread at a time.
class BatchRecorder {
 public:
  // Opens the log (throws OutputError).
  BatchRecorder(const BatchRequest& request, const BatchPlan& plan, const BatchCallbacks& callbacks);
  ~BatchRecorder();
  BatchRecorder(const BatchRecorder&) = delete;
  BatchRecorder& operator=(const BatchRecorder&) = delete;

  void record(const FrameReport& report);
  // The log could not be written, or the callbacks cancelled the batch: it stops, and no later report is
  // recorded.
  bool stopped() const;
  // Asks the callbacks' `cancelled`; when it says stop, says so once and stops the batch. Between frames.
  bool cancel_requested();
  // The outcome once every renderer is done, the summary written and the failures counted. `renderers` of them
  // rendered: when every one lost its device, the batch ends as a device that cannot be opened does.
  BatchOutcome finish(int renderers);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// A batch refused before any frame (its plan or its log failed): the reason through the callbacks, and the outcome.
BatchOutcome refuse_batch(const std::exception& error, const BatchCallbacks& callbacks);

}  // namespace algray
