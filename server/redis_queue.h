// The Redis layout shared by the server's Redis backend and render-worker (docs/scale-out.md):
//   pt:work                 stream of sample passes, read by the consumer group "workers"
//                           (job, run, unit, first, count, mask: the converged pixels, 1 bit each)
//   pt:job:<job>:<run>      hash: spec (the job's JSON spec) and scene (the hash of the .dae
//                           file's bytes); deleting it tells workers the run is over
//   pt:scene:<hash>         the .dae file's bytes, shared by every run of the same content (a
//                           worker that has built that scene fetches nothing more)
//   pt:results:<job>:<run>  stream of finished passes (unit, worker, pass: a pt::FilmPass
//                           encoding, features) or failures (unit, worker, error)
//   pt:worker:<name>        a live worker's presence (its thread count), expiring kWorkerTtlSeconds
//                           after its last heartbeat
//   pt:dead                 stream of passes set aside after kMaxDeliveries failed tries (job, run,
//                           unit, first, count, entry, worker, deliveries, reason), capped in length
// A run is one attempt at a job: a server restart starts a new run, and anything left of an
// older one is ignored.
#pragma once

#include <string>
#include <vector>

#include "redis_client.h"

namespace srv::rq {

inline const std::string kWorkStream = "pt:work";
inline const std::string kGroup = "workers";
inline std::string job_key(const std::string& job, const std::string& run) { return "pt:job:" + job + ":" + run; }
inline std::string scene_key(const std::string& hash) { return "pt:scene:" + hash; }
// FNV-1a of a scene file's bytes, as 16 hex digits.
std::string content_hash(const std::string& bytes);
inline std::string results_key(const std::string& job, const std::string& run) {
  return "pt:results:" + job + ":" + run;
}
// How long a run's keys live if nobody deletes them (a server killed mid-job).
constexpr int kKeyTtlSeconds = 24 * 3600;
constexpr int kWorkerTtlSeconds = 5;
inline std::string worker_key(const std::string& name) { return "pt:worker:" + name; }
// Counts the live workers' keys (SCAN, so a large keyspace is walked in steps).
int count_workers(RedisClient& redis);

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
};

// A decimal uint32 (no sign, no spaces, at most 10 digits); false for anything else or null.
bool parse_u32(const std::string* s, uint32_t& out);

// A stream entry's fields as a work item; false when a field is missing or malformed.
bool parse_work_item(const RedisReply& entry, WorkItem& out);

}  // namespace srv::rq
