#include "redis_client.h"

#include <hiredis/hiredis.h>

#include <cmath>

namespace srv {

namespace {

timeval to_timeval(double seconds) {
  timeval tv;
  tv.tv_sec = long(seconds);
  tv.tv_usec = long((seconds - std::floor(seconds)) * 1e6);
  return tv;
}

RedisReply convert(const redisReply* r) {
  RedisReply out;
  if (!r) return out;
  switch (r->type) {
    case REDIS_REPLY_STRING:
      out.type = RedisReply::string;
      out.str.assign(r->str, r->len);
      break;
    case REDIS_REPLY_STATUS:
      out.type = RedisReply::status;
      out.str.assign(r->str, r->len);
      break;
    case REDIS_REPLY_ERROR:
      out.type = RedisReply::error;
      out.str.assign(r->str, r->len);
      break;
    case REDIS_REPLY_INTEGER:
      out.type = RedisReply::integer;
      out.integer_value = r->integer;
      break;
    case REDIS_REPLY_ARRAY:
      out.type = RedisReply::array;
      for (size_t i = 0; i < r->elements; ++i) out.elements.push_back(convert(r->element[i]));
      break;
    default:
      out.type = RedisReply::nil;
  }
  return out;
}

}  // namespace

const std::string* RedisReply::field(const std::string& name) const {
  for (size_t i = 0; i + 1 < elements.size(); i += 2)
    if (elements[i].str == name) return &elements[i + 1].str;
  return nullptr;
}

RedisAddress RedisAddress::parse(const std::string& url) {
  const std::string scheme = "redis://";
  if (url.compare(0, scheme.size(), scheme) != 0)
    throw std::invalid_argument("queue URL '" + url + "' must start with redis://");
  RedisAddress a;
  std::string rest = url.substr(scheme.size());
  if (!rest.empty() && rest.back() == '/') rest.pop_back();
  size_t colon = rest.rfind(':');
  a.host = rest.substr(0, colon);
  if (colon != std::string::npos) {
    std::string port = rest.substr(colon + 1);
    char* end = nullptr;
    long p = std::strtol(port.c_str(), &end, 10);
    if (port.empty() || *end || p < 1 || p > 65535)
      throw std::invalid_argument("queue URL '" + url + "': port must be 1-65535");
    a.port = int(p);
  }
  if (a.host.empty()) throw std::invalid_argument("queue URL '" + url + "' names no host");
  return a;
}

RedisClient::RedisClient(RedisAddress address, double timeout_seconds)
    : m_address(std::move(address)), m_timeout(timeout_seconds) {
  connect();
}

RedisClient::~RedisClient() {
  if (m_ctx) redisFree(m_ctx);
}

void RedisClient::connect() {
  if (m_ctx) redisFree(m_ctx);
  m_ctx = redisConnectWithTimeout(m_address.host.c_str(), m_address.port, to_timeval(m_timeout));
  if (!m_ctx || m_ctx->err) {
    std::string why = m_ctx ? m_ctx->errstr : "out of memory";
    if (m_ctx) redisFree(m_ctx);
    m_ctx = nullptr;
    throw RedisError("cannot reach Redis at " + m_address.url() + ": " + why);
  }
  redisSetTimeout(m_ctx, to_timeval(m_timeout));
}

void RedisClient::set_timeout(double seconds) {
  m_timeout = seconds;
  if (m_ctx) redisSetTimeout(m_ctx, to_timeval(seconds));
}

RedisReply RedisClient::command(const std::vector<std::string>& args, bool allow_error) {
  std::vector<const char*> argv;
  std::vector<size_t> lens;
  for (const std::string& a : args) {
    argv.push_back(a.data());
    lens.push_back(a.size());
  }
  for (int attempt = 0;; ++attempt) {
    if (!m_ctx) connect();
    auto* r = static_cast<redisReply*>(redisCommandArgv(m_ctx, int(argv.size()), argv.data(), lens.data()));
    if (!r) {
      std::string why = m_ctx->errstr;
      redisFree(m_ctx);
      m_ctx = nullptr;
      if (attempt == 0) continue;
      throw RedisError("Redis at " + m_address.url() + ": " + args[0] + ": " + why);
    }
    RedisReply out = convert(r);
    freeReplyObject(r);
    if (out.type == RedisReply::error && !allow_error)
      throw RedisError("Redis at " + m_address.url() + ": " + args[0] + ": " + out.str);
    return out;
  }
}

}  // namespace srv
