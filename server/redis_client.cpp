#include "redis_client.h"

#include "request_policy.h"

#include <hiredis/hiredis.h>

#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

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

// "CMD key" for messages: the command and, when short, its first argument (usually the key).
std::string describe(const std::vector<std::string>& args) {
  std::string s = args.empty() ? "" : args[0];
  if (args.size() > 1 && args[1].size() <= 64) s += " " + args[1];
  return valid_utf8(s, 200);
}

// Replies that mean this client may not do what it asked: waiting cannot change them.
bool is_refusal(const std::string& error) {
  return error.rfind("NOAUTH", 0) == 0 || error.rfind("WRONGPASS", 0) == 0 || error.rfind("NOPERM", 0) == 0;
}

std::string refusal_hint(const std::string& error) {
  if (error.rfind("NOAUTH", 0) == 0)
    return " (this Redis needs a password: give it with --redis-password-file, PT_REDIS_PASSWORD or redis://user:password@host)";
  if (error.rfind("NOPERM", 0) == 0) return " (the ACL user lacks this permission: docs/scale-out.md lists the rules)";
  return "";
}

}  // namespace

std::string valid_utf8(std::string_view s, size_t max_bytes) {
  // Cut at a character boundary, then every ill-formed byte replaced (request_policy.h).
  return to_valid_utf8(clip_utf8(std::string(s.substr(0, std::min(s.size(), max_bytes + 1))), max_bytes));
}

const std::string* RedisReply::field(const std::string& name) const {
  for (size_t i = 0; i + 1 < elements.size(); i += 2)
    if (elements[i].type == string && elements[i].str == name && elements[i + 1].type == string)
      return &elements[i + 1].str;
  return nullptr;
}

namespace {

// %XX escapes of a URL's user or password (RFC 3986); a '%' not followed by two hex digits is refused.
std::string percent_decode(const std::string& s, const std::string& what) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '%') {
      out += s[i];
      continue;
    }
    auto hex = [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; };
    if (i + 2 >= s.size() || !hex(s[i + 1]) || !hex(s[i + 2]))
      throw std::invalid_argument(what + " has a '%' that is not followed by two hex digits");
    out += char(std::stoi(s.substr(i + 1, 2), nullptr, 16));
    i += 2;
  }
  return out;
}

}  // namespace

RedisAddress RedisAddress::parse(const std::string& url) {
  const std::string scheme = "redis://";
  RedisAddress a;
  std::string rest = url.compare(0, scheme.size(), scheme) == 0 ? url.substr(scheme.size()) : "";
  // Errors name the URL without what may be a password.
  const size_t at = rest.rfind('@'), url_at = url.rfind('@');
  const std::string shown = url_at == std::string::npos ? url : url.substr(0, url.find("://") + 3) + "..." + url.substr(url_at);
  if (url.compare(0, scheme.size(), scheme) != 0)
    throw std::invalid_argument("queue URL '" + valid_utf8(shown, 200) + "' must start with redis://");
  const std::string what = "queue URL '" + valid_utf8(shown, 200) + "'";
  if (at != std::string::npos) {
    const std::string credentials = rest.substr(0, at);
    rest = rest.substr(at + 1);
    const size_t colon = credentials.find(':');
    a.user = percent_decode(credentials.substr(0, colon), what + ": its user");
    if (colon != std::string::npos) a.password = percent_decode(credentials.substr(colon + 1), what + ": its password");
    if (a.user.size() > 256 || a.password.size() > 4096) throw std::invalid_argument(what + ": user or password too long");
  }
  const size_t slash = rest.find('/');
  if (slash != std::string::npos) {
    const std::string db = rest.substr(slash + 1);
    rest = rest.substr(0, slash);
    char* end = nullptr;
    long d = std::strtol(db.c_str(), &end, 10);
    if (!db.empty() && (*end || db[0] == '-' || db[0] == '+' || d < 0 || d > 1000000))
      throw std::invalid_argument(what + ": the database after '/' must be a number");
    a.db = int(d);
  }
  size_t colon = rest.rfind(':');
  a.host = rest.substr(0, colon);
  if (colon != std::string::npos) {
    std::string port = rest.substr(colon + 1);
    char* end = nullptr;
    long p = std::strtol(port.c_str(), &end, 10);
    if (port.empty() || *end || p < 1 || p > 65535) throw std::invalid_argument(what + ": port must be 1-65535");
    a.port = int(p);
  }
  if (a.host.empty()) throw std::invalid_argument(what + " names no host");
  if (a.host.find_first_of("@/?# ") != std::string::npos) throw std::invalid_argument(what + ": a bad host name");
  return a;
}

std::string RedisAddress::url() const {
  std::string u = "redis://";
  if (!user.empty()) u += valid_utf8(user, 256) + "@";
  u += host + ":" + std::to_string(port);
  if (db != 0) u += "/" + std::to_string(db);
  return u;
}

RedisClient::RedisClient(RedisAddress address, double timeout_seconds, bool connect_now)
    : m_address(std::move(address)), m_timeout(timeout_seconds) {
  if (connect_now) connect();
}

RedisClient::~RedisClient() {
  if (m_ctx) redisFree(m_ctx);
}

bool RedisClient::open(std::string& why) {
  if (m_ctx) redisFree(m_ctx);
  m_ctx = redisConnectWithTimeout(m_address.host.c_str(), m_address.port, to_timeval(m_timeout));
  if (!m_ctx || m_ctx->err) {
    why = m_ctx ? valid_utf8(m_ctx->errstr, 200) : "out of memory";
    if (m_ctx) redisFree(m_ctx);
    m_ctx = nullptr;
    return false;
  }
  redisSetTimeout(m_ctx, to_timeval(m_timeout));
  // Every connection logs in again (a reconnect after a Redis restart or a cut link), then selects
  // the database. A refusal is not an outage: it throws at once instead of being waited out.
  auto run = [&](const std::vector<std::string>& args, const std::string& what) -> bool {
    std::vector<const char*> argv;
    std::vector<size_t> lens;
    for (const std::string& a : args) argv.push_back(a.data()), lens.push_back(a.size());
    auto* r = static_cast<redisReply*>(redisCommandArgv(m_ctx, int(argv.size()), argv.data(), lens.data()));
    if (!r) {
      why = valid_utf8(m_ctx->errstr, 200);
      redisFree(m_ctx);
      m_ctx = nullptr;
      return false;
    }
    RedisReply out = convert(r);
    freeReplyObject(r);
    if (out.type == RedisReply::error) {
      redisFree(m_ctx);
      m_ctx = nullptr;
      throw RedisAuthError("Redis at " + m_address.url() + " refused " + what + ": " + valid_utf8(out.str, 300) +
                           (out.str.rfind("WRONGPASS", 0) == 0 || out.str.find("invalid password") != std::string::npos
                                ? " (check the password: --redis-password-file, PT_REDIS_PASSWORD or the URL)"
                                : ""));
    }
    return true;
  };
  if (!m_address.password.empty()) {
    std::vector<std::string> auth{"AUTH"};
    if (!m_address.user.empty()) auth.push_back(m_address.user);
    auth.push_back(m_address.password);
    if (!run(auth, m_address.user.empty() ? "the password" : ("user '" + valid_utf8(m_address.user, 256) + "' and its password").c_str()))
      return false;
  }
  if (m_address.db != 0 && !run({"SELECT", std::to_string(m_address.db)}, "the database")) return false;
  ++m_connections;
  return true;
}

void RedisClient::connect() {
  std::string why;
  if (!open(why)) throw RedisUnreachable("cannot reach Redis at " + m_address.url() + ": " + why);
}

void RedisClient::set_patience(double seconds, const std::atomic<bool>* abort, std::string who) {
  m_patience = std::max(0.0, seconds);
  m_abort = abort;
  m_who = std::move(who);
}

void RedisClient::set_timeout(double seconds) {
  m_timeout = seconds;
  if (m_ctx) redisSetTimeout(m_ctx, to_timeval(seconds));
}

RedisReply RedisClient::command(const std::vector<std::string>& args, bool allow_error, bool resend) {
  using clock = std::chrono::steady_clock;
  std::vector<const char*> argv;
  std::vector<size_t> lens;
  for (const std::string& a : args) {
    argv.push_back(a.data());
    lens.push_back(a.size());
  }
  auto aborted = [&] { return m_abort && m_abort->load(); };
  clock::time_point lost;
  double wait = 0.1;
  for (int attempt = 0;; ++attempt) {
    std::string why;
    if (m_ctx || open(why)) {
      auto* r = static_cast<redisReply*>(redisCommandArgv(m_ctx, int(argv.size()), argv.data(), lens.data()));
      if (r) {
        RedisReply out = convert(r);
        freeReplyObject(r);
        if (out.type == RedisReply::error && is_refusal(out.str))
          throw RedisAuthError("Redis at " + m_address.url() + " refused " + describe(args) + ": " + valid_utf8(out.str, 300) +
                               refusal_hint(out.str));
        // A Redis restarting with its data answers LOADING until it has read it: wait as for a restart.
        if (out.type != RedisReply::error || out.str.rfind("LOADING", 0) != 0) {
          if (attempt > 1 && !m_who.empty())
            std::fprintf(stderr, "%s: Redis at %s is back after %.1f s\n", m_who.c_str(), m_address.url().c_str(),
                         std::chrono::duration<double>(clock::now() - lost).count());
          if (out.type == RedisReply::error && !allow_error)
            throw RedisError("Redis at " + m_address.url() + ": " + describe(args) + ": " + valid_utf8(out.str, 1000));
          return out;
        }
        why = valid_utf8(out.str, 200);
      } else {
        why = valid_utf8(m_ctx->errstr, 200);
        redisFree(m_ctx);
        m_ctx = nullptr;
        if (!resend) throw RedisMaybeSent("Redis at " + m_address.url() + ": the connection broke during " + describe(args) + ": " + why);
      }
    }
    if (attempt == 0) {  // a connection Redis closed (idle, restarted): reopen it at once
      lost = clock::now();
      continue;
    }
    const double gone = std::chrono::duration<double>(clock::now() - lost).count();
    if (gone >= m_patience || aborted()) {
      char buf[64] = "";
      if (m_patience > 0 && !aborted()) std::snprintf(buf, sizeof buf, " was unreachable for %g s", m_patience);
      throw RedisUnreachable("Redis at " + m_address.url() + buf + ": " + describe(args) + ": " + why);
    }
    if (attempt == 1 && !m_who.empty())
      std::fprintf(stderr, "%s: lost Redis at %s (%s); retrying for up to %g s\n", m_who.c_str(),
                   m_address.url().c_str(), why.c_str(), m_patience);
    // Back-off: 0.1 s doubling to 2 s, in short steps so that an abort is seen at once.
    auto until = clock::now() + std::chrono::duration<double>(std::min(wait, m_patience - gone));
    while (clock::now() < until && !aborted()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    wait = std::min(2 * wait, 2.0);
  }
}

}  // namespace srv
