// The Redis layout shared by the server's Redis backend and render-worker (docs/scale-out.md):
//   pt:work                 stream of sample passes, read by the consumer group "workers"
//                           (job, run, unit, first, count, mask: the converged pixels, 1 bit each;
//                           sig on a signed farm)
//   pt:job:<job>:<run>      hash: spec (the job's JSON spec), scene (the SHA-256 of the scene
//                           file's bytes) and sig; deleting it tells workers the run is over
//   pt:scene:<hash>         the .dae file's bytes, shared by every run of the same content (a
//                           worker that has built that scene fetches nothing more)
//   pt:results:<job>:<run>  stream of finished passes (job, run, unit, worker, attempt, pass: a
//                           pt::FilmPass encoding, features, sig) or failures (job, run, unit,
//                           worker, error, sig)
//   pt:worker:<name>        a live worker's presence (its thread count), expiring kWorkerTtlSeconds
//                           after its last heartbeat
//   pt:dead                 stream of passes set aside after kMaxDeliveries failed tries (job, run,
//                           unit, first, count, entry, worker, deliveries, reason), capped in length
// A run is one attempt at a job: a server restart starts a new run, and anything left of an
// older one is ignored. On a signed farm (--farm-key-file) each sig is the HMAC-SHA256 of the
// fields the *_signature functions below name, so that nobody without the key can issue, alter,
// move or answer a pass.
#pragma once

#include <string>
#include <vector>

#include "farm_security.h"
#include "redis_client.h"

namespace srv::rq {

inline const std::string kWorkStream = "pt:work";
inline const std::string kGroup = "workers";
inline std::string job_key(const std::string& job, const std::string& run) { return "pt:job:" + job + ":" + run; }
inline std::string scene_key(const std::string& hash) { return "pt:scene:" + hash; }
// A scene file's content name: its SHA-256 (a signed run names its scene by it, so it must not collide).
inline std::string content_hash(const std::string& bytes) { return sha256_hex(bytes); }
inline std::string results_key(const std::string& job, const std::string& run) {
  return "pt:results:" + job + ":" + run;
}
// How long a run's keys live if nobody deletes them (a server killed mid-job).
constexpr int kKeyTtlSeconds = 24 * 3600;
constexpr int kWorkerTtlSeconds = 5;
inline std::string worker_key(const std::string& name) { return "pt:worker:" + name; }
// The live workers' names and thread counts, from their keys (SCAN, so a large keyspace is walked
// in steps; at most `limit` of them). Names and values are untrusted: cut and made valid UTF-8.
std::vector<std::pair<std::string, int>> live_workers(RedisClient& redis, size_t limit = 1000);

// Creates the stream and the consumer group if missing (idempotent). A group created over an
// existing stream starts at its beginning, so passes added before it (a restarted Redis) are read.
void ensure_group(RedisClient& redis);

// Passes that failed this many deliveries (or whose workers died on them that often) go to
// kDeadStream instead of being tried again, and their job fails.
inline const std::string kDeadStream = "pt:dead";
constexpr int kMaxDeliveries = 3;
constexpr int kDeadStreamLength = 10000;  // entries kept, about
// How many times the pending pass `entry_id` has been delivered (XPENDING); 0 if it is not pending.
int delivery_count(RedisClient& redis, const std::string& entry_id);

struct WorkItem {
  std::string entry_id;
  std::string job, run;
  uint32_t unit = 0, first = 0, count = 0;
  std::string mask;  // packed bits; empty: no pixel converged yet
  std::string sig;   // empty: unsigned
};

// What each signature covers. Numbers are signed as the decimals sent.
inline std::string run_signature(const FarmKey& key, const std::string& job, const std::string& run,
                                 const std::string& spec, const std::string& scene_hash) {
  return key.sign({"pt-run", job, run, spec, scene_hash});
}
inline std::string request_signature(const FarmKey& key, const WorkItem& w) {
  return key.sign({"pt-pass", w.job, w.run, std::to_string(w.unit), std::to_string(w.first), std::to_string(w.count), w.mask});
}
// `attempt` counts a worker's sends of one result (a broken connection may or may not have
// delivered the last), so that an honest resend is never a byte-for-byte copy: a copy is a replay.
inline std::string result_signature(const FarmKey& key, const std::string& job, const std::string& run,
                                    const std::string& unit, const std::string& worker, const std::string& attempt,
                                    const std::string& pass, const std::string& features) {
  return key.sign({"pt-result", job, run, unit, worker, attempt, pass, features});
}
inline std::string error_signature(const FarmKey& key, const std::string& job, const std::string& run,
                                   const std::string& unit, const std::string& worker, const std::string& error) {
  return key.sign({"pt-error", job, run, unit, worker, error});
}

// A decimal uint32 (no sign, no spaces, at most 10 digits); false for anything else or null.
bool parse_u32(const std::string* s, uint32_t& out);

// A stream entry's fields as a work item; false when a field is missing or malformed.
bool parse_work_item(const RedisReply& entry, WorkItem& out);

}  // namespace srv::rq
