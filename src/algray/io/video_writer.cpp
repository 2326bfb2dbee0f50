// The video writer: the ffmpeg program fed raw frames through a pipe, its output in a pending file.
//
// Why the program and not libavcodec: the program brings the encoders, the pixel-format conversion and GIF's
// palette filters in one command line, keeps the codec libraries (and their ABI) out of algray's link, and runs
// in its own process, so that encoding overlaps rendering on another core.
#include "algray/io/video_writer.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <pthread.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "algray/util/file_names.h"
#include "algray/util/temp_files.h"

extern char** environ;

namespace algray {
namespace fs = std::filesystem;

std::optional<VideoFormat> video_format_of(const fs::path& path) {
  const std::string ext = lowercase_extension(path);
  for (const VideoFormatInfo& f : kVideoFormats)
    if (ext == f.extension) return f.format;
  return std::nullopt;
}

std::string video_extensions() {
  std::string out;
  for (std::size_t i = 0; i < kVideoFormats.size(); ++i)
    out += std::string(i == 0 ? "" : i + 1 == kVideoFormats.size() ? " or " : ", ") + kVideoFormats[i].extension;
  return out;
}

namespace {

std::string number_text(double v) {
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out << v;
  return out.str();
}

// The encoder's arguments after the input: even sizes for 4:2:0 video, a palette of the frames' own for GIF.
std::vector<std::string> encoder_arguments(VideoFormat format) {
  const std::string even = "pad=ceil(iw/2)*2:ceil(ih/2)*2";
  switch (format) {
    case VideoFormat::Mp4:
      return {"-vf", even, "-c:v", "libx264", "-preset", "medium", "-crf", "18", "-pix_fmt", "yuv420p",
              "-movflags", "+faststart", "-f", "mp4"};
    case VideoFormat::Webm:
      return {"-vf", even, "-c:v", "libvpx-vp9", "-crf", "30", "-b:v", "0", "-pix_fmt", "yuv420p", "-f", "webm"};
    case VideoFormat::Gif:
      return {"-vf", "split[a][b];[a]palettegen=stats_mode=full[p];[b][p]paletteuse=dither=none", "-loop", "0",
              "-f", "gif"};
  }
  return {};
}

}  // namespace

VideoWriter::VideoWriter(const fs::path& path, int width, int height, double fps)
    : path_(path), width_(width), height_(height) {
  const std::optional<VideoFormat> format = video_format_of(path);
  if (!format)
    throw OutputError("cannot write '" + path.string() + "': a video is " + video_extensions() + ", not '" +
                      path.extension().string() + "'");
  if (width <= 0 || height <= 0) throw OutputError("cannot write '" + path.string() + "': the frames have no pixels");
  if (!(fps > 0 && fps <= 1000))
    throw OutputError("cannot write '" + path.string() + "': the frame rate must be above 0 and at most 1000");
  output_ = std::make_unique<PendingOutput>(path);
  log_ = output_->temp_path().string() + ".log";

  std::vector<std::string> args = {"ffmpeg", "-hide_banner", "-loglevel", "error", "-y", "-f", "rawvideo",
                                    "-pix_fmt", "rgb24", "-video_size",
                                    std::to_string(width) + "x" + std::to_string(height), "-framerate",
                                    number_text(fps), "-i", "pipe:0"};
  for (std::string& a : encoder_arguments(*format)) args.push_back(std::move(a));
  args.push_back(output_->temp_path().string());

  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw WriteError("cannot write '" + path.string() + "': no pipe for ffmpeg");
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], 0);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, log_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = ::posix_spawnp(&pid, "ffmpeg", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[0]);
  if (rc != 0) {
    ::close(fds[1]);
    std::error_code ignored;
    fs::remove(log_, ignored);
    throw WriteError("cannot write '" + path.string() + "': the ffmpeg program could not be started (" +
                     std::strerror(rc) + "); videos need it: apt-get install ffmpeg");
  }
  pid_ = pid;
  pipe_ = fds[1];
}

VideoWriter::~VideoWriter() {
  if (pid_ > 0) {
    ::kill(pid_, SIGTERM);
    stop();
  }
  std::error_code ignored;
  fs::remove(log_, ignored);
}

void VideoWriter::stop() {
  if (pipe_ >= 0) ::close(pipe_);
  pipe_ = -1;
  if (pid_ > 0) {
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
  }
  pid_ = -1;
}

std::string VideoWriter::ffmpeg_message() const {
  std::ifstream in(log_);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  if (text.size() > 2000) text = "..." + text.substr(text.size() - 2000);
  return text.empty() ? "no message" : text;
}

void VideoWriter::add(const FrameImage& frame) {
  if (frame.width != width_ || frame.height != height_)
    throw OutputError("cannot write '" + path_.string() + "': frame " + std::to_string(frames_) + " is " +
                      std::to_string(frame.width) + "x" + std::to_string(frame.height) + ", the video " +
                      std::to_string(width_) + "x" + std::to_string(height_));
  if (pipe_ < 0) throw WriteError("cannot write '" + path_.string() + "': the video is already finished");
  const std::size_t pixels = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  if (frame.rgba.size() != 4 * pixels) throw OutputError("cannot write '" + path_.string() + "': a frame is malformed");
  std::vector<std::uint8_t> bytes(3 * pixels);
  for (std::size_t i = 0; i < pixels; ++i) {
    const float alpha = std::clamp(frame.rgba[4 * i + 3], 0.0f, 1.0f);
    for (std::size_t c = 0; c < 3; ++c) bytes[3 * i + c] = srgb_byte(frame.rgba[4 * i + c] * alpha);
  }
  // A pipe whose reader has died raises SIGPIPE, which would end the whole program: it is held back while
  // writing, and a pending one taken, so that ffmpeg's end is an error with its message instead.
  sigset_t pipe_signal, previous;
  sigemptyset(&pipe_signal);
  sigaddset(&pipe_signal, SIGPIPE);
  ::pthread_sigmask(SIG_BLOCK, &pipe_signal, &previous);
  std::size_t written = 0;
  bool broken = false;
  while (written < bytes.size()) {
    const ssize_t n = ::write(pipe_, bytes.data() + written, bytes.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      broken = true;
      break;
    }
    written += static_cast<std::size_t>(n);
  }
  if (broken) {
    const timespec now{0, 0};
    ::sigtimedwait(&pipe_signal, nullptr, &now);
  }
  ::pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  if (broken) {
    stop();
    throw WriteError("cannot write '" + path_.string() + "': ffmpeg stopped: " + ffmpeg_message());
  }
  ++frames_;
}

void VideoWriter::finish() {
  if (pipe_ >= 0) ::close(pipe_);
  pipe_ = -1;
  int status = 0;
  if (pid_ > 0)
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
  pid_ = -1;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw WriteError("cannot write '" + path_.string() + "': ffmpeg failed: " + ffmpeg_message());
  if (frames_ == 0) throw WriteError("cannot write '" + path_.string() + "': no frame was rendered");
  output_->commit();
  std::error_code ignored;
  fs::remove(log_, ignored);
}

}  // namespace algray
