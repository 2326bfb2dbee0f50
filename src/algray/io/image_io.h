// Rendered-frame container and its EXR/PNG (and plain text) writers, which replace the output file atomically.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "algray/math/colour.h"
#include "algray/util/file_names.h"

namespace algray {

// An output that cannot be written as asked, found before anything is written: a bad path (missing directory,
// a directory as destination, a name too long), an unsupported extension, a malformed image. Bad input.
struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The path was fine but the write itself failed: creating, writing, fsync'ing or renaming the temporary file
// (disk full, file too large, I/O error). Deliberately not an OutputError: the input was not at fault.
struct WriteError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The PNG text key under which a render stores its scene's TOML text, so that the image can be rendered again.
inline constexpr const char* kPngSceneKey = "algray:scene";

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

  // The EXR `software` attribute and the PNG "Software" text; empty: version_string(). read_exr and
  // read_png_text report what the file holds (empty if nothing).
  std::string software;
  // The EXR `comments` attribute and the PNG "Comment" text, e.g. the equation; written only when non-empty.
  // read_exr fills this field and software, never string_attributes, with those two attributes.
  std::string comments;
  // PNG only: further text chunks, in this order, keys of 1 to 79 printable ASCII characters (no leading,
  // trailing or double spaces) other than "Software" and "Comment", each used once; values UTF-8 without NUL,
  // at most kMaxPngTextBytes. Short ASCII values go into tEXt, others into iTXt, compressed above 1 KiB.
  std::vector<std::pair<std::string, std::string>> png_text;
  // Filled by read_exr from the standard `chromaticities` attribute: red x,y, green x,y, blue x,y, white x,y.
  // The writers ignore it: every EXR is tagged Rec.709/sRGB primaries with a D65 white, the renderer's colours.
  std::optional<std::array<float, 8>> chromaticities;
};

// The longest PNG text value written or read, after decompression. A scene is a few KB.
inline constexpr std::size_t kMaxPngTextBytes = 4u << 20;

enum class ImageFormat { Exr, Png };

// The byte write_png stores for a linear value: the sRGB transfer function, times 255, rounded to nearest;
// 0 for NaN and values <= 0, 255 from 1 on.
std::uint8_t srgb_byte(float linear);

// The image as 8-bit sRGB RGBA, 4 bytes per pixel, row-major: the bytes write_png stores for each pixel (its
// alpha 255 where the PNG has none), for callers that show an image rather than save it.
std::vector<std::uint8_t> srgba_bytes(const FrameImage& image);

// Case-insensitive .exr / .png; anything else throws OutputError.
ImageFormat format_from_extension(const std::filesystem::path& p);

// The checks every writer makes before writing, so that callers can make them before a long render: the
// directory exists, is a directory and is writable, the destination is not a directory, the file name fits
// the file system's NAME_MAX and the path PATH_MAX. Throws OutputError "cannot write 'PATH': REASON". A
// missing directory is an error, never created. The extension is not checked here (see format_from_extension).
void check_output_path(const std::filesystem::path& path);

// All writers go through a hidden temporary file in the destination's directory
// (".name.tmp-<pid>-<counter>", the name cut to 200 bytes) that is renamed over the destination only after a
// complete, fsync'd write, so readers never see a partial image. They first make check_output_path's checks
// and validate the image (OutputError); a failure after that, while creating, writing, syncing or renaming
// the temporary, is a WriteError. Either way the temporary is removed, the destination is left untouched and
// the message names the path and the reason.
// Before writing, temporaries for the same name left by dead processes (killed by SIGKILL, say) are removed:
// those whose pid is no live process and which have not been modified for a minute. A live pid's file is a
// concurrent writer's and is kept; the minute spares a writer on another machine sharing the directory, whose
// pid means nothing here.
void write_image(const std::filesystem::path& path, const FrameImage& image);  // picks by extension
// EXR: R,G,B,A half; Z and N.X/N.Y/N.Z float; extra channels uint/float; ZIP compression. The header carries
// software, comments (if any) and chromaticities besides the attributes of the image; string_attributes
// named "software", "comments" or any other standard attribute are refused.
void write_exr(const std::filesystem::path& path, const FrameImage& image);
// PNG: 8-bit sRGB-encoded RGB, or RGBA when some alpha does not round to 255; tagged with sRGB/gAMA/cHRM;
// text chunks "Software", "Comment" (if any) and png_text. string_attributes are not written.
void write_png(const std::filesystem::path& path, const FrameImage& image);
// The bytes write_png would put in the file, in memory (for a frame served or shown, not saved).
std::string png_bytes(const FrameImage& image);
// Text (SVG, JSON, ...) byte for byte, through the same temporary file and rename as the images.
void write_text_file(const std::filesystem::path& path, const std::string& text);

// A file written over a long time by someone else (a video, by the ffmpeg program), with the writers' guarantees:
// check_output_path's checks on construction (OutputError), a hidden temporary beside the destination that a
// signal, the destructor or a failure removes, and commit() to fsync it and rename it over the destination
// (WriteError).
class PendingOutput {
 public:
  explicit PendingOutput(const std::filesystem::path& destination);
  ~PendingOutput();
  PendingOutput(const PendingOutput&) = delete;
  PendingOutput& operator=(const PendingOutput&) = delete;
  const std::filesystem::path& temp_path() const;
  void commit();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Installs (once) SIGINT/SIGTERM/SIGHUP handlers that unlink any temporary file being written, then
// re-raise the signal with its default action, so interrupted runs leave nothing behind. A signal that
// is ignored at the time of the call (e.g. SIGHUP under nohup) stays ignored. Call at program start.
void install_output_cleanup_handlers();

// Reads an EXR back into the algray layout (for tests and tools): R,G,B,A into rgba (missing colour
// reads 0, missing alpha 1), Z into depth, N.* into normal, every other channel into uint_channels
// (UINT) or float_channels (HALF/FLOAT), software, comments and chromaticities into their fields, all other
// string/double attributes and the two matrices. Vectors for absent channels stay empty. Throws OutputError
// on failure.
FrameImage read_exr(const std::filesystem::path& path);

// Reads a PNG's pixels back as a frame (sRGB values to linear, straight alpha), for a video made of images
// written earlier (`algray batch --merge-logs --video`). Throws OutputError on failure.
FrameImage read_png_pixels(const std::filesystem::path& path);

// Whether the file starts with the 8-byte PNG signature. False when it cannot be read; never throws.
bool is_png_file(const std::filesystem::path& path);

// Every tEXt, zTXt and iTXt chunk of a PNG, before and after the image data, in file order, as UTF-8 (tEXt and
// zTXt hold Latin-1, converted). Reads the whole file, so a PNG that is truncated, corrupt (a bad CRC included)
// or not a PNG at all throws OutputError, as does a text chunk longer than kMaxPngTextBytes.
std::vector<std::pair<std::string, std::string>> read_png_text(const std::filesystem::path& path);

}  // namespace algray
