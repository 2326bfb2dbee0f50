// EXR, PNG and text output through temp-file-and-rename, signal-time cleanup of temp files, and EXR read-back.
#include "image_io.h"

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
#include <png.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <system_error>
#include <thread>

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
std::atomic<unsigned long> g_temp_counter{0};

extern "C" void cleanup_then_reraise(int sig) {
  for (TempSlot& slot : g_slots) {
    if (slot.state.load(std::memory_order_acquire) == kActive) ::unlink(slot.path);
  }
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

std::string errno_text(int err) { return std::error_code(err, std::generic_category()).message(); }

// Owns one temporary file for its lifetime: registered for signal cleanup before the file can
// exist, removed on destruction unless it was committed by renaming.
class TempFile {
 public:
  explicit TempFile(const fs::path& destination) {
    std::string stem = destination.filename().string();
    // Stay under NAME_MAX even for long destination names; uniqueness comes from pid and counter.
    if (stem.size() > 200) stem.resize(200);
    path_ = destination.parent_path() /
            ("." + stem + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(++g_temp_counter));
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
    if (::rename(path_.c_str(), destination.c_str()) != 0) throw OutputError("rename failed: " + errno_text(errno));
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
  if (fd < 0) throw OutputError("cannot reopen temporary file for fsync: " + errno_text(errno));
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) throw OutputError("fsync failed: " + errno_text(err));
}

// Best effort: makes the rename itself durable; failure here does not make the image wrong.
void sync_directory(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

void write_atomically(const fs::path& path, const std::function<void(const fs::path&)>& write_to) {
  const std::string where = "cannot write '" + path.string() + "': ";
  try {
    std::error_code ec;
    const fs::path destination = fs::absolute(path, ec);
    if (ec) throw OutputError("cannot resolve path: " + ec.message());
    if (!destination.has_filename()) throw OutputError("path names no file");
    const fs::path dir = destination.parent_path();
    const fs::file_status dir_status = fs::status(dir, ec);
    if (!fs::exists(dir_status)) throw OutputError("directory '" + dir.string() + "' does not exist");
    if (!fs::is_directory(dir_status)) throw OutputError("'" + dir.string() + "' is not a directory");
    if (fs::is_directory(fs::status(destination, ec))) throw OutputError("destination is a directory");

    TempFile temp(destination);
    write_to(temp.path());
    sync_file(temp.path());
    temp.commit(destination);
    sync_directory(dir);
  } catch (const std::exception& e) {
    throw OutputError(where + e.what());
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

void encode_exr(const fs::path& file, const FrameImage& image) {
  const std::size_t n = checked_pixel_count(image);
  if (!image.depth.empty()) check_layer_size("depth", image.depth.size(), n);
  if (!image.normal.empty()) check_layer_size("normal", image.normal.size(), 3 * n);

  Imf::Header header(image.width, image.height);  // display window == data window, origin 0,0
  header.compression() = Imf::ZIP_COMPRESSION;
  // Level 1: measured at 1024x768, the file grows by 6% while the write takes half the time of level 6.
  header.zipCompressionLevel() = 1;
  header.lineOrder() = Imf::INCREASING_Y;

  const auto w = static_cast<std::int64_t>(image.width);
  const auto h = static_cast<std::int64_t>(image.height);
  const Imath::V2i origin(0, 0);
  Imf::ChannelList& channels = header.channels();
  Imf::FrameBuffer frame;
  auto add = [&](const std::string& name, Imf::PixelType type, const void* base, std::size_t x_stride) {
    if (name.empty()) throw OutputError("channel with an empty name");
    if (channels.findChannel(name)) throw OutputError("duplicate channel name '" + name + "'");
    channels.insert(name, Imf::Channel(type));
    frame.insert(name, Imf::Slice::Make(type, base, origin, w, h, x_stride));
  };

  // Converted here rather than by OpenEXR so the rounding is the one Imath::half documents.
  std::vector<Imath::half> rgba_half(image.rgba.begin(), image.rgba.end());
  const char* rgba_names[4] = {"R", "G", "B", "A"};
  for (std::size_t c = 0; c < 4; ++c) add(rgba_names[c], Imf::HALF, rgba_half.data() + c, 4 * sizeof(Imath::half));
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

  if (image.world_to_camera) Imf::addWorldToCamera(header, to_m44(*image.world_to_camera));
  if (image.world_to_ndc) Imf::addWorldToNDC(header, to_m44(*image.world_to_ndc));
  // A clash would silently overwrite (same type) or throw deep inside OpenEXR (other type); refuse early.
  auto check_attribute_name = [&](const std::string& name) {
    if (name.empty()) throw OutputError("attribute with an empty name");
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

  // Compression dominates the write; blocks of lines compress in parallel on OpenEXR's threads.
  const int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  static std::once_flag pool_started;
  std::call_once(pool_started, [threads] { Imf::setGlobalThreadCount(threads); });
  Imf::OutputFile out(file.c_str(), header, threads);
  out.setFrameBuffer(frame);
  out.writePixels(image.height);
}

// ---------------------------------------------------------------------------------------------
// PNG

std::uint8_t to_byte(double v) { return static_cast<std::uint8_t>(std::lround(v * 255.0)); }

std::uint8_t encode_srgb(float linear) {
  if (!(linear > 0.0f)) return 0;  // also maps NaN to black
  if (linear >= 1.0f) return 255;
  const double l = linear;
  return to_byte(l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055);
}

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

// libpng reports errors by longjmp, which must not cross objects with destructors; so this function
// holds none and the caller owns every buffer.
bool encode_png_stream(std::FILE* fp, png_uint_32 width, png_uint_32 height, int color_type, png_bytepp rows,
                       PngErrorState* error) {
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
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

// Opens `file` for writing, lets `write` fill it and closes it, treating a failed flush or close as a failed
// write: buffered data can still fail to reach the file there (e.g. disk full).
void write_with_stdio(const fs::path& file, const std::function<void(std::FILE*)>& write) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> fp(std::fopen(file.c_str(), "wb"), &std::fclose);
  if (!fp) throw OutputError("cannot create temporary file: " + errno_text(errno));
  write(fp.get());
  if (std::fflush(fp.get()) != 0) throw OutputError("write failed: " + errno_text(errno));
  if (std::fclose(fp.release()) != 0) throw OutputError("close failed: " + errno_text(errno));
}

void encode_png(const fs::path& file, const FrameImage& image) {
  const std::size_t n = checked_pixel_count(image);
  bool opaque = true;
  for (std::size_t i = 0; i < n && opaque; ++i) opaque = encode_alpha(image.rgba[4 * i + 3]) == 255;
  const std::size_t channels = opaque ? 3 : 4;

  std::vector<png_byte> bytes(n * channels);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t c = 0; c < 3; ++c) bytes[i * channels + c] = encode_srgb(image.rgba[4 * i + c]);
    if (!opaque) bytes[i * channels + 3] = encode_alpha(image.rgba[4 * i + 3]);
  }
  const auto width = static_cast<std::size_t>(image.width);
  std::vector<png_bytep> rows(static_cast<std::size_t>(image.height));
  for (std::size_t y = 0; y < rows.size(); ++y) rows[y] = bytes.data() + y * width * channels;

  write_with_stdio(file, [&](std::FILE* fp) {
    PngErrorState error;
    if (!encode_png_stream(fp, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height),
                           opaque ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGB_ALPHA, rows.data(), &error)) {
      throw OutputError(std::string("libpng: ") + error.message);
    }
  });
}

void encode_text(const fs::path& file, const std::string& text) {
  write_with_stdio(file, [&](std::FILE* fp) {
    if (std::fwrite(text.data(), 1, text.size(), fp) != text.size())
      throw OutputError("write failed: " + errno_text(errno));
  });
}

}  // namespace

std::string lowercase_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext;
}

double srgb_to_linear(double c) {
  c = std::clamp(c, 0.0, 1.0);
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

ImageFormat format_from_extension(const fs::path& p) {
  const std::string ext = lowercase_extension(p);
  if (ext == ".exr") return ImageFormat::Exr;
  if (ext == ".png") return ImageFormat::Png;
  throw OutputError("unsupported output extension '" + p.extension().string() + "' in '" + p.string() +
                    "'; use .exr or .png");
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

    const Imf::ChannelList& channels = header.channels();
    const std::set<std::string> rgba_names = {"R", "G", "B", "A"};
    const std::set<std::string> normal_names = {"N.X", "N.Y", "N.Z"};
    bool has_rgba = false, has_depth = false, has_normal = false;
    for (auto it = channels.begin(); it != channels.end(); ++it) {
      const std::string name = it.name();
      if (it.channel().xSampling != 1 || it.channel().ySampling != 1) {
        throw OutputError("channel '" + name + "' is subsampled, which algray does not use");
      }
      if (rgba_names.count(name))
        has_rgba = true;
      else if (name == "Z")
        has_depth = true;
      else if (normal_names.count(name))
        has_normal = true;
      else if (it.channel().type == Imf::UINT)
        image.uint_channels.push_back({name, std::vector<std::uint32_t>(n)});
      else
        image.float_channels.push_back({name, std::vector<float>(n)});
    }

    // Slices are attached only after every vector has its final size, so no pointer is invalidated.
    Imf::FrameBuffer frame;
    auto add = [&](const std::string& name, Imf::PixelType type, void* base, std::size_t x_stride, double fill) {
      frame.insert(name, Imf::Slice::Make(type, base, window, x_stride, 0, 1, 1, fill));
    };
    if (has_rgba) {
      image.rgba.resize(4 * n);
      add("R", Imf::FLOAT, image.rgba.data() + 0, 4 * sizeof(float), 0.0);
      add("G", Imf::FLOAT, image.rgba.data() + 1, 4 * sizeof(float), 0.0);
      add("B", Imf::FLOAT, image.rgba.data() + 2, 4 * sizeof(float), 0.0);
      add("A", Imf::FLOAT, image.rgba.data() + 3, 4 * sizeof(float), 1.0);
    }
    if (has_depth) {
      image.depth.resize(n);
      add("Z", Imf::FLOAT, image.depth.data(), sizeof(float), std::numeric_limits<double>::infinity());
    }
    if (has_normal) {
      image.normal.resize(3 * n);
      add("N.X", Imf::FLOAT, image.normal.data() + 0, 3 * sizeof(float), 0.0);
      add("N.Y", Imf::FLOAT, image.normal.data() + 1, 3 * sizeof(float), 0.0);
      add("N.Z", Imf::FLOAT, image.normal.data() + 2, 3 * sizeof(float), 0.0);
    }
    for (auto& ch : image.uint_channels) add(ch.name, Imf::UINT, ch.values.data(), sizeof(std::uint32_t), 0.0);
    for (auto& ch : image.float_channels) add(ch.name, Imf::FLOAT, ch.values.data(), sizeof(float), 0.0);
    in.setFrameBuffer(frame);
    in.readPixels(window.min.y, window.max.y);

    for (auto it = header.begin(); it != header.end(); ++it) {
      if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) {
        image.string_attributes.emplace_back(it.name(), s->value());
      } else if (const auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&it.attribute())) {
        image.double_attributes.emplace_back(it.name(), d->value());
      }
    }
    if (Imf::hasWorldToCamera(header)) image.world_to_camera = from_m44(Imf::worldToCamera(header));
    if (Imf::hasWorldToNDC(header)) image.world_to_ndc = from_m44(Imf::worldToNDC(header));
    return image;
  } catch (const std::exception& e) {
    throw OutputError("cannot read '" + path.string() + "': " + e.what());
  }
}

}  // namespace algray
