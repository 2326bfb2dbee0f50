// A PNG's image data (its IDAT chunks) deflated band by band on every core, and the IEND chunk after it.
#include "algray/io/png_deflate.h"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "algray/io/image_io.h"

namespace algray {
namespace {

constexpr unsigned char kFilterUp = 2;

// One band of rows on its way to the file: its filtered rows' Adler-32 and length, and their deflated bytes.
struct Band {
  std::vector<unsigned char> bytes;     // the band's rows as bytes: the row above it first (zeros for row 0)
  std::vector<unsigned char> filtered;  // a filter byte and the Up-filtered row, per row
  std::vector<unsigned char> deflated;  // raw deflate, ended by a full flush or, for the last band, the end
  uLong adler = 0;
  std::size_t filtered_size = 0;
  bool ready = false;
};

std::string zlib_error(int rc, const z_stream& z) {
  return std::string("zlib: ") + (z.msg ? z.msg : "error " + std::to_string(rc));
}

// Deflates `size` bytes alone (no history from other bands) into `out`, ended by a full flush (byte-aligned,
// the next band may follow) or, when `last`, by the final block.
void deflate_alone(const unsigned char* data, std::size_t size, bool last, int level, std::vector<unsigned char>& out) {
  z_stream z{};
  // -15: raw deflate with the full 32 KB window; the zlib header and trailer are written once for all bands.
  int rc = deflateInit2(&z, level, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY);
  if (rc != Z_OK) throw WriteError(zlib_error(rc, z));
  struct End {
    z_stream& z;
    ~End() { deflateEnd(&z); }
  } end{z};
  out.resize(deflateBound(&z, static_cast<uLong>(size)) + 64);  // the flush marker and slack
  z.next_in = const_cast<unsigned char*>(data);
  z.avail_in = static_cast<uInt>(size);
  std::size_t used = 0;
  const int flush = last ? Z_FINISH : Z_FULL_FLUSH;
  for (;;) {
    z.next_out = out.data() + used;
    z.avail_out = static_cast<uInt>(out.size() - used);
    rc = deflate(&z, flush);
    used = out.size() - z.avail_out;
    if (rc == Z_STREAM_ERROR) throw WriteError(zlib_error(rc, z));
    // Done when the final block is out, or (a flush) when the input is used up and output space remains.
    if (last ? rc == Z_STREAM_END : z.avail_in == 0 && z.avail_out > 0) break;
    out.resize(out.size() * 2);
  }
  out.resize(used);
}

void put_be32(unsigned char* p, std::uint32_t v) {
  p[0] = static_cast<unsigned char>(v >> 24);
  p[1] = static_cast<unsigned char>(v >> 16);
  p[2] = static_cast<unsigned char>(v >> 8);
  p[3] = static_cast<unsigned char>(v);
}

void write_bytes(std::FILE* fp, const void* data, std::size_t size) {
  if (size > 0 && std::fwrite(data, 1, size, fp) != size)
    throw WriteError("write failed: " + std::error_code(errno, std::generic_category()).message());
}

// One PNG chunk: length, type, data and the CRC of type and data. `head` and `tail` go around `data` inside
// the chunk (the zlib header and trailer), so that no band's bytes need copying.
void write_chunk(std::FILE* fp, const char type[4], const std::vector<unsigned char>& head,
                 const std::vector<unsigned char>& data, const std::vector<unsigned char>& tail) {
  const std::size_t size = head.size() + data.size() + tail.size();
  if (size > 0x7fffffffu) throw WriteError("a PNG chunk of " + std::to_string(size) + " bytes is too long");
  unsigned char prefix[8];
  put_be32(prefix, static_cast<std::uint32_t>(size));
  std::copy(type, type + 4, prefix + 4);
  uLong crc = crc32(0L, prefix + 4, 4);
  // Empty parts are skipped: given a null buffer, crc32_z returns the initial value instead of `crc`.
  for (const std::vector<unsigned char>* part : {&head, &data, &tail})
    if (!part->empty()) crc = crc32_z(crc, part->data(), part->size());
  unsigned char suffix[4];
  put_be32(suffix, static_cast<std::uint32_t>(crc));
  write_bytes(fp, prefix, sizeof prefix);
  for (const std::vector<unsigned char>* part : {&head, &data, &tail}) write_bytes(fp, part->data(), part->size());
  write_bytes(fp, suffix, sizeof suffix);
}

// How the image's rows fall into bands, and the bytes each band's filtered rows start from.
struct BandPlan {
  std::size_t height, row_bytes, band_rows, bands;
  const PngRowSource& rows;
  int level;

  // Reads band i's rows (and the row above it), Up-filters them and deflates them alone.
  void deflate_band(std::size_t i, Band& band) const {
    const std::size_t y0 = i * band_rows, count = std::min(band_rows, height - y0);
    band.bytes.resize((count + 1) * row_bytes);
    if (y0 == 0)
      std::fill(band.bytes.begin(), band.bytes.begin() + static_cast<std::ptrdiff_t>(row_bytes), 0);
    else
      rows(y0 - 1, 1, band.bytes.data());
    rows(y0, count, band.bytes.data() + row_bytes);
    band.filtered_size = count * (row_bytes + 1);
    band.filtered.resize(band.filtered_size);
    for (std::size_t r = 0; r < count; ++r) {
      const unsigned char* above = band.bytes.data() + r * row_bytes;
      const unsigned char* row = above + row_bytes;
      unsigned char* out = band.filtered.data() + r * (row_bytes + 1);
      out[0] = kFilterUp;
      for (std::size_t b = 0; b < row_bytes; ++b) out[1 + b] = static_cast<unsigned char>(row[b] - above[b]);
    }
    band.adler = adler32_z(adler32(0L, nullptr, 0), band.filtered.data(), band.filtered_size);
    deflate_alone(band.filtered.data(), band.filtered_size, i + 1 == bands, level, band.deflated);
  }
};

// Worker threads deflating bands into a ring of slots while one caller takes them in order to write them.
class BandPipeline {
 public:
  BandPipeline(const BandPlan& plan, unsigned threads)
      : plan_(plan), window_(2 * static_cast<std::size_t>(threads)), slots_(window_) {
    try {
      for (unsigned t = 0; t < threads; ++t) workers_.emplace_back([this] { work(); });
    } catch (...) {
      stop_and_join();  // no destructor runs for a constructor that throws
      throw;
    }
  }
  // Joined on every way out: a thread still running would use the slots.
  ~BandPipeline() { stop_and_join(); }

  // Band i once deflated; null when a worker failed.
  Band* wait_for(std::size_t i) {
    Band& band = slots_[i % window_];
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return stop_ || band.ready; });
    return band.ready ? &band : nullptr;
  }
  // The band is written: its slot may take the band `window` later.
  void written(Band& band) {
    std::lock_guard<std::mutex> lock(mutex_);
    band.ready = false;
    ++written_;
    changed_.notify_all();
  }
  // The first failure is the one reported; every thread stops.
  void fail(std::exception_ptr e) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!failure_) failure_ = e;
    stop_ = true;
  }
  void stop_and_join() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    for (std::thread& t : workers_) t.join();
    workers_.clear();
  }
  std::exception_ptr failure() const { return failure_; }

 private:
  void work() {
    for (;;) {
      std::size_t i;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return stop_ || next_ >= plan_.bands || next_ < written_ + window_; });
        if (stop_ || next_ >= plan_.bands) return;
        i = next_++;
      }
      Band& band = slots_[i % window_];
      try {
        plan_.deflate_band(i, band);
      } catch (...) {
        fail(std::current_exception());
        changed_.notify_all();
        return;
      }
      std::lock_guard<std::mutex> lock(mutex_);
      band.ready = true;
      changed_.notify_all();
    }
  }

  const BandPlan& plan_;
  // Two bands per thread: one being deflated while the last one waits its turn to be written.
  const std::size_t window_;
  std::vector<Band> slots_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::size_t next_ = 0, written_ = 0;  // the next band to deflate; bands written so far
  bool stop_ = false;                   // a failure, here or in a worker: everyone stops
  std::exception_ptr failure_;
  std::vector<std::thread> workers_;
};

// The zlib header: deflate with a 32 KB window (0x78), and FLEVEL 0 (fastest) for level 1, else 2 (default);
// FCHECK makes the pair a multiple of 31.
std::vector<unsigned char> zlib_header(int level) {
  const unsigned flevel = level <= 1 ? 0 : 2;
  const unsigned cmf = 0x78, flg0 = flevel << 6;
  return {static_cast<unsigned char>(cmf), static_cast<unsigned char>(flg0 + (31 - (cmf * 256 + flg0) % 31) % 31)};
}

}  // namespace

void write_png_image_data(std::FILE* fp, std::size_t height, std::size_t row_bytes, const PngRowSource& rows, int level,
                          std::size_t band_bytes, unsigned threads) {
  const std::size_t band_rows =
      std::clamp<std::size_t>(band_bytes / (row_bytes + 1), 1, std::max<std::size_t>(height, 1));
  const BandPlan plan{height, row_bytes, band_rows, (height + band_rows - 1) / band_rows, rows, level};
  if (threads == 0) threads = std::clamp(std::thread::hardware_concurrency(), 1u, 16u);
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, std::max<std::size_t>(plan.bands, 1)));
  BandPipeline pipeline(plan, threads);

  const std::vector<unsigned char> zlib_head = zlib_header(level);
  const std::vector<unsigned char> none;
  uLong adler = adler32(0L, nullptr, 0);
  for (std::size_t i = 0; i < plan.bands; ++i) {
    Band* band = pipeline.wait_for(i);
    if (!band) break;  // a worker failed
    adler = adler32_combine(adler, band->adler, static_cast<z_off_t>(band->filtered_size));
    std::vector<unsigned char> tail;
    if (i + 1 == plan.bands) {
      tail.resize(4);
      put_be32(tail.data(), static_cast<std::uint32_t>(adler));
    }
    try {
      write_chunk(fp, "IDAT", i == 0 ? zlib_head : none, band->deflated, tail);
    } catch (...) {
      pipeline.fail(std::current_exception());
      break;
    }
    pipeline.written(*band);
  }
  pipeline.stop_and_join();
  if (pipeline.failure()) std::rethrow_exception(pipeline.failure());
  write_chunk(fp, "IEND", none, none, none);
}

}  // namespace algray
