// One image across MPI ranks: rank 0's band queue, its render thread and its gathering loop, and the workers.
#include "algray/cluster/mpi_render.h"

#include <mpi.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <climits>
#include <cstdint>
#include <cstring>
#include <functional>
#include <future>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "algray/render/shade.h"
#include "algray/util/json_text.h"

namespace algray {
namespace {

// A worker's messages to rank 0 start with a header {band, status, length of the text after it}: its first
// request; a finished band (its pixels follow on kPixelsTag: RGBA, then depth and normal when rank 0's film has
// them), which asks for the next; its failure (the reason follows on kTextTag); or, when rank 0 had no more
// bands, its tally of everything it rendered (on kTextTag). Rank 0 answers the first two with {next band or
// kNoBand, its first row, its end row, whether to send depth and normal}.
constexpr int kBandRequestTag = 11;
constexpr int kPixelsTag = 12;
constexpr int kTextTag = 13;
constexpr int kReplyTag = 14;
constexpr int kExitCodeTag = 15;
constexpr int kNoBand = -1;
enum WorkerStatus : int { kFirstRequest = 0, kBandDone = 1, kFailed = 2, kFinished = 3 };

struct Band {
  int first = 0, end = 0;
};

// The rows still to deal, shared by rank 0's gathering loop and its render thread. Each band is cut as it is
// dealt (band_rows), numbered in the order dealt. Band 0 is rank 0's and bands 1 .. ranks - 1 are kept for the
// other ranks' first requests, so that every rank renders a band however late its device is ready (a rank that
// started late used to find rank 0 had rendered the whole image).
class BandQueue {
 public:
  BandQueue(int width, int height, int ranks) : width_(width), height_(height), ranks_(ranks) {
    for (int r = 0; r < ranks; ++r) deal();
  }
  // A rank's first band: the one kept for it (band r for rank r), unless dealing has stopped.
  std::optional<int> first_of(int rank) {
    const std::lock_guard<std::mutex> hold(lock_);
    if (stopped_ || rank < 0 || rank >= static_cast<int>(dealt_.size())) return std::nullopt;
    return rank;
  }
  Band band(int b) const {
    const std::lock_guard<std::mutex> hold(lock_);
    return dealt_.at(static_cast<std::size_t>(b));
  }
  // The next band for whichever rank asks, after its first.
  std::optional<int> take() {
    const std::lock_guard<std::mutex> hold(lock_);
    if (stopped_) return std::nullopt;
    return deal();
  }
  // No band is dealt any more, kept ones included: every rank stops after the band it has in hand.
  void stop() {
    const std::lock_guard<std::mutex> hold(lock_);
    stopped_ = true;
  }

 private:
  std::optional<int> deal() {
    if (next_row_ >= height_) return std::nullopt;
    const int rows = band_rows(height_ - next_row_, height_, width_, ranks_);
    dealt_.push_back({next_row_, next_row_ + rows});
    next_row_ += rows;
    return static_cast<int>(dealt_.size()) - 1;
  }

  mutable std::mutex lock_;
  int width_, height_, ranks_, next_row_ = 0;
  bool stopped_ = false;
  std::vector<Band> dealt_;
};

// What one band's render counted, as text for the message to rank 0 and as rank 0 adds it up.
nlohmann::json band_tally(const RenderResult& r) {
  nlohmann::json passes = nlohmann::json::array();
  for (const PassStats& p : r.passes)
    passes.push_back({{"rays", p.rays},
                      {"launches", p.launches},
                      {"kernel_ms", p.kernel_ms},
                      {"wall_ms", p.wall_ms},
                      {"program_ms", p.program_ms}});
  nlohmann::json devices = nlohmann::json::array();
  for (const DeviceShare& d : r.devices)
    devices.push_back({{"index", d.index},
                       {"name", d.name},
                       {"tiles", d.tiles},
                       {"rays", d.rays},
                       {"kernel_ms", d.kernel_ms},
                       {"programs_ms", d.programs_ms}});
  const PrimarySummary& s = r.primary;
  return {
      {"passes", passes},
      {"devices", devices},
      {"shade_ms", r.shade_ms},
      {"shade_kernel_ms", r.shade_kernel_ms},
      {"primary", {s.rays, s.hits, s.depth_limited, s.isolation_steps, s.refine_iterations, s.pixels, s.pixels_hit}}};
}

// The whole image's counts, band by band from every rank.
class ImageTally {
 public:
  void add(const nlohmann::json& band, int rank) {
    const std::lock_guard<std::mutex> hold(lock_);
    const nlohmann::json& passes = band.at("passes");
    if (passes_.empty()) passes_.resize(passes.size());
    for (std::size_t i = 0; i < passes.size() && i < passes_.size(); ++i) {
      PassStats more;
      more.rays = passes[i].at("rays").get<std::uint64_t>();
      more.launches = passes[i].at("launches").get<int>();
      more.kernel_ms = passes[i].at("kernel_ms").get<double>();
      more.wall_ms = passes[i].at("wall_ms").get<double>();
      more.program_ms = passes[i].at("program_ms").get<std::vector<double>>();
      add_counts(passes_[i], more);
    }
    for (const nlohmann::json& d : band.at("devices")) {
      DeviceShare more{rank, d.at("index").get<int>(), d.at("name").get<std::string>()};
      more.tiles = d.at("tiles").get<int>();
      more.rays = d.at("rays").get<std::uint64_t>();
      more.kernel_ms = d.at("kernel_ms").get<double>();
      more.programs_ms = d.at("programs_ms").get<double>();
      auto it = std::find_if(devices_.begin(), devices_.end(),
                             [&](const DeviceShare& s) { return s.rank == rank && s.index == more.index; });
      if (it == devices_.end())
        devices_.push_back(more);
      else
        add_counts(*it, more);
    }
    shade_ms_ += band.at("shade_ms").get<double>();
    shade_kernel_ms_ += band.at("shade_kernel_ms").get<double>();
    const std::vector<std::uint64_t> p = band.at("primary").get<std::vector<std::uint64_t>>();
    PrimarySummary s;
    s.rays = p.at(0), s.hits = p.at(1), s.depth_limited = p.at(2), s.isolation_steps = p.at(3);
    s.refine_iterations = p.at(4), s.pixels = p.at(5), s.pixels_hit = p.at(6);
    primary_ += s;
  }
  // Into `result`, whose passes carry their names and program keys (a band's, rank 0's first).
  void finish(RenderResult& result) const {
    for (std::size_t i = 0; i < result.passes.size() && i < passes_.size(); ++i) {
      PassStats counted = passes_[i];
      counted.name = result.passes[i].name;
      counted.program_keys = result.passes[i].program_keys;
      result.passes[i] = counted;
    }
    result.devices = devices_;
    std::sort(result.devices.begin(), result.devices.end(), [](const DeviceShare& a, const DeviceShare& b) {
      return a.rank != b.rank ? a.rank < b.rank : a.index < b.index;
    });
    result.shade_ms = shade_ms_;
    result.shade_kernel_ms = shade_kernel_ms_;
    result.primary = primary_;
  }

 private:
  std::mutex lock_;
  std::vector<PassStats> passes_;
  std::vector<DeviceShare> devices_;
  double shade_ms_ = 0, shade_kernel_ms_ = 0;
  PrimarySummary primary_;
};

// The film's channels for rows [first, first + rows): where a band's pixels go, or come from.
struct BandChannels {
  float* rgba;
  float* depth;   // null when the film has no depth
  float* normal;  // likewise
  std::size_t pixels;
};
BandChannels channels_of(FrameImage& film, int first, int rows) {
  const std::size_t at = static_cast<std::size_t>(first) * film.width;
  return {film.rgba.data() + 4 * at, film.depth.empty() ? nullptr : film.depth.data() + at,
          film.normal.empty() ? nullptr : film.normal.data() + 3 * at, static_cast<std::size_t>(rows) * film.width};
}

int message_count(std::size_t values) {
  if (values > static_cast<std::size_t>(INT_MAX))
    throw std::runtime_error("a band of " + std::to_string(values) + " values is too large for one MPI message");
  return static_cast<int>(values);
}

void send_sleeping(const void* data, int count, MPI_Datatype type, int tag) {
  MPI_Request request;
  MPI_Isend(data, count, type, 0, tag, MPI_COMM_WORLD, &request);
  wait_sleeping(request);
}

std::string receive_text(int source, int length) {
  std::string text(static_cast<std::size_t>(length), '\0');
  MPI_Recv(text.data(), length, MPI_CHAR, source, kTextTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return text;
}

// Rank 0's side of the messages: answers every worker until each has said it finished or failed, puts the
// bands they send into the film (or, with no film, reads them and drops them), and adds up their tallies.
class Gatherer {
 public:
  Gatherer(BandQueue& queue, ImageTally& tally, bool depth_and_normal)
      : queue_(queue), tally_(tally), depth_and_normal_(depth_and_normal) {}

  // `film_ready` is waited for before the first band is put in; `film` is null when there is none to fill.
  // `failed(why)` is told each worker's failure; `band_done` each finished band; `idle` runs between polls.
  void serve(int workers, const std::shared_future<void>& film_ready, FrameImage* const& film, int width,
             const std::function<void(const std::string&)>& failed, const std::function<void(int rows)>& band_done,
             const std::function<void()>& idle) {
    std::vector<float> dropped;
    for (int active = workers; active > 0;) {
      int arrived = 0;
      MPI_Status status;
      MPI_Iprobe(MPI_ANY_SOURCE, kBandRequestTag, MPI_COMM_WORLD, &arrived, &status);
      idle();
      if (!arrived) {
        std::this_thread::sleep_for(kMpiPollInterval);
        continue;
      }
      const int source = status.MPI_SOURCE;
      int header[3];
      MPI_Recv(header, 3, MPI_INT, source, kBandRequestTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      if (header[1] == kFinished || header[1] == kFailed) {
        const std::string text = receive_text(source, header[2]);
        if (header[1] == kFinished)
          tally_.add(nlohmann::json::parse(text), source);
        else
          failed("rank " + std::to_string(source) + ": " + text);
        --active;
        continue;
      }
      if (header[1] == kBandDone) {
        film_ready.wait();
        const Band band = queue_.band(header[0]);
        const std::size_t pixels = static_cast<std::size_t>(band.end - band.first) * width;
        BandChannels to{nullptr, nullptr, nullptr, pixels};
        if (film) {
          to = channels_of(*film, band.first, band.end - band.first);
        } else {
          dropped.resize(8 * pixels);
          to = {dropped.data(), dropped.data() + 4 * pixels, dropped.data() + 5 * pixels, pixels};
        }
        MPI_Recv(to.rgba, message_count(4 * pixels), MPI_FLOAT, source, kPixelsTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        if (depth_and_normal_) {
          MPI_Recv(to.depth, message_count(pixels), MPI_FLOAT, source, kPixelsTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
          MPI_Recv(to.normal, message_count(3 * pixels), MPI_FLOAT, source, kPixelsTag, MPI_COMM_WORLD,
                   MPI_STATUS_IGNORE);
        }
        band_done(band.end - band.first);
      }
      const int next = (header[1] == kFirstRequest ? queue_.first_of(source) : queue_.take()).value_or(kNoBand);
      const Band band = next == kNoBand ? Band{} : queue_.band(next);
      const int reply[4] = {next, band.first, band.end, depth_and_normal_ ? 1 : 0};
      MPI_Send(reply, 4, MPI_INT, source, kReplyTag, MPI_COMM_WORLD);
    }
  }

 private:
  BandQueue& queue_;
  ImageTally& tally_;
  bool depth_and_normal_;
};

}  // namespace

int band_rows(int rows_left, int image_height, int image_width, int ranks) {
  ranks = std::max(1, ranks);
  const int smallest = std::max(1, (image_height + 64 * ranks - 1) / (64 * ranks));
  // A band's film is 32 bytes a pixel on the rank that renders it; 8 M pixels keep it within 256 MB.
  constexpr std::int64_t kLargestBandPixels = 8 << 20;
  const int largest = static_cast<int>(std::max<std::int64_t>(1, kLargestBandPixels / std::max(1, image_width)));
  const int share = std::max(smallest, (rows_left + 2 * ranks - 1) / (2 * ranks));
  return std::min({rows_left, share, std::max(largest, 1)});
}

RenderResult render_bands_as_rank0(Renderer& renderer, const Scene& scene, const RenderOptions& options,
                                   bool depth_and_normal, MpiWorld& world) {
  const int width = scene.image.width, height = scene.image.height;
  BandQueue queue(width, height, world.size());
  ImageTally tally;
  std::atomic<int> rows_done{0};
  std::mutex failure_lock;
  std::string failure;  // the first failure, on whichever rank
  auto fail = [&](const std::string& why) {
    const std::lock_guard<std::mutex> hold(failure_lock);
    if (failure.empty()) failure = why;
    queue.stop();
  };

  // Rank 0's own bands, on a thread of their own: MPI is called from the main thread only (FUNNELED). They are
  // one render, so its kernels and buffers are set up once, and its check that the image fits the device comes
  // before the film is made, when it asks for its first band; the other ranks' bands wait for the film. Band 0
  // is its first (BandQueue).
  RenderResult result;
  FrameImage film;
  FrameImage* film_made = nullptr;  // set before film_ready is
  std::promise<void> film_promise;
  const std::shared_future<void> film_ready = film_promise.get_future().share();
  std::optional<int> band_in_hand = queue.first_of(0);
  std::thread own([&] {
    bool promised = false;
    try {
      RenderOptions bands;
      bands.batch_rays = options.batch_rays;
      bands.next_band = [&]() -> std::optional<RenderOptions::RowBand> {
        if (!promised) {
          film = options.film ? options.film() : make_film(width, height, depth_and_normal);
          if (film.width != width || film.height != height || film.depth.empty() == depth_and_normal)
            film = make_film(width, height, depth_and_normal);
          film_made = &film;
          promised = true;
          film_promise.set_value();
        }
        const std::optional<int> b = band_in_hand ? std::exchange(band_in_hand, std::nullopt) : queue.take();
        if (!b) return std::nullopt;
        return RenderOptions::RowBand{queue.band(*b).first, queue.band(*b).end};
      };
      bands.on_band = [&](const RenderOptions::RowBand& band, FrameImage& pixels) {
        const BandChannels to = channels_of(film, band.first, pixels.height);
        std::copy(pixels.rgba.begin(), pixels.rgba.end(), to.rgba);
        if (to.depth) std::copy(pixels.depth.begin(), pixels.depth.end(), to.depth);
        if (to.normal) std::copy(pixels.normal.begin(), pixels.normal.end(), to.normal);
        rows_done += pixels.height;
      };
      result = renderer.render(scene, bands);
      tally.add(band_tally(result), 0);
    } catch (const std::exception& e) {
      fail("rank 0: " + std::string(e.what()));
    }
    if (!promised) film_promise.set_value();
  });

  int reported = 0;
  auto report = [&] {
    if (options.on_progress && rows_done > reported) {
      reported = rows_done;
      options.on_progress({reported, height});
    }
  };
  Gatherer(queue, tally, depth_and_normal)
      .serve(
          world.size() - 1, film_ready, film_made, width, fail, [&](int rows) { rows_done += rows; }, report);
  own.join();
  report();
  if (!failure.empty())
    throw std::runtime_error("the render across " + std::to_string(world.size()) + " MPI ranks failed: " + failure);
  tally.finish(result);
  result.image = std::move(film);
  return result;
}

void render_bands_as_worker(Renderer* renderer, const Scene& scene, const std::string& cannot_render) {
  auto send_text = [](WorkerStatus status, const std::string& text) {
    const int header[3] = {kNoBand, status, static_cast<int>(text.size())};
    send_sleeping(header, 3, MPI_INT, kBandRequestTag);
    send_sleeping(text.data(), static_cast<int>(text.size()), MPI_CHAR, kTextTag);
  };
  // Told to rank 0 as a failure, so that the render fails on every rank rather than waits for this one.
  if (!renderer) return send_text(kFailed, cannot_render);
  bool asked = false;  // a finished band's message is also the request for the next
  int band_index = kNoBand;
  bool with_depth = false;
  RenderOptions bands;
  bands.next_band = [&]() -> std::optional<RenderOptions::RowBand> {
    if (!asked) {
      const int header[3] = {kNoBand, kFirstRequest, 0};
      send_sleeping(header, 3, MPI_INT, kBandRequestTag);
    }
    asked = false;
    int reply[4];
    MPI_Request answered;
    MPI_Irecv(reply, 4, MPI_INT, 0, kReplyTag, MPI_COMM_WORLD, &answered);
    wait_sleeping(answered);
    if (reply[0] == kNoBand) return std::nullopt;
    band_index = reply[0];
    with_depth = reply[3] != 0;
    return RenderOptions::RowBand{reply[1], reply[2]};
  };
  bands.on_band = [&](const RenderOptions::RowBand&, FrameImage& pixels) {
    const int header[3] = {band_index, kBandDone, 0};
    send_sleeping(header, 3, MPI_INT, kBandRequestTag);
    send_sleeping(pixels.rgba.data(), message_count(pixels.rgba.size()), MPI_FLOAT, kPixelsTag);
    if (with_depth) {
      send_sleeping(pixels.depth.data(), message_count(pixels.depth.size()), MPI_FLOAT, kPixelsTag);
      send_sleeping(pixels.normal.data(), message_count(pixels.normal.size()), MPI_FLOAT, kPixelsTag);
    }
    asked = true;
  };
  std::string tally;
  try {
    tally = dump_json(band_tally(renderer->render(scene, bands)));
  } catch (const std::exception& e) {
    // Between bands: the last request was answered, so rank 0 waits for this message next.
    return send_text(kFailed, e.what());
  }
  send_text(kFinished, tally);
}

void release_workers(MpiWorld& world) {
  BandQueue none(1, 1, 1);
  none.stop();
  ImageTally ignored;
  std::promise<void> no_film;
  no_film.set_value();
  FrameImage* film = nullptr;
  Gatherer(none, ignored, false)
      .serve(
          world.size() - 1, no_film.get_future().share(), film, 0, [](const std::string&) {}, [](int) {}, [] {});
}

int share_exit_code(int code, MpiWorld& world) {
  if (world.rank() == 0) {
    for (int rank = 1; rank < world.size(); ++rank) MPI_Send(&code, 1, MPI_INT, rank, kExitCodeTag, MPI_COMM_WORLD);
    return code;
  }
  MPI_Request request;
  MPI_Irecv(&code, 1, MPI_INT, 0, kExitCodeTag, MPI_COMM_WORLD, &request);
  wait_sleeping(request);
  return code;
}

}  // namespace algray
