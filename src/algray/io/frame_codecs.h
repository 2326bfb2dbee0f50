// JPEG and WebP encodings of an 8-bit sRGB RGBA frame in memory, for frames shown rather than saved (PNG is image_io's).
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace algray {

// A frame the encoders cannot take: a size of zero or past the format's limit, a quality outside 1-100, or
// fewer bytes than width x height x 4. Bad input, found before any encoding.
struct CodecError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The largest side each format stores: JPEG's 16-bit sizes, WebP's 14-bit ones.
inline constexpr int kMaxJpegSide = 65500;
inline constexpr int kMaxWebpSide = 16383;

// `rgba`: width x height x 4 bytes, row-major, top row first, straight alpha (image_io's srgba_bytes).

// Baseline JPEG at `quality` (1-100, libjpeg's scale), 4:2:0 chroma. JPEG has no alpha: a pixel that is not
// opaque is shown over `matte` (sRGB bytes), as a page shows it over its own backdrop.
std::string encode_jpeg(const std::uint8_t* rgba, int width, int height, int quality,
                        std::array<std::uint8_t, 3> matte = {0, 0, 0});

// Lossy WebP at `quality` (1-100), with its alpha kept (lossless) where some pixel is not opaque. `effort` is
// libwebp's method, 0 (fastest) to 6.
std::string encode_webp(const std::uint8_t* rgba, int width, int height, int quality, int effort = 0);

}  // namespace algray
