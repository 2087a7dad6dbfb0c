// render-worker: takes sample passes from Redis (stream pt:work, consumer group "workers"),
// renders them and returns per-pixel sums. Work a dead worker held is claimed by a live one once
// it has been idle for --claim-timeout; a live worker keeps its pass fresh by re-claiming it. A
// pass that fails kMaxDeliveries tries goes to the dead-letter stream and fails its job. An
// unreachable Redis (a restart) is waited for, up to --redis-timeout.
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdarg>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include "scene_file.h"
#include "session.h"
#include "job_spec.h"
#include "redis_queue.h"
#include "version.h"

namespace {

using namespace srv;

const char* kUsage =
    "Usage: render-worker [options]\n"
    "Renders sample passes that render-server --queue redis://HOST:PORT hands out.\n"
    "  --queue URL          the Redis server (default redis://127.0.0.1:6379); it may hold a user,\n"
    "                       a password and a database: redis://USER:PASS@HOST:PORT/DB\n"
    "  --redis-password-file F  the Redis password, read from a file (or PT_REDIS_PASSWORD), kept\n"
    "                       out of the process list\n"
    "  --farm-key-file F    the farm's shared key: take only passes the server signed with it, and\n"
    "                       sign the results (the same file as render-server's)\n"
    "  --insecure-farm      allow an unsigned farm on a Redis that is not on loopback\n"
    "  -t, --threads N      render threads (default: all cores)\n"
    "  --name NAME          consumer name in the group (default: host-pid)\n"
    "  --claim-timeout SEC  take over passes a worker left unacknowledged this long (default 10)\n"
    "  --redis-timeout SEC  wait this long for an unreachable Redis, then exit (default 300)\n"
    "  --quiet              log nothing but errors\n"
    "  -h, --help           this text\n"
    "  --version            the version, git commit, Embree and OpenImageIO versions\n";

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

struct Options {
  std::string queue = "redis://127.0.0.1:6379";
  int threads = int(std::max(1u, std::thread::hardware_concurrency()));
  std::string name;
  double claim_timeout = 10;
  double redis_timeout = 300;
  bool quiet = false;
  FarmOptions farm;
};

// This worker has no farm key but the server signs its passes: it cannot take part (exit 2).
struct NeedsFarmKey : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A run being worked on: its spec and its view of the scene. A worker keeps the few most recent
// (jobs rendering at once interleave their passes) and the scene bases they share, keyed by the
// file's content hash, so that a switch between runs rebuilds and downloads nothing.
struct PreparedRun {
  std::string key;
  JobSpec spec;
  std::shared_ptr<const pt::SceneBase> base;
  std::unique_ptr<pt::RenderScene> scene;
  std::vector<std::string> features;
};
constexpr size_t kRunsKept = 4, kBasesKept = 2;

class Worker {
 public:
  explicit Worker(Options o)
      : m_opt(std::move(o)), m_address(farm_address(m_opt.queue, m_opt.farm, "render-worker")),
        m_key(farm_key(m_address, m_opt.farm, "render-worker")), m_redis(m_address, 5.0, false) {
    m_redis.set_patience(m_opt.redis_timeout, &g_stop, "render-worker " + m_opt.name);
    rq::ensure_group(m_redis);
    m_grouped = m_redis.connections();
  }

  std::string address() const { return m_address.url(); }
  bool signed_farm() const { return m_key != nullptr; }

  void run() {
    while (!g_stop) {
      announce(m_redis);
      if (m_redis.connections() != m_grouped) {  // reconnected: a restarted Redis has no group
        rq::ensure_group(m_redis);
        m_grouped = m_redis.connections();
      }
      rq::WorkItem item;
      if (!next_item(item)) continue;
      handle(item);
    }
    m_redis.set_patience(0);
    m_redis.command({"DEL", rq::worker_key(m_opt.name)});  // stopped: no longer counted
  }

 private:
  // A pass whose worker went quiet first (XAUTOCLAIM), else a new one (XREADGROUP, 1 s block).
  // A pass released after a failed try is claimed at once, and counts as a delivery.
  bool next_item(rq::WorkItem& item) {
    std::string idle_ms = std::to_string(int64_t(m_opt.claim_timeout * 1000));
    RedisReply r =
        m_redis.command({"XAUTOCLAIM", rq::kWorkStream, rq::kGroup, m_opt.name, idle_ms, "0-0", "COUNT", "1"}, true);
    if (lost_group(r)) return false;
    if (r.type == RedisReply::array && r.elements.size() >= 2)
      for (const RedisReply& e : r.elements[1].elements)
        if (parse_or_drop(e, item)) {
          int deliveries = rq::delivery_count(m_redis, item.entry_id);
          if (deliveries > rq::kMaxDeliveries) {  // its workers died on it every time: a poison pass
            dead_letter(item, "its workers stopped without finishing it " + std::to_string(deliveries - 1) + " times",
                        deliveries - 1);
            return false;
          }
          log("claimed pass %u of job %s left by another worker or a failed try (delivery %d)", item.unit,
              item.job.c_str(), deliveries);
          return true;
        }
    r = m_redis.command({"XREADGROUP", "GROUP", rq::kGroup, m_opt.name, "COUNT", "1", "BLOCK", "1000", "STREAMS",
                         rq::kWorkStream, ">"},
                        true);
    if (lost_group(r)) return false;
    if (r.type != RedisReply::array || r.elements.empty() || r.elements[0].elements.size() < 2) return false;
    for (const RedisReply& e : r.elements[0].elements[1].elements)
      if (parse_or_drop(e, item)) return true;
    return false;
  }

  // Tells the server this worker is alive (a key that expires unless renewed).
  void announce(RedisClient& redis) {
    redis.command({"SET", rq::worker_key(m_opt.name), std::to_string(m_opt.threads), "EX",
                   std::to_string(rq::kWorkerTtlSeconds)});
  }

  // An error reply: NOGROUP (Redis restarted empty, or the stream was deleted) re-creates the
  // group; any other is thrown.
  bool lost_group(const RedisReply& r) {
    if (r.type != RedisReply::error) return false;
    if (r.str.rfind("NOGROUP", 0) != 0)
      throw RedisError("Redis at " + m_address.url() + ": " + valid_utf8(r.str, 1000));
    rq::ensure_group(m_redis);
    return true;
  }

  // A malformed pass request, or on a signed farm one not signed with the key, is dropped (and
  // logged): only the server can issue work. A keyless worker on a signed farm stops.
  bool parse_or_drop(const RedisReply& entry, rq::WorkItem& item) {
    if (rq::parse_work_item(entry, item)) {
      if (!m_key && !item.sig.empty()) {
        release(item);
        throw NeedsFarmKey("pass " + std::to_string(item.unit) + " of job " + valid_utf8(item.job, 64) +
                           " is signed: this farm signs its passes, so start the worker with the server's "
                           "--farm-key-file");
      }
      if (!m_key || same_signature(rq::request_signature(*m_key, item), item.sig)) return true;
      ++m_refused;
      std::fprintf(stderr, "render-worker %s: refused pass %u of job %s: %s (%llu refused so far)\n",
                   m_opt.name.c_str(), item.unit, valid_utf8(item.job, 64).c_str(),
                   item.sig.empty() ? "unsigned (not issued by the server)"
                                    : "bad signature (not issued by a server with this farm key)",
                   (unsigned long long)m_refused);
    }
    if (entry.type == RedisReply::array && !entry.elements.empty()) acknowledge(entry.elements[0].str);
    return false;
  }

  // Gives a pass back for the next XAUTOCLAIM of any worker to take at once (JUSTID: this claim
  // is not counted as a delivery).
  void release(const rq::WorkItem& item) {
    m_redis.command({"XCLAIM", rq::kWorkStream, rq::kGroup, m_opt.name, "0", item.entry_id, "IDLE",
                     std::to_string(int64_t(3600) * 24 * 365 * 1000), "JUSTID"},
                    true);
  }

  // Error replies are ignored: after a restart of Redis the entry (or the group) may be gone.
  void acknowledge(const std::string& id) {
    m_redis.command({"XACK", rq::kWorkStream, rq::kGroup, id}, true);
    m_redis.command({"XDEL", rq::kWorkStream, id}, true);
  }

  // A try of the pass failed: released for another try (by any worker, at once), or after
  // kMaxDeliveries tries set aside in the dead-letter stream, which fails the job.
  void fail(const rq::WorkItem& item, const std::string& why) {
    int deliveries = rq::delivery_count(m_redis, item.entry_id);
    std::fprintf(stderr, "render-worker %s: job %s pass %u failed (delivery %d of %d): %s\n", m_opt.name.c_str(),
                 item.job.c_str(), item.unit, deliveries, rq::kMaxDeliveries, why.c_str());
    if (deliveries == 0) return;  // no longer pending (Redis restarted): nothing to release
    if (deliveries >= rq::kMaxDeliveries) return dead_letter(item, why, deliveries);
    release(item);
  }

  void dead_letter(const rq::WorkItem& item, const std::string& why, int tries) {
    const std::string range =
        "[" + std::to_string(item.first) + ", " + std::to_string(uint64_t(item.first) + item.count) + ")";
    RedisReply r = m_redis.command({"XADD", rq::kDeadStream, "MAXLEN", "~", std::to_string(rq::kDeadStreamLength), "*",
                                    "job", item.job, "run", item.run, "unit", std::to_string(item.unit), "first",
                                    std::to_string(item.first), "count", std::to_string(item.count), "entry",
                                    item.entry_id, "worker", m_opt.name, "deliveries", std::to_string(tries),
                                    "reason", why},
                                   true);
    if (r.type == RedisReply::error)  // the job still fails, below
      std::fprintf(stderr, "render-worker %s: cannot add to %s: %s\n", m_opt.name.c_str(), rq::kDeadStream.c_str(),
                   valid_utf8(r.str, 1000).c_str());
    // The server fails the job with this; the results key may itself be damaged, which the
    // server's own read of it then reports.
    const std::string results = rq::results_key(item.job, item.run), unit = std::to_string(item.unit);
    const std::string error = "pass " + unit + " (samples " + range + ") failed " + std::to_string(tries) +
                              " times and was set aside in " + rq::kDeadStream + ": " + why;
    std::vector<std::string> args{"XADD", results, "*", "job", item.job, "run", item.run, "unit", unit,
                                  "worker", m_opt.name, "error", error};
    if (m_key) args.insert(args.end(), {"sig", rq::error_signature(*m_key, item.job, item.run, unit, m_opt.name, error)});
    m_redis.command(args, true);
    m_redis.command({"EXPIRE", results, std::to_string(rq::kKeyTtlSeconds)}, true);
    acknowledge(item.entry_id);
    std::fprintf(stderr, "render-worker %s: job %s pass %u set aside in %s after %d tries\n", m_opt.name.c_str(),
                 item.job.c_str(), item.unit, rq::kDeadStream.c_str(), tries);
  }

  void handle(const rq::WorkItem& item) {
    const std::string results = rq::results_key(item.job, item.run);
    try {
      if (!prepare(item)) {  // the run is over: cancelled or finished
        acknowledge(item.entry_id);
        return;
      }
      const uint32_t spp = uint32_t(std::max(0, m_runs.front()->spec.params.spp));
      if (item.first >= spp || item.count > spp - item.first)
        throw std::runtime_error("samples [" + std::to_string(item.first) + ", +" + std::to_string(item.count) +
                                 ") are outside the job's " + std::to_string(spp) + " spp");
      std::atomic<bool> cancel{false};
      bool complete = false;
      pt::FilmPass pass = render_with_heartbeat(item, cancel, complete);
      if (!complete) {
        // Stopped by a signal: leave the pass pending so another worker claims it. Cancelled
        // because the run ended: nobody wants it.
        if (!g_stop) acknowledge(item.entry_id);
        return;
      }
      std::string features;
      for (const std::string& f : m_runs.front()->features) features += (features.empty() ? "" : ",") + f;
      send_result(item, pass.encode(), features);
      m_redis.command({"EXPIRE", results, std::to_string(rq::kKeyTtlSeconds)});
      acknowledge(item.entry_id);
      log("job %s pass %u: samples [%u, %u) in %.2f s", item.job.c_str(), item.unit, item.first,
          item.first + item.count, pass.seconds);
    } catch (const RedisUnreachable&) {
      throw;  // Redis stayed away past --redis-timeout, or a signal: the pass stays pending
    } catch (const RedisAuthError&) {
      throw;  // the credentials or the ACL rules are wrong: no pass can succeed, so the worker stops
    } catch (const std::exception& e) {
      // The run's keys, spec or scene are unusable (a damaged key answers WRONGTYPE): try again,
      // at most kMaxDeliveries times in all.
      fail(item, e.what());
    }
  }

  // Adds the result to the run's results stream. The send is never repeated blindly: when the
  // connection breaks during it, Redis may have the entry already, so the next send is a new
  // attempt (a new signature) that the server merges only if the first never arrived.
  void send_result(const rq::WorkItem& item, const std::string& bytes, const std::string& features) {
    const std::string results = rq::results_key(item.job, item.run), unit = std::to_string(item.unit);
    for (int attempt = 1;; ++attempt) {
      const std::string n = std::to_string(attempt);
      std::vector<std::string> args{"XADD", results, "*", "job", item.job, "run", item.run, "unit", unit, "worker",
                                    m_opt.name, "attempt", n, "pass", bytes, "features", features};
      if (m_key)
        args.insert(args.end(), {"sig", rq::result_signature(*m_key, item.job, item.run, unit, m_opt.name, n, bytes, features)});
      try {
        m_redis.command(args, false, false);
        return;
      } catch (const RedisMaybeSent& e) {
        if (attempt >= 8) throw;
        log("%s; sending pass %u again once Redis answers", e.what(), item.unit);
        m_redis.command({"PING"});  // waits out the outage (up to --redis-timeout)
      }
    }
  }

  // Makes the run's spec and view current, from the cache or from Redis; false if the run's key
  // is gone (the run is over).
  bool prepare(const rq::WorkItem& item) {
    std::string key = rq::job_key(item.job, item.run);
    for (auto it = m_runs.begin(); it != m_runs.end(); ++it)
      if ((*it)->key == key) {
        m_runs.splice(m_runs.begin(), m_runs, it);  // most recent first
        return m_redis.command({"EXISTS", key}).integer_value == 1;
      }
    RedisReply r = m_redis.command({"HMGET", key, "spec", "scene", "sig"});
    if (r.elements.size() != 3 || r.elements[0].is_nil() || r.elements[1].is_nil()) return false;
    if (r.elements[0].type != RedisReply::string || r.elements[1].type != RedisReply::string)
      throw std::runtime_error(key + ": unexpected reply");
    // The spec and the scene's content hash are what the worker renders: on a signed farm only
    // the server's.
    if (m_key && (r.elements[2].type != RedisReply::string ||
                  !same_signature(rq::run_signature(*m_key, item.job, item.run, r.elements[0].str, r.elements[1].str),
                                  r.elements[2].str)))
      throw std::runtime_error(valid_utf8(key, 200) + ": the run's spec and scene are not signed with the farm key");
    auto run = std::make_unique<PreparedRun>();
    run->key = key;
    run->spec = parse_job_spec(json::parse(r.elements[0].str));
    run->spec.params.threads = m_opt.threads;
    run->base = scene_base(r.elements[1].str, run->spec.scene);
    run->scene = pt::make_view(*run->base, run->spec.params);
    run->features = feature_names(run->scene->features);
    m_runs.push_front(std::move(run));
    if (m_runs.size() > kRunsKept) m_runs.pop_back();
    return true;
  }

  // The built scene for a content hash: cached, or downloaded, parsed and built.
  std::shared_ptr<const pt::SceneBase> scene_base(const std::string& hash, const std::string& name) {
    for (auto it = m_bases.begin(); it != m_bases.end(); ++it)
      if (it->first == hash) {
        m_bases.splice(m_bases.begin(), m_bases, it);
        return it->second;
      }
    RedisReply text = m_redis.command({"GET", rq::scene_key(hash)});
    if (text.type != RedisReply::string)
      throw std::runtime_error("the scene of job '" + name + "' is no longer in Redis");
    if (rq::content_hash(text.str) != hash)  // the run names its scene by content; anything else is not it
      throw std::runtime_error("the scene of job '" + name + "' in Redis does not match its content hash");
    auto t0 = std::chrono::steady_clock::now();
    auto base = std::make_shared<const pt::SceneBase>(pt::make_scene_base(pt::parse_scene(text.str, pt::scene_file_name(name, text.str))));
    log("scene '%s' built in %.3f s", name.c_str(),
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    m_bases.emplace_front(hash, base);
    if (m_bases.size() > kBasesKept) m_bases.pop_back();  // views still rendering keep theirs alive
    return base;
  }

  // Renders while a second connection keeps the pass claimed (so it is not taken over) and
  // watches for the run's end.
  pt::FilmPass render_with_heartbeat(const rq::WorkItem& item, std::atomic<bool>& cancel, bool& complete) {
    std::mutex m;
    std::condition_variable cv;
    bool finished = false;
    std::thread beat([&] {
      // Beats go on through a Redis outage (each a fresh try); the run's key gone cancels the pass,
      // as after a restart of Redis that lost it (the server then issues the pass again).
      RedisClient hb(m_address, 5.0, false);
      std::string key = rq::job_key(item.job, item.run), last_error;
      auto period = std::chrono::duration<double>(std::min(1.0, std::max(0.2, m_opt.claim_timeout / 4)));
      std::unique_lock<std::mutex> lock(m);
      while (!cv.wait_for(lock, period, [&] { return finished; })) {
        lock.unlock();
        try {
          hb.command({"XCLAIM", rq::kWorkStream, rq::kGroup, m_opt.name, "0", item.entry_id, "JUSTID"}, true);
          announce(hb);
          if (hb.command({"EXISTS", key}).integer_value == 0) cancel = true;
        } catch (const std::exception& e) {
          if (e.what() != last_error) std::fprintf(stderr, "render-worker: heartbeat: %s\n", e.what());
          last_error = e.what();
        }
        lock.lock();
      }
    });
    std::thread signals([&] {  // a signal stops the pass too
      std::unique_lock<std::mutex> lock(m);
      while (!cv.wait_for(lock, std::chrono::milliseconds(50), [&] { return finished; }))
        if (g_stop) cancel = true;
    });
    const PreparedRun& run = *m_runs.front();
    const pt::RenderParams& p = run.spec.params;
    size_t n = size_t(p.cell_w > 0 ? p.cell_w : p.width) * size_t(p.cell_w > 0 ? p.cell_h : p.height);
    std::vector<uint8_t> skip = item.mask.empty() ? std::vector<uint8_t>() : pt::unpack_mask(item.mask, n);
    pt::FilmPass pass;
    std::exception_ptr failure;
    try {
      pass = pt::render_film_pass(*run.scene, p, item.first, item.count, skip, &cancel, &complete);
    } catch (...) {
      failure = std::current_exception();
    }
    {
      std::lock_guard<std::mutex> lock(m);
      finished = true;
    }
    cv.notify_all();
    beat.join();
    signals.join();
    if (failure) std::rethrow_exception(failure);
    if (cancel) complete = false;
    return pass;
  }

  void log(const char* fmt, ...) __attribute__((format(printf, 2, 3))) {
    if (m_opt.quiet) return;
    va_list ap;
    va_start(ap, fmt);
    std::fprintf(stderr, "render-worker %s: ", m_opt.name.c_str());
    std::vfprintf(stderr, fmt, ap);
    std::fputc('\n', stderr);
    va_end(ap);
  }

  Options m_opt;
  RedisAddress m_address;
  std::shared_ptr<const FarmKey> m_key;  // null: an unsigned farm
  RedisClient m_redis;
  uint64_t m_refused = 0;  // pass requests refused (unsigned or badly signed)
  uint64_t m_grouped = 0;  // the connection on which the group was last ensured
  std::list<std::unique_ptr<PreparedRun>> m_runs;  // most recent first
  std::list<std::pair<std::string, std::shared_ptr<const pt::SceneBase>>> m_bases;
};

bool parse_options(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      return argv[++i];
    };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return false;
    } else if (a == "--version") {
      std::printf("%s\n", pt::version_text("render-worker").c_str());
      return false;
    } else if (a == "--queue") {
      o.queue = value();
    } else if (a == "-t" || a == "--threads") {
      o.threads = std::atoi(value().c_str());
      if (o.threads < 1 || o.threads > 1024) throw std::invalid_argument("--threads must be 1-1024");
    } else if (a == "--name") {
      o.name = value();
    } else if (a == "--claim-timeout") {
      o.claim_timeout = std::atof(value().c_str());
      if (!(o.claim_timeout >= 0.2 && o.claim_timeout <= 3600)) throw std::invalid_argument("--claim-timeout must be 0.2-3600 s");
    } else if (a == "--redis-timeout") {
      o.redis_timeout = std::atof(value().c_str());
      if (!(o.redis_timeout >= 0.1 && o.redis_timeout <= 3600)) throw std::invalid_argument("--redis-timeout must be 0.1-3600 s");
    } else if (a == "--quiet") {
      o.quiet = true;
    } else if (a == "--redis-password-file") {
      o.farm.password_file = value();
    } else if (a == "--farm-key-file") {
      o.farm.key_file = value();
    } else if (a == "--insecure-farm") {
      o.farm.insecure = true;
    } else {
      throw std::invalid_argument("unknown option '" + a + "' (see --help)");
    }
  }
  if (o.name.empty()) {
    char host[256] = "worker";
    gethostname(host, sizeof host - 1);
    o.name = std::string(host) + "-" + std::to_string(getpid());
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  try {
    if (!parse_options(argc, argv, opt)) return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render-worker: %s\n", e.what());
    return 2;
  }
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  signal(SIGPIPE, SIG_IGN);
  // Redis unreachable is waited for inside (up to --redis-timeout); other errors (a damaged
  // pt:work) start the worker again after a back-off.
  for (double wait = 0.1; !g_stop; wait = std::min(wait * 2, 2.0)) {
    try {
      Worker worker(opt);
      std::fprintf(stderr, "render-worker %s: taking passes from %s with %d threads%s\n", opt.name.c_str(),
                   worker.address().c_str(), opt.threads, worker.signed_farm() ? " (signed farm)" : "");
      wait = 0.1;
      worker.run();
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "render-worker: %s\n", e.what());
      return 2;
    } catch (const NeedsFarmKey& e) {
      std::fprintf(stderr, "render-worker %s: %s\n", opt.name.c_str(), e.what());
      return 2;
    } catch (const RedisAuthError& e) {
      std::fprintf(stderr, "render-worker: %s\n", e.what());
      return 1;
    } catch (const RedisUnreachable& e) {
      if (g_stop) break;
      std::fprintf(stderr, "render-worker: %s; giving up\n", e.what());
      return 1;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "render-worker: %s; retrying in %.1f s\n", e.what(), wait);
      for (double t = 0; t < wait && !g_stop; t += 0.1) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  return 0;
}
