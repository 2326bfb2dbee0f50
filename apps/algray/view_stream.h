// The view's frame stream: the device's one queue, each page's newest state, and the thread that renders them.
#pragma once

#include <algray/algray.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "view_limits.h"
#include "view_query.h"

namespace algray::cli {

using StreamClock = std::chrono::steady_clock;

// The one OpenCL queue, taken by one frame at a time: a /frame.png request's, or the stream thread's. A request
// waits for it only while it is still wanted: its client there, its time left, and no newer frame of its page
// (the request's `page` parameter) come since.
class FrameQueue {
 public:
  // A request's place: its page's generation when it came; superseded once a newer one of the page came.
  struct Ticket {
    std::string page;
    std::uint64_t generation = 0;
  };
  Ticket arrive(const std::string& page);
  bool superseded(const Ticket& t);
  void leave(const Ticket& t);
  // Waits for the queue, checking `going_on` (which throws to give up) every 50 ms.
  void take(const std::function<void()>& going_on);
  void give_back();

 private:
  std::mutex mutex_;
  std::condition_variable free_;
  bool busy_ = false;
  std::map<std::string, std::uint64_t> latest_;  // a page's newest frame; only pages with frames pending
};

// One setting of a page's state applied, and the scene after it (for the page's next state, which repeats most).
struct AppliedSetting {
  Setting setting;
  api::Scene scene;
};
using AppliedSettings = std::vector<AppliedSetting>;

// How a streamed frame is encoded, as the page asks: PNG (lossless, the scene embedded, as /frame.png and
// `algray render` write it) or JPEG or WebP at a quality from 1 to 100.
enum class FrameEncoding { Png, Jpeg, Webp };

// What the page wants on screen: the scene with its settings applied, the frame's size and mode, and how to send
// it. Only a frame in the scene's full mode (antialiasing, shadows: seconds) stops for a newer state; a preview
// runs to its end, so that a page whose states come faster than frames (a drag) still sees every frame it can.
struct StreamState {
  explicit StreamState(api::Scene scene_) : scene(std::move(scene_)) {}
  std::uint64_t seq = 0;  // the page's count, newer is larger
  api::Scene scene;       // with the frame's size and preview mode set (image.width, image.height, render.preview)
  int width = 0, height = 0;
  bool full = false;
  std::string stage;  // the page's name for it, sent back with the frame
  FrameEncoding encoding = FrameEncoding::Png;
  int quality = 80;
  StreamClock::time_point arrived;
};

// Facts of one render from its --stats JSON, for the page's info line and the frame's timings.
struct FrameFacts {
  double kernel_ms = 0, passes_ms = 0, shade_ms = 0;
  int degree = 0, new_programs = 0;
  std::string phases_json;  // the render's phases and their wall times (--stats' phases_ms)
  std::string precision, precision_reason;  // the reason where a stream's previews race (PrecisionRace)
};
FrameFacts frame_facts(const std::string& stats_json);

class StreamSession;

// Every page's stream, and one thread that renders their newest states in turn, one frame at a time on the
// device, while each stream's own connection thread encodes and sends the frame before. A page's next frame is
// rendered only when its last has been taken for sending, so a client that stops reading holds at most one
// frame, and costs no more work until its connection times out.
class StreamHub {
 public:
  StreamHub(api::Renderer& renderer, FrameQueue& queue, const ViewLimits& limits);
  ~StreamHub();
  StreamHub(const StreamHub&) = delete;
  StreamHub& operator=(const StreamHub&) = delete;

  // A new stream for `page`, closing any older one of the same page. BadRequest 429 past --max-streams.
  std::shared_ptr<StreamSession> open(const std::string& page);
  // The page's newest state: false when `state` is not newer than the last one it sent (dropped). BadRequest
  // 404 when the page has no stream open.
  bool post(const std::string& page, std::shared_ptr<const StreamState> state);
  // The settings of the page's last state, with the scene after each (empty at first), and this state's for the
  // next. BadRequest 404 when the page has no stream open.
  std::shared_ptr<const AppliedSettings> applied_settings(const std::string& page);
  void remember_settings(const std::string& page, std::shared_ptr<const AppliedSettings> applied);
  // Ends the session's stream: its frame stops between tiles, and its page may open another.
  void close(const std::shared_ptr<StreamSession>& session);
  void stop();  // closes every stream and ends the render thread

  // The next message of `session`'s stream, encoded: a frame, or a frame's error, as [u32 header bytes][u32 body
  // bytes][header JSON][body], big-endian. Waits for it, asking `gone` every 50 ms; nothing once the stream
  // ended (closed, replaced, or `gone`). `last_send_ms`: how long the message before took to send, reported.
  std::optional<std::string> next_message(const std::shared_ptr<StreamSession>& session,
                                          const std::function<bool()>& gone, double last_send_ms);
  // The first message of every stream: the page's name and the encodings the server offers.
  static std::string hello_message(const std::string& page);

 private:
  void run();
  std::shared_ptr<StreamSession> pick(std::shared_ptr<const StreamState>& state);
  void render(const std::shared_ptr<StreamSession>& session, const std::shared_ptr<const StreamState>& state);

  api::Renderer& renderer_;
  FrameQueue& queue_;
  ViewLimits limits_;
  std::mutex mutex_;
  std::condition_variable work_;
  std::map<std::string, std::shared_ptr<StreamSession>> sessions_;
  std::string last_served_;  // the page served last, for taking pages in turn
  std::uint64_t held_pixels_ = 0;  // of frames rendered and not yet taken by their streams
  bool stopping_ = false;
  std::thread thread_;
};

// A state's encoding and quality from the page's `encoding` and `quality` parameters (BadRequest if neither
// png, jpeg nor webp, or a quality outside 1-100).
FrameEncoding parse_encoding(const std::string& name);

}  // namespace algray::cli
