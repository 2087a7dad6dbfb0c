// GuardedServer: httplib's keep-alive loop (process_request per request) over our own Stream, which
// enforces the per-request deadline and byte caps; the 503 for connections over the cap; a
// lingering close so a refused client still reads its answer.
#include "connection.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <string>

namespace srv {

namespace {

using Clock = std::chrono::steady_clock;

// Waits until the socket is ready for `events` or `until` passes, in slices of 100 ms so that a
// server stop (svr_sock closed) ends the wait. 1: ready (or hung up), 0: timed out, -1: error or stop.
int wait_ready(socket_t sock, short events, Clock::time_point until, const std::atomic<socket_t>& svr_sock) {
  for (;;) {
    if (svr_sock == INVALID_SOCKET) return -1;
    long long left = std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now()).count();
    if (left <= 0) return 0;
    pollfd p{sock, events, 0};
    int n = ::poll(&p, 1, int(std::min(left, 100LL)));
    if (n < 0 && errno != EINTR) return -1;
    if (n > 0) return 1;
  }
}

Clock::time_point after(double seconds) {
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

void ip_and_port(const sockaddr_storage& addr, std::string& ip, int& port) {
  char buf[INET6_ADDRSTRLEN] = "";
  if (addr.ss_family == AF_INET) {
    auto* a = reinterpret_cast<const sockaddr_in*>(&addr);
    inet_ntop(AF_INET, &a->sin_addr, buf, sizeof buf);
    port = ntohs(a->sin_port);
  } else if (addr.ss_family == AF_INET6) {
    auto* a = reinterpret_cast<const sockaddr_in6*>(&addr);
    inet_ntop(AF_INET6, &a->sin6_addr, buf, sizeof buf);
    port = ntohs(a->sin6_port);
  }
  ip = buf;
}

// The Stream httplib reads requests from and writes responses to. Reads are buffered (httplib
// reads the head a byte at a time) and accounted: head bytes up to the blank line, then body bytes.
class GuardedStream final : public httplib::Stream {
 public:
  GuardedStream(socket_t sock, const std::atomic<socket_t>& svr_sock, const ConnectionLimits& limits,
                size_t max_body, double write_timeout)
      : m_sock(sock), m_svr_sock(svr_sock), m_limits(limits), m_max_body(max_body), m_write_timeout(write_timeout) {}

  // Starts the clock and the byte counts for the next request on this connection.
  void begin_request() {
    m_deadline = after(m_limits.request_timeout);
    m_in_head = true;
    m_head = m_body = 0;
    m_tail = 0;
    m_failure = ReadFailure::none;
    m_status = 0;
  }
  // Waits (up to the keep-alive timeout) for the first byte of another request.
  bool wait_for_request(double seconds) const {
    return m_pos < m_len || wait_ready(m_sock, POLLIN, after(seconds), m_svr_sock) == 1;
  }
  ReadFailure failure() const { return m_failure; }
  void extend_deadline(double seconds) { m_deadline = std::max(m_deadline, after(seconds)); }
  int status() const { return m_status; }  // of the response to the current request; 0 before it starts

  bool is_readable() const override {
    return m_pos < m_len || wait_ready(m_sock, POLLIN, m_deadline, m_svr_sock) == 1;
  }
  bool is_writable() const override {
    return wait_ready(m_sock, POLLOUT, after(m_write_timeout), m_svr_sock) == 1;
  }

  ssize_t read(char* ptr, size_t size) override {
    if (m_failure != ReadFailure::none) return -1;
    if (m_pos == m_len) {
      int ready = wait_ready(m_sock, POLLIN, m_deadline, m_svr_sock);
      if (ready == 0) m_failure = ReadFailure::timeout;  // the whole request is late, however it trickled
      if (ready != 1) return -1;
      ssize_t n;
      do n = ::recv(m_sock, m_buf, sizeof m_buf, 0);
      while (n < 0 && errno == EINTR);
      if (n <= 0) return n;
      m_pos = 0;
      m_len = size_t(n);
    }
    size_t n = std::min(size, m_len - m_pos);
    size_t i = 0;
    for (; i < n && m_in_head; ++i) {
      m_tail = (m_tail << 8) | uint8_t(m_buf[m_pos + i]);
      if (++m_head > m_limits.max_head_bytes) {
        m_failure = ReadFailure::head_too_large;
        return -1;
      }
      if (m_tail == 0x0d0a0d0au) m_in_head = false;  // "\r\n\r\n": the head ends
    }
    m_body += n - i;
    if (m_body > m_max_body) {  // httplib's own check trusts Content-Length and reads chunked bodies whole
      m_failure = ReadFailure::body_too_large;
      return -1;
    }
    std::memcpy(ptr, m_buf + m_pos, n);
    m_pos += n;
    return ssize_t(n);
  }

  ssize_t write(const char* ptr, size_t size) override {
    // The first bytes of a response are its status line: remember the status (a 1xx comes first
    // for Expect: 100-continue, the real one after it).
    if (m_status < 200 && size >= 12 && std::memcmp(ptr, "HTTP/1.", 7) == 0)
      m_status = std::atoi(std::string(ptr + 9, 3).c_str());
    if (wait_ready(m_sock, POLLOUT, after(m_write_timeout), m_svr_sock) != 1) return -1;
    ssize_t n;
    do n = ::send(m_sock, ptr, size, MSG_NOSIGNAL);
    while (n < 0 && errno == EINTR);
    return n;
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage addr{};
    socklen_t len = sizeof addr;
    if (getpeername(m_sock, reinterpret_cast<sockaddr*>(&addr), &len) == 0) ip_and_port(addr, ip, port);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage addr{};
    socklen_t len = sizeof addr;
    if (getsockname(m_sock, reinterpret_cast<sockaddr*>(&addr), &len) == 0) ip_and_port(addr, ip, port);
  }
  socket_t socket() const override { return m_sock; }

 private:
  socket_t m_sock;
  const std::atomic<socket_t>& m_svr_sock;
  const ConnectionLimits& m_limits;
  size_t m_max_body;
  double m_write_timeout;
  char m_buf[4096];
  size_t m_pos = 0, m_len = 0;
  Clock::time_point m_deadline = Clock::time_point::max();
  bool m_in_head = true;
  size_t m_head = 0, m_body = 0;
  uint32_t m_tail = 0;
  ReadFailure m_failure = ReadFailure::none;
  int m_status = 0;
};

thread_local GuardedStream* t_stream = nullptr;
thread_local bool t_close = false;
thread_local bool t_on_accept_thread = false;  // BoundedThreadPool ran this connection inline

// Sends our FIN, then reads and discards what the client still sends (briefly, boundedly) before
// closing: closing with unread bytes would reset the connection and could destroy the answer
// before the client reads it.
void linger_close(socket_t sock, const std::atomic<socket_t>& svr_sock, double seconds = 1.0) {
  ::shutdown(sock, SHUT_WR);
  auto until = after(seconds);
  char scratch[16384];
  size_t drained = 0;
  while (drained < (size_t(1) << 20) && wait_ready(sock, POLLIN, until, svr_sock) == 1) {
    ssize_t n = ::recv(sock, scratch, sizeof scratch, 0);
    if (n <= 0) break;
    drained += size_t(n);
  }
  ::close(sock);
}

}  // namespace

GuardedServer::GuardedServer(const ConnectionLimits& limits) : m_limits(limits) {}

void GuardedServer::widen_backlog(int backlog) {
  if (svr_sock_ != INVALID_SOCKET) ::listen(svr_sock_, backlog);
}

bool GuardedServer::process_and_close_socket(socket_t sock) {
  struct Count {
    std::atomic<int>& n;
    ~Count() { --n; }
  } count{m_open};
  // Served on the accepting thread: every thread is busy and connections are queued, so this one
  // is over capacity whatever the count says.
  if (++m_open > m_limits.max_connections || t_on_accept_thread) {
    // Over the cap: answer at once without reading, so a flood of idle or slow connections
    // cannot queue up the server's threads.
    std::string body = "{\"error\":{\"status\":503,\"message\":\"too many open connections (limit " +
                       std::to_string(m_limits.max_connections) + "); retry later\"}}";
    std::string head = "HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/json\r\nRetry-After: 1\r\n"
                       "Connection: close\r\nContent-Length: " + std::to_string(body.size()) + "\r\n\r\n";
    std::string all = head + body;
    ::send(sock, all.data(), all.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    linger_close(sock, svr_sock_, t_on_accept_thread ? 0.02 : 1.0);  // never stall the accepting thread
    return false;
  }
  double write_timeout = double(write_timeout_sec_) + double(write_timeout_usec_) / 1e6;
  GuardedStream strm(sock, svr_sock_, m_limits, payload_max_length_, write_timeout);
  t_stream = &strm;
  bool ret = false, linger = false;
  for (size_t left = keep_alive_max_count_; left > 0; --left) {
    if (!strm.wait_for_request(double(keep_alive_timeout_sec_))) break;  // idle: close quietly
    strm.begin_request();
    t_close = false;
    bool closed_by_client = false;
    ret = process_request(strm, left == 1, closed_by_client, nullptr);
    if (strm.failure() == ReadFailure::head_too_large && strm.status() == 0) {
      // A request line over the cap fails inside httplib's line reader, which then answers nothing.
      std::string body = "{\"error\":{\"status\":431,\"message\":\"the request line and headers exceed " +
                         std::to_string(m_limits.max_head_bytes) + " bytes\"}}";
      std::string all = "HTTP/1.1 431 Request Header Fields Too Large\r\nContent-Type: application/json\r\n"
                        "Connection: close\r\nContent-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
      strm.write(all.data(), all.size());
    }
    linger = t_close || strm.failure() != ReadFailure::none || ends_connection(strm.status());
    if (!ret || closed_by_client || linger) break;
  }
  t_stream = nullptr;
  if (linger) {
    linger_close(sock, svr_sock_);
  } else {
    ::shutdown(sock, SHUT_RDWR);
    ::close(sock);
  }
  return ret;
}

BoundedThreadPool::BoundedThreadPool(size_t threads, size_t max_pending) : m_max_pending(max_pending) {
  for (size_t i = 0; i < threads; ++i) m_threads.emplace_back([this] { work(); });
}

BoundedThreadPool::~BoundedThreadPool() { shutdown(); }

void BoundedThreadPool::enqueue(std::function<void()> fn) {
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    // Idle threads take queued connections at once (a burst of watchers waits here only for a
    // thread to wake); only past them do connections count against the bound.
    if (m_jobs.size() < m_max_pending + m_idle) {
      m_jobs.push_back(std::move(fn));
      m_cv.notify_one();
      return;
    }
  }
  t_on_accept_thread = true;
  fn();
  t_on_accept_thread = false;
}

void BoundedThreadPool::shutdown() {
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    if (m_shutdown) return;
    m_shutdown = true;
  }
  m_cv.notify_all();
  for (auto& t : m_threads)
    if (t.joinable()) t.join();
}

void BoundedThreadPool::work() {
  for (;;) {
    std::function<void()> fn;
    {
      std::unique_lock<std::mutex> lock(m_mutex);
      ++m_idle;
      m_cv.wait(lock, [&] { return m_shutdown || !m_jobs.empty(); });
      --m_idle;
      if (m_jobs.empty()) return;  // shut down, nothing left
      fn = std::move(m_jobs.front());
      m_jobs.pop_front();
    }
    fn();
  }
}

bool ends_connection(int status) {
  return status == 400 || status == 408 || status == 411 || status == 413 || status == 414 || status == 431;
}

ReadFailure current_read_failure() { return t_stream ? t_stream->failure() : ReadFailure::none; }

void close_after_response() { t_close = true; }

void extend_request_deadline(double seconds) {
  if (t_stream) t_stream->extend_deadline(seconds);
}

}  // namespace srv
