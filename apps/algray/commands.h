// The commands of the command line, each from its parsed request to an exit code (exit_codes.h).
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "algray/api/batch.h"
#include "algray/api/probe_report.h"
#include "algray/api/render_job.h"
#include "algray/scene/scene.h"
#include "view_limits.h"
#ifdef ALGRAY_WITH_MPI
#include "algray/cluster/mpi_world.h"
#endif

namespace algray::cli {

struct RenderRequest {
  std::optional<std::string> scene_path;  // unset: the built-in default scene
  std::optional<std::string> equation;    // -e: an equation alone, instead of a scene
  std::vector<Override> overrides;        // --set, --width, --height, --precision, in order
  RenderOutputs outputs;                  // -o, --stats, --reference, --aov, --heatmap
  std::string device_spec;                // --device
  bool use_cache = true;                  // --no-cache turns it off
  bool progress = false;                  // per-tile progress on stderr
  bool quiet = false;                     // --quiet: nothing on `out` on success
};

struct ProbeRequest {
  std::optional<std::string> scene_path;  // unset: the built-in default scene
  std::optional<std::string> equation;    // -e: an equation alone, instead of a scene
  std::vector<Override> overrides;        // --set and the solver flags, in order
  std::string device_spec;
  ProbeTarget target;
  bool all_solvers = false;              // every isolation x refinement, side by side
  std::optional<std::string> plot_path;  // .svg or .png
  PlotRange plot_range;
  bool json = false;                      // JSON on stdout instead of text
  std::optional<std::string> stats_path;  // the JSON report written to a file as well
  bool use_cache = true;
};

struct ViewRequest {
  std::optional<std::string> scene_path;  // unset: the built-in default scene
  std::optional<std::string> equation;    // -e: an equation alone, instead of a scene
  std::vector<Override> overrides;        // --set, --precision, in order
  std::string device_spec;
  std::string host = "127.0.0.1";  // another address (--host) is reachable from other machines: a warning says so
  int port = 0;                    // 0: any free port
  bool open = false;               // open the URL in a browser (xdg-open)
  bool use_cache = true;
  ViewLimits limits;  // what one client may cost the server (view_limits.h)
  std::string token;  // required in every URL when set; off loopback a random one when empty
};

// Each prints errors (and nothing else on success, unless progress) to `err`; probe's report goes to `out`, and a
// render's one line on what it wrote and how long it took (unless quiet).
int run_render(const RenderRequest& request, std::ostream& out, std::ostream& err);
#ifdef ALGRAY_WITH_MPI
// `algray render` under an MPI launcher: every rank renders bands of the image, rank 0 writes the files. Every
// rank returns the same exit code.
int run_render_across_ranks(const RenderRequest& request, MpiWorld& world, std::ostream& err);
#endif
int run_probe(const ProbeRequest& request, std::ostream& out, std::ostream& err);
int run_batch_command(const BatchRequest& request, bool progress, std::ostream& err);
// `algray batch --merge-logs`: the shard logs joined into the batch's log.
int run_merge_logs(const BatchRequest& request, std::ostream& err);
// `algray view`: serves the page and its frames until killed; prints the URL on `out` once listening.
int run_view(const ViewRequest& request, std::ostream& out, std::ostream& err);
// `algray devices`: the list on `out`, and as JSON in `stats_path` when given.
int run_devices(const std::string& stats_path, std::ostream& out, std::ostream& err);

}  // namespace algray::cli
