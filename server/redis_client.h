// A small synchronous Redis client over hiredis: binary-safe commands built from argument lists,
// replies as plain values, and reconnects with back-off while Redis is unreachable (a restart).
// One client per thread.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

struct redisContext;

namespace srv {

// An error reply from Redis (WRONGTYPE, NOGROUP, ...), or the base of the one below.
struct RedisError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// Redis refused this client: a wrong or missing password (WRONGPASS, NOAUTH) or an ACL user
// without a permission it needs (NOPERM). Retrying cannot help, so it is never retried.
struct RedisAuthError : RedisError {
  using RedisError::RedisError;
};
// The connection broke after a command that must not be sent twice was written: Redis may or may
// not have run it. The caller decides (render-worker sends its result again as a new attempt).
struct RedisMaybeSent : RedisError {
  using RedisError::RedisError;
};
// Redis could not be reached (no connection, a broken one), and stayed so for the client's patience
// or until its abort flag was set.
struct RedisUnreachable : RedisError {
  using RedisError::RedisError;
};

// `s` cut to at most `max_bytes` and made valid UTF-8: each byte of an invalid sequence becomes
// U+FFFD. Text read from Redis (or in its error replies) is untrusted and ends up in JSON.
std::string valid_utf8(std::string_view s, size_t max_bytes = 4096);

struct RedisReply {
  enum Type { nil, string, integer, array, status, error } type = nil;
  std::string str;  // string, status and error replies
  long long integer_value = 0;
  std::vector<RedisReply> elements;

  bool is_nil() const { return type == nil; }
  // The field/value pairs of a stream entry, as found in XREADGROUP/XAUTOCLAIM replies; only
  // string values are returned.
  const std::string* field(const std::string& name) const;
};

// "redis://[user[:password]@]host[:port][/db]" (the port defaults to 6379, the database to 0; user and
// password may be percent-encoded); throws std::invalid_argument naming the URL, without its password.
struct RedisAddress {
  std::string host = "127.0.0.1";
  int port = 6379;
  int db = 0;
  std::string user, password;  // AUTH [user] password on every connection when a password is set
  static RedisAddress parse(const std::string& url);
  // The URL without the password: what logs, errors and /api/health show.
  std::string url() const;
};

class RedisClient {
 public:
  // Connects at once (throwing RedisUnreachable when Redis cannot be reached) unless `connect_now`
  // is false; then the first command connects.
  explicit RedisClient(RedisAddress address, double timeout_seconds = 5.0, bool connect_now = true);
  ~RedisClient();
  RedisClient(const RedisClient&) = delete;
  RedisClient& operator=(const RedisClient&) = delete;

  // Runs one command. A Redis error reply throws RedisError with its text, except where
  // `allow_error` is set (then it comes back as a reply of type error). A broken connection is
  // re-opened and the command sent again (see set_patience); commands here are idempotent or their
  // effects are de-duplicated by the caller. With `resend` false, a connection that breaks after
  // the command was written throws RedisMaybeSent instead (one not yet written is still retried).
  RedisReply command(const std::vector<std::string>& args, bool allow_error = false, bool resend = true);
  // How long a command keeps retrying an unreachable Redis (back-off 0.1 s doubling to 2 s) before
  // it throws RedisUnreachable; 0 (the default): one immediate reconnect only. A set `abort` ends
  // the wait at once. `who` prefixes the log lines of an outage ("" logs nothing).
  void set_patience(double seconds, const std::atomic<bool>* abort = nullptr, std::string who = "");
  // The socket timeout for later commands (blocking reads need more than their BLOCK time).
  void set_timeout(double seconds);
  // Connections opened so far: a change means Redis may have restarted and lost what it held.
  uint64_t connections() const { return m_connections; }
  const RedisAddress& address() const { return m_address; }

 private:
  bool open(std::string& why);  // a new connection; false (and why) when Redis cannot be reached
  void connect();
  RedisAddress m_address;
  double m_timeout;
  double m_patience = 0;
  const std::atomic<bool>* m_abort = nullptr;
  std::string m_who;
  uint64_t m_connections = 0;
  redisContext* m_ctx = nullptr;
};

}  // namespace srv
