// Connection-level defences httplib 0.11 lacks: a cap on open connections (503 beyond it), a
// deadline for reading each whole request however slowly it trickles in (slowloris), a cap on the
// bytes of a request head (431), and closing a connection after a refused request instead of
// parsing its unread body as the next request. They live in the Stream httplib reads through.
#pragma once

#include <httplib.h>

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace srv {

struct ConnectionLimits {
  int max_connections = 128;       // open at once; more are answered 503 and closed
  double request_timeout = 10;     // seconds to receive one request (head and body); also each read's timeout
  size_t max_head_bytes = 16384;   // request line plus headers
};

// httplib::Server with the limits above; everything else (routes, handlers) is httplib's.
class GuardedServer : public httplib::Server {
 public:
  explicit GuardedServer(const ConnectionLimits& limits);
  const ConnectionLimits& limits() const { return m_limits; }
  // httplib 0.11 listens with a backlog of 5: a burst of connections (fifty watchers opening at
  // once while the accept thread waits for a core) has its SYNs dropped and retried a second
  // later. Call after binding; listen() again only changes the backlog.
  void widen_backlog(int backlog = 1024);
  int open_connections() const { return m_open.load(); }

 private:
  bool process_and_close_socket(socket_t sock) override;

  ConnectionLimits m_limits;
  std::atomic<int> m_open{0};
};

// httplib's thread pool with a bound on accepted connections waiting for a thread: each holds a file
// descriptor, and a flood queued without bound used them all up (a finished render then could not
// write its image). Past the bound a connection is served on the accepting thread itself, which
// answers it 503 at once (all threads being busy means the connection cap is reached); meanwhile
// new connections wait in the kernel's backlog, where they cost this process no descriptor.
class BoundedThreadPool : public httplib::TaskQueue {
 public:
  BoundedThreadPool(size_t threads, size_t max_pending);
  ~BoundedThreadPool() override;
  void enqueue(std::function<void()> fn) override;
  void shutdown() override;

 private:
  void work();

  size_t m_max_pending;
  std::mutex m_mutex;
  std::condition_variable m_cv;
  std::deque<std::function<void()>> m_jobs;
  std::vector<std::thread> m_threads;
  bool m_shutdown = false;
  size_t m_idle = 0;  // threads waiting for a connection
};

// Why reading the current thread's request failed, for the error handler to answer 408 or 431
// instead of httplib's generic 400.
enum class ReadFailure { none, timeout, head_too_large, body_too_large };
ReadFailure current_read_failure();
// Statuses after which a connection cannot be trusted (the request was not read, or not wholly:
// its leftover bytes would be parsed as the next request); GuardedServer closes it after the answer.
bool ends_connection(int status);
// Closes the current thread's connection once this response is sent (a request whose body was
// never read must not have its body parsed as the next request).
void close_after_response();
// Gives the current request `seconds` from now to arrive whole: an upload of many megabytes needs
// longer than --read-timeout; called before its body is read, once its size is known.
void extend_request_deadline(double seconds);

}  // namespace srv
