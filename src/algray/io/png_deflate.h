// A PNG's image data (its IDAT chunks) deflated band by band on every core, and the IEND chunk after it.
#pragma once

#include <cstddef>
#include <cstdio>
#include <functional>

namespace algray {

// Writes `count` rows from row y0 on into `out`, row_bytes each, one after another (no filter bytes). Called
// from several threads at once, each with its own rows and buffer.
using PngRowSource = std::function<void(std::size_t y0, std::size_t count, unsigned char* out)>;

// Writes to `fp` the IDAT chunks of an image of `height` rows of `row_bytes` bytes (8-bit samples, so the Up
// filter's byte distance is irrelevant), then IEND: the file's signature, header and text must be written
// already. Rows are Up-filtered and deflated at zlib level `level` in bands of about `band_bytes` on up to
// `threads` threads (0: one per core), at most two bands per thread in memory at once. Each band is deflated
// alone and ended with a full flush, so that the bands' outputs in order, between one zlib header and the
// Adler-32 of all the rows (combined from the bands'), are one valid zlib stream. Throws WriteError ("write
// failed: ...", "zlib: ...") or what `rows` throws, once every thread has stopped.
void write_png_image_data(std::FILE* fp, std::size_t height, std::size_t row_bytes, const PngRowSource& rows,
                          int level = 1, std::size_t band_bytes = std::size_t{1} << 18, unsigned threads = 0);

}  // namespace algray
