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

int count_workers(RedisClient& redis) {
  int n = 0;
  std::string cursor = "0";
  do {
    RedisReply r = redis.command({"SCAN", cursor, "MATCH", "pt:worker:*", "COUNT", "1000"});
    if (r.elements.size() != 2) break;
    cursor = r.elements[0].str;
    n += int(r.elements[1].elements.size());
  } while (cursor != "0");
  return n;
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
  return parse_u32(body.field("unit"), out.unit) && parse_u32(body.field("first"), out.first) &&
         parse_u32(body.field("count"), out.count) && out.count > 0;
}

std::string content_hash(const std::string& bytes) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char ch : bytes) h = (h ^ ch) * 1099511628211ull;
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", (unsigned long long)h);
  return buf;
}

}  // namespace srv::rq
