// Rendered-frame container and its EXR/PNG (and plain text) writers, which replace the output file atomically.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace algray {

struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// One rendered frame, row-major, top row first, linear (not sRGB) colour.
struct FrameImage {
  int width = 0, height = 0;
  // 4 floats per pixel, straight (not premultiplied) alpha.
  std::vector<float> rgba;
  // 1 per pixel: distance from the eye, +inf on a miss. May be left empty, then no Z channel is written.
  std::vector<float> depth;
  // 3 per pixel: unit world-space normal, 0,0,0 on a miss. May be left empty, then no N.* channels are written.
  std::vector<float> normal;
  struct UintChannel {
    std::string name;
    std::vector<std::uint32_t> values;
  };
  struct FloatChannel {
    std::string name;
    std::vector<float> values;
  };
  // Diagnostics such as "solver.isolationSteps", one value per pixel. read_exr returns them sorted by name,
  // because that is the order EXR stores channels in.
  std::vector<UintChannel> uint_channels;
  std::vector<FloatChannel> float_channels;
  // EXR header metadata, e.g. {"algray/equation", "..."} and {"algray/tolerance", 1e-9}.
  std::vector<std::pair<std::string, std::string>> string_attributes;
  std::vector<std::pair<std::string, double>> double_attributes;
  // Row-major: element [r*4+c] is Imath::M44f[r][c]. Imath multiplies row vectors (p' = p * M), so a
  // translation lives in elements 12..14; callers using column vectors must transpose.
  std::optional<std::array<float, 16>> world_to_camera;  // standard worldToCamera attribute
  std::optional<std::array<float, 16>> world_to_ndc;     // standard worldToNDC attribute
};

enum class ImageFormat { Exr, Png };

// ".png" for "a/B.PNG": the extension, lower case, with its dot; "" without one.
std::string lowercase_extension(const std::filesystem::path& p);

// An sRGB-encoded value in [0, 1] (a display colour, as other programs write them) as linear light.
double srgb_to_linear(double c);

// Case-insensitive .exr / .png; anything else throws OutputError.
ImageFormat format_from_extension(const std::filesystem::path& p);

// All writers go through a hidden temporary file in the destination's directory
// (".name.tmp-<pid>-<counter>") that is renamed over the destination only after a complete,
// fsync'd write, so readers never see a partial image. On failure the temporary is removed, the
// destination is left untouched and OutputError names the path and the reason. A missing
// directory is an error, never created.
void write_image(const std::filesystem::path& path, const FrameImage& image);  // picks by extension
// EXR: R,G,B,A half; Z and N.X/N.Y/N.Z float; extra channels uint/float; ZIP compression.
void write_exr(const std::filesystem::path& path, const FrameImage& image);
// PNG: 8-bit sRGB-encoded RGB, or RGBA when some alpha does not round to 255; tagged with sRGB/gAMA/cHRM.
void write_png(const std::filesystem::path& path, const FrameImage& image);
// Text (SVG, JSON, ...) byte for byte, through the same temporary file and rename as the images.
void write_text_file(const std::filesystem::path& path, const std::string& text);

// Installs (once) SIGINT/SIGTERM/SIGHUP handlers that unlink any temporary file being written, then
// re-raise the signal with its default action, so interrupted runs leave nothing behind. A signal that
// is ignored at the time of the call (e.g. SIGHUP under nohup) stays ignored. Call at program start.
void install_output_cleanup_handlers();

// Reads an EXR back into the algray layout (for tests and tools): R,G,B,A into rgba (missing colour
// reads 0, missing alpha 1), Z into depth, N.* into normal, every other channel into uint_channels
// (UINT) or float_channels (HALF/FLOAT), all string/double attributes and the two matrices. Vectors for
// absent channels stay empty. Throws OutputError on failure.
FrameImage read_exr(const std::filesystem::path& path);

}  // namespace algray
