// The batch across MPI ranks: planning agreed by every rank, rank 0's dealer loop and render thread, the workers.
#include "algray/cluster/mpi_batch.h"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "algray/util/json_text.h"

namespace algray {
namespace {

// A rank asks rank 0 for a frame with the report of its previous one (empty the first time); rank 0 answers with
// a frame number or kNoMoreFrames, and at the end sends every rank the batch's outcome.
constexpr int kRequestTag = 1;
constexpr int kFrameTag = 2;
constexpr int kOutcomeTag = 3;
constexpr int kNoMoreFrames = -1;
constexpr int kPlanned = -1;  // in the exchange of plans: this rank's plan is good


void say(const BatchCallbacks& callbacks, const std::string& text) {
  if (callbacks.on_message) callbacks.on_message(text);
}

constexpr char kBase64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

std::string base64(const void* data, std::size_t size) {
  const auto* p = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  for (std::size_t i = 0; i < size; i += 3) {
    const unsigned v = (p[i] << 16) | (i + 1 < size ? p[i + 1] << 8 : 0) | (i + 2 < size ? p[i + 2] : 0);
    out += kBase64[(v >> 18) & 63];
    out += kBase64[(v >> 12) & 63];
    out += i + 1 < size ? kBase64[(v >> 6) & 63] : '=';
    out += i + 2 < size ? kBase64[v & 63] : '=';
  }
  return out;
}

std::string unbase64(const std::string& text) {
  std::string out;
  unsigned value = 0;
  int bits = 0;
  for (const char c : text) {
    const char* at = std::strchr(kBase64, c);
    if (c == '=' || !c || !at) continue;
    value = (value << 6) | static_cast<unsigned>(at - kBase64);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((value >> bits) & 0xff);
    }
  }
  return out;
}

std::string encode(const FrameReport& report) {
  nlohmann::json j = {{"number", report.number},
                      {"entry", report.entry},
                      {"message", report.message},
                      {"device_lost", report.device_lost}};
  if (report.warnings) j["warnings"] = *report.warnings;
  // A --video frame travels to rank 0, whose one writer encodes the frames in order.
  if (report.image)
    j["image"] = {{"width", report.image->width},
                  {"height", report.image->height},
                  {"rgba", base64(report.image->rgba.data(), report.image->rgba.size() * sizeof(float))}};
  return dump_json(j);
}

FrameReport decode(const std::string& text) {
  const nlohmann::json j = nlohmann::json::parse(text);
  FrameReport report;
  report.number = j.at("number").get<int>();
  report.entry = j.at("entry");
  report.message = j.at("message").get<std::string>();
  report.device_lost = j.at("device_lost").get<bool>();
  if (j.contains("warnings")) report.warnings = j["warnings"].get<std::string>();
  if (j.contains("image")) {
    auto image = std::make_shared<FrameImage>();
    image->width = j["image"].at("width").get<int>();
    image->height = j["image"].at("height").get<int>();
    const std::string bytes = unbase64(j["image"].at("rgba").get<std::string>());
    image->rgba.resize(bytes.size() / sizeof(float));
    std::memcpy(image->rgba.data(), bytes.data(), image->rgba.size() * sizeof(float));
    report.image = std::move(image);
  }
  return report;
}

// Frames not yet dealt and the batch's recorder, shared by rank 0's two threads: the one answering the other
// ranks and the one rendering rank 0's own frames.
class Dealer {
 public:
  Dealer(BatchRecorder* recorder, int frames, int ranks) : recorder_(recorder), frames_(frames), ranks_(ranks) {}

  // Records what `rank` finished, if anything, and deals it its next frame: none once every frame is dealt, the
  // log has failed, or the rank's device has.
  std::optional<int> serve(std::optional<FrameReport> finished, int rank) {
    const std::lock_guard<std::mutex> lock(mutex_);
    bool device_lost = false;
    if (finished) {
      finished->entry["rank"] = rank;
      finished->entry["ranks"] = ranks_;
      device_lost = finished->device_lost;
      if (device_lost)
        finished->message += "algray: rank " + std::to_string(rank) + " renders no more frames" +
                             (++devices_lost_ < ranks_ ? "; the other ranks take the rest\n" : "\n");
      if (recorder_) recorder_->record(*finished);
    }
    if (device_lost || !recorder_ || recorder_->stopped() || next_ >= frames_) return std::nullopt;
    return next_++;
  }

 private:
  std::mutex mutex_;
  BatchRecorder* recorder_;
  int frames_, ranks_;
  int next_ = 0;
  int devices_lost_ = 0;
};

// A renderer that hands in each frame's report with its request for the next one, to `ask` (rank 0's dealer,
// directly or through MPI).
template <typename Ask>
class AskingRenderer : public FrameDealer {
 public:
  explicit AskingRenderer(Ask ask) : ask_(std::move(ask)) {}
  std::optional<int> next_frame() override {
    std::optional<FrameReport> report = std::move(finished_);
    finished_.reset();
    return ask_(std::move(report));
  }
  void finished(FrameReport report) override { finished_ = std::move(report); }
  // After the last frame (a device that failed): its report, and the answer that there are no more.
  void hand_in() {
    if (finished_) next_frame();
  }

 private:
  Ask ask_;
  std::optional<FrameReport> finished_;
};

// Rank 0: deals every frame to whichever rank asks, renders its own share on a thread of its own, and records.
BatchOutcome lead(const BatchRequest& req, const BatchPlan& plan, const BatchCallbacks& callbacks,
                  const MpiWorld& world) {
  std::optional<BatchRecorder> recorder;
  std::optional<BatchOutcome> refused;
  try {
    recorder.emplace(req, plan, callbacks);
  } catch (const std::exception& e) {
    // The log cannot be opened: nothing is dealt, and every rank is told so when it asks.
    refused = refuse_batch(e, callbacks);
  }
  Dealer dealer(recorder ? &*recorder : nullptr, plan.numbered_frames, world.size());

  std::optional<std::string> own_failure;
  std::thread own_frames([&] {
    try {
      RenderContext context(req.device_spec, req.use_cache);
      AskingRenderer renderer([&](std::optional<FrameReport> report) { return dealer.serve(std::move(report), 0); });
      render_dealt_frames(req, plan, context, renderer);
      renderer.hand_in();
    } catch (const std::exception& e) {
      own_failure = e.what();
    }
  });

  int asking = world.size() - 1;  // ranks not yet told that there are no more frames
  std::string request;
  while (asking > 0) {
    MPI_Status status;
    int arrived = 0;
    MPI_Iprobe(MPI_ANY_SOURCE, kRequestTag, MPI_COMM_WORLD, &arrived, &status);
    if (!arrived) {
      std::this_thread::sleep_for(kMpiPollInterval);
      continue;
    }
    int length = 0;
    MPI_Get_count(&status, MPI_CHAR, &length);
    request.assign(static_cast<std::size_t>(length), '\0');
    MPI_Recv(request.data(), length, MPI_CHAR, status.MPI_SOURCE, kRequestTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    std::optional<FrameReport> report;
    if (length > 0) report = decode(request);
    const int number = dealer.serve(std::move(report), status.MPI_SOURCE).value_or(kNoMoreFrames);
    MPI_Send(&number, 1, MPI_INT, status.MPI_SOURCE, kFrameTag, MPI_COMM_WORLD);
    if (number == kNoMoreFrames) --asking;
  }
  own_frames.join();

  BatchOutcome outcome = BatchOutcome::Stopped;
  if (refused) {
    outcome = *refused;
  } else if (own_failure) {
    say(callbacks, "algray: rank 0 stopped rendering: " + *own_failure + "\n");
  } else {
    outcome = recorder->finish(world.size());
  }
  const int code = static_cast<int>(outcome);
  for (int rank = 1; rank < world.size(); ++rank) MPI_Send(&code, 1, MPI_INT, rank, kOutcomeTag, MPI_COMM_WORLD);
  return outcome;
}

// Every other rank: asks rank 0 for frames and renders them until there are none, then waits for the outcome.
BatchOutcome follow(const BatchRequest& req, const BatchPlan& plan) {
  {
    RenderContext context(req.device_spec, req.use_cache);
    AskingRenderer renderer([](std::optional<FrameReport> report) -> std::optional<int> {
      const std::string text = report ? encode(*report) : std::string();
      MPI_Request sent, answered;
      int number = kNoMoreFrames;
      MPI_Isend(text.data(), static_cast<int>(text.size()), MPI_CHAR, 0, kRequestTag, MPI_COMM_WORLD, &sent);
      MPI_Irecv(&number, 1, MPI_INT, 0, kFrameTag, MPI_COMM_WORLD, &answered);
      wait_sleeping(sent);
      wait_sleeping(answered);
      if (number == kNoMoreFrames) return std::nullopt;
      return number;
    });
    render_dealt_frames(req, plan, context, renderer);
    renderer.hand_in();
  }
  int code = static_cast<int>(BatchOutcome::Stopped);
  MPI_Request answered;
  MPI_Irecv(&code, 1, MPI_INT, 0, kOutcomeTag, MPI_COMM_WORLD, &answered);
  wait_sleeping(answered);
  return static_cast<BatchOutcome>(code);
}

}  // namespace

BatchOutcome run_mpi_batch(const BatchRequest& req, const BatchCallbacks& callbacks, MpiWorld& world) {
  const bool root = world.rank() == 0;
  // Every rank sees the same command line, so each refuses these alike with no message between them.
  if (req.shard || req.jobs_path == "-") {
    if (root)
      say(callbacks, req.shard ? "algray: --shard (or a Slurm array task's share) does not combine with MPI ranks, "
                                 "which share out every frame of the batch: use one or the other\n"
                               : "algray: a batch across MPI ranks reads its jobs file on every rank: give its "
                                 "path, not - (standard input reaches rank 0 only)\n");
    return BatchOutcome::BadInput;
  }

  // Every rank plans, so that bad input is found everywhere before anything renders; a rank whose view of the
  // files differs from rank 0's (another node's file system) refuses too.
  BatchPlan plan;
  int refusal = kPlanned;
  std::string reason;
  try {
    plan = plan_batch(req);
  } catch (const std::exception& e) {
    BatchCallbacks keep;
    keep.on_message = [&](const std::string& text) { reason += text; };
    refusal = static_cast<int>(refuse_batch(e, keep));
  }
  std::vector<int> refusals(static_cast<std::size_t>(world.size()));
  MPI_Request exchanged;
  MPI_Iallgather(&refusal, 1, MPI_INT, refusals.data(), 1, MPI_INT, MPI_COMM_WORLD, &exchanged);
  wait_sleeping(exchanged);
  const auto first_refusal = std::find_if(refusals.begin(), refusals.end(), [](int r) { return r != kPlanned; });
  if (first_refusal != refusals.end()) {
    // Rank 0's reason when it has one; otherwise each rank that refused gives its own, which only it knows.
    if (root && refusal != kPlanned) {
      say(callbacks, reason);
    } else if (refusal != kPlanned && refusals.front() == kPlanned) {
      say(callbacks, "algray: rank " + std::to_string(world.rank()) + " (not rank 0) refused the batch:\n" + reason);
    } else if (root) {
      say(callbacks, "algray: rank " + std::to_string(first_refusal - refusals.begin()) +
                         " refused the batch (its reason above); nothing was rendered\n");
    }
    return static_cast<BatchOutcome>(refusals.front() != kPlanned ? refusals.front() : *first_refusal);
  }
  return root ? lead(req, plan, callbacks, world) : follow(req, plan);
}

}  // namespace algray
