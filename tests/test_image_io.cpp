// Tests for EXR/PNG output: round trips, sRGB encoding, atomic replacement and cleanup after signals.
#include "image_io.h"
#include "noisy_image.h"
#include "temp_dir.h"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#include <ImfChannelList.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <half.h>
#pragma GCC diagnostic pop
#include <png.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;
using algray::FrameImage;
using algray::OutputError;

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
    CHECK(WEXITSTATUS(*status) == 2);  // both writes reported failure
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
