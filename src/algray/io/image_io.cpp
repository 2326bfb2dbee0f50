// EXR, PNG and text output through temp-file-and-rename, signal-time and stale temp-file cleanup, and read-back of
// EXR images and PNG text.
#include "algray/io/image_io.h"

// OpenEXR/Imath headers trip -Wconversion/-Wshadow when not reached through -isystem.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#include <ImathBox.h>
#include <ImathMatrix.h>
#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <half.h>
#pragma GCC diagnostic pop
#include <fcntl.h>
#include <limits.h>
#include <png.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csetjmp>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <system_error>
#include <thread>

#include "algray/io/png_deflate.h"
#include "algray/util/temp_files.h"
#include "algray/util/version.h"

namespace algray {
namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------------------------
// Temp-file registry readable from a signal handler. A handler may only touch lock-free atomics and
// plain memory, so paths live in fixed char buffers and a slot's state gates whether the handler
// may trust its path.

constexpr std::size_t kSlotCount = 16;
constexpr std::size_t kPathCapacity = 4096;
enum SlotState : int { kFree = 0, kClaimed = 1, kActive = 2 };

struct TempSlot {
  std::atomic<int> state{kFree};
  char path[kPathCapacity];
};
static_assert(std::atomic<int>::is_always_lock_free, "signal handler needs lock-free atomics");

TempSlot g_slots[kSlotCount];

extern "C" void cleanup_then_reraise(int sig) {
  for (TempSlot& slot : g_slots) {
    if (slot.state.load(std::memory_order_acquire) == kActive) ::unlink(slot.path);
  }
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

std::string errno_text(int err) { return std::error_code(err, std::generic_category()).message(); }

// ".NAME.tmp-": what every temporary for `destination` starts with, before "<pid>-<counter>".
std::string temp_prefix(const fs::path& destination) {
  std::string prefix = ".";
  // Stay under NAME_MAX even for long destination names; uniqueness comes from pid and counter.
  prefix.append(destination.filename().string(), 0, 200);
  prefix += ".tmp-";
  return prefix;
}

// Owns one temporary file for its lifetime: registered for signal cleanup before the file can
// exist, removed on destruction unless it was committed by renaming.
class TempFile {
 public:
  explicit TempFile(const fs::path& destination) {
    path_ = destination.parent_path() / temp_file_name(temp_prefix(destination));
    const std::string& text = path_.native();
    if (text.size() >= kPathCapacity) return;  // too long to register; a truncated path could unlink a stranger
    for (std::size_t i = 0; i < kSlotCount; ++i) {
      int expected = kFree;
      if (g_slots[i].state.compare_exchange_strong(expected, kClaimed)) {
        std::memcpy(g_slots[i].path, text.c_str(), text.size() + 1);
        g_slots[i].state.store(kActive, std::memory_order_release);
        slot_ = static_cast<int>(i);
        break;
      }
    }
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  ~TempFile() {
    if (!committed_) {
      std::error_code ignored;
      fs::remove(path_, ignored);
    }
    release_slot();
  }

  const fs::path& path() const { return path_; }

  void commit(const fs::path& destination) {
    if (::rename(path_.c_str(), destination.c_str()) != 0) throw WriteError("rename failed: " + errno_text(errno));
    committed_ = true;
    release_slot();
  }

 private:
  void release_slot() {
    if (slot_ < 0) return;
    g_slots[slot_].state.store(kClaimed, std::memory_order_release);
    g_slots[slot_].state.store(kFree, std::memory_order_release);
    slot_ = -1;
  }

  fs::path path_;
  int slot_ = -1;
  bool committed_ = false;
};

// Without this the rename could reach the disk before the data, and a crash would leave a truncated
// file under the destination name.
void sync_file(const fs::path& p) {
  const int fd = ::open(p.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw WriteError("cannot reopen temporary file for fsync: " + errno_text(errno));
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) throw WriteError("fsync failed: " + errno_text(err));
}

// Best effort: makes the rename itself durable; failure here does not make the image wrong.
void sync_directory(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

std::string cannot_write(const fs::path& path) { return "cannot write '" + path.string() + "': "; }

void write_atomically(const fs::path& path, const std::function<void(const fs::path&)>& write_to) {
  check_output_path(path);
  const fs::path destination = fs::absolute(path);
  remove_stale_temps(destination.parent_path(), temp_prefix(destination));
  // What write_to throws as OutputError is the image's fault, found before the file is touched; anything
  // else failed on the way to the disk.
  try {
    TempFile temp(destination);
    write_to(temp.path());
    sync_file(temp.path());
    temp.commit(destination);
    sync_directory(destination.parent_path());
  } catch (const OutputError& e) {
    throw OutputError(cannot_write(path) + e.what());
  } catch (const std::exception& e) {
    throw WriteError(cannot_write(path) + e.what());
  }
}

// ---------------------------------------------------------------------------------------------
// Validation shared by both writers.

std::size_t checked_pixel_count(const FrameImage& image) {
  if (image.width <= 0 || image.height <= 0) {
    throw OutputError("invalid image size " + std::to_string(image.width) + "x" + std::to_string(image.height));
  }
  const auto w = static_cast<std::size_t>(image.width);
  const auto h = static_cast<std::size_t>(image.height);
  // 16 floats per pixel is the widest buffer anyone sizes from this count.
  if (w > std::numeric_limits<std::size_t>::max() / 16 / h) throw OutputError("image too large");
  const std::size_t n = w * h;
  if (image.rgba.size() != 4 * n)
    throw OutputError("rgba holds " + std::to_string(image.rgba.size()) + " floats, expected " + std::to_string(4 * n));
  return n;
}

void check_layer_size(const std::string& what, std::size_t have, std::size_t expected) {
  if (have != expected) {
    throw OutputError(what + " holds " + std::to_string(have) + " values, expected " + std::to_string(expected));
  }
}

// ---------------------------------------------------------------------------------------------
// EXR

Imath::M44f to_m44(const std::array<float, 16>& a) {
  Imath::M44f m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m[r][c] = a[static_cast<std::size_t>(r * 4 + c)];
  return m;
}

std::array<float, 16> from_m44(const Imath::M44f& m) {
  std::array<float, 16> a{};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) a[static_cast<std::size_t>(r * 4 + c)] = m[r][c];
  return a;
}

const char* const kRgbaNames[4] = {"R", "G", "B", "A"};

// Colour is converted to half a strip of lines at a time (write_exr_strips), so a poster needs no second copy of
// its film: its slices are set per strip; the float channels are read where they are.
void add_exr_channels(Imf::Header& header, Imf::FrameBuffer& frame, const FrameImage& image, std::size_t n) {
  const auto w = static_cast<std::int64_t>(image.width);
  const auto h = static_cast<std::int64_t>(image.height);
  const Imath::V2i origin(0, 0);
  Imf::ChannelList& channels = header.channels();
  auto add = [&](const std::string& name, Imf::PixelType type, const void* base, std::size_t x_stride) {
    if (name.empty()) throw OutputError("channel with an empty name");
    if (channels.findChannel(name)) throw OutputError("duplicate channel name '" + name + "'");
    channels.insert(name, Imf::Channel(type));
    frame.insert(name, Imf::Slice::Make(type, base, origin, w, h, x_stride));
  };
  for (const char* name : kRgbaNames) {
    if (channels.findChannel(name)) throw OutputError(std::string("duplicate channel name '") + name + "'");
    channels.insert(name, Imf::Channel(Imf::HALF));
  }
  if (!image.depth.empty()) add("Z", Imf::FLOAT, image.depth.data(), sizeof(float));
  if (!image.normal.empty()) {
    const char* normal_names[3] = {"N.X", "N.Y", "N.Z"};
    for (std::size_t c = 0; c < 3; ++c) add(normal_names[c], Imf::FLOAT, image.normal.data() + c, 3 * sizeof(float));
  }
  for (const auto& ch : image.uint_channels) {
    check_layer_size("channel '" + ch.name + "'", ch.values.size(), n);
    add(ch.name, Imf::UINT, ch.values.data(), sizeof(std::uint32_t));
  }
  for (const auto& ch : image.float_channels) {
    check_layer_size("channel '" + ch.name + "'", ch.values.size(), n);
    add(ch.name, Imf::FLOAT, ch.values.data(), sizeof(float));
  }
}

void add_exr_attributes(Imf::Header& header, const FrameImage& image) {
  if (image.world_to_camera) Imf::addWorldToCamera(header, to_m44(*image.world_to_camera));
  if (image.world_to_ndc) Imf::addWorldToNDC(header, to_m44(*image.world_to_ndc));
  // The renderer's colours are linear Rec.709 (sRGB primaries) with a D65 white.
  Imf::addChromaticities(header, Imf::Chromaticities(Imath::V2f(0.64f, 0.33f), Imath::V2f(0.30f, 0.60f),
                                                     Imath::V2f(0.15f, 0.06f), Imath::V2f(0.3127f, 0.3290f)));
  // OpenEXR 3.1 has no addSoftware(); this is the attribute newer versions define under that name.
  header.insert("software", Imf::StringAttribute(image.software.empty() ? version_string() : image.software));
  if (!image.comments.empty()) Imf::addComments(header, image.comments);
  // A clash would silently overwrite (same type) or throw deep inside OpenEXR (other type); refuse early.
  auto check_attribute_name = [&](const std::string& name) {
    if (name.empty()) throw OutputError("attribute with an empty name");
    // Refused even when the field is empty, so that it is never written one way in one file and the other in the next.
    if (name == "software" || name == "comments")
      throw OutputError("attribute '" + name + "' comes from FrameImage::" + name + ", not from string_attributes");
    if (header.find(name) != header.end()) throw OutputError("attribute name '" + name + "' is already in use");
  };
  for (const auto& [name, value] : image.string_attributes) {
    check_attribute_name(name);
    header.insert(name, Imf::StringAttribute(value));
  }
  for (const auto& [name, value] : image.double_attributes) {
    check_attribute_name(name);
    header.insert(name, Imf::DoubleAttribute(value));
  }
}

// Compression dominates the write; blocks of lines compress in parallel on OpenEXR's threads. A strip holds
// about 4 MB of half colour, and at least four ZIP blocks (16 lines) per thread, so the threads stay busy.
void write_exr_strips(const fs::path& file, const Imf::Header& header, const Imf::FrameBuffer& frame,
                      const FrameImage& image) {
  const auto w = static_cast<std::int64_t>(image.width);
  const auto h = static_cast<std::int64_t>(image.height);
  const int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  static std::once_flag pool_started;
  std::call_once(pool_started, [threads] { Imf::setGlobalThreadCount(threads); });
  Imf::OutputFile out(file.c_str(), header, threads);
  const std::int64_t strip_lines = std::min<std::int64_t>(h, std::max<std::int64_t>(64 * threads, (4 << 20) / (8 * w)));
  std::vector<Imath::half> rgba_half(static_cast<std::size_t>(4 * w * strip_lines));
  for (std::int64_t y0 = 0; y0 < h; y0 += strip_lines) {
    const std::int64_t lines = std::min(strip_lines, h - y0);
    // Converted here rather than by OpenEXR so the rounding is the one Imath::half documents.
    const float* from = image.rgba.data() + 4 * w * y0;
    for (std::size_t i = 0; i < static_cast<std::size_t>(4 * w * lines); ++i) rgba_half[i] = Imath::half(from[i]);
    Imf::FrameBuffer strip = frame;
    for (std::size_t c = 0; c < 4; ++c)
      strip.insert(kRgbaNames[c], Imf::Slice::Make(Imf::HALF, rgba_half.data() + c, Imath::V2i(0, static_cast<int>(y0)),
                                                   w, lines, 4 * sizeof(Imath::half)));
    out.setFrameBuffer(strip);
    out.writePixels(static_cast<int>(lines));
  }
}

void encode_exr(const fs::path& file, const FrameImage& image) {
  const std::size_t n = checked_pixel_count(image);
  if (!image.depth.empty()) check_layer_size("depth", image.depth.size(), n);
  if (!image.normal.empty()) check_layer_size("normal", image.normal.size(), 3 * n);

  Imf::Header header(image.width, image.height);  // display window == data window, origin 0,0
  header.compression() = Imf::ZIP_COMPRESSION;
  // Level 1: measured at 1024x768, the file grows by 6% while the write takes half the time of level 6.
  header.zipCompressionLevel() = 1;
  header.lineOrder() = Imf::INCREASING_Y;
  Imf::FrameBuffer frame;
  add_exr_channels(header, frame, image, n);
  add_exr_attributes(header, image);
  write_exr_strips(file, header, frame, image);
}

// Read back: which of algray's layers the file holds. Its other channels are sized in `image` as they are found.
struct ExrLayers {
  bool rgba = false, depth = false, normal = false;
};

ExrLayers sort_exr_channels(const Imf::ChannelList& channels, std::size_t n, FrameImage& image) {
  const std::set<std::string> rgba_names = {"R", "G", "B", "A"};
  const std::set<std::string> normal_names = {"N.X", "N.Y", "N.Z"};
  ExrLayers layers;
  for (auto it = channels.begin(); it != channels.end(); ++it) {
    const std::string name = it.name();
    if (it.channel().xSampling != 1 || it.channel().ySampling != 1) {
      throw OutputError("channel '" + name + "' is subsampled, which algray does not use");
    }
    if (rgba_names.count(name))
      layers.rgba = true;
    else if (name == "Z")
      layers.depth = true;
    else if (normal_names.count(name))
      layers.normal = true;
    else if (it.channel().type == Imf::UINT)
      image.uint_channels.push_back({name, std::vector<std::uint32_t>(n)});
    else
      image.float_channels.push_back({name, std::vector<float>(n)});
  }
  return layers;
}

// Slices are attached only after every vector has its final size, so no pointer is invalidated.
Imf::FrameBuffer exr_read_slices(const Imath::Box2i& window, const ExrLayers& layers, std::size_t n,
                                 FrameImage& image) {
  Imf::FrameBuffer frame;
  auto add = [&](const std::string& name, Imf::PixelType type, void* base, std::size_t x_stride, double fill) {
    frame.insert(name, Imf::Slice::Make(type, base, window, x_stride, 0, 1, 1, fill));
  };
  if (layers.rgba) {
    image.rgba.resize(4 * n);
    add("R", Imf::FLOAT, image.rgba.data() + 0, 4 * sizeof(float), 0.0);
    add("G", Imf::FLOAT, image.rgba.data() + 1, 4 * sizeof(float), 0.0);
    add("B", Imf::FLOAT, image.rgba.data() + 2, 4 * sizeof(float), 0.0);
    add("A", Imf::FLOAT, image.rgba.data() + 3, 4 * sizeof(float), 1.0);
  }
  if (layers.depth) {
    image.depth.resize(n);
    add("Z", Imf::FLOAT, image.depth.data(), sizeof(float), std::numeric_limits<double>::infinity());
  }
  if (layers.normal) {
    image.normal.resize(3 * n);
    add("N.X", Imf::FLOAT, image.normal.data() + 0, 3 * sizeof(float), 0.0);
    add("N.Y", Imf::FLOAT, image.normal.data() + 1, 3 * sizeof(float), 0.0);
    add("N.Z", Imf::FLOAT, image.normal.data() + 2, 3 * sizeof(float), 0.0);
  }
  for (auto& ch : image.uint_channels) add(ch.name, Imf::UINT, ch.values.data(), sizeof(std::uint32_t), 0.0);
  for (auto& ch : image.float_channels) add(ch.name, Imf::FLOAT, ch.values.data(), sizeof(float), 0.0);
  return frame;
}

void read_exr_attributes(const Imf::Header& header, FrameImage& image) {
  for (auto it = header.begin(); it != header.end(); ++it) {
    const std::string name = it.name();
    if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) {
      if (name == "software")
        image.software = s->value();
      else if (name == "comments")
        image.comments = s->value();
      else
        image.string_attributes.emplace_back(name, s->value());
    } else if (const auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&it.attribute())) {
      image.double_attributes.emplace_back(it.name(), d->value());
    }
  }
  if (Imf::hasWorldToCamera(header)) image.world_to_camera = from_m44(Imf::worldToCamera(header));
  if (Imf::hasWorldToNDC(header)) image.world_to_ndc = from_m44(Imf::worldToNDC(header));
  if (Imf::hasChromaticities(header)) {
    const Imf::Chromaticities& c = Imf::chromaticities(header);
    image.chromaticities =
        std::array<float, 8>{c.red.x, c.red.y, c.green.x, c.green.y, c.blue.x, c.blue.y, c.white.x, c.white.y};
  }
}

// ---------------------------------------------------------------------------------------------
// PNG

std::uint8_t to_byte(double v) { return static_cast<std::uint8_t>(std::lround(v * 255.0)); }

// The sRGB transfer function, rounded to a byte: the definition the fast encoder below is built from.
std::uint8_t encode_srgb_exactly(float linear) {
  if (!(linear > 0.0f)) return 0;  // also maps NaN to black
  if (linear >= 1.0f) return 255;
  const double l = linear;
  return to_byte(l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055);
}

// encode_srgb_exactly without a pow() per value (a third of a 1024^2 PNG's write): a table by the float's top
// bits gives the byte at the bottom of its bucket, and one comparison with the next byte's threshold (the
// smallest float that reaches it, found by bisection on the exact function) finishes it. A bucket spans a
// relative 2^-8 of the value, less than one byte step anywhere on the curve, so it holds at most one threshold.
class SrgbEncoder {
 public:
  SrgbEncoder() {
    threshold_[0] = 0;
    for (int b = 1; b < 256; ++b) {
      // Positive floats order like their bit patterns: bisect those for the first one that encodes to >= b.
      std::uint32_t lo = 0, hi = bits_of(1.0f);
      while (lo < hi) {
        const std::uint32_t mid = lo + (hi - lo) / 2;
        if (encode_srgb_exactly(float_of(mid)) >= b)
          hi = mid;
        else
          lo = mid + 1;
      }
      threshold_[b] = float_of(lo);
    }
    for (std::uint32_t bucket = 0; bucket < kBuckets; ++bucket)
      table_[bucket] = encode_srgb_exactly(float_of(bucket << kDroppedBits));
  }
  std::uint8_t operator()(float linear) const {
    if (!(linear > 0.0f)) return 0;
    if (linear >= 1.0f) return 255;
    const std::uint8_t b = table_[bits_of(linear) >> kDroppedBits];
    return b < 255 && linear >= threshold_[b + 1] ? static_cast<std::uint8_t>(b + 1) : b;
  }

 private:
  static constexpr int kDroppedBits = 15;                                       // of the 23 mantissa bits, 8 stay
  static constexpr std::uint32_t kBuckets = (0x3f800000u >> kDroppedBits) + 1;  // every float in [0, 1]
  static std::uint32_t bits_of(float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
  }
  static float float_of(std::uint32_t u) {
    float f;
    std::memcpy(&f, &u, sizeof f);
    return f;
  }
  float threshold_[256];
  std::uint8_t table_[kBuckets];
};

}  // namespace

namespace {

const SrgbEncoder& srgb_encoder() {
  static const SrgbEncoder encoder;
  return encoder;
}

}  // namespace

std::uint8_t srgb_byte(float linear) { return srgb_encoder()(linear); }

namespace {

std::uint8_t encode_alpha(float a) {
  if (!(a > 0.0f)) return 0;
  if (a >= 1.0f) return 255;
  return to_byte(a);
}

struct PngErrorState {
  char message[256] = "unknown libpng error";
};

void png_error_to_state(png_structp png, png_const_charp msg) {
  auto* state = static_cast<PngErrorState*>(png_get_error_ptr(png));
  std::snprintf(state->message, sizeof state->message, "%s", msg ? msg : "libpng error");
  png_longjmp(png, 1);
}

void png_ignore_warning(png_structp, png_const_charp) {}

// The file up to its image data: signature, header, colour space and text, through libpng. libpng reports
// errors by longjmp, which must not cross objects with destructors; so this function holds none and the caller
// owns every buffer. The image data and the end (png_deflate.h) follow without libpng, which deflates on one
// core only.
bool encode_png_head(std::FILE* fp, png_uint_32 width, png_uint_32 height, int color_type, png_textp text,
                     int text_count, PngErrorState* error) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, error, png_error_to_state, png_ignore_warning);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, fp);
  png_set_IHDR(png, info, width, height, 8, color_type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  // gAMA and cHRM alongside sRGB keep old decoders that ignore sRGB close to correct.
  png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  // Before the image data, so that a reader wanting only the text can stop early.
  png_set_text(png, info, text, text_count);
  png_write_info(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

// Opens `file` for writing, lets `write` fill it and closes it, treating a failed flush or close as a failed
// write: buffered data can still fail to reach the file there (e.g. disk full).
void write_with_stdio(const fs::path& file, const std::function<void(std::FILE*)>& write) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> fp(std::fopen(file.c_str(), "wb"), &std::fclose);
  if (!fp) throw WriteError("cannot create temporary file: " + errno_text(errno));
  write(fp.get());
  if (std::fflush(fp.get()) != 0) throw WriteError("write failed: " + errno_text(errno));
  if (std::fclose(fp.release()) != 0) throw WriteError("close failed: " + errno_text(errno));
}

// PNG keywords are Latin-1; keeping to printable ASCII spares every reader the question of encoding.
void check_png_key(const std::string& key) {
  const bool printable = std::all_of(key.begin(), key.end(), [](unsigned char c) { return c >= 32 && c <= 126; });
  if (key.empty() || key.size() > 79 || !printable || key.front() == ' ' || key.back() == ' ' ||
      key.find("  ") != std::string::npos)
    throw OutputError("PNG text key '" + key +
                      "' is not 1 to 79 printable ASCII characters without leading, trailing or double spaces");
}

bool is_ascii(const std::string& s) {
  return std::all_of(s.begin(), s.end(), [](unsigned char c) { return c < 128; });
}

bool is_utf8(const std::string& s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t extra = 0;
    std::uint32_t code = 0, min = 0;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xE0) == 0xC0) {
      extra = 1, code = c & 0x1Fu, min = 0x80;
    } else if ((c & 0xF0) == 0xE0) {
      extra = 2, code = c & 0x0Fu, min = 0x800;
    } else if ((c & 0xF8) == 0xF0) {
      extra = 3, code = c & 0x07u, min = 0x10000;
    } else {
      return false;
    }
    if (s.size() - i <= extra) return false;
    for (std::size_t k = 1; k <= extra; ++k) {
      const auto cc = static_cast<unsigned char>(s[i + k]);
      if ((cc & 0xC0) != 0x80) return false;
      code = (code << 6) | (cc & 0x3Fu);
    }
    // Overlong forms, surrogates and values past U+10FFFF are not UTF-8.
    if (code < min || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return false;
    i += extra + 1;
  }
  return true;
}

void check_png_value(const std::string& key, const std::string& value) {
  if (value.find('\0') != std::string::npos) throw OutputError("PNG text '" + key + "' contains a NUL byte");
  if (!is_utf8(value)) throw OutputError("PNG text '" + key + "' is not valid UTF-8");
  if (value.size() > kMaxPngTextBytes)
    throw OutputError("PNG text '" + key + "' is " + std::to_string(value.size()) + " bytes; at most " +
                      std::to_string(kMaxPngTextBytes) + " are written");
}

// Software, Comment and png_text in order, checked; throws OutputError before any file exists.
std::vector<std::pair<std::string, std::string>> png_text_entries(const FrameImage& image) {
  std::vector<std::pair<std::string, std::string>> entries;
  entries.emplace_back("Software", image.software.empty() ? version_string() : image.software);
  if (!image.comments.empty()) entries.emplace_back("Comment", image.comments);
  std::set<std::string> used = {"Software", "Comment"};
  for (const auto& [key, value] : image.png_text) {
    check_png_key(key);
    if (key == "Software" || key == "Comment")
      throw OutputError("PNG text '" + key + "' comes from FrameImage::" +
                        (key == "Software" ? "software" : "comments") + ", not from png_text");
    if (!used.insert(key).second) throw OutputError("PNG text key '" + key + "' is given twice");
    entries.emplace_back(key, value);
  }
  for (const auto& [key, value] : entries) check_png_value(key, value);
  return entries;
}

// Points into `entries`, which must outlive the result; png_set_text copies, never writes through them.
std::vector<png_text> png_text_chunks(const std::vector<std::pair<std::string, std::string>>& entries) {
  // Compressing a few hundred bytes gains nothing; a scene of a few KB shrinks to a third.
  constexpr std::size_t kCompressAbove = 1024;
  std::vector<png_text> chunks(entries.size());
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto& [key, value] = entries[i];
    png_text& t = chunks[i];
    t.key = const_cast<png_charp>(key.c_str());
    t.text = const_cast<png_charp>(value.c_str());
    t.text_length = value.size();
    t.lang = nullptr;
    t.lang_key = nullptr;
    if (is_ascii(value) && value.size() <= kCompressAbove)
      t.compression = PNG_TEXT_COMPRESSION_NONE;  // tEXt: ASCII is Latin-1 too
    else
      t.compression = value.size() > kCompressAbove ? PNG_ITXT_COMPRESSION_zTXt : PNG_ITXT_COMPRESSION_NONE;
  }
  return chunks;
}

// The PNG into an open stream: a file's, or memory's (png_bytes).
void encode_png_to(std::FILE* fp, const FrameImage& image) {
  const std::size_t n = checked_pixel_count(image);
  const std::vector<std::pair<std::string, std::string>> entries = png_text_entries(image);
  std::vector<png_text> text = png_text_chunks(entries);
  bool opaque = true;
  for (std::size_t i = 0; i < n && opaque; ++i) opaque = encode_alpha(image.rgba[4 * i + 3]) == 255;
  const std::size_t channels = opaque ? 3 : 4;

  // Rows are made 8-bit band by band, on the threads that deflate them, so that a poster needs no 8-bit copy
  // of the whole image.
  const auto fill = [&image, channels](std::size_t y0, std::size_t count, unsigned char* out) {
    const std::size_t width = static_cast<std::size_t>(image.width);
    const float* rgba = image.rgba.data() + 4 * y0 * width;
    // The encoder itself, inlined here, rather than srgb_byte's call and its static's guard per value.
    const SrgbEncoder& srgb = srgb_encoder();
    for (std::size_t i = 0; i < count * width; ++i) {
      for (std::size_t c = 0; c < 3; ++c) out[i * channels + c] = srgb(rgba[4 * i + c]);
      if (channels == 4) out[i * 4 + 3] = encode_alpha(rgba[4 * i + 3]);
    }
  };
  const std::size_t row_bytes = static_cast<std::size_t>(image.width) * channels;

  {
    PngErrorState error;
    if (!encode_png_head(fp, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height),
                         opaque ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGB_ALPHA, text.data(),
                         static_cast<int>(text.size()), &error)) {
      throw WriteError(std::string("libpng: ") + error.message);
    }
    // zlib level 1 with the Up filter: measured on a 1024^2 render, 10 ms of CPU against 51 ms for libpng's
    // default (level 6, every filter tried per row), for a file 32% larger (250 KB against 190 KB).
    try {
      write_png_image_data(fp, static_cast<std::size_t>(image.height), row_bytes, fill, 1);
    } catch (const WriteError&) {
      // The message a failed PNG write has always had (libpng's, from when libpng wrote the image data too).
      throw WriteError("libpng: Write Error");
    }
  }
}

void encode_png(const fs::path& file, const FrameImage& image) {
  write_with_stdio(file, [&](std::FILE* fp) { encode_png_to(fp, image); });
}

void encode_text(const fs::path& file, const std::string& text) {
  write_with_stdio(file, [&](std::FILE* fp) {
    if (std::fwrite(text.data(), 1, text.size(), fp) != text.size())
      throw WriteError("write failed: " + errno_text(errno));
  });
}

// PNG reading: two steps, each a function holding nothing with a destructor, because libpng errors arrive by
// longjmp; the caller owns the structs, the file and the row buffer.

constexpr png_byte kPngSignature[8] = {137, 80, 78, 71, 13, 10, 26, 10};

// libpng's own reader says only "Read Error" for a file that ends early.
void png_read_from_file(png_structp png, png_bytep data, std::size_t length) {
  auto* fp = static_cast<std::FILE*>(png_get_io_ptr(png));
  if (std::fread(data, 1, length, fp) == length) return;
  png_error(png, std::feof(fp) ? "the file ends early (truncated)" : "read failed");
}

bool png_read_head(png_structp png, png_infop info, std::FILE* fp, int* passes) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_read_fn(png, fp, png_read_from_file);
  png_set_sig_bytes(png, sizeof kPngSignature);
  // A damaged text chunk is an error rather than silently dropped: it may be the scene the caller wants.
  png_set_benign_errors(png, 0);
  png_set_crc_action(png, PNG_CRC_ERROR_QUIT, PNG_CRC_ERROR_QUIT);
  png_set_chunk_malloc_max(png, kMaxPngTextBytes + 4096);  // the key and chunk header besides the text
  // Every ancillary chunk but the text is skipped unread, so that an odd colour profile cannot fail the read.
  png_set_keep_unknown_chunks(png, PNG_HANDLE_CHUNK_NEVER, nullptr, -1);
  static constexpr png_byte text_chunks[] = "tEXt\0zTXt\0iTXt";
  png_set_keep_unknown_chunks(png, PNG_HANDLE_CHUNK_AS_DEFAULT, text_chunks, 3);
  png_read_info(png, info);
  *passes = png_set_interlace_handling(png);
  png_read_update_info(png, info);
  return true;
}

// Decodes the rows one at a time into `row` (the text after the image data comes only after them), then
// reads to IEND.
bool png_read_rest(png_structp png, png_infop info, png_bytep row, int passes) {
  if (setjmp(png_jmpbuf(png))) return false;
  const png_uint_32 height = png_get_image_height(png, info);
  for (int pass = 0; pass < passes; ++pass)
    for (png_uint_32 y = 0; y < height; ++y) png_read_row(png, row, nullptr);
  png_read_end(png, info);
  return true;
}

std::string latin1_to_utf8(const char* text) {
  std::string out;
  for (const char* p = text; *p; ++p) {
    const auto c = static_cast<unsigned char>(*p);
    if (c < 0x80) {
      out += static_cast<char>(c);
    } else {
      out += static_cast<char>(0xC0 | (c >> 6));
      out += static_cast<char>(0x80 | (c & 0x3F));
    }
  }
  return out;
}

}  // namespace

ImageFormat format_from_extension(const fs::path& p) {
  const std::string ext = lowercase_extension(p);
  if (ext == ".exr") return ImageFormat::Exr;
  if (ext == ".png") return ImageFormat::Png;
  throw OutputError("unsupported output extension '" + p.extension().string() + "' in '" + p.string() +
                    "'; use .exr or .png");
}

void check_output_path(const fs::path& path) {
  const std::string where = cannot_write(path);
  if (!path.has_filename()) throw OutputError(where + "the path names no file");
  // The directory as the user wrote it reads better in a message than its absolute form.
  const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  std::error_code ec;
  const fs::file_status dir_status = fs::status(dir, ec);
  if (dir_status.type() == fs::file_type::not_found)
    throw OutputError(where + "directory '" + dir.string() + "' does not exist");
  if (ec) throw OutputError(where + "cannot examine directory '" + dir.string() + "': " + ec.message());
  if (!fs::is_directory(dir_status)) throw OutputError(where + "'" + dir.string() + "' is not a directory");
  // Also catches a read-only file system (EROFS), even for root.
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    throw OutputError(where + "directory '" + dir.string() + "' is not writable: " + errno_text(errno));
  if (fs::is_directory(fs::status(path, ec))) throw OutputError(where + "it is a directory");

  const std::size_t name_length = path.filename().native().size();
  const long name_max = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  if (name_max > 0 && name_length > static_cast<std::size_t>(name_max))
    throw OutputError(where + "the file name is " + std::to_string(name_length) + " bytes long; the file system of '" +
                      dir.string() + "' allows at most " + std::to_string(name_max));
  const fs::path absolute = fs::absolute(path, ec);
  if (ec) throw OutputError(where + "cannot resolve the path: " + ec.message());
  if (absolute.native().size() >= PATH_MAX)
    throw OutputError(where + "the path is " + std::to_string(absolute.native().size()) +
                      " bytes long; the system allows at most " + std::to_string(PATH_MAX - 1));
}

void write_image(const fs::path& path, const FrameImage& image) {
  switch (format_from_extension(path)) {
    case ImageFormat::Exr:
      return write_exr(path, image);
    case ImageFormat::Png:
      return write_png(path, image);
  }
}

void write_exr(const fs::path& path, const FrameImage& image) {
  write_atomically(path, [&](const fs::path& temp) { encode_exr(temp, image); });
}

void write_png(const fs::path& path, const FrameImage& image) {
  write_atomically(path, [&](const fs::path& temp) { encode_png(temp, image); });
}

std::string png_bytes(const FrameImage& image) {
  // open_memstream: the same stdio stream the file path writes through, so the bytes are the file's.
  char* data = nullptr;
  std::size_t size = 0;
  std::FILE* fp = ::open_memstream(&data, &size);
  if (!fp) throw WriteError("cannot open a memory stream for the PNG: " + errno_text(errno));
  try {
    encode_png_to(fp, image);
  } catch (...) {
    std::fclose(fp);
    std::free(data);
    throw;
  }
  const bool flushed = std::fclose(fp) == 0;
  std::string bytes = flushed ? std::string(data, size) : std::string();
  std::free(data);
  if (!flushed) throw WriteError("write failed: " + errno_text(errno));
  return bytes;
}

struct PendingOutput::State {
  fs::path destination;
  TempFile temp;
  explicit State(const fs::path& d) : destination(d), temp(d) {}
};

PendingOutput::PendingOutput(const fs::path& destination) {
  check_output_path(destination);
  const fs::path absolute = fs::absolute(destination);
  remove_stale_temps(absolute.parent_path(), temp_prefix(absolute));
  state_ = std::make_unique<State>(absolute);
}

PendingOutput::~PendingOutput() = default;

const fs::path& PendingOutput::temp_path() const { return state_->temp.path(); }

void PendingOutput::commit() {
  try {
    sync_file(state_->temp.path());
    state_->temp.commit(state_->destination);
    sync_directory(state_->destination.parent_path());
  } catch (const std::exception& e) {
    throw WriteError(cannot_write(state_->destination) + e.what());
  }
}

void write_text_file(const fs::path& path, const std::string& text) {
  write_atomically(path, [&](const fs::path& temp) { encode_text(temp, text); });
}

void install_output_cleanup_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    const int signals[] = {SIGINT, SIGTERM, SIGHUP};
    struct sigaction action {};
    action.sa_handler = cleanup_then_reraise;
    sigemptyset(&action.sa_mask);
    for (int sig : signals) sigaddset(&action.sa_mask, sig);
    // The handler re-raises its own signal and needs it delivered at once, not after returning.
    action.sa_flags = SA_NODEFER;
    for (int sig : signals) {
      struct sigaction previous {};
      if (::sigaction(sig, nullptr, &previous) == 0 && previous.sa_handler == SIG_IGN) continue;
      ::sigaction(sig, &action, nullptr);
    }
  });
}

FrameImage read_exr(const fs::path& path) {
  try {
    Imf::InputFile in(path.c_str());
    const Imf::Header& header = in.header();
    const Imath::Box2i window = header.dataWindow();
    FrameImage image;
    image.width = window.max.x - window.min.x + 1;
    image.height = window.max.y - window.min.y + 1;
    const std::size_t n = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
    const ExrLayers layers = sort_exr_channels(header.channels(), n, image);
    in.setFrameBuffer(exr_read_slices(window, layers, n, image));
    in.readPixels(window.min.y, window.max.y);
    read_exr_attributes(header, image);
    return image;
  } catch (const std::exception& e) {
    throw OutputError("cannot read '" + path.string() + "': " + e.what());
  }
}

FrameImage read_png_pixels(const fs::path& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str()))
    throw OutputError("cannot read '" + path.string() + "': " + png.message);
  png.format = PNG_FORMAT_RGBA;
  std::vector<png_byte> bytes(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, bytes.data(), 0, nullptr))
    throw OutputError("cannot read '" + path.string() + "': " + png.message);
  FrameImage image;
  image.width = static_cast<int>(png.width);
  image.height = static_cast<int>(png.height);
  image.rgba.resize(bytes.size());
  float linear[256];
  for (int v = 0; v < 256; ++v) linear[v] = static_cast<float>(srgb_to_linear(v / 255.0));
  for (std::size_t i = 0; i < bytes.size(); ++i)
    image.rgba[i] = i % 4 == 3 ? static_cast<float>(bytes[i]) / 255.0f : linear[bytes[i]];
  return image;
}

bool is_png_file(const fs::path& path) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> fp(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!fp) return false;
  png_byte head[sizeof kPngSignature];
  return std::fread(head, 1, sizeof head, fp.get()) == sizeof head &&
         std::memcmp(head, kPngSignature, sizeof head) == 0;
}

std::vector<std::pair<std::string, std::string>> read_png_text(const fs::path& path) {
  const std::string where = "cannot read '" + path.string() + "'";
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> fp(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!fp) throw OutputError(where + ": " + errno_text(errno));
  png_byte head[sizeof kPngSignature];
  if (std::fread(head, 1, sizeof head, fp.get()) != sizeof head || std::memcmp(head, kPngSignature, sizeof head) != 0)
    throw OutputError(where + ": not a PNG file (no PNG signature)");

  struct Reader {
    png_structp png = nullptr;
    png_infop info = nullptr;
    ~Reader() { png_destroy_read_struct(&png, info ? &info : nullptr, nullptr); }
  } reader;
  PngErrorState error;
  reader.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &error, png_error_to_state, png_ignore_warning);
  if (reader.png) reader.info = png_create_info_struct(reader.png);
  if (!reader.png || !reader.info) throw OutputError(where + ": out of memory for libpng");

  int passes = 1;
  if (!png_read_head(reader.png, reader.info, fp.get(), &passes))
    throw OutputError(where + " as PNG: " + error.message);
  std::vector<png_byte> row(png_get_rowbytes(reader.png, reader.info));
  if (!png_read_rest(reader.png, reader.info, row.data(), passes))
    throw OutputError(where + " as PNG: " + error.message);

  png_textp text = nullptr;
  const int count = png_get_text(reader.png, reader.info, &text, nullptr);
  std::vector<std::pair<std::string, std::string>> out;
  for (int i = 0; i < count; ++i) {
    const png_text& t = text[i];
    const bool utf8 = t.compression == PNG_ITXT_COMPRESSION_NONE || t.compression == PNG_ITXT_COMPRESSION_zTXt;
    std::string value = t.text ? (utf8 ? std::string(t.text) : latin1_to_utf8(t.text)) : std::string();
    if (value.size() > kMaxPngTextBytes)
      throw OutputError(where + ": PNG text '" + std::string(t.key) + "' is longer than " +
                        std::to_string(kMaxPngTextBytes) + " bytes");
    out.emplace_back(latin1_to_utf8(t.key), std::move(value));
  }
  return out;
}

std::vector<std::uint8_t> srgba_bytes(const FrameImage& image) {
  const std::size_t n = checked_pixel_count(image);
  std::vector<std::uint8_t> out(4 * n);
  const SrgbEncoder& srgb = srgb_encoder();
  for (std::size_t i = 0; i < 4 * n; i += 4) {
    for (std::size_t c = 0; c < 3; ++c) out[i + c] = srgb(image.rgba[i + c]);
    out[i + 3] = encode_alpha(image.rgba[i + 3]);
  }
  return out;
}

}  // namespace algray
