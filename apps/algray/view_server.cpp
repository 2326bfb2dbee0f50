// The view's HTTP server: the per-connection loop with its limits, and the stream that enforces them.
#include "view_server.h"

#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <nlohmann/json.hpp>

#include "algray/util/json_text.h"
#include "view_query.h"

namespace algray::cli {
namespace {

// The connection whose request this thread is handling, for client_gone() and deadline(): cpp-httplib 0.11.4
// gives a handler neither its socket nor a way to ask.
thread_local socket_t current_socket = INVALID_SOCKET;
thread_local ViewClock::time_point current_deadline;

ViewClock::duration seconds(double s) {
  return std::chrono::duration_cast<ViewClock::duration>(std::chrono::duration<double>(s));
}

// Waits for `events` on `sock` until `until`: false when the time ran out first. A hang-up or error counts as
// ready, so that the recv or send after it reports it.
bool wait_for(socket_t sock, short events, ViewClock::time_point until) {
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - ViewClock::now()).count();
    if (left <= 0) return false;
    pollfd p{sock, events, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(std::min<long long>(left + 1, 1000)));
    if (ready > 0 || (ready < 0 && errno != EINTR)) return true;
  }
}

const char* reason_phrase(int status) {
  switch (status) {
    case 408:
      return "Request Timeout";
    case 429:
      return "Too Many Requests";
    case 414:
      return "URI Too Long";
    case 431:
      return "Request Header Fields Too Large";
    default:
      return "Error";
  }
}

std::string address_of(const sockaddr_storage& a, socklen_t len, int& port) {
  char host[NI_MAXHOST] = "", serv[NI_MAXSERV] = "";
  if (::getnameinfo(reinterpret_cast<const sockaddr*>(&a), len, host, sizeof host, serv, sizeof serv,
                    NI_NUMERICHOST | NI_NUMERICSERV) != 0)
    return {};
  port = std::atoi(serv);
  return host;
}

// A connection's socket as cpp-httplib reads and writes it, counting what one request may take: at most
// --max-header-bytes, and its line and headers within --header-timeout however slowly they come. Past either it
// answers the limit itself and stops; cpp-httplib's own answer to the failed read (a bare 400) is then dropped.
// Writes never raise SIGPIPE (a client that left mid-answer).
class LimitedStream final : public httplib::Stream {
 public:
  LimitedStream(socket_t sock, const ViewLimits& limits, ViewClock::duration write_timeout)
      : sock_(sock), limits_(limits), write_timeout_(write_timeout) {}

  void start_request() {
    const auto now = ViewClock::now();
    header_deadline_ = now + seconds(limits_.header_timeout_s);
    request_deadline_ = now + seconds(limits_.request_timeout_s);
    bytes_left_ = limits_.max_header_bytes;
    in_request_line_ = true;
    line_bytes_ = 0;
  }
  ViewClock::time_point request_deadline() const { return request_deadline_; }
  bool buffered() const { return pos_ < len_; }
  bool refused() const { return refused_; }

  void refuse(int status, const std::string& message, const std::string& limit) {
    if (refused_) return;
    const std::string body = error_json(message, limit);
    const std::string head = "HTTP/1.1 " + std::to_string(status) + " " + reason_phrase(status) +
                             "\r\nContent-Type: application/json\r\nContent-Length: " + std::to_string(body.size()) +
                             "\r\nConnection: close\r\n\r\n";
    send_all(head + body);
    refused_ = true;
  }

  bool is_readable() const override {
    return buffered() || wait_for(sock_, POLLIN, std::min(header_deadline_, request_deadline_));
  }
  bool is_writable() const override { return !refused_ && wait_for(sock_, POLLOUT, ViewClock::now() + write_timeout_); }

  ssize_t read(char* ptr, size_t size) override {
    if (refused_) return -1;
    if (bytes_left_ == 0) {
      refuse(431,
             "the request's line and headers are longer than --max-header-bytes (" +
                 std::to_string(limits_.max_header_bytes) + " bytes)",
             "--max-header-bytes");
      return -1;
    }
    if (!buffered()) {
      if (!wait_for(sock_, POLLIN, header_deadline_)) {
        refuse(408,
               "the request's line and headers took longer than --header-timeout (" +
                   format_number(limits_.header_timeout_s) + " s) to arrive",
               "--header-timeout");
        return -1;
      }
      ssize_t n;
      do n = ::recv(sock_, buffer_, sizeof buffer_, 0);
      while (n < 0 && errno == EINTR);
      if (n <= 0) return n;
      pos_ = 0;
      len_ = static_cast<std::size_t>(n);
    }
    const std::size_t n = std::min({size, len_ - pos_, bytes_left_});
    if (in_request_line_) {
      const void* end = std::memchr(buffer_ + pos_, '\n', n);
      in_request_line_ = end == nullptr;
      line_bytes_ += end ? static_cast<const char*>(end) - (buffer_ + pos_) : n;
      // cpp-httplib's own refusal of a long URL is a bare 414 on a connection it keeps open.
      if (line_bytes_ > CPPHTTPLIB_REQUEST_URI_MAX_LENGTH) {
        refuse(414,
               "the request line is longer than " + std::to_string(CPPHTTPLIB_REQUEST_URI_MAX_LENGTH) +
                   " bytes, cpp-httplib's limit on a URL",
               "request line");
        return -1;
      }
    }
    std::memcpy(ptr, buffer_ + pos_, n);
    pos_ += n;
    bytes_left_ -= n;
    return static_cast<ssize_t>(n);
  }

  ssize_t write(const char* ptr, size_t size) override {
    if (refused_) return static_cast<ssize_t>(size);
    return send_all(std::string_view(ptr, size)) ? static_cast<ssize_t>(size) : -1;
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage a{};
    socklen_t len = sizeof a;
    if (::getpeername(sock_, reinterpret_cast<sockaddr*>(&a), &len) == 0) ip = address_of(a, len, port);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage a{};
    socklen_t len = sizeof a;
    if (::getsockname(sock_, reinterpret_cast<sockaddr*>(&a), &len) == 0) ip = address_of(a, len, port);
  }
  socket_t socket() const override { return sock_; }

 private:
  bool send_all(std::string_view data) {
    const auto until = ViewClock::now() + write_timeout_;
    while (!data.empty()) {
      if (!wait_for(sock_, POLLOUT, until)) return false;
      const ssize_t n = ::send(sock_, data.data(), data.size(), MSG_NOSIGNAL);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return false;
      data.remove_prefix(static_cast<std::size_t>(n));
    }
    return true;
  }

  socket_t sock_;
  const ViewLimits& limits_;
  ViewClock::duration write_timeout_;
  char buffer_[4096];
  std::size_t pos_ = 0, len_ = 0;
  std::size_t bytes_left_ = 0;
  bool in_request_line_ = true;
  std::size_t line_bytes_ = 0;
  ViewClock::time_point header_deadline_, request_deadline_;
  bool refused_ = false;
};

// Closes a connection refused before its request was read in full: the unread request would otherwise make the close a
// reset, which can destroy the answer before the client reads it. Bounded: 100 ms and 64 KiB.
void drain_and_close(socket_t sock) {
  ::shutdown(sock, SHUT_WR);
  const auto until = ViewClock::now() + std::chrono::milliseconds(100);
  char sink[4096];
  for (std::size_t total = 0; total < 65536 && wait_for(sock, POLLIN, until);) {
    const ssize_t n = ::recv(sock, sink, sizeof sink, MSG_DONTWAIT);
    if (n <= 0) break;
    total += static_cast<std::size_t>(n);
  }
  ::close(sock);
}

}  // namespace

std::string error_json(const std::string& message, const std::string& limit) {
  nlohmann::json body{{"error", message}};
  if (!limit.empty()) body["limit"] = limit;
  return algray::dump_json(body);
}

ViewServer::ViewServer(const ViewLimits& limits) : limits_(limits) {
  // Spare threads beyond the connection limit, so that a connection over it is refused at once rather than
  // queued behind the ones holding every thread.
  new_task_queue = [threads = static_cast<std::size_t>(limits.max_connections) + 4] {
    return new httplib::ThreadPool(threads);
  };
  set_socket_options([](socket_t sock) {
    const int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
}

bool ViewServer::client_gone() {
  if (current_socket == INVALID_SOCKET) return false;
  pollfd p{current_socket, POLLRDHUP, 0};
  return ::poll(&p, 1, 0) > 0 && (p.revents & (POLLRDHUP | POLLHUP | POLLERR)) != 0;
}

ViewClock::time_point ViewServer::deadline() { return current_deadline; }

void ViewServer::limit_send_buffer(int bytes) {
  if (current_socket != INVALID_SOCKET) ::setsockopt(current_socket, SOL_SOCKET, SO_SNDBUF, &bytes, sizeof bytes);
}

bool ViewServer::process_and_close_socket(socket_t sock) {
  struct Count {
    std::atomic<int>& open;
    ~Count() { --open; }
  } count{open_connections_};
  const int open = ++open_connections_;
  // Every answer, and every message of a stream, is written whole: Nagle's algorithm would only hold its last
  // segment back until the client's delayed ACK (measured: 40 ms on a state's answer after the first few).
  const int yes = 1;
  ::setsockopt(sock, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);
  LimitedStream stream(sock, limits_,
                       std::chrono::seconds(write_timeout_sec_) + std::chrono::microseconds(write_timeout_usec_));
  if (open > limits_.max_connections) {
    stream.refuse(
        429,
        "the server already has --max-connections (" + std::to_string(limits_.max_connections) + ") connections open",
        "--max-connections");
    drain_and_close(sock);
    return false;
  }
  bool ok = false;
  for (std::size_t left = keep_alive_max_count_; left > 0 && svr_sock_ != INVALID_SOCKET; --left) {
    if (!stream.buffered() && !wait_for(sock, POLLIN, ViewClock::now() + std::chrono::seconds(keep_alive_timeout_sec_)))
      break;
    stream.start_request();
    current_socket = sock;
    current_deadline = stream.request_deadline();
    bool closed = false;
    ok = process_request(stream, left == 1, closed, nullptr);
    current_socket = INVALID_SOCKET;
    if (!ok || closed || stream.refused()) break;
  }
  if (stream.refused()) {
    drain_and_close(sock);
  } else {
    ::shutdown(sock, SHUT_RDWR);
    ::close(sock);
  }
  return ok;
}

}  // namespace algray::cli
