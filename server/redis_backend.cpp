// The Redis backend: a job becomes sample passes on the stream pt:work; render-workers render them
// and return per-pixel sums on the run's results stream, which are merged here as they arrive
// (pt::FilmAccumulator) and stream to the page like the embedded renderer's tiles.
#include <chrono>
#include <mutex>
#include <cstdio>
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

// Pass sizes: 1, 1, 2, 4, ... samples per pixel (quick first pictures; ranges aligned to powers
// of two keep Sobol points well stratified within each pass), then a fixed size of about 2^21
// pixel-samples, which takes a worker a fraction of a second to a few seconds.
struct PassPlan {
  std::vector<std::pair<uint32_t, uint32_t>> ranges;  // [first, first + count)
  PassPlan(int spp, size_t pixels) {
    uint32_t cap = 1;
    while (cap < 1024 && double(cap) * 2 * pixels <= double(1 << 21)) cap *= 2;
    for (uint32_t first = 0; first < uint32_t(spp);) {
      uint32_t count = std::min(std::max(1u, std::min(cap, first)), uint32_t(spp) - first);
      ranges.push_back({first, count});
      first += count;
    }
  }
};

class RedisBackend : public RenderBackend {
 public:
  RedisBackend(SceneLibrary& scenes, const std::string& url, int in_flight)
      : m_scenes(scenes), m_address(RedisAddress::parse(url)), m_in_flight(std::max(1, in_flight)) {
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

    RedisClient redis(m_address);
    const std::string run = new_run_id(), job_key = rq::job_key(job.id, run), results = rq::results_key(job.id, run);
    // The scene's bytes go up once per content: repeated jobs on a large scene send only its hash.
    const std::string scene_hash = rq::content_hash(scene_text), ttl = std::to_string(rq::kKeyTtlSeconds);
    redis.command({"SET", rq::scene_key(scene_hash), scene_text, "EX", ttl, "NX"});
    redis.command({"EXPIRE", rq::scene_key(scene_hash), ttl});
    std::string().swap(scene_text);
    redis.command({"HSET", job_key, "spec", job_spec_to_json(spec).dump(), "scene", scene_hash});
    redis.command({"EXPIRE", job_key, ttl});
    struct Cleanup {  // however the render ends, workers learn the run is over
      RedisClient& redis;
      std::string job_key, results;
      ~Cleanup() {
        try {
          redis.command({"DEL", job_key, results});
        } catch (const std::exception& e) {
          std::fprintf(stderr, "render-server: cannot clean up %s: %s\n", job_key.c_str(), e.what());
        }
      }
    } cleanup{redis, job_key, results};

    PassPlan plan(p.spp, pixels);
    pt::FilmAccumulator film(p, w, h);
    std::vector<pt::Tile> tiles;
    for (int y = 0; y < h; y += p.tile_size)
      for (int x = 0; x < w; x += p.tile_size) tiles.push_back({x, y, std::min(x + p.tile_size, w), std::min(y + p.tile_size, h)});

    size_t next = 0;  // the next pass to hand out
    std::set<uint32_t> merged;
    bool started = false;
    std::string last_id = "0-0";
    double merge_seconds = 0;  // decoding, merging and publishing passes: the server's cost per pass
    size_t pass_bytes = 0;
    auto t0 = clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(clock::now() - t0).count(); };
    RenderResult result;
    redis.set_timeout(5.0);
    for (;;) {
      // Keep a few passes queued ahead of the merges, each carrying the pixels converged so far.
      while (next < plan.ranges.size() && next < merged.size() + size_t(m_in_flight) && !film.finished()) {
        auto [first, count] = plan.ranges[next];
        redis.command({"XADD", rq::kWorkStream, "*", "job", job.id, "run", run, "unit", std::to_string(next), "first",
                       std::to_string(first), "count", std::to_string(count), "mask",
                       p.adaptive ? pt::pack_mask(film.done()) : std::string()});
        ++next;
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
      if (r.is_nil() || r.elements.empty() || r.elements[0].elements.size() < 2) continue;
      auto merge_start = clock::now();
      bool changed = false;
      for (const RedisReply& e : r.elements[0].elements[1].elements) {
        if (e.elements.size() != 2) continue;
        last_id = e.elements[0].str;
        const RedisReply& body = e.elements[1];
        if (const std::string* err = body.field("error")) throw std::runtime_error(*err);
        const std::string *unit = body.field("unit"), *bytes = body.field("pass");
        if (!unit || !bytes) continue;
        uint32_t u = uint32_t(std::strtoul(unit->c_str(), nullptr, 10));
        if (u >= next || merged.count(u)) continue;  // a pass rendered twice (its first worker looked dead)
        pt::FilmPass pass = pt::FilmPass::decode(*bytes, w, h);
        pass_bytes += bytes->size();
        if (pass.first != plan.ranges[u].first || pass.count != plan.ranges[u].second) continue;
        if (!started) {
          std::vector<std::string> features;
          if (const std::string* f = body.field("features"))
            for (size_t at = 0; at < f->size();) {
              size_t comma = f->find(',', at);
              if (comma == std::string::npos) comma = f->size();
              features.push_back(f->substr(at, comma - at));
              at = comma + 1;
            }
          sink.started(w, h, features);
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
      if (film.finished() || merged.size() == plan.ranges.size()) {
        result.why = pt::StopReason::finished;
        break;
      }
    }
    if (!started && result.why != pt::StopReason::cancelled) sink.started(w, h, {});
    result.image = film.image();
    result.report = {film.progress(), film.samples(), film.rays(), film.nonfinite(), film.error_estimate()};
    result.seconds = elapsed();
    if (!merged.empty())
      std::fprintf(stderr, "render-server: job %s: %zu passes merged in %.3f s (%.2f ms and %.2f MB a pass), %.2f s in all\n",
                   job.id.c_str(), merged.size(), merge_seconds, 1e3 * merge_seconds / merged.size(),
                   pass_bytes / 1e6 / merged.size(), result.seconds);
    return result;
  }

 private:
  SceneLibrary& m_scenes;
  RedisAddress m_address;
  int m_in_flight;
  std::mutex m_health_mutex;
  std::unique_ptr<RedisClient> m_health;
};

}  // namespace

std::unique_ptr<RenderBackend> make_redis_backend(SceneLibrary& scenes, const std::string& url, int units_in_flight) {
  return std::make_unique<RedisBackend>(scenes, url, units_in_flight);
}

}  // namespace srv
