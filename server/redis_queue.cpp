#include "redis_queue.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace srv::rq {

void ensure_group(RedisClient& redis) {
  RedisReply r = redis.command({"XGROUP", "CREATE", kWorkStream, kGroup, "0", "MKSTREAM"}, true);
  if (r.type == RedisReply::error && r.str.rfind("BUSYGROUP", 0) != 0)
    throw RedisError("Redis at " + redis.address().url() + ": cannot create the consumer group: " + r.str);
}

int delivery_count(RedisClient& redis, const std::string& entry_id) {
  // The extended form answers [[id, consumer, idle ms, deliveries]] for a pending entry.
  RedisReply r = redis.command({"XPENDING", kWorkStream, kGroup, entry_id, entry_id, "1"}, true);
  if (r.type != RedisReply::array || r.elements.size() != 1) return 0;
  const RedisReply& e = r.elements[0];
  if (e.type != RedisReply::array || e.elements.size() != 4 || e.elements[3].type != RedisReply::integer) return 0;
  return int(std::min<long long>(std::max<long long>(e.elements[3].integer_value, 0), 1 << 30));
}

std::vector<std::pair<std::string, int>> live_workers(RedisClient& redis, size_t limit) {
  std::vector<std::string> keys;
  std::string cursor = "0";
  do {
    RedisReply r = redis.command({"SCAN", cursor, "MATCH", "pt:worker:*", "COUNT", "1000"});
    if (r.elements.size() != 2 || r.elements[0].type != RedisReply::string) break;
    cursor = r.elements[0].str;
    for (const RedisReply& k : r.elements[1].elements)
      if (k.type == RedisReply::string && keys.size() < limit) keys.push_back(k.str);
  } while (cursor != "0" && keys.size() < limit);
  std::vector<std::pair<std::string, int>> out;
  if (keys.empty()) return out;
  std::vector<std::string> mget{"MGET"};
  mget.insert(mget.end(), keys.begin(), keys.end());
  RedisReply values = redis.command(mget);
  const size_t prefix = worker_key("").size();
  for (size_t i = 0; i < keys.size(); ++i) {
    uint32_t threads = 0;
    const bool known = i < values.elements.size() && values.elements[i].type == RedisReply::string &&
                       parse_u32(&values.elements[i].str, threads);
    if (i < values.elements.size() && values.elements[i].is_nil()) continue;  // expired since the SCAN
    out.emplace_back(valid_utf8(std::string_view(keys[i]).substr(prefix), 64), known ? int(std::min(threads, 100000u)) : 0);
  }
  return out;
}

bool parse_u32(const std::string* s, uint32_t& out) {
  if (!s || s->empty() || s->size() > 10) return false;
  uint64_t v = 0;
  for (char c : *s) {
    if (c < '0' || c > '9') return false;  // strtoull would take a sign, spaces and a NUL's early end
    v = v * 10 + uint64_t(c - '0');
  }
  if (v > 0xffffffffull) return false;
  out = uint32_t(v);
  return true;
}

bool parse_work_item(const RedisReply& entry, WorkItem& out) {
  // An entry is [id, [field, value, ...]]; an entry deleted while pending has a nil body.
  if (entry.type != RedisReply::array || entry.elements.size() != 2 || entry.elements[0].type != RedisReply::string)
    return false;
  out = WorkItem();
  out.entry_id = entry.elements[0].str;
  const RedisReply& body = entry.elements[1];
  const std::string *job = body.field("job"), *run = body.field("run"), *mask = body.field("mask");
  if (!job || !run || job->empty() || run->empty()) return false;
  out.job = *job;
  out.run = *run;
  if (mask) out.mask = *mask;
  if (const std::string* sig = body.field("sig")) out.sig = *sig;
  return parse_u32(body.field("unit"), out.unit) && parse_u32(body.field("first"), out.first) &&
         parse_u32(body.field("count"), out.count) && out.count > 0;
}

}  // namespace srv::rq
