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

}  // namespace

void write_png_image_data(std::FILE* fp, std::size_t height, std::size_t row_bytes, const PngRowSource& rows, int level,
                          std::size_t band_bytes, unsigned threads) {
  const std::size_t band_rows =
      std::clamp<std::size_t>(band_bytes / (row_bytes + 1), 1, std::max<std::size_t>(height, 1));
  const std::size_t bands = (height + band_rows - 1) / band_rows;
  if (threads == 0) threads = std::clamp(std::thread::hardware_concurrency(), 1u, 16u);
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, std::max<std::size_t>(bands, 1)));
  // Two bands per thread: one being deflated while the last one waits its turn to be written.
  const std::size_t window = 2 * static_cast<std::size_t>(threads);
  std::vector<Band> slots(window);

  std::mutex mutex;
  std::condition_variable changed;
  std::size_t next = 0, written = 0;  // the next band to deflate; bands written so far
  bool stop = false;                  // a failure, here or in a worker: everyone stops
  std::exception_ptr failure;

  auto deflate_band = [&](std::size_t i, Band& band) {
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
  };
  auto work = [&] {
    for (;;) {
      std::size_t i;
      {
        std::unique_lock<std::mutex> lock(mutex);
        changed.wait(lock, [&] { return stop || next >= bands || next < written + window; });
        if (stop || next >= bands) return;
        i = next++;
      }
      Band& band = slots[i % window];
      try {
        deflate_band(i, band);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!failure) failure = std::current_exception();
        stop = true;
        changed.notify_all();
        return;
      }
      std::lock_guard<std::mutex> lock(mutex);
      band.ready = true;
      changed.notify_all();
    }
  };

  std::vector<std::thread> workers;
  // Joined on every way out: a thread still running would use this frame's buffers.
  struct Join {
    std::vector<std::thread>& workers;
    std::mutex& mutex;
    std::condition_variable& changed;
    bool& stop;
    ~Join() {
      {
        std::lock_guard<std::mutex> lock(mutex);
        stop = true;
      }
      changed.notify_all();
      for (std::thread& t : workers) t.join();
    }
  } join{workers, mutex, changed, stop};
  for (unsigned t = 0; t < threads; ++t) workers.emplace_back(work);

  // The zlib header: deflate with a 32 KB window (0x78), and FLEVEL 0 (fastest) for level 1, else 2 (default);
  // FCHECK makes the pair a multiple of 31.
  const unsigned flevel = level <= 1 ? 0 : 2;
  const unsigned cmf = 0x78, flg0 = flevel << 6;
  const std::vector<unsigned char> zlib_head{static_cast<unsigned char>(cmf),
                                             static_cast<unsigned char>(flg0 + (31 - (cmf * 256 + flg0) % 31) % 31)};
  const std::vector<unsigned char> none;
  uLong adler = adler32(0L, nullptr, 0);
  for (std::size_t i = 0; i < bands; ++i) {
    Band& band = slots[i % window];
    {
      std::unique_lock<std::mutex> lock(mutex);
      changed.wait(lock, [&] { return stop || band.ready; });
      if (!band.ready) break;  // a worker failed
    }
    adler = adler32_combine(adler, band.adler, static_cast<z_off_t>(band.filtered_size));
    std::vector<unsigned char> tail;
    if (i + 1 == bands) {
      tail.resize(4);
      put_be32(tail.data(), static_cast<std::uint32_t>(adler));
    }
    try {
      write_chunk(fp, "IDAT", i == 0 ? zlib_head : none, band.deflated, tail);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex);
      if (!failure) failure = std::current_exception();
      stop = true;
      break;
    }
    std::lock_guard<std::mutex> lock(mutex);
    band.ready = false;
    ++written;
    changed.notify_all();
  }
  {
    std::lock_guard<std::mutex> lock(mutex);
    stop = true;
  }
  changed.notify_all();
  for (std::thread& t : workers) t.join();
  workers.clear();
  if (failure) std::rethrow_exception(failure);
  write_chunk(fp, "IEND", none, none, none);
}

}  // namespace algray
