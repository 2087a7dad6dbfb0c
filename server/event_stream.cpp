// The event stream and the shared encodings of a job's image: see event_stream.h.
#include "event_stream.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <vector>

#include "image.h"

namespace srv {

namespace {

using Clock = std::chrono::steady_clock;

std::atomic<uint64_t> g_watchers{0}, g_png_encodes{0}, g_tile_events{0};

// A job's PNG encodings, shared by every client: each region version, and the whole image once a
// pass, is encoded once however many ask. `mutex` is never held by the render threads; it is taken
// before the job's mutex when both are needed.
struct Encodings {
  std::mutex mutex;
  std::vector<std::shared_ptr<const std::string>> region_event;  // a region's SSE tile event, less its id
  std::vector<uint64_t> region_event_version;
  std::vector<double> region_event_time;  // steady seconds when each was encoded
  std::string image_png;                  // the whole display image
  int image_png_width = 0, image_png_height = 0;
  uint64_t image_png_pass = ~uint64_t(0), image_png_version = 0;
  double image_png_time = 0;  // steady seconds when it was encoded
  std::shared_ptr<const std::string> denoised_event;  // the SSE 'denoised' event, less its id
  uint64_t denoised_event_version = 0;
  std::atomic<size_t> bytes{0};  // what the encodings above hold, about
};

// The encodings of the jobs clients asked for most recently. A job's stay while a stream or a
// request holds them; the others go, least recently asked for first, once the cache holds more than
// kCacheBytes (a 4096x4096 job's encodings alone take about 70 MB) or kCachedJobs jobs.
constexpr size_t kCachedJobs = 32, kCacheBytes = size_t(256) << 20;
std::mutex g_cache_mutex;
std::vector<std::pair<std::string, std::shared_ptr<Encodings>>> g_cache;  // most recent last

std::shared_ptr<Encodings> encodings_for(const Job& job) {
  std::lock_guard<std::mutex> lock(g_cache_mutex);
  std::shared_ptr<Encodings> found;
  for (size_t i = 0; i < g_cache.size() && !found; ++i)
    if (g_cache[i].first == job.id) {
      found = g_cache[i].second;
      g_cache.erase(g_cache.begin() + long(i));
    }
  if (!found) found = std::make_shared<Encodings>();
  size_t total = found->bytes;
  for (const auto& entry : g_cache) total += entry.second->bytes;
  for (size_t i = 0; i < g_cache.size() && (total > kCacheBytes || g_cache.size() >= kCachedJobs);) {
    if (g_cache[i].second.use_count() > 1) {  // a stream or a request holds it
      ++i;
      continue;
    }
    total -= g_cache[i].second->bytes;
    g_cache.erase(g_cache.begin() + long(i));
  }
  g_cache.push_back({job.id, found});
  return found;
}

std::string encode_png(const std::vector<uint8_t>& rgb, int w, int h) {
  ++g_png_encodes;
  return pt::encode_png8(rgb, w, h);
}

double steady_seconds() { return std::chrono::duration<double>(Clock::now().time_since_epoch()).count(); }

std::string base64(const std::string& in) {
  static const char* tbl = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    uint32_t v = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8) | uint8_t(in[i + 2]);
    out += tbl[v >> 18];
    out += tbl[(v >> 12) & 63];
    out += tbl[(v >> 6) & 63];
    out += tbl[v & 63];
  }
  if (i + 1 == in.size()) {
    uint32_t v = uint8_t(in[i]) << 16;
    out += tbl[v >> 18];
    out += tbl[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == in.size()) {
    uint32_t v = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8);
    out += tbl[v >> 18];
    out += tbl[(v >> 12) & 63];
    out += tbl[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

std::string sse(const std::string& event, const json& data, uint64_t id) {
  return "id: " + std::to_string(id) + "\nevent: " + event + "\ndata: " + dump_json(data) + "\n\n";
}

// 8-bit RGB of a w x h rectangle of the job's display image; job.mutex must be held.
std::vector<uint8_t> copy_display(const Job& job, int x, int y, int w, int h) {
  std::vector<uint8_t> rgb(size_t(w) * h * 3);
  for (int r = 0; r < h; ++r)
    std::memcpy(&rgb[size_t(r) * w * 3], &job.display[(size_t(y + r) * job.width + x) * 3], size_t(w) * 3);
  return rgb;
}

// A region's encoding younger than this is sent to watchers as it is, though the region has changed
// since: watchers that wake at different moments share one encoding instead of each asking for the
// newest version. The changes reach them in a later round; a job's last round is always exact.
constexpr double kRegionRefreshSeconds = 0.25;

// The tile events for the regions of `job` newer than `sent` (which is brought up to date), each
// region encoded once for every watcher. The job's mutex is held only to copy pixels. `exact`:
// every region at its current version (the stream's last round).
std::vector<std::shared_ptr<const std::string>> changed_regions(Job& job, Encodings& enc, std::vector<uint64_t>& sent,
                                                                bool exact) {
  struct Stale {
    size_t index;
    uint64_t version;
    int x, y, w, h;
    std::vector<uint8_t> rgb;
  };
  std::vector<std::pair<size_t, uint64_t>> changed;
  std::vector<Stale> stale;
  std::lock_guard<std::mutex> encoding(enc.mutex);
  {
    std::lock_guard<std::mutex> lock(job.mutex);
    size_t n = job.region_version.size();
    if (enc.region_event.size() != n) {
      enc.region_event.assign(n, nullptr);
      enc.region_event_version.assign(n, 0);
      enc.region_event_time.assign(n, 0.0);
    }
    if (sent.size() != n) sent.assign(n, 0);
    double now = steady_seconds();
    for (size_t i = 0; i < n; ++i) {
      uint64_t v = job.region_version[i], cached = enc.region_event_version[i];
      if (v <= sent[i]) continue;
      if (cached == v || (!exact && cached > sent[i] && now - enc.region_event_time[i] < kRegionRefreshSeconds)) {
        changed.push_back({i, cached});
        continue;
      }
      changed.push_back({i, v});
      int x = int(i % size_t(job.regions_x)) * job.region_size, y = int(i / size_t(job.regions_x)) * job.region_size;
      int w = std::min(job.region_size, job.width - x), h = std::min(job.region_size, job.height - y);
      stale.push_back({i, v, x, y, w, h, copy_display(job, x, y, w, h)});
    }
  }
  for (Stale& s : stale) {
    char head[128];
    std::snprintf(head, sizeof head, "event: tile\ndata: {\"x\":%d,\"y\":%d,\"w\":%d,\"h\":%d,\"png\":\"", s.x, s.y, s.w,
                  s.h);
    size_t before = enc.region_event[s.index] ? enc.region_event[s.index]->size() : 0;
    enc.region_event[s.index] =
        std::make_shared<const std::string>(head + base64(encode_png(s.rgb, s.w, s.h)) + "\"}\n\n");
    enc.bytes += enc.region_event[s.index]->size() - before;
    enc.region_event_version[s.index] = s.version;
    enc.region_event_time[s.index] = steady_seconds();
  }
  std::vector<std::shared_ptr<const std::string>> events;
  for (auto [i, v] : changed) {
    events.push_back(enc.region_event[i]);
    sent[i] = v;
  }
  return events;
}

struct Snapshot {
  std::string png;
  int width = 0, height = 0;
  uint64_t version = 0;  // the job version the picture shows
};

// What all event streams together send a second, at most (about: a round is sent whole, then the
// watcher pauses for its share).
constexpr double kStreamBytesPerSecond = 16e6;

// A long pass still refreshes the whole-image PNG, at most this often.
constexpr double kImageRefreshSeconds = 1.0;

Snapshot snapshot_png(Job& job) {
  std::shared_ptr<Encodings> held = encodings_for(job);
  Encodings& enc = *held;
  std::lock_guard<std::mutex> encoding(enc.mutex);
  std::vector<uint8_t> rgb;
  Snapshot s;
  uint64_t pass;
  {
    std::lock_guard<std::mutex> lock(job.mutex);
    if (!job.has_image) return s;
    bool same_pass = enc.image_png_pass == job.passes;
    if (enc.image_png_version == job.version ||
        (same_pass && steady_seconds() - enc.image_png_time < kImageRefreshSeconds))
      return {enc.image_png, enc.image_png_width, enc.image_png_height, enc.image_png_version};
    rgb = copy_display(job, 0, 0, job.width, job.height);
    s.width = job.width;
    s.height = job.height;
    s.version = job.version;
    pass = job.passes;
  }
  s.png = encode_png(rgb, s.width, s.height);  // outside the mutex the render threads take
  enc.bytes += s.png.size() - enc.image_png.size();  // unsigned wrap-around cancels out
  enc.image_png = s.png;
  enc.image_png_width = s.width;
  enc.image_png_height = s.height;
  enc.image_png_pass = pass;
  enc.image_png_version = s.version;
  enc.image_png_time = steady_seconds();
  return s;
}

// The job's last denoised picture as an SSE 'denoised' event (less its id), encoded once for all
// watchers; null when there is none newer than `after`.
std::shared_ptr<const std::string> denoised_event(Job& job, Encodings& enc, uint64_t& after) {
  std::lock_guard<std::mutex> encoding(enc.mutex);
  std::vector<uint8_t> rgb;
  json head;
  uint64_t version;
  int w = 0, h = 0;
  {
    std::lock_guard<std::mutex> lock(job.mutex);
    const Job::Denoised& d = job.denoised;
    if (d.version <= after || d.display.size() != size_t(job.width) * job.height * 3) return nullptr;
    after = d.version;
    if (enc.denoised_event && enc.denoised_event_version == d.version) return enc.denoised_event;
    rgb = d.display;
    version = d.version;
    w = job.width, h = job.height;
    head = {{"width", job.width}, {"height", job.height}, {"spp", d.spp}, {"final", d.final}, {"seconds", d.seconds}};
  }
  head["png"] = base64(encode_png(rgb, w, h));  // outside the render threads' mutex
  const size_t before = enc.denoised_event ? enc.denoised_event->size() : 0;
  enc.denoised_event = std::make_shared<const std::string>("event: denoised\ndata: " + dump_json(head) + "\n\n");
  enc.bytes += enc.denoised_event->size() - before;
  enc.denoised_event_version = version;
  return enc.denoised_event;
}

void run_stream(JobManager& jobs, const std::shared_ptr<Job>& job, httplib::DataSink& sink) {
  const std::shared_ptr<Encodings> encodings = encodings_for(*job);  // held for the stream's life
  std::vector<uint64_t> sent;
  uint64_t seen = 0, denoised_sent = 0;
  bool first = true;
  // Watchers cost the renderer CPU: tiles are batched per round (a round at most every 40 ms) and
  // a status event goes out at most every 250 ms unless the state changes.
  const auto round_gap = std::chrono::milliseconds(40), status_gap = std::chrono::milliseconds(250);
  Clock::time_point last_status;
  std::string last_state;
  auto write = [&](const std::string& s) { return sink.write(s.data(), s.size()); };
  if (!write("retry: 2000\n\n")) return;
  for (;;) {
    json status;
    uint64_t version;
    bool final_state, has_image = false, png_on_disk = false;
    int width = 0, height = 0;
    {
      std::unique_lock<std::mutex> lock(job->mutex);
      bool changed = job->changed.wait_for(lock, std::chrono::seconds(15),
                                           [&] { return job->version != seen || jobs.stopping(); });
      if (jobs.stopping()) return;
      if (!changed) {
        lock.unlock();
        if (!write(": keep-alive\n\n")) return;
        continue;
      }
      version = job->version;
      final_state = is_final(job->state);
      if (first || final_state || last_state != job_state_name(job->state) || Clock::now() - last_status >= status_gap) {
        status = jobs.status_json(*job, false);
        if (!job->history.empty()) {
          const ErrorPoint& p = job->history.back();
          status["error_point"] = {{"seconds", p.seconds}, {"spp", p.spp}, {"error", p.error}};
        }
        last_state = job_state_name(job->state);
        last_status = Clock::now();
      }
      has_image = job->has_image;
      png_on_disk = !has_image && job->state == JobState::done;  // finished before a restart
      width = job->width;
      height = job->height;
    }
    if (first) {
      // A late or reconnecting client starts from the current picture.
      Snapshot snap;
      if (png_on_disk) {
        read_file(jobs.job_dir(job->id) + "/image.png", snap.png);
        snap = {snap.png, width, height, version};
      } else if (has_image) {
        snap = snapshot_png(*job);
      }
      if (!snap.png.empty()) {
        if (!write(sse("image", {{"width", snap.width}, {"height", snap.height}, {"png", base64(snap.png)}}, version)))
          return;
        std::lock_guard<std::mutex> lock(job->mutex);
        sent.assign(job->region_version.size(), 0);
        for (size_t i = 0; i < sent.size(); ++i) sent[i] = std::min(job->region_version[i], snap.version);
      }
      first = false;
    }
    if (!status.is_null() && !write(sse("status", status, version))) return;
    // The id is this round's version, not the region's: ids never go back within a stream.
    const std::string id = "id: " + std::to_string(version) + "\n";
    std::vector<std::shared_ptr<const std::string>> tiles = changed_regions(*job, *encodings, sent, final_state);
    for (const auto& event : tiles) {
      if (!write(id) || !write(*event)) return;
      ++g_tile_events;
    }
    // After the tiles: a denoised picture replaces the raw one at a pass end (or the end).
    if (auto event = denoised_event(*job, *encodings, denoised_sent))
      if (!write(id) || !write(*event)) return;
    seen = version;
    if (final_state) {
      write(sse("end", {{"state", status["state"]}}, version));
      return;
    }
    // After a round that sent tiles, let more accumulate, but wake at once for a change of state.
    // The pause grows with what the round sent times the watchers sharing the budget: however
    // many watch, and whatever tile size the job has, streams send about kStreamBytesPerSecond
    // in all (sending, on loopback also receiving, is what watching costs the render).
    if (tiles.empty()) continue;
    size_t bytes = 0;
    for (const auto& event : tiles) bytes += event->size();
    auto pause = std::max<Clock::duration>(
        round_gap, std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                       double(bytes) * double(std::max<uint64_t>(1, g_watchers.load())) / kStreamBytesPerSecond)));
    std::unique_lock<std::mutex> lock(job->mutex);
    job->changed.wait_for(lock, pause, [&] {
      return last_state != job_state_name(job->state) || is_final(job->state) || jobs.stopping();
    });
  }
}

}  // namespace

void stream_events(JobManager& jobs, const std::shared_ptr<Job>& job, httplib::DataSink& sink) {
  struct Count {
    Count() { ++g_watchers; }
    ~Count() { --g_watchers; }
  } count;
  try {
    run_stream(jobs, job, sink);
  } catch (const std::exception& e) {  // out of memory, an encoder failure: this stream ends, not the server
    std::fprintf(stderr, "render-server: job %s: an event stream ended: %s\n", job->id.c_str(), e.what());
  } catch (...) {
    std::fprintf(stderr, "render-server: job %s: an event stream ended on an unknown error\n", job->id.c_str());
  }
}

std::string current_png(Job& job) { return snapshot_png(job).png; }

StreamStats stream_stats() { return {g_watchers.load(), g_png_encodes.load(), g_tile_events.load()}; }

}  // namespace srv
