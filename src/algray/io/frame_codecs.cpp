// JPEG through libjpeg-turbo and WebP through libwebp, both into memory, with their inputs checked first.
#include "algray/io/frame_codecs.h"

// jpeglib.h needs FILE and size_t declared before it.
#include <cstddef>
#include <cstdio>
#include <csetjmp>
#include <cstdlib>
#include <memory>
#include <vector>

#include <jpeglib.h>
#include <webp/encode.h>

namespace algray {
namespace {

void check_frame(const char* format, const std::uint8_t* rgba, int width, int height, int quality, int max_side) {
  const std::string name(format);
  if (rgba == nullptr) throw CodecError(name + ": no pixels");
  if (width < 1 || height < 1 || width > max_side || height > max_side)
    throw CodecError(name + ": a frame of " + std::to_string(width) + "x" + std::to_string(height) +
                     " pixels; each side must be from 1 to " + std::to_string(max_side));
  if (quality < 1 || quality > 100)
    throw CodecError(name + ": quality " + std::to_string(quality) + "; it must be from 1 to 100");
}

bool opaque(const std::uint8_t* rgba, std::size_t pixels) {
  for (std::size_t i = 0; i < pixels; ++i)
    if (rgba[4 * i + 3] != 255) return false;
  return true;
}

// libjpeg reports a fatal error by calling error_exit, which must not return: it jumps back to the encoder,
// which then throws (a C++ exception must not cross libjpeg's C frames).
struct JpegError {
  jpeg_error_mgr manager;
  std::jmp_buf back;
  char message[JMSG_LENGTH_MAX] = "";
};

[[noreturn]] void jpeg_error_exit(j_common_ptr info) {
  auto* error = reinterpret_cast<JpegError*>(info->err);
  (*info->err->format_message)(info, error->message);
  std::longjmp(error->back, 1);
}

// The encoding itself, apart from anything with a destructor, so that the longjmp skips nothing.
bool jpeg_rows(jpeg_compress_struct& info, JpegError& error, const std::uint8_t* pixels, int width, int height,
               int channels, int quality, unsigned char** out, unsigned long* size) {
  if (setjmp(error.back) != 0) return false;
  jpeg_create_compress(&info);
  jpeg_mem_dest(&info, out, size);
  info.image_width = static_cast<JDIMENSION>(width);
  info.image_height = static_cast<JDIMENSION>(height);
  info.input_components = channels;
  // libjpeg-turbo reads RGBA as it is (the alpha byte skipped): no copy for an opaque frame.
  info.in_color_space = channels == 4 ? JCS_EXT_RGBA : JCS_RGB;
  jpeg_set_defaults(&info);
  jpeg_set_quality(&info, quality, TRUE);
  jpeg_start_compress(&info, TRUE);
  const std::size_t stride = static_cast<std::size_t>(width) * channels;
  while (info.next_scanline < info.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(pixels + info.next_scanline * stride);
    jpeg_write_scanlines(&info, &row, 1);
  }
  jpeg_finish_compress(&info);
  return true;
}

}  // namespace

std::string encode_jpeg(const std::uint8_t* rgba, int width, int height, int quality,
                        std::array<std::uint8_t, 3> matte) {
  check_frame("JPEG", rgba, width, height, quality, kMaxJpegSide);
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  // Pixels not opaque over the matte, as a browser composites a PNG: in sRGB bytes, rounded to nearest.
  std::vector<std::uint8_t> flat;
  const std::uint8_t* source = rgba;
  int channels = 4;
  if (!opaque(rgba, pixels)) {
    flat.resize(3 * pixels);
    for (std::size_t i = 0; i < pixels; ++i) {
      const unsigned a = rgba[4 * i + 3];
      for (int c = 0; c < 3; ++c) flat[3 * i + c] = static_cast<std::uint8_t>((rgba[4 * i + c] * a + matte[c] * (255 - a) + 127) / 255);
    }
    source = flat.data();
    channels = 3;
  }
  jpeg_compress_struct info{};
  JpegError error{};
  info.err = jpeg_std_error(&error.manager);
  error.manager.error_exit = jpeg_error_exit;
  unsigned char* out = nullptr;
  unsigned long size = 0;
  const bool ok = jpeg_rows(info, error, source, width, height, channels, quality, &out, &size);
  jpeg_destroy_compress(&info);
  const std::unique_ptr<unsigned char, decltype(&std::free)> owned(out, &std::free);
  if (!ok) throw std::runtime_error(std::string("libjpeg: ") + error.message);
  return std::string(reinterpret_cast<const char*>(out), size);
}

std::string encode_webp(const std::uint8_t* rgba, int width, int height, int quality, int effort) {
  check_frame("WebP", rgba, width, height, quality, kMaxWebpSide);
  if (effort < 0 || effort > 6) throw CodecError("WebP: effort " + std::to_string(effort) + "; it must be from 0 to 6");
  WebPConfig config;
  if (!WebPConfigPreset(&config, WEBP_PRESET_DEFAULT, static_cast<float>(quality)))
    throw std::runtime_error("libwebp: this libwebp is not the version algray was built with");
  config.method = effort;
  WebPPicture picture;
  if (!WebPPictureInit(&picture)) throw std::runtime_error("libwebp: this libwebp is not the version algray was built with");
  picture.width = width;
  picture.height = height;
  picture.use_argb = 0;
  WebPMemoryWriter writer;
  WebPMemoryWriterInit(&writer);
  picture.writer = WebPMemoryWrite;
  picture.custom_ptr = &writer;
  // An opaque frame is imported without its alpha, so that none is stored.
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  const bool ok = opaque(rgba, pixels) ? WebPPictureImportRGBX(&picture, rgba, 4 * width)
                                       : WebPPictureImportRGBA(&picture, rgba, 4 * width);
  const bool encoded = ok && WebPEncode(&config, &picture);
  const int code = picture.error_code;
  WebPPictureFree(&picture);
  std::string out;
  if (encoded) out.assign(reinterpret_cast<const char*>(writer.mem), writer.size);
  WebPMemoryWriterClear(&writer);
  if (!encoded) throw std::runtime_error("libwebp: encoding failed (VP8 error " + std::to_string(code) + ")");
  return out;
}

}  // namespace algray
