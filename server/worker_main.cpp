// render-worker: takes sample passes from Redis (stream pt:work, consumer group "workers"),
// renders them and returns per-pixel sums. Work a dead worker held is claimed by a live one once
// it has been idle for --claim-timeout; a live worker keeps its pass fresh by re-claiming it.
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

#include "collada.h"
#include "film.h"
#include "job_spec.h"
#include "redis_queue.h"

namespace {

using namespace srv;

const char* kUsage =
    "Usage: render-worker [options]\n"
    "Renders sample passes that render-server --queue redis://HOST:PORT hands out.\n"
    "  --queue URL          the Redis server (default redis://127.0.0.1:6379)\n"
    "  -t, --threads N      render threads (default: all cores)\n"
    "  --name NAME          consumer name in the group (default: host-pid)\n"
    "  --claim-timeout SEC  take over passes a worker left unacknowledged this long (default 10)\n"
    "  --quiet              log nothing but errors\n"
    "  -h, --help           this text\n";

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

struct Options {
  std::string queue = "redis://127.0.0.1:6379";
  int threads = int(std::max(1u, std::thread::hardware_concurrency()));
  std::string name;
  double claim_timeout = 10;
  bool quiet = false;
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
  explicit Worker(Options o) : m_opt(std::move(o)), m_address(RedisAddress::parse(m_opt.queue)), m_redis(m_address) {
    rq::ensure_group(m_redis);
  }

  void run() {
    m_redis.set_timeout(5.0);
    while (!g_stop) {
      announce(m_redis);
      rq::WorkItem item;
      if (!next_item(item)) continue;
      handle(item);
    }
    m_redis.command({"DEL", rq::worker_key(m_opt.name)});  // stopped: no longer counted
  }

 private:
  // A pass whose worker went quiet first (XAUTOCLAIM), else a new one (XREADGROUP, 1 s block).
  bool next_item(rq::WorkItem& item) {
    std::string idle_ms = std::to_string(int64_t(m_opt.claim_timeout * 1000));
    RedisReply r = m_redis.command({"XAUTOCLAIM", rq::kWorkStream, rq::kGroup, m_opt.name, idle_ms, "0-0", "COUNT", "1"});
    if (r.elements.size() >= 2)
      for (const RedisReply& e : r.elements[1].elements)
        if (parse_or_drop(e, item)) {
          log("claimed pass %u of job %s left by another worker", item.unit, item.job.c_str());
          return true;
        }
    r = m_redis.command({"XREADGROUP", "GROUP", rq::kGroup, m_opt.name, "COUNT", "1", "BLOCK", "1000", "STREAMS",
                         rq::kWorkStream, ">"});
    if (r.is_nil() || r.elements.empty() || r.elements[0].elements.size() < 2) return false;
    for (const RedisReply& e : r.elements[0].elements[1].elements)
      if (parse_or_drop(e, item)) return true;
    return false;
  }

  // Tells the server this worker is alive (a key that expires unless renewed).
  void announce(RedisClient& redis) {
    redis.command({"SET", rq::worker_key(m_opt.name), std::to_string(m_opt.threads), "EX",
                   std::to_string(rq::kWorkerTtlSeconds)});
  }

  bool parse_or_drop(const RedisReply& entry, rq::WorkItem& item) {
    if (rq::parse_work_item(entry, item)) return true;
    if (entry.type == RedisReply::array && !entry.elements.empty()) acknowledge(entry.elements[0].str);
    return false;
  }

  void acknowledge(const std::string& id) {
    m_redis.command({"XACK", rq::kWorkStream, rq::kGroup, id});
    m_redis.command({"XDEL", rq::kWorkStream, id});
  }

  void handle(const rq::WorkItem& item) {
    const std::string results = rq::results_key(item.job, item.run);
    try {
      if (!prepare(item)) {  // the run is over: cancelled or finished
        acknowledge(item.entry_id);
        return;
      }
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
      m_redis.command({"XADD", results, "*", "unit", std::to_string(item.unit), "worker", m_opt.name, "pass",
                       pass.encode(), "features", features});
      m_redis.command({"EXPIRE", results, std::to_string(rq::kKeyTtlSeconds)});
      acknowledge(item.entry_id);
      log("job %s pass %u: samples [%u, %u) in %.2f s", item.job.c_str(), item.unit, item.first,
          item.first + item.count, pass.seconds);
    } catch (const RedisError&) {
      throw;  // the queue is gone: the caller reconnects; the pass stays pending
    } catch (const std::exception& e) {
      // The scene or spec cannot render: tell the server (which fails the job), drop the pass.
      std::fprintf(stderr, "render-worker: job %s: %s\n", item.job.c_str(), e.what());
      m_redis.command({"XADD", results, "*", "unit", std::to_string(item.unit), "worker", m_opt.name, "error", e.what()});
      acknowledge(item.entry_id);
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
    RedisReply r = m_redis.command({"HMGET", key, "spec", "scene"});
    if (r.elements.size() != 2 || r.elements[0].is_nil() || r.elements[1].is_nil()) return false;
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
    if (text.is_nil()) throw std::runtime_error("the scene of job '" + name + "' is no longer in Redis");
    auto t0 = std::chrono::steady_clock::now();
    auto base = std::make_shared<const pt::SceneBase>(pt::make_scene_base(pt::parse_collada(text.str, name + ".dae")));
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
      try {
        RedisClient hb(m_address);
        std::string key = rq::job_key(item.job, item.run);
        auto period = std::chrono::duration<double>(std::min(1.0, std::max(0.2, m_opt.claim_timeout / 4)));
        std::unique_lock<std::mutex> lock(m);
        while (!cv.wait_for(lock, period, [&] { return finished; })) {
          lock.unlock();
          hb.command({"XCLAIM", rq::kWorkStream, rq::kGroup, m_opt.name, "0", item.entry_id, "JUSTID"});
          announce(hb);
          if (hb.command({"EXISTS", key}).integer_value == 0) cancel = true;
          lock.lock();
        }
      } catch (const std::exception& e) {
        std::fprintf(stderr, "render-worker: heartbeat: %s\n", e.what());
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
  RedisClient m_redis;
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
    } else if (a == "--quiet") {
      o.quiet = true;
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
  // The queue may restart or be briefly unreachable: reconnect with back-off until stopped.
  for (double wait = 0.5; !g_stop; wait = std::min(wait * 2, 5.0)) {
    try {
      Worker worker(opt);
      std::fprintf(stderr, "render-worker %s: taking passes from %s with %d threads\n", opt.name.c_str(),
                   opt.queue.c_str(), opt.threads);
      wait = 0.5;
      worker.run();
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "render-worker: %s\n", e.what());
      return 2;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "render-worker: %s; retrying in %.1f s\n", e.what(), wait);
      for (double t = 0; t < wait && !g_stop; t += 0.1) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  return 0;
}
