// Tests for EXR/PNG output: round trips, header and text metadata, sRGB encoding, atomic replacement, the kinds
// of failure, and cleanup after signals and of stale temporaries.
#include "algray/io/image_io.h"
#include "algray/io/png_deflate.h"
#include "algray/util/version.h"
#include "noisy_image.h"
#include "temp_dir.h"
#include "test_seed.h"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#include <ImfChannelList.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <half.h>
#pragma GCC diagnostic pop
#include <png.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

namespace fs = std::filesystem;
using algray::FrameImage;
using algray::OutputError;
using algray::WriteError;

namespace {

using algray::testing::TempDir;

std::vector<std::string> list_dir(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

bool has_temp_file(const fs::path& dir) {
  for (const auto& name : list_dir(dir))
    if (name.find(".tmp-") != std::string::npos) return true;
  return false;
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_bytes(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary);
  out << bytes;
}

// Every pixel distinct in every layer, so a transposed or shifted read cannot pass.
FrameImage make_image(int width, int height) {
  FrameImage im;
  im.width = width;
  im.height = height;
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  im.rgba.resize(4 * n);
  im.depth.resize(n);
  im.normal.resize(3 * n);
  FrameImage::UintChannel steps{"solver.isolationSteps", std::vector<std::uint32_t>(n)};
  FrameImage::FloatChannel residual{"solver.residual", std::vector<float>(n)};
  for (std::size_t i = 0; i < n; ++i) {
    const float f = static_cast<float>(i);
    im.rgba[4 * i + 0] = 0.01f * f;
    im.rgba[4 * i + 1] = 1.5f - 0.02f * f;
    im.rgba[4 * i + 2] = 0.001f * f * f;
    im.rgba[4 * i + 3] = (i % 3 == 0) ? 0.25f : 1.0f;
    const bool miss = (i % 4 == 1);
    im.depth[i] = miss ? std::numeric_limits<float>::infinity() : 1.0f + 0.123456789f * f;
    const float a = 0.37f * f, b = 0.11f * f;
    im.normal[3 * i + 0] = miss ? 0.0f : std::cos(a) * std::sin(b);
    im.normal[3 * i + 1] = miss ? 0.0f : std::sin(a) * std::sin(b);
    im.normal[3 * i + 2] = miss ? 0.0f : std::cos(b);
    steps.values[i] = (i == 0) ? 0xFFFFFFFFu : static_cast<std::uint32_t>(i * 7919u + 3u);
    residual.values[i] = 1e-30f * (f + 1.0f);
  }
  im.uint_channels.push_back(std::move(steps));
  im.float_channels.push_back(std::move(residual));
  return im;
}

FrameImage solid_image(int width, int height, float r, float g, float b, float a) {
  FrameImage im;
  im.width = width;
  im.height = height;
  for (int i = 0; i < width * height; ++i) im.rgba.insert(im.rgba.end(), {r, g, b, a});
  return im;
}

template <class T>
const T* find_attr(const std::vector<std::pair<std::string, T>>& attrs, const std::string& name) {
  for (const auto& [k, v] : attrs)
    if (k == name) return &v;
  return nullptr;
}

struct PngData {
  png_uint_32 width = 0, height = 0;
  int bit_depth = 0, color_type = 0, channels = 0;
  bool has_srgb = false;
  std::vector<png_byte> bytes;
};

void fail_png(png_structp png, png_const_charp) { png_longjmp(png, 1); }

// Everything with a destructor is declared before setjmp, because libpng errors arrive by longjmp.
bool read_png(const fs::path& p, PngData& out) {
  std::vector<png_bytep> rows;
  std::FILE* fp = std::fopen(p.c_str(), "rb");
  if (!fp) return false;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, fail_png, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    std::fclose(fp);
    return false;
  }
  png_init_io(png, fp);
  png_read_info(png, info);
  out.width = png_get_image_width(png, info);
  out.height = png_get_image_height(png, info);
  out.bit_depth = png_get_bit_depth(png, info);
  out.color_type = png_get_color_type(png, info);
  out.channels = png_get_channels(png, info);
  out.has_srgb = png_get_valid(png, info, PNG_INFO_sRGB) != 0;
  const std::size_t stride = png_get_rowbytes(png, info);
  out.bytes.resize(stride * out.height);
  rows.resize(out.height);
  for (std::size_t y = 0; y < rows.size(); ++y) rows[y] = out.bytes.data() + y * stride;
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  std::fclose(fp);
  return true;
}

using algray::testing::noisy_image;
using algray::testing::unit_float;

// Runs image_writer_tool with these arguments in a child process and returns its pid (-1 if fork failed).
// The child execs at once instead of writing itself: this process may already run OpenEXR's global thread
// pool, whose threads would be missing in a forked child and deadlock its EXR write.
pid_t spawn_writer(std::vector<std::string> args) {
  args.insert(args.begin(), ALGRAY_IMAGE_WRITER_TOOL);
  std::vector<char*> argv;  // built before fork: the child may only make async-signal-safe calls
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t child = ::fork();
  if (child == 0) {
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  return child;
}

// Polls for the child's exit for at most `timeout`; returns its wait status, or nothing if it did not
// exit in time (or cannot be waited for).
std::optional<int> poll_child(pid_t child, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    int status = 0;
    const pid_t r = ::waitpid(child, &status, WNOHANG);
    if (r == child) return status;
    if (r < 0 && errno != EINTR) return std::nullopt;
    if (std::chrono::steady_clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

// SIGKILLs a child that overran its time and reaps it, still without waiting forever.
void kill_child(pid_t child) {
  ::kill(child, SIGKILL);
  (void)poll_child(child, std::chrono::seconds(5));
}

// Waits for the child, but never forever: a writer that hangs (e.g. deadlocked) is killed after 20 s.
std::optional<int> wait_child(pid_t child) {
  const std::optional<int> status = poll_child(child, std::chrono::seconds(20));
  if (!status) kill_child(child);
  return status;
}

// PNG chunk surgery for the reader tests: a file as its chunks, and back with correct CRCs.
struct PngChunk {
  std::string type, data;
};

std::uint32_t png_crc(const std::string& bytes) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (unsigned char b : bytes) {
    crc ^= b;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

std::string be32(std::uint32_t v) {
  return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8), static_cast<char>(v)};
}

std::vector<PngChunk> split_png(const std::string& file) {
  std::vector<PngChunk> chunks;
  std::size_t at = 8;
  while (at + 12 <= file.size()) {
    const auto byte = [&](std::size_t i) { return static_cast<std::uint32_t>(static_cast<unsigned char>(file[i])); };
    const std::uint32_t length = byte(at) << 24 | byte(at + 1) << 16 | byte(at + 2) << 8 | byte(at + 3);
    chunks.push_back({file.substr(at + 4, 4), file.substr(at + 8, length)});
    at += 12 + length;
  }
  return chunks;
}

std::string join_png(const std::vector<PngChunk>& chunks) {
  std::string file = "\x89PNG\r\n\x1a\n";
  for (const PngChunk& c : chunks) {
    file += be32(static_cast<std::uint32_t>(c.data.size())) + c.type + c.data;
    file += be32(png_crc(c.type + c.data));
  }
  return file;
}

// `chunk` inserted just before IEND, i.e. after the image data.
std::string with_chunk_at_end(const std::string& png, const PngChunk& chunk) {
  std::vector<PngChunk> chunks = split_png(png);
  REQUIRE(!chunks.empty());
  REQUIRE(chunks.back().type == "IEND");
  chunks.insert(chunks.end() - 1, chunk);
  return join_png(chunks);
}

// A scene as it will be embedded: several KB, with quotes, backslashes, blank lines, tabs and UTF-8.
std::string multi_kb_scene() {
  std::string text =
      "# Gr\xC3\xBC\xC3\x9F"
      "e aus K\xC3\xB6ln \xE2\x80\x94 \xCF\x80 \xE2\x89\x88 3.14159, \xF0\x9F\x8C\x80\n"
      "[surface]\nname = \"Barth \\\"sextic\\\"\"\nequation = '4*(t^2*x^2-y^2)*(t^2*y^2-z^2)'\n\n\t\n";
  for (int i = 0; text.size() < 6000; ++i)
    text += "[[light]]\nposition = [" + std::to_string(i) + ", -2.5, 1e3]\nintensity = 0." + std::to_string(i % 10) +
            "\ncomment = \"line " + std::to_string(i) + " \\u00e9\\n\"\n";
  return text;
}

// Runs `write` and says how it failed, so that the checks can come after whatever had to be undone first.
enum class Outcome { Wrote, OutputErr, WriteErr, OtherErr };
Outcome outcome_of(const std::function<void()>& write, std::string& message) {
  try {
    write();
    return Outcome::Wrote;
  } catch (const OutputError& e) {
    message = e.what();
    return Outcome::OutputErr;
  } catch (const WriteError& e) {
    message = e.what();
    return Outcome::WriteErr;
  } catch (const std::exception& e) {
    message = e.what();
    return Outcome::OtherErr;
  }
}

// Lowers this process's soft file-size limit while it lives, with SIGXFSZ ignored so that a write past the
// limit fails with EFBIG instead of killing the process. Only files are limited: Catch's pipes are not.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    REQUIRE(::getrlimit(RLIMIT_FSIZE, &saved_) == 0);
    saved_handler_ = ::signal(SIGXFSZ, SIG_IGN);
    struct rlimit lowered = saved_;
    lowered.rlim_cur = bytes;  // the hard limit stays, so the old soft limit can be restored
    REQUIRE(::setrlimit(RLIMIT_FSIZE, &lowered) == 0);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &saved_);
    ::signal(SIGXFSZ, saved_handler_);
  }

 private:
  struct rlimit saved_ {};
  void (*saved_handler_)(int) = SIG_DFL;
};

// A child that only sleeps until killed: a pid that is certainly alive. Killed and reaped on destruction.
class SleepingChild {
 public:
  SleepingChild() : pid_(::fork()) {
    if (pid_ == 0) {
      for (;;) ::pause();
    }
    REQUIRE(pid_ > 0);
  }
  SleepingChild(const SleepingChild&) = delete;
  SleepingChild& operator=(const SleepingChild&) = delete;
  ~SleepingChild() {
    ::kill(pid_, SIGKILL);
    int status = 0;
    ::waitpid(pid_, &status, 0);
  }
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_;
};

// The pid of a child that has exited and been reaped: no process has it, until the system hands it out again.
pid_t dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  REQUIRE(child > 0);
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  return child;
}

// Makes a file as a writer's temporary would be, last modified `age` ago.
void make_temp_like(const fs::path& p, std::chrono::seconds age) {
  write_bytes(p, "partial image data");
  fs::last_write_time(p, fs::file_time_type::clock::now() - age);
}
}  // namespace

TEST_CASE("format_from_extension accepts exr and png in any case", "[image_io]") {
  CHECK(algray::format_from_extension("a/b.exr") == algray::ImageFormat::Exr);
  CHECK(algray::format_from_extension("B.EXR") == algray::ImageFormat::Exr);
  CHECK(algray::format_from_extension("x.png") == algray::ImageFormat::Png);
  CHECK(algray::format_from_extension("x.PNG") == algray::ImageFormat::Png);
  CHECK_THROWS_AS(algray::format_from_extension("x.tiff"), OutputError);
  CHECK_THROWS_WITH(algray::format_from_extension("noext"), Catch::Contains("use .exr or .png"));
}

TEST_CASE("EXR round trip keeps every channel, attribute and matrix", "[image_io][exr]") {
  TempDir dir;
  FrameImage im = make_image(7, 5);
  im.string_attributes = {{"algray/equation", "x^4 - 5*x^2*y + z^3 = 1"}, {"algray/scene", "torus.toml"}};
  im.double_attributes = {{"algray/tolerance", 1e-9}, {"algray/seconds", 12.625}};
  std::array<float, 16> w2c{}, w2ndc{};
  for (std::size_t i = 0; i < 16; ++i) {
    w2c[i] = 0.5f + static_cast<float>(i);
    w2ndc[i] = -2.25f * static_cast<float>(i) + 0.1f;
  }
  im.world_to_camera = w2c;
  im.world_to_ndc = w2ndc;
  const fs::path out = dir / "frame.exr";
  algray::write_image(out, im);
  CHECK(list_dir(dir.path()) == std::vector<std::string>{"frame.exr"});

  const FrameImage back = algray::read_exr(out);
  REQUIRE(back.width == 7);
  REQUIRE(back.height == 5);
  REQUIRE(back.rgba.size() == im.rgba.size());
  for (std::size_t i = 0; i < im.rgba.size(); ++i) {
    INFO("rgba index " << i);
    // Stored as half: the read-back must be exactly the half-rounded input, and near the input.
    CHECK(back.rgba[i] == static_cast<float>(Imath::half(im.rgba[i])));
    CHECK(back.rgba[i] == Approx(im.rgba[i]).epsilon(1e-3).margin(1e-4));
  }
  REQUIRE(back.depth.size() == im.depth.size());
  for (std::size_t i = 0; i < im.depth.size(); ++i) {
    INFO("depth index " << i);
    CHECK(back.depth[i] == im.depth[i]);  // exact, +inf included
  }
  CHECK(std::isinf(back.depth[1]));
  CHECK(back.normal == im.normal);
  REQUIRE(back.uint_channels.size() == 1);
  CHECK(back.uint_channels[0].name == "solver.isolationSteps");
  CHECK(back.uint_channels[0].values == im.uint_channels[0].values);
  REQUIRE(back.float_channels.size() == 1);
  CHECK(back.float_channels[0].name == "solver.residual");
  CHECK(back.float_channels[0].values == im.float_channels[0].values);

  for (const auto& [name, value] : im.string_attributes) {
    INFO(name);
    const std::string* got = find_attr(back.string_attributes, name);
    REQUIRE(got);
    CHECK(*got == value);
  }
  for (const auto& [name, value] : im.double_attributes) {
    INFO(name);
    const double* got = find_attr(back.double_attributes, name);
    REQUIRE(got);
    CHECK(*got == value);
  }
  REQUIRE(back.world_to_camera);
  CHECK(*back.world_to_camera == w2c);
  REQUIRE(back.world_to_ndc);
  CHECK(*back.world_to_ndc == w2ndc);

  // The on-disk layout is part of the contract: other tools read these channel types directly.
  Imf::InputFile file(out.c_str());
  const Imf::Header& h = file.header();
  CHECK(h.compression() == Imf::ZIP_COMPRESSION);
  CHECK(h.displayWindow() == Imath::Box2i(Imath::V2i(0, 0), Imath::V2i(6, 4)));
  CHECK(h.dataWindow() == h.displayWindow());
  const Imf::ChannelList& ch = h.channels();
  for (const char* name : {"R", "G", "B", "A"}) {
    REQUIRE(ch.findChannel(name));
    CHECK(ch.findChannel(name)->type == Imf::HALF);
  }
  for (const char* name : {"Z", "N.X", "N.Y", "N.Z", "solver.residual"}) {
    REQUIRE(ch.findChannel(name));
    CHECK(ch.findChannel(name)->type == Imf::FLOAT);
  }
  REQUIRE(ch.findChannel("solver.isolationSteps"));
  CHECK(ch.findChannel("solver.isolationSteps")->type == Imf::UINT);
}

TEST_CASE("EXR without optional layers reads back without them", "[image_io][exr]") {
  TempDir dir;
  const FrameImage im = solid_image(3, 2, 0.25f, 0.5f, 2.0f, 1.0f);
  algray::write_exr(dir / "plain.exr", im);
  const FrameImage back = algray::read_exr(dir / "plain.exr");
  CHECK(back.width == 3);
  CHECK(back.height == 2);
  CHECK(back.rgba == im.rgba);  // all exactly representable in half
  CHECK(back.depth.empty());
  CHECK(back.normal.empty());
  CHECK(back.uint_channels.empty());
  CHECK(back.float_channels.empty());
  CHECK_FALSE(back.world_to_camera);
  CHECK_FALSE(back.world_to_ndc);
}

// The byte a PNG holds for an alpha value: linear, rounded to nearest, clamped (NaN and below 0 to 0).
int expected_alpha_byte(float a) {
  if (!(a > 0.0f)) return 0;
  if (a >= 1.0f) return 255;
  return static_cast<int>(std::lround(a * 255.0));
}

// Whether every alpha value encodes to the byte 255, the writer's rule for leaving the alpha channel out.
bool all_alpha_opaque(const FrameImage& im) {
  for (std::size_t i = 3; i < im.rgba.size(); i += 4)
    if (expected_alpha_byte(im.rgba[i]) != 255) return false;
  return true;
}

// Random linear values with the edge cases mixed in: below 0, above 1, NaN, exact 0 and 1.
FrameImage random_png_image(std::mt19937& rng, int width, int height, bool opaque) {
  FrameImage im;
  im.width = width;
  im.height = height;
  const auto special = [&rng] { return rng() % 50; };
  auto draw = [&] {
    switch (special()) {
      case 0:
        return std::numeric_limits<float>::quiet_NaN();
      case 1:
        return 0.0f;
      case 2:
        return 1.0f;
      default:
        return -0.2f + 1.5f * unit_float(rng);
    }
  };
  im.rgba.resize(4 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (std::size_t i = 0; i < im.rgba.size(); ++i) im.rgba[i] = (opaque && i % 4 == 3) ? 1.0f : draw();
  // Runs of one colour, which deflate turns into back-references, across band boundaries too.
  for (std::size_t i = 4; i + 4 <= im.rgba.size() / 3; i += 4)
    if (special() < 25)
      std::copy_n(im.rgba.begin() + static_cast<std::ptrdiff_t>(i) - 4, 4,
                  im.rgba.begin() + static_cast<std::ptrdiff_t>(i));
  // The writer drops the alpha channel when every alpha byte would be 255, which a small random image can
  // draw; one pixel seen through keeps the RGBA path under test.
  if (!opaque && all_alpha_opaque(im)) im.rgba[3] = 0.5f;
  return im;
}

// Every decoded byte is what the image's floats encode to.
void check_png_pixels(const PngData& png, const FrameImage& im, bool opaque) {
  REQUIRE(png.width == static_cast<png_uint_32>(im.width));
  REQUIRE(png.height == static_cast<png_uint_32>(im.height));
  REQUIRE(png.bit_depth == 8);
  REQUIRE(opaque == all_alpha_opaque(im));
  REQUIRE(png.color_type == (opaque ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGB_ALPHA));
  const std::size_t channels = opaque ? 3 : 4, n = static_cast<std::size_t>(im.width) * im.height;
  REQUIRE(png.bytes.size() == n * channels);
  std::size_t wrong = 0, first_wrong = n;
  for (std::size_t i = 0; i < n; ++i) {
    bool ok = true;
    for (std::size_t c = 0; c < 3; ++c) ok &= png.bytes[i * channels + c] == algray::srgb_byte(im.rgba[4 * i + c]);
    if (!opaque) ok &= int(png.bytes[i * 4 + 3]) == expected_alpha_byte(im.rgba[4 * i + 3]);
    if (!ok && wrong++ == 0) first_wrong = i;
  }
  INFO("first wrong pixel " << first_wrong);
  CHECK(wrong == 0);
}

TEST_CASE("PNG image data deflated in parallel bands decodes with libpng to the image's bytes", "[image_io][png]") {
  TempDir dir;
  // A fixed seed and a fresh one each run (ALGRAY_TEST_SEED names it); the seed is printed with any failure.
  for (const std::mt19937::result_type seed :
       {std::mt19937::result_type{1}, std::mt19937::result_type{algray::testing::fresh_test_seed()}}) {
    INFO("seed " << seed);
    std::mt19937 rng(seed);
    // Bands are about 256 KB of filtered rows, so the large sizes take many bands on every thread, more than
    // the writer keeps in memory at once; the small ones one band, with one row or one column.
    std::vector<std::pair<int, int>> sizes = {{1, 1}, {1, 700}, {700, 1}, {1024, 700}, {2100, 130}};
    std::uniform_int_distribution<int> side(1, 900);
    for (int k = 0; k < 4; ++k) sizes.push_back({side(rng), side(rng)});
    for (const auto& [w, h] : sizes)
      for (const bool opaque : {true, false}) {
        INFO(w << "x" << h << (opaque ? " opaque" : " with alpha"));
        const FrameImage im = random_png_image(rng, w, h, opaque);
        algray::write_png(dir / "random.png", im);
        PngData png;
        REQUIRE(read_png(dir / "random.png", png));
        check_png_pixels(png, im, opaque);
      }
  }
}

TEST_CASE("write_png_image_data: any band size, thread count and level gives one valid zlib stream",
          "[image_io][png]") {
  TempDir dir;
  for (const std::mt19937::result_type seed :
       {std::mt19937::result_type{2}, std::mt19937::result_type{algray::testing::fresh_test_seed()}}) {
    INFO("seed " << seed);
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> side(1, 120);
    for (int k = 0; k < 6; ++k) {
      const int w = side(rng), h = side(rng);
      const FrameImage im = random_png_image(rng, w, h, true);
      const std::size_t row_bytes = 3 * static_cast<std::size_t>(w);
      const auto rows = [&](std::size_t y0, std::size_t count, unsigned char* out) {
        for (std::size_t i = 0; i < count * static_cast<std::size_t>(w); ++i)
          for (std::size_t c = 0; c < 3; ++c) out[3 * i + c] = algray::srgb_byte(im.rgba[4 * (y0 * w + i) + c]);
      };
      // Bands of one row to all rows at once, on 1 to 5 threads.
      for (const std::size_t band_bytes :
           {std::size_t{1}, row_bytes + 1, 7 * (row_bytes + 1) + 3, std::size_t{1} << 20})
        for (const unsigned threads : {1u, 2u, 3u, 5u})
          for (const int level : {1, 6}) {
            INFO(w << "x" << h << ", bands of " << band_bytes << " bytes, " << threads << " threads, level " << level);
            const fs::path file = dir / "data.png";
            {
              std::unique_ptr<std::FILE, int (*)(std::FILE*)> fp(std::fopen(file.c_str(), "wb"), &std::fclose);
              REQUIRE(fp);
              // The signature and IHDR (8-bit RGB) by hand; then what is under test, the data and IEND.
              const std::string ihdr = be32(static_cast<std::uint32_t>(w)) + be32(static_cast<std::uint32_t>(h)) +
                                       std::string{'\x08', '\x02', '\0', '\0', '\0'};
              const std::string head = "\x89PNG\r\n\x1a\n" + be32(13) + "IHDR" + ihdr + be32(png_crc("IHDR" + ihdr));
              REQUIRE(std::fwrite(head.data(), 1, head.size(), fp.get()) == head.size());
              algray::write_png_image_data(fp.get(), static_cast<std::size_t>(h), row_bytes, rows, level, band_bytes,
                                           threads);
            }
            PngData png;
            REQUIRE(read_png(file, png));
            check_png_pixels(png, im, true);
          }
    }
  }
}

TEST_CASE("PNG stores sRGB-encoded 8-bit values and the sRGB chunk", "[image_io][png]") {
  TempDir dir;
  // linear -> expected sRGB byte, from the exact piecewise sRGB transfer function.
  const std::vector<std::pair<float, int>> cases = {{0.0f, 0},  {0.5f, 188},  {1.0f, 255}, {2.0f, 255},
                                                    {-1.0f, 0}, {0.18f, 118}, {0.002f, 7}, {0.0031308f, 10}};
  FrameImage im;
  im.width = static_cast<int>(cases.size());
  im.height = 2;
  for (int y = 0; y < 2; ++y)
    for (const auto& [linear, expected] : cases) {
      (void)expected;
      // The second row swaps channels so rows cannot be confused.
      if (y == 0)
        im.rgba.insert(im.rgba.end(), {linear, 0.0f, 1.0f, 1.0f});
      else
        im.rgba.insert(im.rgba.end(), {1.0f, linear, 0.0f, 1.0f});
    }

  SECTION("opaque image is written as RGB") {
    algray::write_image(dir / "rgb.png", im);
    PngData png;
    REQUIRE(read_png(dir / "rgb.png", png));
    CHECK(png.width == cases.size());
    CHECK(png.height == 2);
    CHECK(png.bit_depth == 8);
    CHECK(png.color_type == PNG_COLOR_TYPE_RGB);
    CHECK(png.has_srgb);
    REQUIRE(png.bytes.size() == cases.size() * 2 * 3);
    for (std::size_t x = 0; x < cases.size(); ++x) {
      INFO("linear " << cases[x].first);
      const std::size_t row1 = cases.size() * 3;
      CHECK(int(png.bytes[3 * x + 0]) == cases[x].second);
      CHECK(int(png.bytes[3 * x + 1]) == 0);
      CHECK(int(png.bytes[3 * x + 2]) == 255);
      CHECK(int(png.bytes[row1 + 3 * x + 0]) == 255);
      CHECK(int(png.bytes[row1 + 3 * x + 1]) == cases[x].second);
      CHECK(int(png.bytes[row1 + 3 * x + 2]) == 0);
    }
    CHECK(list_dir(dir.path()) == std::vector<std::string>{"rgb.png"});
  }

  SECTION("translucent pixels make it RGBA with straight, linearly encoded alpha") {
    im.rgba[3] = 0.5f;   // first pixel
    im.rgba[7] = 0.0f;   // second pixel: colour must survive zero alpha (not premultiplied)
    im.rgba[11] = 1.7f;  // clamps
    algray::write_png(dir / "rgba.png", im);
    PngData png;
    REQUIRE(read_png(dir / "rgba.png", png));
    CHECK(png.color_type == PNG_COLOR_TYPE_RGB_ALPHA);
    CHECK(png.has_srgb);
    REQUIRE(png.bytes.size() == cases.size() * 2 * 4);
    CHECK(int(png.bytes[3]) == 128);
    CHECK(int(png.bytes[4 + 0]) == 188);
    CHECK(int(png.bytes[4 + 2]) == 255);
    CHECK(int(png.bytes[7]) == 0);
    CHECK(int(png.bytes[11]) == 255);
    CHECK(int(png.bytes[15]) == 255);
  }
}

TEST_CASE("writing over an existing file replaces it completely", "[image_io][atomic]") {
  TempDir dir;
  const fs::path exr = dir / "out.exr";
  algray::write_exr(exr, make_image(64, 48));
  const auto big_size = fs::file_size(exr);
  algray::write_exr(exr, make_image(7, 5));
  CHECK(fs::file_size(exr) < big_size);
  const FrameImage back = algray::read_exr(exr);
  CHECK(back.width == 7);
  CHECK(back.height == 5);

  const fs::path png = dir / "out.png";
  write_bytes(png, std::string(100000, 'x'));
  algray::write_png(png, solid_image(4, 3, 1.0f, 0.0f, 0.0f, 1.0f));
  PngData data;
  REQUIRE(read_png(png, data));
  CHECK(data.width == 4);
  CHECK(data.height == 3);
  CHECK(fs::file_size(png) < 1000);
  CHECK(list_dir(dir.path()) == std::vector<std::string>{"out.exr", "out.png"});
}

TEST_CASE("a failed write leaves the destination untouched and no temp file", "[image_io][atomic]") {
  TempDir dir;
  const std::string original = "original bytes that must survive\n";
  const FrameImage im = make_image(7, 5);

  SECTION("unsupported extension") {
    const fs::path dest = dir / "out.tiff";
    write_bytes(dest, original);
    CHECK_THROWS_AS(algray::write_image(dest, im), OutputError);
    CHECK(read_bytes(dest) == original);
    CHECK(list_dir(dir.path()) == std::vector<std::string>{"out.tiff"});
  }
  SECTION("missing directory is reported, not created") {
    const fs::path dest = dir / "missing" / "out.exr";
    CHECK_THROWS_WITH(algray::write_exr(dest, im), Catch::Contains("missing") && Catch::Contains("does not exist"));
    CHECK_THROWS_AS(algray::write_png(dir / "missing" / "out.png", im), OutputError);
    CHECK(list_dir(dir.path()).empty());
  }
  SECTION("destination is a directory") {
    const fs::path dest = dir / "out.exr";
    fs::create_directory(dest);
    write_bytes(dest / "inside", original);
    CHECK_THROWS_AS(algray::write_exr(dest, im), OutputError);
    CHECK_THROWS_AS(algray::write_png(dir / "out.exr", im), OutputError);
    CHECK(fs::is_directory(dest));
    CHECK(read_bytes(dest / "inside") == original);
    CHECK(list_dir(dir.path()) == std::vector<std::string>{"out.exr"});
  }
  SECTION("malformed image") {
    const fs::path dest = dir / "out.exr";
    write_bytes(dest, original);
    FrameImage bad = im;
    bad.rgba.pop_back();
    CHECK_THROWS_AS(algray::write_exr(dest, bad), OutputError);
    FrameImage clash = im;
    clash.uint_channels.push_back({"Z", std::vector<std::uint32_t>(35)});
    CHECK_THROWS_WITH(algray::write_exr(dest, clash), Catch::Contains("Z"));
    FrameImage attr_clash = im;
    attr_clash.string_attributes.push_back({"compression", "none"});
    CHECK_THROWS_AS(algray::write_exr(dest, attr_clash), OutputError);
    CHECK(read_bytes(dest) == original);
    CHECK(list_dir(dir.path()) == std::vector<std::string>{"out.exr"});
  }
  SECTION("the disk refuses data halfway through the write") {
    // A file-size limit makes the temp file's writes fail with EFBIG after a few kilobytes; done in a
    // child process so the limit does not leak into the test process. The 256x256 image is noise, hence
    // incompressible, so the PNG outgrows the limit too.
    const fs::path exr = dir / "out.exr";
    const fs::path png = dir / "out.png";
    write_bytes(exr, original);
    write_bytes(png, original);
    const pid_t child = spawn_writer({"--fsize-limit=4096", "256", "7", exr.string(), png.string()});
    REQUIRE(child >= 0);
    const std::optional<int> status = wait_child(child);
    if (!status) FAIL("image_writer_tool did not exit within 20 s and was killed");
    REQUIRE(WIFEXITED(*status));
    INFO("exit status 127 means " ALGRAY_IMAGE_WRITER_TOOL " could not be executed");
    CHECK(WEXITSTATUS(*status) == 2);  // both writes failed with WriteError (an OutputError would count 10)
    CHECK((read_bytes(exr) == original));
    CHECK((read_bytes(png) == original));
    CHECK(list_dir(dir.path()) == std::vector<std::string>{"out.exr", "out.png"});
  }
}

TEST_CASE("a writer killed by SIGTERM leaves no temp file behind", "[image_io][signal]") {
  TempDir dir;
  const fs::path dest = dir / "killed.exr";
  // Noisy data compresses slowly, which keeps the write in progress long enough to be interrupted.
  int side = 1024;
  bool interrupted = false;
  for (int attempt = 0; attempt < 3 && !interrupted; ++attempt, side *= 2) {
    constexpr std::mt19937::result_type seed = 42;
    const pid_t child = spawn_writer({"--cleanup-handlers", std::to_string(side), std::to_string(seed), dest.string()});
    REQUIRE(child >= 0);
    // Signal only once the temp file exists, so the kill lands inside the write rather than before it.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    bool saw_temp = false, finished_first = false;
    int status = 0;
    while (!saw_temp && !finished_first && std::chrono::steady_clock::now() < deadline) {
      saw_temp = has_temp_file(dir.path());
      if (!saw_temp) {
        const pid_t r = ::waitpid(child, &status, WNOHANG);
        if (r < 0 && errno != EINTR) FAIL("waitpid failed on image_writer_tool: " << std::strerror(errno));
        finished_first = r == child;
      }
      if (!saw_temp && !finished_first) std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    if (!saw_temp && !finished_first) {
      kill_child(child);
      FAIL("image_writer_tool neither created a temp file nor exited within 10 s and was killed");
    }
    if (!finished_first) {
      ::kill(child, SIGTERM);
      const std::optional<int> waited = wait_child(child);
      if (!waited) FAIL("image_writer_tool did not exit within 20 s of SIGTERM and was killed");
      status = *waited;
      if (WIFSIGNALED(status)) {
        // Killed by the default action of the re-raised signal, after the handler cleaned up.
        CHECK(WTERMSIG(status) == SIGTERM);
        CHECK(list_dir(dir.path()).empty());
        interrupted = true;
        continue;
      }
    }
    REQUIRE(WIFEXITED(status));
    INFO("exit status 127 means " ALGRAY_IMAGE_WRITER_TOOL " could not be executed");
    REQUIRE(WEXITSTATUS(status) == 0);
    // The writer won the race: whatever exists must be the complete image.
    CHECK_FALSE(has_temp_file(dir.path()));
    const FrameImage back = algray::read_exr(dest);
    CHECK(back.width == side);
    CHECK(back.depth == noisy_image(side, seed).depth);
    fs::remove(dest);
  }
  CHECK(interrupted);
}

TEST_CASE("the version names the project version and a commit of this repository", "[image_io][version]") {
  const std::string version = algray::version();
  CHECK_THAT(version, Catch::Matches("[0-9]+\\.[0-9]+\\.[0-9]+"));
  const std::string revision = algray::git_revision();
  CHECK_THAT(revision, Catch::Matches("unknown|[0-9a-f]{7,40}(-dirty)?"));
  if (revision == "unknown") {
    CHECK(algray::version_string() == "algray " + version);
  } else {
    CHECK(algray::version_string() == "algray " + version + " (git " + revision + ")");
  }
  // Built from a checkout git can read, the revision must be known and name a commit that exists here; HEAD
  // itself may have moved on since the build.
  if (std::system("git -C '" ALGRAY_SOURCE_DIR "' rev-parse --verify -q HEAD >/dev/null 2>&1") == 0) {
    REQUIRE(revision != "unknown");
    const std::string hash = revision.substr(0, revision.find('-'));
    const std::string command = "git -C '" ALGRAY_SOURCE_DIR "' cat-file -e '" + hash + "^{commit}' 2>/dev/null";
    CHECK(std::system(command.c_str()) == 0);
  }
}

TEST_CASE("EXR header carries software, comments and Rec.709 chromaticities", "[image_io][exr]") {
  TempDir dir;
  FrameImage im = solid_image(3, 2, 0.25f, 0.5f, 1.0f, 1.0f);
  im.string_attributes = {{"algray/equation", "x^2 + y^2 + z^2 - 1"}};

  SECTION("software defaults to the version string; comments are written when given") {
    im.comments = "Sphere: x^2 + y^2 + z^2 - 1 = 0\nsecond line, \xC3\xA9";
    algray::write_exr(dir / "a.exr", im);
    const FrameImage back = algray::read_exr(dir / "a.exr");
    CHECK(back.software == algray::version_string());
    CHECK(back.comments == im.comments);
    // The two standard attributes come back in their fields only, so writing `back` again cannot clash.
    CHECK_FALSE(find_attr(back.string_attributes, "software"));
    CHECK_FALSE(find_attr(back.string_attributes, "comments"));
    REQUIRE(find_attr(back.string_attributes, "algray/equation"));
    REQUIRE(back.chromaticities);
    const std::array<float, 8> rec709 = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};
    CHECK(*back.chromaticities == rec709);
    algray::write_exr(dir / "b.exr", back);
    CHECK(algray::read_exr(dir / "b.exr").comments == im.comments);

    // What other tools see: the standard names and types.
    Imf::InputFile file((dir / "a.exr").c_str());
    const Imf::Header& h = file.header();
    REQUIRE(h.findTypedAttribute<Imf::StringAttribute>("software"));
    CHECK(h.findTypedAttribute<Imf::StringAttribute>("software")->value() == algray::version_string());
    REQUIRE(Imf::hasComments(h));
    CHECK(Imf::comments(h) == im.comments);
    REQUIRE(Imf::hasChromaticities(h));
    CHECK(Imf::chromaticities(h).white == Imath::V2f(0.3127f, 0.3290f));
  }
  SECTION("a given software string is kept; no comments means no attribute") {
    im.software = "some tool 2.0";
    algray::write_exr(dir / "a.exr", im);
    const FrameImage back = algray::read_exr(dir / "a.exr");
    CHECK(back.software == "some tool 2.0");
    CHECK(back.comments.empty());
    Imf::InputFile file((dir / "a.exr").c_str());
    CHECK_FALSE(Imf::hasComments(file.header()));
  }
  SECTION("software and comments as string attributes are refused, with nothing written") {
    for (const char* name : {"software", "comments", "chromaticities"}) {
      INFO(name);
      FrameImage clash = im;
      clash.string_attributes.push_back({name, "x"});
      CHECK_THROWS_AS(algray::write_exr(dir / "a.exr", clash), OutputError);
    }
    FrameImage clash = im;
    clash.string_attributes.push_back({"comments", "x"});
    CHECK_THROWS_WITH(algray::write_exr(dir / "a.exr", clash), Catch::Contains("FrameImage::comments"));
    CHECK(list_dir(dir.path()).empty());
  }
}

TEST_CASE("PNG text chunks round trip, the scene compressed", "[image_io][png]") {
  TempDir dir;
  FrameImage im = solid_image(5, 4, 0.2f, 0.4f, 0.8f, 1.0f);
  const std::string scene = multi_kb_scene();
  REQUIRE(scene.size() > 5000);
  im.comments = "4*(t^2*x^2-y^2)*(t^2*y^2-z^2) = 0";
  im.png_text = {{algray::kPngSceneKey, scene},
                 {"Title", "Barth sextic"},
                 {"algray:short-utf8", "\xCF\x80 r\xC3\xA9sum\xC3\xA9"},
                 {"Empty", ""}};
  const fs::path out = dir / "scene.png";
  algray::write_png(out, im);
  CHECK(algray::is_png_file(out));

  const auto text = algray::read_png_text(out);
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"Software", algray::version_string()},
      {"Comment", im.comments},
      {algray::kPngSceneKey, scene},
      {"Title", "Barth sextic"},
      {"algray:short-utf8", "\xCF\x80 r\xC3\xA9sum\xC3\xA9"},
      {"Empty", ""}};
  REQUIRE(text.size() == expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    INFO("chunk " << i << ": " << expected[i].first);
    CHECK(text[i].first == expected[i].first);
    CHECK((text[i].second == expected[i].second));
  }

  // The chunk types as other readers see them: ASCII in tEXt, UTF-8 in iTXt, the scene compressed.
  const std::vector<PngChunk> chunks = split_png(read_bytes(out));
  auto chunk_for = [&](const std::string& key) -> const PngChunk* {
    for (const PngChunk& c : chunks)
      if ((c.type == "tEXt" || c.type == "iTXt" || c.type == "zTXt") &&
          c.data.compare(0, key.size() + 1, key + '\0') == 0)
        return &c;
    return nullptr;
  };
  REQUIRE(chunk_for("Software"));
  CHECK(chunk_for("Software")->type == "tEXt");
  REQUIRE(chunk_for("algray:short-utf8"));
  CHECK(chunk_for("algray:short-utf8")->type == "iTXt");
  const PngChunk* scene_chunk = chunk_for(algray::kPngSceneKey);
  REQUIRE(scene_chunk);
  CHECK(scene_chunk->type == "iTXt");
  CHECK(scene_chunk->data.at(std::strlen(algray::kPngSceneKey) + 1) == 1);  // iTXt compression flag
  CHECK(scene_chunk->data.size() < scene.size() / 2);
  // Before the image data, so that a reader after the scene can stop early.
  std::size_t scene_at = 0, idat_at = 0;
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    if (&chunks[i] == scene_chunk) scene_at = i;
    if (chunks[i].type == "IDAT" && idat_at == 0) idat_at = i;
  }
  CHECK(scene_at < idat_at);

  // The pixels are unchanged by the text.
  PngData png;
  REQUIRE(read_png(out, png));
  CHECK(png.width == 5);
  CHECK(int(png.bytes[2]) == 231);  // 0.8 linear in sRGB
}

TEST_CASE("PNG text that cannot be stored is refused before anything is written", "[image_io][png]") {
  TempDir dir;
  const FrameImage base = solid_image(2, 2, 0.5f, 0.5f, 0.5f, 1.0f);
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"", "empty key"},
      {std::string(80, 'k'), "key too long"},
      {" lead", "leading space"},
      {"trail ", "trailing space"},
      {"double  space", "double space"},
      {"caf\xC3\xA9", "non-ASCII key"},
      {"tab\tkey", "control character"},
      {"Software", "reserved for FrameImage::software"},
      {"Comment", "reserved for FrameImage::comments"},
      {"nul", std::string("a\0b", 3)},
      {"latin1", "caf\xE9"},
      {"overlong", "\xC0\xAF"},
      {"surrogate", "\xED\xA0\x80"},
      {"cut", "\xE2\x82"},
      {"huge", std::string(algray::kMaxPngTextBytes + 1, 'x')},
  };
  for (const auto& [key, value] : bad) {
    INFO("key '" << key << "' value of " << value.size() << " bytes");
    FrameImage im = base;
    im.png_text = {{"Fine", "ok"}, {key, value}};
    CHECK_THROWS_AS(algray::write_png(dir / "t.png", im), OutputError);
  }
  FrameImage twice = base;
  twice.png_text = {{"Title", "a"}, {"Title", "b"}};
  CHECK_THROWS_WITH(algray::write_png(dir / "t.png", twice), Catch::Contains("twice"));
  FrameImage bad_comment = base;
  bad_comment.comments = "caf\xE9";
  CHECK_THROWS_AS(algray::write_png(dir / "t.png", bad_comment), OutputError);
  CHECK(list_dir(dir.path()).empty());

  // The limits themselves are accepted.
  FrameImage edge = base;
  edge.png_text = {{std::string(79, 'k'), "x"}, {"one space", std::string(algray::kMaxPngTextBytes, 'y')}};
  algray::write_png(dir / "t.png", edge);
  const auto text = algray::read_png_text(dir / "t.png");
  REQUIRE(text.size() == 3);
  CHECK(text[1].first == std::string(79, 'k'));
  CHECK(text[2].second.size() == algray::kMaxPngTextBytes);
}

TEST_CASE("read_png_text reads text after the image data, tEXt as Latin-1, and skips other chunks", "[image_io][png]") {
  TempDir dir;
  FrameImage im = solid_image(3, 3, 1.0f, 0.0f, 0.0f, 1.0f);
  im.software = "writer";
  algray::write_png(dir / "a.png", im);
  std::string png = read_bytes(dir / "a.png");
  png = with_chunk_at_end(png, {"tEXt", std::string("Author") + '\0' + "Andr\xE9 \xA9"});
  // A colour profile that is garbage and a private chunk must not stop the text from being read.
  png = with_chunk_at_end(png, {"iCCP", std::string("junk\0\0not zlib at all", 21)});
  png = with_chunk_at_end(png, {"prVt", "private data"});
  write_bytes(dir / "b.png", png);

  const auto text = algray::read_png_text(dir / "b.png");
  REQUIRE(text.size() == 2);
  CHECK(text[0] == std::pair<std::string, std::string>{"Software", "writer"});
  CHECK(text[1] == std::pair<std::string, std::string>{"Author", "Andr\xC3\xA9 \xC2\xA9"});
}

TEST_CASE("read_png_text throws OutputError on damaged or foreign files, never crashes", "[image_io][png]") {
  TempDir dir;
  FrameImage im = solid_image(16, 16, 0.3f, 0.6f, 0.9f, 1.0f);
  im.png_text = {{algray::kPngSceneKey, multi_kb_scene()}, {"Title", "t"}};
  algray::write_png(dir / "good.png", im);
  const std::string good = read_bytes(dir / "good.png");
  REQUIRE(algray::read_png_text(dir / "good.png").size() == 3);

  auto expect_failure = [&](const std::string& name, const std::string& bytes, const std::string& why) {
    INFO(name << ": " << why);
    write_bytes(dir / name, bytes);
    CHECK_THROWS_AS(algray::read_png_text(dir / name), OutputError);
    CHECK_THROWS_WITH(algray::read_png_text(dir / name), Catch::Contains(name));
  };
  SECTION("truncated anywhere") {
    const std::vector<PngChunk> chunks = split_png(good);
    std::size_t idat_end = 8;
    for (const PngChunk& c : chunks) {
      idat_end += 12 + c.data.size();
      if (c.type == "IDAT") break;
    }
    for (const std::size_t length : {std::size_t{0}, std::size_t{7}, std::size_t{8}, std::size_t{20}, std::size_t{40},
                                     good.size() / 3, good.size() / 2, idat_end - 5, good.size() - 12, good.size() - 1})
      expect_failure("cut-" + std::to_string(length) + ".png", good.substr(0, length),
                     "cut to " + std::to_string(length) + " of " + std::to_string(good.size()) + " bytes");
    CHECK_THROWS_WITH(algray::read_png_text(dir / ("cut-" + std::to_string(good.size() / 2) + ".png")),
                      Catch::Contains("truncated"));
    CHECK_FALSE(algray::is_png_file(dir / "cut-7.png"));
    CHECK(algray::is_png_file(dir / "cut-8.png"));
  }
  SECTION("not a PNG") {
    expect_failure("text.png", "[surface]\nequation = \"x\"\n", "a scene named .png");
    expect_failure("empty.png", "", "empty");
    CHECK_THROWS_WITH(algray::read_png_text(dir / "text.png"), Catch::Contains("not a PNG"));
    CHECK_FALSE(algray::is_png_file(dir / "text.png"));
    CHECK_THROWS_AS(algray::read_png_text(dir / "missing.png"), OutputError);
    CHECK_FALSE(algray::is_png_file(dir / "missing.png"));
    CHECK_FALSE(algray::is_png_file(dir.path()));
  }
  SECTION("a text chunk with a bad CRC is an error, not silently dropped") {
    std::string bad = with_chunk_at_end(good, {"tEXt", std::string("Note\0hello", 10)});
    bad[bad.size() - 12 - 4 - 1] ^= 0x20;  // last byte of the tEXt data, before its CRC and IEND
    expect_failure("crc.png", bad, "bad CRC");
    CHECK_THROWS_WITH(algray::read_png_text(dir / "crc.png"), Catch::Contains("CRC"));
  }
  SECTION("a text chunk larger than the cap") {
    const std::string huge = "Big" + std::string(1, '\0') + std::string(algray::kMaxPngTextBytes + 8192, 'z');
    expect_failure("huge.png", with_chunk_at_end(good, {"tEXt", huge}), "tEXt over the cap");
    std::string lying = good.substr(0, 33);  // signature and IHDR
    lying += be32(0x7FFFFFFFu) + "tEXt" + "abc";
    expect_failure("lying.png", lying, "chunk length far past the end of the file");
  }
  SECTION("random damage: each flip returns or throws OutputError") {
    std::mt19937 rng(20240611);
    for (int trial = 0; trial < 300; ++trial) {
      std::string bytes = good;
      const int flips = 1 + static_cast<int>(rng() % 4);
      for (int f = 0; f < flips; ++f) bytes[rng() % bytes.size()] ^= static_cast<char>(1 + rng() % 255);
      write_bytes(dir / "fuzz.png", bytes);
      std::string message;
      const Outcome got = outcome_of([&] { (void)algray::read_png_text(dir / "fuzz.png"); }, message);
      INFO("trial " << trial << ": " << message);
      CHECK((got == Outcome::Wrote || got == Outcome::OutputErr));
    }
  }
}

TEST_CASE("a write that fails on the way to the disk is a WriteError, not an OutputError", "[image_io][atomic]") {
  static_assert(!std::is_base_of_v<OutputError, WriteError> && !std::is_base_of_v<WriteError, OutputError>,
                "the CLI tells bad input from failed writes by type");
  TempDir dir;
  const std::string original = "original bytes that must survive\n";
  const fs::path exr = dir / "out.exr", png = dir / "out.png", json = dir / "out.json";
  for (const fs::path& p : {exr, png, json}) write_bytes(p, original);
  // Noise does not compress, so each file outgrows the limit whatever the format.
  const FrameImage im = noisy_image(128, 3);
  const std::string text(20000, 't');
  std::string exr_message, png_message, json_message, bad_message;
  Outcome exr_outcome, png_outcome, json_outcome, bad_outcome;
  {
    const FileSizeLimit limit(4096);
    exr_outcome = outcome_of([&] { algray::write_exr(exr, im); }, exr_message);
    png_outcome = outcome_of([&] { algray::write_png(png, im); }, png_message);
    json_outcome = outcome_of([&] { algray::write_text_file(json, text); }, json_message);
    // Under the same limit, bad input is still reported as bad input.
    bad_outcome = outcome_of([&] { algray::write_png(dir / "missing" / "x.png", im); }, bad_message);
  }
  CHECK(exr_outcome == Outcome::WriteErr);
  CHECK(png_outcome == Outcome::WriteErr);
  CHECK(json_outcome == Outcome::WriteErr);
  CHECK(bad_outcome == Outcome::OutputErr);
  CHECK_THAT(png_message, Catch::StartsWith("cannot write '" + png.string() + "': "));
  CHECK_THAT(json_message, Catch::Contains("File too large"));
  INFO(exr_message);
  for (const fs::path& p : {exr, png, json}) CHECK(read_bytes(p) == original);
  CHECK(list_dir(dir.path()) == std::vector<std::string>{"out.exr", "out.json", "out.png"});
}

TEST_CASE("check_output_path finds path problems before anything is written", "[image_io][atomic]") {
  TempDir dir;
  write_bytes(dir / "file", "x");
  fs::create_directory(dir / "sub");
  const FrameImage im = solid_image(2, 2, 0.5f, 0.5f, 0.5f, 1.0f);
  using Catch::Contains;

  CHECK_NOTHROW(algray::check_output_path(dir / "fine.png"));
  CHECK_THROWS_WITH(algray::check_output_path(dir / "missing" / "a.png"),
                    Contains("cannot write '") && Contains("missing") && Contains("does not exist"));
  CHECK_THROWS_WITH(algray::check_output_path(dir / "file" / "a.png"), Contains("file"));
  CHECK_THROWS_AS(algray::check_output_path(dir / "file" / "a.png"), OutputError);
  CHECK_THROWS_WITH(algray::check_output_path(dir / "sub"), Contains("is a directory"));
  CHECK_THROWS_AS(algray::check_output_path(dir.path().string() + "/"), OutputError);

  const long name_max = ::pathconf(dir.path().c_str(), _PC_NAME_MAX);
  REQUIRE(name_max > 0);
  const std::string longest = std::string(static_cast<std::size_t>(name_max) - 4, 'n') + ".png";
  const std::string too_long = std::string(static_cast<std::size_t>(name_max) - 3, 'n') + ".png";
  CHECK_THROWS_WITH(
      algray::check_output_path(dir / too_long),
      Contains("file name is " + std::to_string(too_long.size()) + " bytes") && Contains(std::to_string(name_max)));
  // The writers make the same check, as bad input, and leave nothing behind.
  CHECK_THROWS_AS(algray::write_png(dir / too_long, im), OutputError);
  CHECK_THROWS_AS(algray::write_text_file(dir / too_long, "x"), OutputError);
  // The longest name still works: its temporary's name is cut to fit.
  CHECK_NOTHROW(algray::check_output_path(dir / longest));
  algray::write_png(dir / longest, im);
  CHECK(list_dir(dir.path()) == std::vector<std::string>{"file", longest, "sub"});
}

TEST_CASE("temporaries of dead writers are removed by the next write to that name", "[image_io][stale]") {
  TempDir dir;
  const FrameImage im = solid_image(2, 2, 0.5f, 0.5f, 0.5f, 1.0f);
  const pid_t dead = dead_pid();
  const SleepingChild live;
  const std::string d = std::to_string(dead), l = std::to_string(live.pid()), self = std::to_string(::getpid());
  const auto old = std::chrono::seconds(600), fresh = std::chrono::seconds(0);

  make_temp_like(dir / (".out.png.tmp-" + d + "-1"), old);    // removed: dead, long untouched
  make_temp_like(dir / (".out.png.tmp-" + d + "-27"), old);   // removed too
  make_temp_like(dir / (".out.png.tmp-" + d + "-2"), fresh);  // kept: might be another machine's live writer
  make_temp_like(dir / (".out.png.tmp-" + l + "-1"), old);    // kept: a live writer
  // Kept: this process's, another thread's (a counter this process will not reach here, so no write reuses it).
  make_temp_like(dir / (".out.png.tmp-" + self + "-987654"), old);
  make_temp_like(dir / (".other.png.tmp-" + d + "-1"), old);  // kept: another destination's
  make_temp_like(dir / (".out.png.tmp-" + d + "-x"), old);    // kept: not a temporary's name
  make_temp_like(dir / (".out.png.tmp-" + d), old);           // kept: not a temporary's name
  make_temp_like(dir / ("out.png.tmp-" + d + "-1"), old);     // kept: not hidden, so not ours
  const std::vector<std::string> kept = {".other.png.tmp-" + d + "-1",
                                         ".out.png.tmp-" + d,
                                         ".out.png.tmp-" + d + "-2",
                                         ".out.png.tmp-" + d + "-x",
                                         ".out.png.tmp-" + l + "-1",
                                         ".out.png.tmp-" + self + "-987654",
                                         "out.png",
                                         "out.png.tmp-" + d + "-1"};

  algray::write_png(dir / "out.png", im);
  std::vector<std::string> expected = kept;
  std::sort(expected.begin(), expected.end());
  CHECK(list_dir(dir.path()) == expected);

  SECTION("a long name's temporaries are matched by the same 200-byte cut") {
    const std::string name = std::string(230, 'L') + ".exr";
    const std::string stale = "." + name.substr(0, 200) + ".tmp-" + d + "-3";
    make_temp_like(dir / stale, old);
    algray::write_exr(dir / name, im);
    CHECK_FALSE(fs::exists(dir / stale));
    CHECK(fs::exists(dir / name));
  }
}

TEST_CASE("a writer killed by SIGKILL leaves a temporary that a later write removes", "[image_io][stale]") {
  TempDir dir;
  const fs::path dest = dir / "killed.exr";
  // Large noise keeps the write going long enough to be caught with its temporary open.
  const pid_t child = spawn_writer({"2048", "5", dest.string()});
  REQUIRE(child >= 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!has_temp_file(dir.path()) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  ::kill(child, SIGKILL);
  const std::optional<int> status = wait_child(child);
  REQUIRE(status);
  if (!has_temp_file(dir.path())) {
    // The write finished (renamed) before the kill landed: nothing to clean up, nothing this test can show.
    WARN("image_writer_tool renamed its file before SIGKILL; the stale-temporary case was not exercised");
    CHECK(fs::exists(dest));
    return;
  }
  CHECK(WIFSIGNALED(*status));  // SIGKILL runs no handler, so the temporary stays
  CHECK_FALSE(fs::exists(dest));
  std::string temp_name;
  for (const auto& name : list_dir(dir.path())) temp_name = name;
  CHECK_THAT(temp_name, Catch::StartsWith(".killed.exr.tmp-" + std::to_string(child) + "-"));
  fs::last_write_time(dir / temp_name, fs::file_time_type::clock::now() - std::chrono::minutes(5));

  algray::write_exr(dest, solid_image(2, 2, 0.5f, 0.5f, 0.5f, 1.0f));
  CHECK(list_dir(dir.path()) == std::vector<std::string>{"killed.exr"});
}

namespace {

// The sRGB transfer function, times 255, rounded: what every PNG byte must be.
int srgb_byte_by_definition(float linear) {
  if (!(linear > 0.0f)) return 0;
  if (linear >= 1.0f) return 255;
  const double l = linear;
  return static_cast<int>(std::lround(255.0 * (l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055)));
}

float float_of_bits(std::uint32_t u) {
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

}  // namespace

TEST_CASE("the PNG's sRGB bytes are the transfer function's, rounded, at every threshold", "[image_io][png]") {
  // The encoder is a table: checked on every 61st float of (0, 1) and on the floats next to each change of
  // byte, where a table is most likely off (every float of (0, 1) was checked once: no difference).
  int checked = 0, changes = 0, wrong = 0;
  float first_wrong = 0;
  auto check = [&](float f) {
    ++checked;
    if (int(algray::srgb_byte(f)) == srgb_byte_by_definition(f)) return;
    if (wrong++ == 0) first_wrong = f;
  };
  for (std::uint32_t u = 1; u < 0x3f800000u; u += 61) {
    check(float_of_bits(u));
    if (srgb_byte_by_definition(float_of_bits(u)) == srgb_byte_by_definition(float_of_bits(u + 61))) continue;
    ++changes;
    for (std::uint32_t v = u + 1; v < u + 61; ++v) check(float_of_bits(v));
  }
  INFO(wrong << " of " << checked << " floats encoded wrongly, the first " << first_wrong << " ("
             << int(algray::srgb_byte(first_wrong)) << " for " << srgb_byte_by_definition(first_wrong) << ")");
  CHECK(wrong == 0);
  CHECK(checked > 17000000);
  CHECK(changes == 255);
  for (float special : {0.0f, -0.0f, -1.0f, 1.0f, 7.5f, std::numeric_limits<float>::quiet_NaN(),
                        std::numeric_limits<float>::infinity(), std::numeric_limits<float>::denorm_min()})
    CHECK(int(algray::srgb_byte(special)) == srgb_byte_by_definition(special));
}

TEST_CASE("EXR and PNG written in strips read back whole", "[image_io][exr][png]") {
  // Taller than one strip of either writer (EXR: about 4 MB of half colour; PNG: about 1 MB of bytes), with an
  // odd last strip, so that a line out of place or a strip written twice shows.
  TempDir dir;
  const int width = 1000, height = 1123;
  FrameImage im;
  im.width = width;
  im.height = height;
  const std::size_t n = static_cast<std::size_t>(width) * height;
  std::mt19937 rng(20261201);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  im.rgba.resize(4 * n);
  im.depth.resize(n);
  im.normal.resize(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) im.rgba[4 * i + c] = unit(rng);
    im.rgba[4 * i + 3] = (i % 7 == 0) ? 0.5f : 1.0f;
    im.depth[i] = static_cast<float>(i);  // each line its own values
    for (int c = 0; c < 3; ++c) im.normal[3 * i + c] = unit(rng);
  }
  algray::write_image(dir / "tall.exr", im);
  algray::write_image(dir / "tall.png", im);
  const FrameImage back = algray::read_exr(dir / "tall.exr");
  REQUIRE(back.rgba.size() == im.rgba.size());
  std::size_t first_wrong = n * 4;
  for (std::size_t i = im.rgba.size(); i-- > 0;)
    if (back.rgba[i] != static_cast<float>(Imath::half(im.rgba[i]))) first_wrong = i;
  INFO("first EXR colour value off: line " << first_wrong / 4 / width);
  CHECK(first_wrong == n * 4);
  CHECK(back.depth == im.depth);
  CHECK(back.normal == im.normal);
  PngData png;
  REQUIRE(read_png(dir / "tall.png", png));
  REQUIRE(png.color_type == PNG_COLOR_TYPE_RGB_ALPHA);
  REQUIRE(png.bytes.size() == 4 * n);
  std::size_t png_wrong = n;
  for (std::size_t i = n; i-- > 0;) {
    bool same = int(png.bytes[4 * i + 3]) == (i % 7 == 0 ? 128 : 255);
    for (int c = 0; c < 3; ++c) same = same && int(png.bytes[4 * i + c]) == srgb_byte_by_definition(im.rgba[4 * i + c]);
    if (!same) png_wrong = i;
  }
  INFO("first PNG pixel off: line " << png_wrong / width);
  CHECK(png_wrong == n);
}

TEST_CASE("png_bytes is what write_png puts in the file, opaque or not, text included", "[image_io][png]") {
  TempDir dir;
  for (const std::mt19937::result_type seed :
       {std::mt19937::result_type{7}, std::mt19937::result_type{algray::testing::fresh_test_seed()}}) {
    std::mt19937 rng(seed);
    for (int c = 0; c < 4; ++c) {
      INFO("seed " << seed << ", case " << c);
      FrameImage im =
          random_png_image(rng, 1 + static_cast<int>(rng() % 300), 1 + static_cast<int>(rng() % 200), c % 2 == 0);
      im.comments = "case " + std::to_string(c);
      im.png_text = {{algray::kPngSceneKey, multi_kb_scene()}};
      const fs::path out = dir / "frame.png";
      algray::write_png(out, im);
      CHECK(algray::png_bytes(im) == read_bytes(out));
    }
  }
  // A bad image is refused in memory as on disk.
  FrameImage broken = make_image(4, 4);
  broken.rgba.resize(3);
  CHECK_THROWS_AS(algray::png_bytes(broken), algray::OutputError);
}
