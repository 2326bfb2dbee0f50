// The view's HTTP server: cpp-httplib's request handling on connections it bounds in number, bytes and time.
#pragma once

#include <httplib.h>

#include <atomic>
#include <chrono>
#include <string>

#include "view_limits.h"

namespace algray::cli {

using ViewClock = std::chrono::steady_clock;

// Debian's cpp-httplib 0.11.4 is a compiled library (libcpp-httplib.so): its CPPHTTPLIB_* macros were fixed when
// it was built, so defining them here changes nothing. Its limits are 8 worker threads, a 5 s timeout per read
// (restarted by every byte, so a client trickling a header line every 2 s holds a thread forever) and 8 KiB per
// header line with no limit on their number. This server replaces the per-connection loop (the one virtual hook)
// with its own: a bounded count of connections with a spare thread to refuse the next one, a stream that caps a
// request's bytes and the time to receive its headers, and an exclusive listening socket (no SO_REUSEPORT, which
// lets a second server share the port and take half of the page's requests).
class ViewServer : public httplib::Server {
 public:
  explicit ViewServer(const ViewLimits& limits);

  // For handlers, on the thread that runs them: whether the client of this request has closed its connection,
  // and when this request's time (--request-timeout, from its first byte) runs out.
  static bool client_gone();
  static ViewClock::time_point deadline();
  // Caps the bytes the kernel queues for this request's client (SO_SNDBUF): a stream's writer then waits for a
  // slow client after little more than one frame, rather than after megabytes of stale ones.
  static void limit_send_buffer(int bytes);

 private:
  bool process_and_close_socket(socket_t sock) override;

  ViewLimits limits_;
  std::atomic<int> open_connections_{0};
};

// The JSON body of every refusal: the reason, and the limit's flag where a limit refused it.
std::string error_json(const std::string& message, const std::string& limit = {});

}  // namespace algray::cli
