// Tests for the view's frame codecs: JPEG and WebP decode back to the frame within lossy tolerances, alpha is kept
// (WebP) or matted (JPEG), and frames they cannot take are refused before any encoding.
#include "algray/io/frame_codecs.h"

#include <jpeglib.h>
#include <webp/decode.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

// A smooth frame with an edge, as a render has: a gradient, and a disc of another colour.
std::vector<std::uint8_t> test_frame(int w, int h, std::uint8_t alpha) {
  std::vector<std::uint8_t> px(4 * static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = &px[4 * (static_cast<std::size_t>(y) * w + x)];
      const bool disc = std::hypot(x - w / 2.0, y - h / 2.0) < w / 4.0;
      p[0] = disc ? 230 : static_cast<std::uint8_t>(255 * x / w);
      p[1] = disc ? 120 : static_cast<std::uint8_t>(255 * y / h);
      p[2] = disc ? 20 : 90;
      p[3] = alpha;
    }
  return px;
}

std::vector<std::uint8_t> decode_jpeg(const std::string& data, int& w, int& h) {
  jpeg_decompress_struct info{};
  jpeg_error_mgr error{};
  info.err = jpeg_std_error(&error);
  jpeg_create_decompress(&info);
  jpeg_mem_src(&info, reinterpret_cast<const unsigned char*>(data.data()), data.size());
  jpeg_read_header(&info, TRUE);
  info.out_color_space = JCS_RGB;
  jpeg_start_decompress(&info);
  w = static_cast<int>(info.output_width);
  h = static_cast<int>(info.output_height);
  std::vector<std::uint8_t> rgb(3 * static_cast<std::size_t>(w) * h);
  while (info.output_scanline < info.output_height) {
    JSAMPROW row = rgb.data() + 3 * static_cast<std::size_t>(info.output_scanline) * w;
    jpeg_read_scanlines(&info, &row, 1);
  }
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  return rgb;
}

// The mean absolute difference per channel between `rgb` (3 or 4 channels) and the frame's colour over `matte`.
double mean_error(const std::vector<std::uint8_t>& got, int channels, const std::vector<std::uint8_t>& frame,
                  int matte) {
  double sum = 0;
  const std::size_t n = frame.size() / 4;
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      const double a = frame[4 * i + 3] / 255.0;
      sum += std::abs(got[channels * i + c] - (frame[4 * i + c] * a + matte * (1 - a)));
    }
  return sum / (3.0 * static_cast<double>(n));
}

}  // namespace

TEST_CASE("JPEG decodes back to the frame, opaque or over its matte") {
  const int w = 96, h = 64;
  for (const std::uint8_t alpha : {std::uint8_t{255}, std::uint8_t{128}}) {
    const std::vector<std::uint8_t> frame = test_frame(w, h, alpha);
    const std::string jpeg = algray::encode_jpeg(frame.data(), w, h, 90, {34, 34, 34});
    REQUIRE(jpeg.substr(0, 2) == "\xFF\xD8");
    int dw = 0, dh = 0;
    const std::vector<std::uint8_t> rgb = decode_jpeg(jpeg, dw, dh);
    CHECK(dw == w);
    CHECK(dh == h);
    INFO("alpha " << int(alpha));
    CHECK(mean_error(rgb, 3, frame, 34) < 3.0);
  }
  // A lower quality is a smaller file.
  const std::vector<std::uint8_t> frame = test_frame(w, h, 255);
  CHECK(algray::encode_jpeg(frame.data(), w, h, 30).size() < algray::encode_jpeg(frame.data(), w, h, 95).size());
}

TEST_CASE("WebP decodes back to the frame, with its alpha") {
  const int w = 96, h = 64;
  for (const std::uint8_t alpha : {std::uint8_t{255}, std::uint8_t{100}}) {
    const std::vector<std::uint8_t> frame = test_frame(w, h, alpha);
    const std::string webp = algray::encode_webp(frame.data(), w, h, 90);
    REQUIRE(webp.substr(0, 4) == "RIFF");
    int dw = 0, dh = 0;
    std::uint8_t* decoded =
        WebPDecodeRGBA(reinterpret_cast<const std::uint8_t*>(webp.data()), webp.size(), &dw, &dh);
    REQUIRE(decoded != nullptr);
    const std::vector<std::uint8_t> rgba(decoded, decoded + 4 * static_cast<std::size_t>(dw) * dh);
    WebPFree(decoded);
    CHECK(dw == w);
    CHECK(dh == h);
    // Colour against the frame's own (no matte: the alpha goes with it), and the alpha exact (stored lossless).
    std::vector<std::uint8_t> opaque = frame;
    for (std::size_t i = 3; i < opaque.size(); i += 4) opaque[i] = 255;
    INFO("alpha " << int(alpha));
    CHECK(mean_error(rgba, 4, opaque, 0) < 4.0);
    bool alpha_kept = true;
    for (std::size_t i = 3; i < rgba.size(); i += 4) alpha_kept = alpha_kept && rgba[i] == alpha;
    CHECK(alpha_kept);
  }
}

TEST_CASE("The codecs refuse frames they cannot take, naming why") {
  const std::vector<std::uint8_t> frame = test_frame(8, 8, 255);
  using algray::CodecError;
  CHECK_THROWS_WITH(algray::encode_jpeg(frame.data(), 0, 8, 80), Catch::Contains("from 1 to 65500"));
  CHECK_THROWS_WITH(algray::encode_jpeg(frame.data(), 8, 8, 0), Catch::Contains("quality 0"));
  CHECK_THROWS_AS(algray::encode_jpeg(nullptr, 8, 8, 80), CodecError);
  CHECK_THROWS_WITH(algray::encode_webp(frame.data(), 20000, 8, 80), Catch::Contains("from 1 to 16383"));
  CHECK_THROWS_WITH(algray::encode_webp(frame.data(), 8, 8, 101), Catch::Contains("quality 101"));
  CHECK_THROWS_WITH(algray::encode_webp(frame.data(), 8, 8, 80, 7), Catch::Contains("effort 7"));
}
