// What one `algray view` server lets a client cost it: connections, request bytes and time, settings, frame size.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace algray::cli {

// Every limit has a flag (main.cpp) and is named in the 4xx answer of a request that passes it. The defaults let
// the page show any scene at its own size in full mode, and let no single request hold the server for long.
struct ViewLimits {
  int max_connections = 64;              // open at once; one more is answered 429 and closed
  int max_streams = 8;                   // pages' frame streams open at once (each holds a connection)
  std::size_t max_header_bytes = 65536;  // request line and headers together (cpp-httplib caps only each line)
  double header_timeout_s = 5;           // to receive a request's line and headers, however slowly they trickle
  double request_timeout_s = 60;         // from the request's first byte to its answer: queueing, parsing, rendering
  int max_settings = 64;                 // set= items per request (the page sends about 10 plus its parameters)
  double max_parse_ms = 2000;            // time spent applying one request's set= items, checked between items
  // camera rays x (1 + shadow points per hit) x (1 + bounces) per frame; 2^28 admits the built-in scene at 1024^2
  // in full mode (2x2 antialiasing, two 5x5 lights).
  std::uint64_t max_frame_samples = std::uint64_t{1} << 28;
};

}  // namespace algray::cli
