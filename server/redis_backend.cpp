// The Redis backend: a job becomes sample passes on the stream pt:work; render-workers render them
// and return per-pixel sums on the run's results stream, which are merged here as they arrive
// (pt::Film) and stream to the page like the embedded renderer's tiles.
#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <tuple>

#include "checkpoint.h"
#include "farm_ledger.h"
#include "scene_file.h"
#include "job_store.h"
#include "film_pass.h"
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

  // Checkpoints: the ranges issued so far and the measured rate.
  void save(pt::BinaryWriter& out) const {
    out.pod(m_next_first), out.pod(m_rate), out.pod(uint64_t(m_ranges.size()));
    for (auto [first, count] : m_ranges) out.pod(first), out.pod(count);
  }
  void restore(pt::BinaryReader& in) {
    m_next_first = in.pod<uint32_t>(), m_rate = in.pod<double>();
    const uint64_t n = in.pod<uint64_t>();
    if (n > m_spp || m_next_first > m_spp || !(m_rate >= 0 && m_rate < 1e15)) in.fail("an impossible pass plan");
    m_ranges.clear();
    for (uint64_t k = 0; k < n; ++k) {
      const uint32_t first = in.pod<uint32_t>(), count = in.pod<uint32_t>();
      if (count == 0 || first >= m_next_first || count > m_next_first - first) in.fail("an impossible pass");
      m_ranges.push_back({first, count});
    }
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

// A job's passes, rendered by workers and merged here as they arrive: the PassSource the driver
// runs for this backend. PassPlan sizes the passes by the workers' speed (the driver's targets do
// not apply: a target is a whole frame's pass, and workers render many at once), and each
// advance() returns once something was merged.
class WorkerPasses : public pt::PassSource {
 public:
  WorkerPasses(const Job& job, const std::string& scene_text, RedisClient& redis, JobSink& sink,
               std::function<int()> live_workers, int in_flight, const FarmKey* key, FarmLedger& ledger)
      : m_job(job), m_params(job.spec.params), m_scene_text(scene_text), m_redis(redis), m_sink(sink), m_key(key),
        m_ledger(ledger),
        m_live_workers(std::move(live_workers)), m_in_flight(in_flight),
        m_w(m_params.cell_w > 0 ? m_params.cell_w : m_params.width),
        m_h(m_params.cell_w > 0 ? m_params.cell_h : m_params.height),
        m_run(new_run_id()), m_job_key(rq::job_key(job.id, m_run)), m_results(rq::results_key(job.id, m_run)),
        m_scene_hash(rq::content_hash(scene_text)), m_spec_json(job_spec_to_json(job.spec).dump()),
        // the scene decides whether passes carry caustics; plan for the larger
        m_plan(m_params.spp, size_t(m_w) * m_h, m_params.caustic_tracing ? 32.0 : 20.0),
        m_film(m_w, m_h, m_params.spp, pt::adaptive_rule(m_params), false, m_params.features) {
    m_tiles = pt::tile_grid(m_w, m_h, m_params.tile_size);
  }
  // However the render ends, workers learn the run is over.
  ~WorkerPasses() override {
    try {
      m_redis.set_patience(0);
      m_redis.command({"DEL", m_job_key, m_results});
    } catch (const std::exception& e) {
      std::fprintf(stderr, "render-server: cannot clean up %s: %s\n", m_job_key.c_str(), e.what());
    }
  }

  bool advance(int, const std::atomic<bool>* cancel, const pt::TileCallback& on_tile) override;
  void set_deadline(std::chrono::steady_clock::time_point t) override { m_deadline = t; }
  const pt::Film& film() const override { return m_film; }
  double seconds() const override { return m_seconds_before + std::chrono::duration<double>(clock::now() - m_t0).count(); }
  bool finished() const override {
    return m_film.finished() || (m_plan.exhausted() && m_merged.size() == m_plan.issued());
  }
  pt::RenderCounts counts() const override { return {m_samples, m_rays, m_nonfinite}; }
  bool anything_to_keep() const override { return m_started; }
  const std::vector<pt::Tile>& tiles() const override { return m_tiles; }
  // Checkpoints: the merged film, the passes issued and which of them were merged. A restored run
  // (a new run id) issues again the passes that were out when the server stopped.
  void save(pt::BinaryWriter& out) const override;
  void restore(pt::BinaryReader& in) override;
  // After the last advance: the sink has started, and the log has the job's merge costs.
  void finish(pt::StopReason why);
  // After a restore: the sink starts with the checkpoint's time and the job's features.
  void resumed(const std::vector<std::string>& features) {
    m_sink.started(m_w, m_h, features, m_seconds_before);
    m_started = true;
  }

 private:
  using clock = std::chrono::steady_clock;
  bool gather(const std::atomic<bool>* cancel, const pt::TileCallback& on_tile);  // advance's work
  void issue(size_t unit);
  void publish();
  bool merge(const RedisReply& r);  // true when a pass was merged
  // Why the result entry `body` must not be merged ("" when it may be); `pass` receives it decoded.
  // `worker` is the name it claims, cut and made valid UTF-8 for logs.
  std::string check(const RedisReply& body, const std::string& worker, uint32_t& unit, pt::FilmPass& pass);

  const Job& m_job;
  const pt::RenderParams& m_params;
  const std::string& m_scene_text;
  RedisClient& m_redis;
  JobSink& m_sink;
  const FarmKey* m_key;  // null: an unsigned farm
  FarmLedger& m_ledger;
  std::function<int()> m_live_workers;
  int m_in_flight;
  int m_w, m_h;
  std::string m_run, m_job_key, m_results, m_scene_hash, m_spec_json;
  PassPlan m_plan;
  pt::Film m_film;
  std::vector<pt::Tile> m_tiles;
  std::set<uint32_t> m_merged;
  std::map<uint32_t, std::string> m_signatures;  // merged units' result signatures: a copy is a replay
  std::map<uint32_t, std::string> m_masks;       // the converged-pixel mask each unmerged unit was sent
  std::string m_last_id = "0-0";
  uint64_t m_published = ~uint64_t(0);  // the connection the run was last published on (none yet)
  int m_workers = 1;
  clock::time_point m_next_worker_count = clock::now(), m_t0 = clock::now();
  clock::time_point m_deadline = clock::time_point::max();
  bool m_started = false;
  double m_merge_seconds = 0;  // decoding, merging and publishing passes: the server's cost per pass
  size_t m_pass_bytes = 0;
  uint64_t m_samples = 0, m_rays = 0, m_nonfinite = 0;
  double m_seconds_before = 0;  // rendering time a checkpoint restored
};

void WorkerPasses::save(pt::BinaryWriter& out) const {
  m_plan.save(out);
  out.pod(uint64_t(m_merged.size()));
  for (uint32_t u : m_merged) out.pod(u);
  out.pod(m_samples), out.pod(m_rays), out.pod(m_nonfinite), out.pod(seconds());
  m_film.save(out);
}

void WorkerPasses::restore(pt::BinaryReader& in) {
  m_plan.restore(in);
  const uint64_t n = in.pod<uint64_t>();
  if (n > m_plan.issued()) in.fail("more passes merged than issued");
  m_merged.clear();
  for (uint64_t k = 0; k < n; ++k) {
    const uint32_t u = in.pod<uint32_t>();
    if (u >= m_plan.issued()) in.fail("a pass never issued");
    m_merged.insert(u);
  }
  m_samples = in.pod<uint64_t>(), m_rays = in.pod<uint64_t>(), m_nonfinite = in.pod<uint64_t>();
  m_seconds_before = in.pod<double>();
  if (!(m_seconds_before >= 0 && m_seconds_before < 1e12)) in.fail("an impossible render time");
  m_film.restore(in);
  m_t0 = clock::now();
}

void WorkerPasses::issue(size_t unit) {
  rq::WorkItem w;
  w.job = m_job.id, w.run = m_run, w.unit = uint32_t(unit);
  std::tie(w.first, w.count) = m_plan.range(unit);
  w.mask = m_params.adaptive ? pt::pack_mask(m_film.done_mask()) : std::string();
  std::vector<std::string> args{"XADD", rq::kWorkStream, "*", "job", w.job, "run", w.run, "unit", std::to_string(unit),
                                "first", std::to_string(w.first), "count", std::to_string(w.count), "mask", w.mask};
  if (m_key) args.insert(args.end(), {"sig", rq::request_signature(*m_key, w)});
  m_redis.command(args);
  m_masks[w.unit] = std::move(w.mask);
}

// Puts what workers need in Redis: the group, the scene's bytes (once per content: repeated jobs on
// a large scene send only its hash), the run's hash. Again on every new connection: a Redis
// restarted without its data has lost them, and the passes issued so far, which go out again (a
// pass rendered twice is merged once).
void WorkerPasses::publish() {
  const std::string ttl = std::to_string(rq::kKeyTtlSeconds);
  do {
    m_redis.command({"PING"});
    m_published = m_redis.connections();
    rq::ensure_group(m_redis);
    m_redis.command({"SET", rq::scene_key(m_scene_hash), m_scene_text, "EX", ttl, "NX"});
    m_redis.command({"EXPIRE", rq::scene_key(m_scene_hash), ttl});
    const std::string sig = m_key ? rq::run_signature(*m_key, m_job.id, m_run, m_spec_json, m_scene_hash) : "";
    bool fresh = m_redis.command({"HSET", m_job_key, "spec", m_spec_json, "scene", m_scene_hash, "sig", sig}).integer_value > 0;
    m_redis.command({"EXPIRE", m_job_key, ttl});
    if (fresh && m_plan.issued() > m_merged.size()) {
      std::fprintf(stderr, "render-server: job %s: the run's keys were gone from Redis; issuing its %zu unmerged passes again\n",
                   m_job.id.c_str(), m_plan.issued() - m_merged.size());
      for (size_t u = 0; u < m_plan.issued(); ++u)
        if (!m_merged.count(uint32_t(u))) issue(u);
    }
    if (fresh) m_last_id = "0-0";  // results of the lost stream that came in again
  } while (m_redis.connections() != m_published);
}

// check()'s answer for a second rendering of a merged pass: not merged, and not a refusal either.
const std::string kRenderedTwice = "rendered twice";

std::string WorkerPasses::check(const RedisReply& body, const std::string& worker, uint32_t& u, pt::FilmPass& pass) {
  const std::string *job = body.field("job"), *run = body.field("run"), *unit = body.field("unit"),
                    *bytes = body.field("pass"), *error = body.field("error"), *sig = body.field("sig"),
                    *name = body.field("worker");  // as signed; `worker` is its printable form
  if ((job && *job != m_job.id) || (run && *run != m_run))
    return "a result for another job or run (job '" + valid_utf8(job ? *job : m_job.id, 64) + "')";
  if (!unit || (!bytes && !error)) return "a malformed entry (no unit, or neither pass nor error)";
  if (m_key) {
    if (!sig) return "unsigned";
    const std::string features = body.field("features") ? *body.field("features") : "";
    const std::string attempt = body.field("attempt") ? *body.field("attempt") : "";
    const std::string signer = name ? *name : "";
    const bool good = bytes ? m_key->verify(*sig, {"pt-result", m_job.id, m_run, *unit, signer, attempt, *bytes, features})
                            : m_key->verify(*sig, {"pt-error", m_job.id, m_run, *unit, signer, *error});
    if (!good) return "bad signature (not made with the farm key, or made for another job, run, pass or worker)";
  }
  if (error) return "";  // signed (or an unsigned farm's): the job fails with its text
  if (!rq::parse_u32(unit, u) || u >= m_plan.issued()) return "pass '" + valid_utf8(*unit, 20) + "' was never issued";
  if (m_merged.count(u)) {
    // A second rendering or sending of a pass (its first worker looked dead, a connection broke
    // while sending) is normal and differs in its signature; the same signed bytes again are a copy.
    auto it = m_signatures.find(u);
    return sig && it != m_signatures.end() && it->second == *sig ? "replayed (pass " + std::to_string(u) + " was already merged)"
                                                                 : kRenderedTwice;
  }
  try {
    pass = pt::FilmPass::decode(*bytes, m_w, m_h);
  } catch (const std::exception& e) {
    return std::string("a bad pass: ") + e.what();
  }
  const auto [first, count] = m_plan.range(u);
  if (pass.first != first || pass.count != count)
    return "samples [" + std::to_string(pass.first) + ", " + std::to_string(uint64_t(pass.first) + pass.count) + ") where pass " +
           std::to_string(u) + " asked for [" + std::to_string(first) + ", " + std::to_string(first + count) + ")";
  auto mask = m_masks.find(u);
  if (mask != m_masks.end() && !mask->second.empty()) {
    const std::vector<uint8_t> skip = pt::unpack_mask(mask->second, pass.samples.size());
    for (size_t i = 0; i < skip.size(); ++i)
      if (skip[i] && pass.samples[i] != 0)
        return "samples in pixel " + std::to_string(i) + ", which pass " + std::to_string(u) + " was told to skip";
  }
  return "";
}

bool WorkerPasses::merge(const RedisReply& r) {
  // Everything read from Redis is checked: [[stream, [[id, [field, value, ...]], ...]]].
  if (r.type != RedisReply::array || r.elements.empty() || r.elements[0].elements.size() < 2) return false;
  bool changed = false;
  for (const RedisReply& e : r.elements[0].elements[1].elements) {
    if (e.elements.size() != 2 || e.elements[0].type != RedisReply::string) continue;
    m_last_id = e.elements[0].str;
    const RedisReply& body = e.elements[1];
    const std::string worker = valid_utf8(body.field("worker") ? *body.field("worker") : "(unnamed)", 64);
    uint32_t u = 0;
    pt::FilmPass pass;
    const std::string refusal = check(body, worker, u, pass);
    if (refusal == kRenderedTwice) continue;  // its first worker looked dead: the first copy counts
    if (!refusal.empty()) {
      m_ledger.rejected(worker, m_job.id, refusal);
      continue;
    }
    if (const std::string* err = body.field("error")) throw std::runtime_error(valid_utf8(*err, 2000));
    m_pass_bytes += body.field("pass")->size();
    uint64_t pass_samples = 0;
    for (uint32_t n : pass.samples) pass_samples += n;
    m_plan.observe(pass_samples, pass.seconds);
    if (!m_started) {
      m_sink.started(m_w, m_h, parse_features(body.field("features")), 0);
      m_started = true;
    }
    m_film.merge(pass);
    m_merged.insert(u);
    m_masks.erase(u);
    if (const std::string* sig = body.field("sig")) m_signatures[u] = *sig;
    m_ledger.merged(worker);
    m_samples += pass_samples;
    m_rays += pass.rays;
    m_nonfinite += pass.nonfinite;
    changed = true;
  }
  return changed;
}

bool WorkerPasses::advance(int, const std::atomic<bool>* cancel, const pt::TileCallback& on_tile) {
  try {
    return gather(cancel, on_tile);
  } catch (const RedisUnreachable&) {
    if (cancel && cancel->load()) return false;  // cancelled (or the server stopping) while waiting
    throw;  // away past --redis-timeout: the job fails, saying so
  }
}

bool WorkerPasses::gather(const std::atomic<bool>* cancel, const pt::TileCallback& on_tile) {
  for (;;) {
    // Keep every live worker busy plus a few passes queued, each carrying the pixels converged so
    // far. The worker count is looked up at most once a second.
    if (m_redis.connections() != m_published) publish();
    if (clock::now() >= m_next_worker_count) {
      m_workers = std::max(1, m_live_workers());
      m_next_worker_count = clock::now() + std::chrono::seconds(1);
    }
    const size_t ahead = size_t(std::max(m_in_flight, m_workers + 2));
    while (!m_plan.exhausted() && m_plan.issued() < m_merged.size() + ahead && !m_film.finished()) {
      m_plan.next(m_film.remaining(), m_workers);
      issue(m_plan.issued() - 1);
    }
    if (cancel && cancel->load()) return false;
    if (clock::now() >= m_deadline && !m_merged.empty()) return false;  // never before a first picture
    RedisReply r = m_redis.command({"XREAD", "COUNT", "4", "BLOCK", "100", "STREAMS", m_results, m_last_id});
    const auto merge_start = clock::now();
    if (!merge(r)) continue;
    if (on_tile)
      for (const pt::Tile& t : m_tiles) on_tile(t);
    m_merge_seconds += std::chrono::duration<double>(clock::now() - merge_start).count();
    return true;
  }
}

void WorkerPasses::finish(pt::StopReason why) {
  if (!m_started && why != pt::StopReason::cancelled) m_sink.started(m_w, m_h, {}, 0);
  if (m_merged.empty()) return;
  std::string sizes;
  for (size_t u = 0; u < m_plan.issued(); ++u) sizes += (u ? " " : "") + std::to_string(m_plan.range(u).second);
  std::fprintf(stderr, "render-server: job %s: %zu passes merged in %.3f s (%.2f ms and %.2f MB a pass), %.2f s in all; spp a pass: %s\n",
               m_job.id.c_str(), m_merged.size(), m_merge_seconds, 1e3 * m_merge_seconds / m_merged.size(),
               m_pass_bytes / 1e6 / m_merged.size(), seconds(), sizes.c_str());
}

class RedisBackend : public RenderBackend {
 public:
  RedisBackend(SceneLibrary& scenes, const std::string& url, int in_flight, double redis_timeout, const FarmOptions& farm)
      : m_scenes(scenes), m_address(farm_address(url, farm, "render-server")),
        m_key(farm_key(m_address, farm, "render-server")), m_loopback(resolves_to_loopback(m_address.host)),
        m_in_flight(std::max(1, in_flight)),
        m_redis_timeout(redis_timeout) {
    RedisClient redis(m_address);
    rq::ensure_group(redis);
  }

  std::string name() const override { return m_address.url(); }

  int live_workers() override {
    std::lock_guard<std::mutex> lock(m_health_mutex);
    try {
      if (!m_health) m_health = std::make_unique<RedisClient>(m_address, 1.0);
      auto live = rq::live_workers(*m_health);
      m_ledger.heard(live);
      return int(live.size());
    } catch (const std::exception&) {
      m_health.reset();
      m_ledger.heard({});
      return 0;  // Redis unreachable: no worker can take work
    }
  }

  nlohmann::json farm() override {
    nlohmann::json f = m_ledger.to_json();
    f["queue"] = m_address.url();
    f["authenticated"] = !m_address.password.empty();
    f["signed"] = m_key != nullptr;
    f["insecure"] = !m_key && !m_loopback;
    return f;
  }

  RenderResult render(const Job& job, JobSink& sink, const std::atomic<bool>& stop, const CheckpointPlan& plan) override {
    const JobSpec& spec = job.spec;
    std::string path = m_scenes.resolve(spec.scene), scene_text;
    if (path.empty() || !read_file(path, scene_text)) throw std::runtime_error("scene '" + spec.scene + "' is gone");
    // A bad file fails here, not once on every worker; the server itself builds no BVH.
    pt::parse_scene(scene_text, pt::scene_file_name(spec.scene, scene_text));
    // An unreachable Redis (a restart) is waited for, up to --redis-timeout; a cancel ends the wait.
    RedisClient redis(m_address, 5.0, false);
    redis.set_patience(m_redis_timeout, &stop, "render-server: job " + job.id);
    WorkerPasses passes(job, scene_text, redis, sink, [this] { return live_workers(); }, m_in_flight, m_key.get(), m_ledger);
    RenderResult result = render_job(passes, job, sink, stop, plan, pt::render_fingerprint(scene_text, spec.params),
                                     [&](bool resumed) {
                                       if (!resumed) return;  // the first merged pass starts the sink
                                       std::vector<std::string> features;
                                       {
                                         std::lock_guard<std::mutex> lock(job.mutex);
                                         features = job.features;
                                       }
                                       passes.resumed(features);
                                     });
    passes.finish(result.why);
    return result;
  }

 private:
  SceneLibrary& m_scenes;
  RedisAddress m_address;
  std::shared_ptr<const FarmKey> m_key;  // null: an unsigned farm
  bool m_loopback;  // Redis is on this machine: an unsigned farm is not exposed
  FarmLedger m_ledger;
  int m_in_flight;
  double m_redis_timeout;  // seconds a job waits for an unreachable Redis (--redis-timeout)
  std::mutex m_health_mutex;
  std::unique_ptr<RedisClient> m_health;
};

}  // namespace

std::unique_ptr<RenderBackend> make_redis_backend(SceneLibrary& scenes, const std::string& url, int units_in_flight,
                                                  double redis_timeout, const FarmOptions& farm) {
  return std::make_unique<RedisBackend>(scenes, url, units_in_flight, redis_timeout, farm);
}

}  // namespace srv
