// A small synchronous Redis client over hiredis: binary-safe commands built from argument lists,
// replies as plain values, and a reconnect on a broken connection. One client per thread.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

struct redisContext;

namespace srv {

struct RedisError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct RedisReply {
  enum Type { nil, string, integer, array, status, error } type = nil;
  std::string str;  // string, status and error replies
  long long integer_value = 0;
  std::vector<RedisReply> elements;

  bool is_nil() const { return type == nil; }
  // The field/value pairs of a stream entry, as found in XREADGROUP/XAUTOCLAIM replies.
  const std::string* field(const std::string& name) const;
};

// "redis://host:port" (the port defaults to 6379); throws std::invalid_argument naming the URL.
struct RedisAddress {
  std::string host = "127.0.0.1";
  int port = 6379;
  static RedisAddress parse(const std::string& url);
  std::string url() const { return "redis://" + host + ":" + std::to_string(port); }
};

class RedisClient {
 public:
  // Connects at once; throws RedisError when the server cannot be reached.
  explicit RedisClient(RedisAddress address, double timeout_seconds = 5.0);
  ~RedisClient();
  RedisClient(const RedisClient&) = delete;
  RedisClient& operator=(const RedisClient&) = delete;

  // Runs one command. A Redis error reply throws RedisError with its text, except where
  // `allow_error` is set (then it comes back as a reply of type error). A broken connection is
  // re-opened once and the command sent again; commands here are idempotent or their effects are
  // de-duplicated by the caller.
  RedisReply command(const std::vector<std::string>& args, bool allow_error = false);
  // The socket timeout for later commands (blocking reads need more than their BLOCK time).
  void set_timeout(double seconds);
  const RedisAddress& address() const { return m_address; }

 private:
  void connect();
  RedisAddress m_address;
  double m_timeout;
  redisContext* m_ctx = nullptr;
};

}  // namespace srv
