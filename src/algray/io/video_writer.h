// Videos (.mp4, .webm, .gif) encoded from frames handed over one at a time, in order, by the ffmpeg program, and
// written atomically like the images.
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "algray/io/image_io.h"

namespace algray {

enum class VideoFormat { Mp4, Webm, Gif };

struct VideoFormatInfo {
  VideoFormat format;
  const char* extension;  // lower case, with its dot
  const char* what;
};

// The one list of video types: what --video, the jobs file's checks, the help and the tests read.
inline constexpr std::array<VideoFormatInfo, 3> kVideoFormats = {{
    {VideoFormat::Mp4, ".mp4", "H.264 in MP4"},
    {VideoFormat::Webm, ".webm", "VP9 in WebM"},
    {VideoFormat::Gif, ".gif", "an animated GIF"},
}};

// By extension (any case); nullopt for none of kVideoFormats.
std::optional<VideoFormat> video_format_of(const std::filesystem::path& path);
// ".mp4, .webm or .gif", for messages.
std::string video_extensions();

// Encodes frames as they come: ffmpeg runs beside the renderer, reading raw 8-bit sRGB frames from a pipe and
// writing a hidden temporary beside `path` that finish() renames over it. Frames may be any size other than
// the first's: each must match it. Alpha is composited over black (video has none).
class VideoWriter {
 public:
  // OutputError: an unknown extension, an unwritable path, a size of zero or a frame rate that is not positive.
  // WriteError: ffmpeg cannot be started (it is not installed: the message says how to install it).
  VideoWriter(const std::filesystem::path& path, int width, int height, double fps);
  // Abandons an unfinished video: ffmpeg is stopped and the temporary removed; the destination is untouched.
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  // OutputError for a frame of another size; WriteError when ffmpeg has stopped (its message included).
  void add(const FrameImage& frame);
  // Ends the stream, waits for ffmpeg and puts the video in place (WriteError with ffmpeg's message on failure).
  void finish();
  int frames() const { return frames_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  void stop();
  std::string ffmpeg_message() const;

  std::filesystem::path path_;
  std::unique_ptr<PendingOutput> output_;
  std::filesystem::path log_;
  int width_, height_, frames_ = 0;
  int pipe_ = -1;
  int pid_ = -1;
};

}  // namespace algray
