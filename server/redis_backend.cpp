// The Redis backend: a job becomes sample passes on the stream pt:work; render-workers render them
// and return per-pixel sums on the run's results stream, which are merged here as they arrive
// (pt::FilmAccumulator) and stream to the page like the embedded renderer's tiles.
#include <atomic>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <random>
#include <set>

#include "collada.h"
#include "film.h"
#include "jobs.h"
#include "redis_queue.h"
#include "render_backend.h"
#include "scene_library.h"

namespace srv {

namespace {

std::string new_run_id() {
  static std::mutex mutex;
  static std::mt19937_64 rng(std::random_device{}());
  std::lock_guard<std::mutex> lock(mutex);
  char buf[20];
  std::snprintf(buf, sizeof buf, "%016llx", (unsigned long long)rng());
  return buf;
}

// Pass sizes. The first passes are 1, 1, 2, 4, ... samples per pixel (quick first pictures), then
// passes grow to what a worker renders in about kPassSeconds, measured from the passes returned,
// and longer for large frames so that a worker sends at most kPassBytesPerSecond: the server's
// merges and the network then cost the same per worker whatever the workers' speed
// (docs/scale-out.md works out the numbers). A pass takes no more than an even share of the
// remaining samples among the live workers (rounded up to a power of two), so that the last
// passes of a job run side by side rather than one after another. Counts are
// powers of two and ranges start at a multiple of their count, which keeps each pass's Sobol
// points well stratified.
constexpr double kPassSeconds = 2.0, kPassBytesPerSecond = 4e6;

class PassPlan {
 public:
  // A pass carries 20 bytes a pixel (FilmPass), 32 with light-traced caustics.
  PassPlan(int spp, size_t pixels, double bytes_per_pixel)
      : m_spp(uint32_t(spp)), m_pixels(pixels), m_pixel_bytes(bytes_per_pixel) {}

  bool exhausted() const { return m_next_first >= m_spp; }
  size_t issued() const { return m_ranges.size(); }
  std::pair<uint32_t, uint32_t> range(size_t unit) const { return m_ranges[unit]; }

  // A returned pass: `samples` rendered in `seconds` by one worker.
  void observe(uint64_t samples, double seconds) {
    if (samples == 0 || !(seconds > 1e-3)) return;
    double rate = samples / seconds;
    m_rate = m_rate > 0 ? 0.5 * (m_rate + rate) : rate;
  }

  // The next range, for `active` pixels still rendering and `workers` live workers.
  std::pair<uint32_t, uint32_t> next(size_t active, int workers) {
    uint32_t first = m_next_first, count = 1;
    if (first > 0) {
      uint32_t want = first, floor = 1;  // ramp: 1, 1, 2, 4, ... until a pass has been measured
      if (m_rate > 0) {
        double seconds = std::max(kPassSeconds, m_pixel_bytes * double(m_pixels) / kPassBytesPerSecond);
        uint32_t timed = uint32_t(std::min(1024.0, std::max(1.0, m_rate * seconds / double(std::max<size_t>(active, 1)))));
        want = std::min(timed, 2 * first);  // grow at most twofold a pass
        floor = std::max(1u, timed / 4);    // the last passes shrink, but not to a trail of tiny ones
      }
      uint32_t share = 1, left = m_spp - first, n = uint32_t(std::max(1, workers));
      while (share * n < left) share *= 2;  // an even share, rounded up
      want = std::min(want, std::max(share, floor));
      while (count * 2 <= want && first % (count * 2) == 0) count *= 2;
    }
    count = std::min(count, m_spp - first);
    m_ranges.push_back({first, count});
    m_next_first = first + count;
    return m_ranges.back();
  }

 private:
  uint32_t m_spp, m_next_first = 0;
  size_t m_pixels;
  double m_pixel_bytes;
  double m_rate = 0;  // pixel-samples per second of one worker, smoothed
  std::vector<std::pair<uint32_t, uint32_t>> m_ranges;
};

// The features a worker reports: comma-separated names from Redis, so bounded and made valid UTF-8.
std::vector<std::string> parse_features(const std::string* text) {
  std::vector<std::string> out;
  if (!text) return out;
  for (size_t at = 0; at < text->size() && out.size() < 64;) {
    size_t comma = text->find(',', at);
    if (comma == std::string::npos) comma = text->size();
    out.push_back(valid_utf8(std::string_view(*text).substr(at, comma - at), 64));
    at = comma + 1;
  }
  return out;
}

class RedisBackend : public RenderBackend {
 public:
  RedisBackend(SceneLibrary& scenes, const std::string& url, int in_flight, double redis_timeout)
      : m_scenes(scenes), m_address(RedisAddress::parse(url)), m_in_flight(std::max(1, in_flight)),
        m_redis_timeout(redis_timeout) {
    RedisClient redis(m_address);
    rq::ensure_group(redis);
  }

  std::string name() const override { return m_address.url(); }

  int live_workers() override {
    std::lock_guard<std::mutex> lock(m_health_mutex);
    try {
      if (!m_health) m_health = std::make_unique<RedisClient>(m_address, 1.0);
      return rq::count_workers(*m_health);
    } catch (const std::exception&) {
      m_health.reset();
      return 0;  // Redis unreachable: no worker can take work
    }
  }

  RenderResult render(const Job& job, JobSink& sink, const std::atomic<bool>& stop) override {
    using clock = std::chrono::steady_clock;
    const JobSpec& spec = job.spec;
    const pt::RenderParams& p = spec.params;
    std::string path = m_scenes.resolve(spec.scene), scene_text;
    if (path.empty() || !read_file(path, scene_text)) throw std::runtime_error("scene '" + spec.scene + "' is gone");
    // A bad file fails here, not once on every worker; the server itself builds no BVH.
    pt::parse_collada(scene_text, spec.scene + ".dae");
    const int w = p.cell_w > 0 ? p.cell_w : p.width, h = p.cell_w > 0 ? p.cell_h : p.height;
    const size_t pixels = size_t(w) * h;

    // An unreachable Redis (a restart) is waited for, up to --redis-timeout; a cancel ends the wait.
    RedisClient redis(m_address, 5.0, false);
    redis.set_patience(m_redis_timeout, &stop, "render-server: job " + job.id);
    const std::string run = new_run_id(), job_key = rq::job_key(job.id, run), results = rq::results_key(job.id, run);
    const std::string scene_hash = rq::content_hash(scene_text), ttl = std::to_string(rq::kKeyTtlSeconds);
    const std::string spec_json = job_spec_to_json(spec).dump();
    struct Cleanup {  // however the render ends, workers learn the run is over
      RedisClient& redis;
      std::string job_key, results;
      ~Cleanup() {
        try {
          redis.set_patience(0);
          redis.command({"DEL", job_key, results});
        } catch (const std::exception& e) {
          std::fprintf(stderr, "render-server: cannot clean up %s: %s\n", job_key.c_str(), e.what());
        }
      }
    } cleanup{redis, job_key, results};

    PassPlan plan(p.spp, pixels, p.caustic_tracing ? 32.0 : 20.0);  // the scene decides; plan for the larger
    pt::FilmAccumulator film(p, w, h);
    std::vector<pt::Tile> tiles;
    for (int y = 0; y < h; y += p.tile_size)
      for (int x = 0; x < w; x += p.tile_size) tiles.push_back({x, y, std::min(x + p.tile_size, w), std::min(y + p.tile_size, h)});

    std::set<uint32_t> merged;
    std::string last_id = "0-0";
    auto issue = [&](size_t unit) {
      auto [first, count] = plan.range(unit);
      redis.command({"XADD", rq::kWorkStream, "*", "job", job.id, "run", run, "unit", std::to_string(unit), "first",
                     std::to_string(first), "count", std::to_string(count), "mask",
                     p.adaptive ? pt::pack_mask(film.done()) : std::string()});
    };
    // Puts what workers need in Redis: the group, the scene's bytes (once per content: repeated
    // jobs on a large scene send only its hash), the run's hash. Again on every new connection:
    // a Redis restarted without its data has lost them, and the passes issued so far, which go
    // out again (a pass rendered twice is merged once).
    uint64_t published = ~uint64_t(0);  // the connection the run was last published on (none yet)
    auto publish = [&] {
      do {
        redis.command({"PING"});
        published = redis.connections();
        rq::ensure_group(redis);
        redis.command({"SET", rq::scene_key(scene_hash), scene_text, "EX", ttl, "NX"});
        redis.command({"EXPIRE", rq::scene_key(scene_hash), ttl});
        bool fresh = redis.command({"HSET", job_key, "spec", spec_json, "scene", scene_hash}).integer_value > 0;
        redis.command({"EXPIRE", job_key, ttl});
        if (fresh && plan.issued() > merged.size()) {
          std::fprintf(stderr,
                       "render-server: job %s: the run's keys were gone from Redis; issuing its %zu unmerged passes again\n",
                       job.id.c_str(), plan.issued() - merged.size());
          for (size_t u = 0; u < plan.issued(); ++u)
            if (!merged.count(uint32_t(u))) issue(u);
        }
        if (fresh) last_id = "0-0";  // results of the lost stream that came in again
      } while (redis.connections() != published);
    };

    int workers = 1;
    auto next_worker_count = clock::now();
    bool started = false;
    double merge_seconds = 0;  // decoding, merging and publishing passes: the server's cost per pass
    size_t pass_bytes = 0;
    auto t0 = clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(clock::now() - t0).count(); };
    RenderResult result;
    try {
      for (;;) {
        // Keep every live worker busy plus a few passes queued, each carrying the pixels converged
        // so far. The worker count is looked up at most once a second.
        if (redis.connections() != published) publish();
        if (clock::now() >= next_worker_count) {
          workers = std::max(1, live_workers());
          next_worker_count = clock::now() + std::chrono::seconds(1);
        }
        const size_t ahead = size_t(std::max(m_in_flight, workers + 2));
        while (!plan.exhausted() && plan.issued() < merged.size() + ahead && !film.finished()) {
          plan.next(film.remaining(), workers);
          issue(plan.issued() - 1);
        }
        if (stop) {
          result.why = pt::StopReason::cancelled;
          break;
        }
        if (spec.time_limit > 0 && elapsed() >= spec.time_limit && !merged.empty()) {
          result.why = pt::StopReason::time_limit;
          break;
        }
        RedisReply r = redis.command({"XREAD", "COUNT", "4", "BLOCK", "100", "STREAMS", results, last_id});
        // Everything read from Redis is checked: [[stream, [[id, [field, value, ...]], ...]]].
        if (r.type != RedisReply::array || r.elements.empty() || r.elements[0].elements.size() < 2) continue;
        auto merge_start = clock::now();
        bool changed = false;
        for (const RedisReply& e : r.elements[0].elements[1].elements) {
          if (e.elements.size() != 2 || e.elements[0].type != RedisReply::string) continue;
          last_id = e.elements[0].str;
          const RedisReply& body = e.elements[1];
          if (const std::string* err = body.field("error")) throw std::runtime_error(valid_utf8(*err, 2000));
          const std::string* bytes = body.field("pass");
          uint32_t u = 0;
          if (!rq::parse_u32(body.field("unit"), u) || !bytes) continue;
          if (u >= plan.issued() || merged.count(u)) continue;  // a pass rendered twice (its first worker looked dead)
          pt::FilmPass pass = pt::FilmPass::decode(*bytes, w, h);
          pass_bytes += bytes->size();
          if (pass.first != plan.range(u).first || pass.count != plan.range(u).second) continue;
          uint64_t pass_samples = 0;
          for (uint32_t n : pass.samples) pass_samples += n;
          plan.observe(pass_samples, pass.seconds);
          if (!started) {
            sink.started(w, h, parse_features(body.field("features")));
            started = true;
          }
          film.merge(pass);
          merged.insert(u);
          changed = true;
        }
        if (!changed) continue;
        std::vector<pt::Vec3> buf;
        for (const pt::Tile& t : tiles) {
          film.read_tile(t, buf);
          sink.tile(t, buf);
        }
        result.report = {film.progress(), film.samples(), film.rays(), film.nonfinite(), film.error_estimate()};
        sink.pass(result.report);
        merge_seconds += std::chrono::duration<double>(clock::now() - merge_start).count();
        if (spec.target_error > 0 && result.report.error <= spec.target_error) {
          result.why = pt::StopReason::target_error;
          break;
        }
        if (film.finished() || (plan.exhausted() && merged.size() == plan.issued())) {
          result.why = pt::StopReason::finished;
          break;
        }
      }
    } catch (const RedisUnreachable&) {
      if (!stop) throw;  // away past --redis-timeout: the job fails, saying so
      result.why = pt::StopReason::cancelled;  // cancelled (or the server stopping) while waiting
    }
    if (!started && result.why != pt::StopReason::cancelled) sink.started(w, h, {});
    result.image = film.image();
    result.report = {film.progress(), film.samples(), film.rays(), film.nonfinite(), film.error_estimate()};
    result.seconds = elapsed();
    if (!merged.empty()) {
      std::string sizes;
      for (size_t u = 0; u < plan.issued(); ++u) sizes += (u ? " " : "") + std::to_string(plan.range(u).second);
      std::fprintf(stderr, "render-server: job %s: %zu passes merged in %.3f s (%.2f ms and %.2f MB a pass), %.2f s in all; spp a pass: %s\n",
                   job.id.c_str(), merged.size(), merge_seconds, 1e3 * merge_seconds / merged.size(),
                   pass_bytes / 1e6 / merged.size(), result.seconds, sizes.c_str());
    }
    return result;
  }

 private:
  SceneLibrary& m_scenes;
  RedisAddress m_address;
  int m_in_flight;
  double m_redis_timeout;  // seconds a job waits for an unreachable Redis (--redis-timeout)
  std::mutex m_health_mutex;
  std::unique_ptr<RedisClient> m_health;
};

}  // namespace

std::unique_ptr<RenderBackend> make_redis_backend(SceneLibrary& scenes, const std::string& url, int units_in_flight,
                                                  double redis_timeout) {
  return std::make_unique<RedisBackend>(scenes, url, units_in_flight, redis_timeout);
}

}  // namespace srv
