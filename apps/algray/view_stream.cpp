// The view's frame stream: the device queue, the pages' newest states, the render thread and the stream's messages.
#include "view_stream.h"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "algray/io/frame_codecs.h"
#include "algray/util/json_text.h"

namespace algray::cli {

using nlohmann::json;

// One page's stream, guarded by its hub's mutex.
class StreamSession {
 public:
  explicit StreamSession(std::string page_) : page(std::move(page_)) {}

  // A frame rendered (or failed) and not yet taken by the stream's connection thread.
  struct Held {
    std::shared_ptr<const StreamState> state;
    std::optional<api::Image> image;
    std::uint64_t pixels = 0;
    FrameFacts facts;
    double queue_ms = 0, render_ms = 0;
    json error;  // where the frame failed: its error, key and column, as /frame.png answers them
  };

  const std::string page;
  std::condition_variable ready;               // `held` filled, or the stream ended
  std::shared_ptr<const StreamState> state;    // the page's newest
  std::shared_ptr<const AppliedSettings> applied = std::make_shared<AppliedSettings>();  // its settings
  std::uint64_t done_seq = 0;                  // the newest state rendered or failed, not to be rendered again
  std::optional<Held> held;
  bool closed = false;
};

namespace {

double ms_since(StreamClock::time_point t) {
  return std::chrono::duration<double, std::milli>(StreamClock::now() - t).count();
}

// Frames rendered and waiting for their streams may hold at most this many pixels together (16 bytes each as
// float RGBA: 256 MB), unless there is only one: a client that stops reading holds its one frame until its
// connection times out, and many such clients must not add up.
constexpr std::uint64_t kHeldPixelBudget = std::uint64_t{1} << 24;

// The backdrop of the page's stage (#222), under a JPEG frame's pixels that are not opaque, as under a PNG's.
constexpr std::array<std::uint8_t, 3> kPageBackdrop = {0x22, 0x22, 0x22};

std::string message(const json& header, const std::string& body = {}) {
  const std::string head = algray::dump_json(header);
  std::string out;
  out.reserve(8 + head.size() + body.size());
  for (const std::size_t n : {head.size(), body.size()})
    for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<char>((n >> shift) & 0xFF));
  out += head;
  out += body;
  return out;
}

const char* mime_of(FrameEncoding e) {
  switch (e) {
    case FrameEncoding::Jpeg:
      return "image/jpeg";
    case FrameEncoding::Webp:
      return "image/webp";
    case FrameEncoding::Png:
      break;
  }
  return "image/png";
}

BadRequest no_stream(const std::string& page) {
  return BadRequest("no stream is open for page '" + page + "': open /stream?page=" + page + " first", "page", 0, 404);
}

// Thrown by the queue's wait when the frame is no longer wanted.
struct NotWanted {};

}  // namespace

FrameQueue::Ticket FrameQueue::arrive(const std::string& page) {
  const std::lock_guard<std::mutex> lock(mutex_);
  return {page, page.empty() ? 0 : ++latest_[page]};
}

bool FrameQueue::superseded(const Ticket& t) {
  const std::lock_guard<std::mutex> lock(mutex_);
  return !t.page.empty() && latest_[t.page] != t.generation;
}

void FrameQueue::leave(const Ticket& t) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!t.page.empty() && latest_[t.page] == t.generation) latest_.erase(t.page);
}

void FrameQueue::take(const std::function<void()>& going_on) {
  std::unique_lock<std::mutex> lock(mutex_);
  while (busy_) {
    lock.unlock();
    going_on();
    lock.lock();
    free_.wait_for(lock, std::chrono::milliseconds(50), [&] { return !busy_; });
  }
  busy_ = true;
}

void FrameQueue::give_back() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    busy_ = false;
  }
  free_.notify_one();
}

FrameFacts frame_facts(const std::string& stats_json) {
  const json s = json::parse(stats_json);
  FrameFacts f;
  f.kernel_ms = s["render_ms"].value("kernel", 0.0);
  for (const json& p : s["programs"]) f.new_programs += p.value("origin", "") != "memory";
  for (const json& surface : s["surfaces"]) f.degree = std::max(f.degree, surface.value("degree", 0));
  f.passes_ms = s["render_ms"].value("passes_wall", 0.0);
  f.shade_ms = s["render_ms"].value("shading", 0.0);
  f.phases_json = s.value("phases_ms", json::object()).dump();
  const json& solver = s["solver"];
  f.precision = solver.value("precision", "");
  f.precision_reason = solver.value("precision_reason", "");
  return f;
}

FrameEncoding parse_encoding(const std::string& name) {
  if (name == "png") return FrameEncoding::Png;
  if (name == "jpeg") return FrameEncoding::Jpeg;
  if (name == "webp") return FrameEncoding::Webp;
  throw BadRequest("encoding must be png, jpeg or webp, not '" + name + "'", "encoding");
}

StreamHub::StreamHub(api::Renderer& renderer, FrameQueue& queue, const ViewLimits& limits)
    : renderer_(renderer), queue_(queue), limits_(limits), thread_([this] { run(); }) {}

StreamHub::~StreamHub() { stop(); }

void StreamHub::stop() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    for (auto& [page, session] : sessions_) {
      session->closed = true;
      session->ready.notify_all();
    }
    sessions_.clear();
  }
  work_.notify_all();
  if (thread_.joinable()) thread_.join();
}

std::shared_ptr<StreamSession> StreamHub::open(const std::string& page) {
  std::shared_ptr<StreamSession> old;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (const auto it = sessions_.find(page); it != sessions_.end()) old = it->second;
    if (!old && static_cast<int>(sessions_.size()) >= limits_.max_streams)
      throw BadRequest("the server already has --max-streams (" + std::to_string(limits_.max_streams) +
                           ") streams open",
                       {}, 0, 429, "--max-streams");
  }
  // A page that opens its stream again (after a network error) replaces the old one, which ends.
  if (old) close(old);
  auto session = std::make_shared<StreamSession>(page);
  const std::lock_guard<std::mutex> lock(mutex_);
  if (stopping_) throw BadRequest("the server is stopping", {}, 0, 503);
  sessions_[page] = session;
  return session;
}

bool StreamHub::post(const std::string& page, std::shared_ptr<const StreamState> state) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto it = sessions_.find(page);
    if (it == sessions_.end()) throw no_stream(page);
    StreamSession& s = *it->second;
    // States come in order from one page; one that overtook a newer one on another connection is dropped.
    if (s.state && state->seq <= s.state->seq) return false;
    s.state = std::move(state);
  }
  work_.notify_all();
  return true;
}

std::shared_ptr<const AppliedSettings> StreamHub::applied_settings(const std::string& page) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto it = sessions_.find(page);
  if (it == sessions_.end()) throw no_stream(page);
  return it->second->applied;
}

void StreamHub::remember_settings(const std::string& page, std::shared_ptr<const AppliedSettings> applied) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (const auto it = sessions_.find(page); it != sessions_.end()) it->second->applied = std::move(applied);
}

void StreamHub::close(const std::shared_ptr<StreamSession>& session) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (const auto it = sessions_.find(session->page); it != sessions_.end() && it->second == session)
      sessions_.erase(it);
    session->closed = true;
    if (session->held) {
      held_pixels_ -= session->held->pixels;
      session->held.reset();
    }
    session->ready.notify_all();
  }
  work_.notify_all();
}

std::shared_ptr<StreamSession> StreamHub::pick(std::shared_ptr<const StreamState>& state) {
  // Pages in turn, from the one after the page served last, so that one busy page does not starve the others.
  for (int round = 0; round < 2; ++round)
    for (const auto& [page, s] : sessions_) {
      if ((round == 0) == (page <= last_served_)) continue;
      if (s->closed || s->held || !s->state || s->state->seq <= s->done_seq) continue;
      const std::uint64_t pixels =
          static_cast<std::uint64_t>(s->state->width) * static_cast<std::uint64_t>(s->state->height);
      if (held_pixels_ > 0 && held_pixels_ + pixels > kHeldPixelBudget) continue;
      state = s->state;
      last_served_ = page;
      return s;
    }
  return nullptr;
}

void StreamHub::run() {
  for (;;) {
    std::shared_ptr<const StreamState> state;
    std::shared_ptr<StreamSession> session;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      work_.wait(lock, [&] { return stopping_ || (session = pick(state)) != nullptr; });
      if (stopping_) return;
    }
    render(session, state);
  }
}

void StreamHub::render(const std::shared_ptr<StreamSession>& session,
                       const std::shared_ptr<const StreamState>& state) {
  const auto deadline = StreamClock::now() + std::chrono::duration_cast<StreamClock::duration>(
                                                 std::chrono::duration<double>(limits_.request_timeout_s));
  // Still wanted: its stream open, and (a full-mode frame) no newer state come.
  const auto wanted = [&] {
    const std::lock_guard<std::mutex> lock(mutex_);
    return !stopping_ && !session->closed && (!state->full || session->state->seq == state->seq);
  };
  bool timed_out = false;
  // The size and preview mode are the scene's own (StreamState), so that the render does not read it again.
  api::RenderSettings settings;
  settings.depth_and_normal = false;
  // Asked between tiles: the device goes to the next frame as soon as this one is not wanted.
  settings.cancelled = [&] {
    if (!wanted()) return true;
    timed_out = StreamClock::now() > deadline;
    return timed_out;
  };
  StreamSession::Held held;
  held.state = state;
  const auto error = [&](const std::string& what, const std::string& key = {}, int column = 0,
                         const std::string& limit = {}) {
    held.error = {{"error", what}, {"key", key}, {"column", column}};
    if (!limit.empty()) held.error["limit"] = limit;
  };
  try {
    queue_.take([&] {
      if (!wanted()) throw NotWanted{};
    });
    held.queue_ms = ms_since(state->arrived);
    const auto started = StreamClock::now();
    try {
      held.image = renderer_.render(state->scene, settings);
    } catch (...) {
      queue_.give_back();
      throw;
    }
    queue_.give_back();
    held.render_ms = ms_since(started);
    held.facts = frame_facts(held.image->stats_json());
    held.pixels = static_cast<std::uint64_t>(state->width) * static_cast<std::uint64_t>(state->height);
  } catch (const NotWanted&) {
    return;  // its page's newer state, if any, is picked next
  } catch (const api::Cancelled&) {
    if (!timed_out) return;
    error("the frame took longer than --request-timeout (" + format_number(limits_.request_timeout_s) + " s)", {}, 0,
          "--request-timeout");
  } catch (const api::SceneError& e) {
    error(e.what());
  } catch (const api::DeviceError& e) {
    error(e.what());
  } catch (const std::exception& e) {
    error(std::string("internal error: ") + e.what());
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  session->done_seq = std::max(session->done_seq, state->seq);
  if (session->closed) return;
  held_pixels_ += held.pixels;
  session->held = std::move(held);
  session->ready.notify_all();
}

std::string StreamHub::hello_message(const std::string& page) {
  return message({{"type", "hello"}, {"page", page}, {"encodings", {"png", "jpeg", "webp"}}});
}

std::optional<std::string> StreamHub::next_message(const std::shared_ptr<StreamSession>& session,
                                                   const std::function<bool()>& gone, double last_send_ms) {
  StreamSession::Held held;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!session->held) {
      if (session->closed || stopping_) return std::nullopt;
      if (session->ready.wait_for(lock, std::chrono::milliseconds(50)) == std::cv_status::timeout) {
        lock.unlock();
        const bool left = gone();
        lock.lock();
        if (left) {
          lock.unlock();
          close(session);
          return std::nullopt;
        }
      }
    }
    held = std::move(*session->held);
    session->held.reset();
    held_pixels_ -= held.pixels;
  }
  work_.notify_all();  // the page's next frame may start while this one is encoded and sent
  const StreamState& state = *held.state;
  json header{{"seq", state.seq}, {"stage", state.stage}};
  if (!held.image) {
    header["type"] = "error";
    header.update(held.error);
    return message(header);
  }
  const auto started = StreamClock::now();
  std::string body;
  if (state.encoding == FrameEncoding::Png) {
    body = held.image->png();
  } else {
    const std::vector<std::uint8_t> pixels = held.image->srgba();
    const int w = held.image->width(), h = held.image->height();
    body = state.encoding == FrameEncoding::Jpeg ? encode_jpeg(pixels.data(), w, h, state.quality, kPageBackdrop)
                                                 : encode_webp(pixels.data(), w, h, state.quality);
  }
  const FrameFacts& f = held.facts;
  header.update({{"type", "frame"},
                 {"mime", mime_of(state.encoding)},
                 {"width", held.image->width()},
                 {"height", held.image->height()},
                 {"degree", f.degree},
                 {"precision", f.precision},
                 {"precision_reason", f.precision_reason},
                 {"new_programs", f.new_programs},
                 {"queue_ms", held.queue_ms},
                 {"render_ms", held.render_ms},
                 {"kernel_ms", f.kernel_ms},
                 {"passes_ms", f.passes_ms},
                 {"shade_ms", f.shade_ms},
                 {"encode_ms", ms_since(started)},
                 {"previous_send_ms", last_send_ms},
                 {"phases_ms", json::parse(f.phases_json)},
                 {"bytes", body.size()}});
  return message(header, body);
}

}  // namespace algray::cli
