// Job queue, render workers and persistence. Layout on disk: <data>/jobs/<id>/job.json (spec and
// state), image.exr and image.png once done; every file is written to a temp name, then renamed.
#include "jobs.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <new>
#include <random>
#include <sstream>

#include "collada.h"
#include "image.h"
#include "render_backend.h"

namespace srv {

namespace {

double now_unix() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::string new_job_id() {
  // Sortable by creation time, unique within a process and across restarts.
  static std::mutex mutex;
  static std::mt19937_64 rng(std::random_device{}());
  std::lock_guard<std::mutex> lock(mutex);
  auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  char buf[40];
  std::snprintf(buf, sizeof buf, "%011llx%05llx", (unsigned long long)ms, (unsigned long long)(rng() & 0xfffff));
  return buf;
}

bool valid_job_id(const std::string& id) {
  if (id.empty() || id.size() > 40) return false;
  for (char c : id)
    if (!std::isxdigit((unsigned char)c)) return false;
  return true;
}

void make_dirs(const std::string& path) {
  std::string cur;
  std::stringstream ss(path);
  std::string part;
  if (!path.empty() && path[0] == '/') cur = "/";
  while (std::getline(ss, part, '/')) {
    if (part.empty()) continue;
    cur += part + "/";
    mkdir(cur.c_str(), 0755);
  }
}

// Writes a whole file under a temp name, flushes it to the disk and renames it into place: readers,
// and a server restarted after a crash, never see a partial file. Errors name the file and the cause
// (no space, not a directory, ...).
void write_file_atomic(const std::string& path, const std::string& data) {
  std::string tmp = path + ".tmp" + std::to_string(getpid());
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
  size_t done = 0;
  int err = 0;
  while (done < data.size() && !err) {
    ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0 && errno != EINTR) err = errno;
    if (n > 0) done += size_t(n);
  }
  if (!err && ::fsync(fd) != 0) err = errno;
  if (::close(fd) != 0 && !err) err = errno;
  if (err) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot write " + path + ": " + std::strerror(err));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    err = errno;
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot move " + path + " into place: " + std::strerror(err));
  }
}

// Temp files a killed server left behind (job.json.tmp<pid>, .image.exr.tmp<pid>-<n>): never read,
// removed at start so they cannot pile up. Returns how many.
int remove_temp_files(const std::string& dir) {
  int removed = 0;
  if (DIR* d = opendir(dir.c_str())) {
    while (dirent* e = readdir(d)) {
      std::string name = e->d_name;
      if (name.find(".tmp") != std::string::npos && std::remove((dir + "/" + name).c_str()) == 0) ++removed;
    }
    closedir(d);
  }
  return removed;
}

}  // namespace

bool read_file(const std::string& path, std::string& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream ss;
  ss << in.rdbuf();
  out = ss.str();
  return true;
}

const char* job_state_name(JobState s) {
  switch (s) {
    case JobState::queued: return "queued";
    case JobState::running: return "running";
    case JobState::done: return "done";
    case JobState::failed: return "failed";
    case JobState::cancelled: return "cancelled";
  }
  return "?";
}

bool parse_job_state(const std::string& s, JobState* out) {
  for (JobState st : {JobState::queued, JobState::running, JobState::done, JobState::failed, JobState::cancelled})
    if (s == job_state_name(st)) {
      *out = st;
      return true;
    }
  return false;
}

JobManager::JobManager(ManagerConfig config) : m_config(std::move(config)), m_scenes(m_config.scene_dirs, m_config.scene_cache_bytes) {}

JobManager::~JobManager() { stop(); }

std::string JobManager::backend_name() const { return m_backend ? m_backend->name() : "embedded"; }
int JobManager::live_workers() const { return m_backend ? m_backend->live_workers() : -1; }

std::string JobManager::job_dir(const std::string& id) const { return m_config.data_dir + "/jobs/" + id; }

void JobManager::start() {
  make_dirs(m_config.data_dir + "/jobs");
  // A real write, not access(): root passes access() on a read-only mount or a full disk.
  try {
    std::string probe = m_config.data_dir + "/jobs/.write-probe";
    write_file_atomic(probe, "ok\n");
    std::remove(probe.c_str());
  } catch (const std::exception& e) {
    throw std::runtime_error("data directory '" + m_config.data_dir + "' is not writable (" + e.what() + ")");
  }
  if (m_config.queue.empty() || m_config.queue == "embedded")
    m_backend = make_embedded_backend(m_scenes, m_config.threads);
  else
    m_backend = make_redis_backend(m_scenes, m_config.queue, m_config.units_in_flight);
  load_persisted();
  for (int i = 0; i < std::max(1, m_config.concurrency); ++i) m_workers.emplace_back([this] { worker_loop(); });
}

void JobManager::stop() {
  if (m_stopping.exchange(true)) {
    for (auto& w : m_workers)
      if (w.joinable()) w.join();
    return;
  }
  m_queue_cv.notify_all();
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    for (auto& kv : m_jobs) kv.second->changed.notify_all();
  }
  for (auto& w : m_workers)
    if (w.joinable()) w.join();
}

JobSpec JobManager::check(const json& body) const {
  JobSpec spec = parse_job_spec(body, m_config.limits);
  if (m_scenes.resolve(spec.scene).empty())
    throw ApiError(404, "unknown scene '" + spec.scene + "'", "scene");
  return spec;
}

std::pair<std::shared_ptr<Job>, bool> JobManager::submit(const json& body, const std::string& key) {
  JobSpec spec = check(body);
  std::lock_guard<std::mutex> lock(m_mutex);
  if (m_stopping) throw ApiError(503, "the server is shutting down");
  if (!key.empty()) {
    auto it = m_idempotency.find(key);
    if (it != m_idempotency.end()) {
      auto job = m_jobs.at(it->second);
      if (job_spec_to_json(job->spec) != job_spec_to_json(spec))
        throw ApiError(409, "Idempotency-Key was used for a different job", "Idempotency-Key");
      return {job, false};
    }
  }
  if (m_queue.size() >= m_config.max_queue)
    throw ApiError(429, "the queue is full (" + std::to_string(m_config.max_queue) + " jobs waiting); retry later");
  auto job = std::make_shared<Job>();
  job->id = new_job_id();
  job->spec = spec;
  job->idempotency_key = key;
  job->created_at = now_unix();
  {
    // Stored before it is acknowledged: a job the client was told about survives a crash.
    std::lock_guard<std::mutex> jl(job->mutex);
    make_dirs(job_dir(job->id));
    try {
      write_job_file(*job);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "render-server: job %s: %s\n", job->id.c_str(), e.what());
      rmdir(job_dir(job->id).c_str());
      std::string why = e.what();
      throw ApiError(507, "the data directory cannot store the job (" + why.substr(why.rfind(": ") + 2) + ")");
    }
  }
  m_jobs[job->id] = job;
  if (!key.empty()) m_idempotency[key] = job->id;
  m_queue.push_back(job);
  m_queue_cv.notify_one();
  return {job, true};
}

std::shared_ptr<Job> JobManager::get(const std::string& id) const {
  if (!valid_job_id(id)) return nullptr;
  std::lock_guard<std::mutex> lock(m_mutex);
  auto it = m_jobs.find(id);
  return it == m_jobs.end() ? nullptr : it->second;
}

std::vector<std::shared_ptr<Job>> JobManager::list() const {
  std::lock_guard<std::mutex> lock(m_mutex);
  std::vector<std::shared_ptr<Job>> out;
  for (auto& kv : m_jobs) out.push_back(kv.second);
  return out;
}

void JobManager::cancel(const std::string& id) {
  auto job = get(id);
  if (!job) throw ApiError(404, "no job '" + id + "'");
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    auto it = std::find(m_queue.begin(), m_queue.end(), job);
    if (it != m_queue.end()) {
      m_queue.erase(it);
      std::lock_guard<std::mutex> jl(job->mutex);
      job->state = JobState::cancelled;
      job->finished_at = now_unix();
      ++job->version;
      persist(*job);
      job->changed.notify_all();
      return;
    }
  }
  std::lock_guard<std::mutex> jl(job->mutex);
  if (is_final(job->state))
    throw ApiError(409, std::string("job is already ") + job_state_name(job->state));
  job->cancel = true;  // the worker stops within a few samples and marks it cancelled
}

json JobManager::status_json(const Job& j, bool with_history) const {
  json s{{"id", j.id},
         {"url", "/api/jobs/" + j.id},
         {"state", job_state_name(j.state)},
         {"spec", job_spec_to_json(j.spec)},
         {"progress", j.progress},
         {"samples", j.samples},
         {"spp_done", j.width > 0 ? double(j.samples) / (double(j.width) * j.height) : 0.0},
         {"elapsed", j.elapsed},
         {"eta", j.eta >= 0 ? json(j.eta) : json(nullptr)},
         {"error_estimate", j.error_estimate >= 0 ? json(j.error_estimate) : json(nullptr)},
         {"nonfinite_samples", j.nonfinite},
         {"rays", j.rays},
         {"created_at", j.created_at},
         {"started_at", j.started_at > 0 ? json(j.started_at) : json(nullptr)},
         {"finished_at", j.finished_at > 0 ? json(j.finished_at) : json(nullptr)},
         {"width", j.spec.params.cell_w > 0 ? j.spec.params.cell_w : j.spec.params.width},
         {"height", j.spec.params.cell_h > 0 ? j.spec.params.cell_h : j.spec.params.height},
         {"tile_size", j.spec.params.tile_size},
         {"features", j.features},
         {"images", {{"png", "/api/jobs/" + j.id + "/image.png"}, {"exr", "/api/jobs/" + j.id + "/image.exr"}}},
         {"events", "/api/jobs/" + j.id + "/events"}};
  if (!j.message.empty()) s["message"] = j.message;
  if (with_history) {
    json h = json::array();
    for (const ErrorPoint& p : j.history) h.push_back({{"seconds", p.seconds}, {"spp", p.spp}, {"error", p.error}});
    s["error_history"] = h;
  }
  return s;
}

double JobManager::focus_distance(const Job& job, double x, double y) {
  pt::RenderParams p = job.spec.params;
  std::string size = std::to_string(p.width) + "x" + std::to_string(p.height);
  if (!(x >= 0 && x <= p.width)) throw ApiError(400, "x must lie inside the " + size + " image", "x");
  if (!(y >= 0 && y <= p.height)) throw ApiError(400, "y must lie inside the " + size + " image", "y");
  auto base = m_scenes.load(job.spec.scene);
  p.env_map.clear();
  auto scene = pt::make_view(*base, p);
  return pt::autofocus_distance(*scene, float(x / p.width), float(1 - y / p.height));
}

void JobManager::write_job_file(Job& j) {
  json doc = status_json(j);
  doc["idempotency_key"] = j.idempotency_key;
  write_file_atomic(job_dir(j.id) + "/job.json", doc.dump(1));
}

void JobManager::persist(Job& j) {
  try {
    write_job_file(j);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render-server: job %s: %s\n", j.id.c_str(), e.what());
  }
}

void JobManager::load_persisted() {
  std::string root = m_config.data_dir + "/jobs";
  DIR* d = opendir(root.c_str());
  if (!d) return;
  std::vector<std::string> ids;
  while (dirent* e = readdir(d))
    if (valid_job_id(e->d_name)) ids.push_back(e->d_name);
  closedir(d);
  std::sort(ids.begin(), ids.end());  // ids sort by creation time: the queue keeps its order
  int temp_files = 0;
  for (const std::string& id : ids) {
    temp_files += remove_temp_files(root + "/" + id);
    std::string text;
    if (!read_file(root + "/" + id + "/job.json", text)) {
      rmdir((root + "/" + id).c_str());  // empty: killed between mkdir and job.json (never acknowledged)
      continue;
    }
    try {
      json doc = json::parse(text);
      auto job = std::make_shared<Job>();
      job->id = id;
      job->spec = parse_job_spec(doc.at("spec"), m_config.limits);
      job->idempotency_key = doc.value("idempotency_key", "");
      job->created_at = doc.value("created_at", 0.0);
      JobState st = JobState::queued;
      parse_job_state(doc.value("state", "queued"), &st);
      struct stat sb;
      auto present = [&](const char* name) {
        return stat((root + "/" + id + "/" + name).c_str(), &sb) == 0 && S_ISREG(sb.st_mode) && sb.st_size > 0;
      };
      bool image_ok = present("image.png") && present("image.exr");
      if (st == JobState::running || (st == JobState::done && !image_ok)) st = JobState::queued;  // interrupted: run again
      job->state = st;
      if (st != JobState::queued) {
        job->message = doc.value("message", "");
        job->progress = doc.value("progress", 0.0);
        job->samples = doc.value("samples", uint64_t(0));
        job->elapsed = doc.value("elapsed", 0.0);
        job->nonfinite = doc.value("nonfinite_samples", uint64_t(0));
        job->rays = doc.value("rays", uint64_t(0));
        if (doc.contains("error_estimate") && doc["error_estimate"].is_number()) job->error_estimate = doc["error_estimate"];
        if (doc.contains("started_at") && doc["started_at"].is_number()) job->started_at = doc["started_at"];
        if (doc.contains("finished_at") && doc["finished_at"].is_number()) job->finished_at = doc["finished_at"];
        for (const json& p : doc.value("error_history", json::array()))
          job->history.push_back({p.value("seconds", 0.0), p.value("spp", 0.0), p.value("error", 0.0)});
        if (doc.contains("features")) job->features = doc["features"].get<std::vector<std::string>>();
        job->width = job->spec.params.width;
        job->height = job->spec.params.height;
      }
      m_jobs[id] = job;
      if (!job->idempotency_key.empty()) m_idempotency[job->idempotency_key] = id;
      if (st == JobState::queued) {
        std::lock_guard<std::mutex> jl(job->mutex);
        persist(*job);
        m_queue.push_back(job);
      }
    } catch (const std::exception& e) {
      std::fprintf(stderr, "render-server: skipping %s/%s/job.json: %s\n", root.c_str(), id.c_str(), e.what());
    }
  }
  if (temp_files > 0) std::fprintf(stderr, "render-server: removed %d temp files an earlier run left\n", temp_files);
}

void JobManager::worker_loop() {
  for (;;) {
    std::shared_ptr<Job> job;
    {
      std::unique_lock<std::mutex> lock(m_mutex);
      m_queue_cv.wait(lock, [&] { return m_stopping || !m_queue.empty(); });
      if (m_stopping) return;
      job = m_queue.front();
      m_queue.pop_front();
    }
    run_job(job);
  }
}

namespace {

// Carries a backend's reports into the job's state (under its mutex) and wakes its watchers.
class JobStateSink : public JobSink {
 public:
  JobStateSink(Job& job, std::function<void(Job&)> persist) : m_job(job), m_persist(std::move(persist)) {}

  void started(int width, int height, const std::vector<std::string>& features) override {
    Job& j = m_job;
    {
      std::lock_guard<std::mutex> lock(j.mutex);
      if (j.cancel) throw ApiError(409, "cancelled");
      j.state = JobState::running;
      j.started_at = now_unix();
      j.width = width;
      j.height = height;
      j.tile_size = j.spec.params.tile_size;
      j.tiles_x = (width + j.tile_size - 1) / j.tile_size;
      j.tiles_y = (height + j.tile_size - 1) / j.tile_size;
      size_t n = size_t(width) * height;
      j.linear.assign(n * 3, 0.0f);
      j.display.assign(n * 3, 0);
      j.tile_version.assign(size_t(j.tiles_x) * j.tiles_y, 0);
      j.tile_png.assign(j.tile_version.size(), std::string());
      j.tile_png_version.assign(j.tile_version.size(), 0);
      j.samples = 0;
      j.history.clear();
      j.has_image = false;
      j.features = features;
      ++j.version;
      m_persist(j);
    }
    m_start = std::chrono::steady_clock::now();
    m_last_persist = m_start;
    j.changed.notify_all();
  }

  void tile(const pt::Tile& t, const std::vector<pt::Vec3>& mean) override {
    Job& j = m_job;
    {
      std::lock_guard<std::mutex> lock(j.mutex);
      size_t k = 0;
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x, ++k) {
          size_t i = (size_t(y) * j.width + x) * 3;
          for (int c = 0; c < 3; ++c) {
            j.linear[i + c] = mean[k][c];
            j.display[i + c] = pt::tonemap_course(mean[k][c]);
          }
        }
      j.tile_version[size_t(t.y0 / j.tile_size) * j.tiles_x + t.x0 / j.tile_size] = ++j.version;
      j.has_image = true;
      j.elapsed = seconds();
    }
    // Every notify wakes every watcher, and each takes the job's mutex the render threads need:
    // tile updates wake them at most every kTileNotifyGap (watchers batch tiles over 40 ms rounds
    // anyway); pass() and state changes, which always follow the tiles, wake them at once.
    int64_t now = std::chrono::steady_clock::now().time_since_epoch().count(), last = m_last_notify.load();
    if (now - last >= kTileNotifyGap && m_last_notify.compare_exchange_strong(last, now)) j.changed.notify_all();
  }

  void pass(const RenderReport& r) override {
    Job& j = m_job;
    {
      std::lock_guard<std::mutex> lock(j.mutex);
      j.samples = r.samples;
      j.rays = r.rays;
      j.nonfinite = r.nonfinite;
      j.elapsed = seconds();
      j.progress = r.progress;
      if (std::isfinite(r.error)) {
        j.error_estimate = r.error;
        j.history.push_back({j.elapsed, double(r.samples) / (double(j.width) * j.height), r.error});
      }
      pt::RunLimits limits;
      limits.target_error = j.spec.target_error;
      limits.time_limit = j.spec.time_limit;
      j.eta = pt::remaining_seconds(j.elapsed, j.progress, r.error, j.elapsed, limits);
      ++j.version;
      if (std::chrono::steady_clock::now() - m_last_persist > std::chrono::seconds(1)) {
        m_persist(j);
        m_last_persist = std::chrono::steady_clock::now();
      }
    }
    j.changed.notify_all();
  }

 private:
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count(); }
  Job& m_job;
  std::function<void(Job&)> m_persist;
  std::chrono::steady_clock::time_point m_start = std::chrono::steady_clock::now(), m_last_persist = m_start;
  static constexpr int64_t kTileNotifyGap =
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::milliseconds(20)).count();
  std::atomic<int64_t> m_last_notify{0};
};

}  // namespace

void JobManager::run_job(const std::shared_ptr<Job>& job) {
  auto notify = [&] { job->changed.notify_all(); };
  try {
    // One flag stops the render: user cancel or shutdown (polled every 20 ms). The time limit and
    // the error target are the backend's.
    std::atomic<bool> stop{false}, done{false};
    std::thread poller([&] {
      while (!done) {
        if (job->cancel || m_stopping) {
          stop = true;
          return;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    });
    struct Joiner {
      std::atomic<bool>& done;
      std::thread& t;
      ~Joiner() {
        done = true;
        if (t.joinable()) t.join();
      }
    } joiner{done, poller};

    JobStateSink sink(*job, [this](Job& j) { persist(j); });
    RenderResult result = m_backend->render(*job, sink, stop);

    if (m_stopping && !job->cancel) {  // shutdown: run it again after a restart
      std::lock_guard<std::mutex> lock(job->mutex);
      job->state = JobState::queued;
      job->progress = 0;
      ++job->version;
      persist(*job);
      notify();
      return;
    }
    if (job->cancel) {
      std::lock_guard<std::mutex> lock(job->mutex);
      job->state = JobState::cancelled;
      job->finished_at = now_unix();
      ++job->version;
      persist(*job);
      notify();
      return;
    }
    // Finished (sample budget, error target or time limit): images first, then the state.
    const pt::ImageRGB& img = result.image;
    const RenderReport& r = result.report;
    pt::Metadata meta{{"pathtracer:scene", job->spec.scene},
                      {"pathtracer:job", job->id},
                      {"pathtracer:spec", job_spec_to_json(job->spec).dump()},
                      {"pathtracer:achieved_spp", std::to_string(double(r.samples) / (double(img.width) * img.height))},
                      {"pathtracer:wall_seconds", std::to_string(result.seconds)},
                      {"pathtracer:error_estimate", std::to_string(r.error)},
                      {"pathtracer:seed", std::to_string(job->spec.params.seed)},
                      {"pathtracer:nonfinite_samples", std::to_string(r.nonfinite)},
                      {"pathtracer:backend", m_backend->name()}};
    try {
      pt::write_image(img, job_dir(job->id) + "/image.exr", meta);
      pt::write_image(img, job_dir(job->id) + "/image.png");
    } catch (const std::exception& e) {  // a full disk or a vanished data directory: the job fails, saying so
      std::string why = e.what(), dir = job_dir(job->id) + "/";
      for (size_t at; (at = why.find(dir)) != std::string::npos;) why.erase(at, dir.size());  // no server paths
      throw std::runtime_error("cannot store the finished image: " + why);
    }
    std::lock_guard<std::mutex> lock(job->mutex);
    job->state = JobState::done;
    job->progress = 1;
    job->eta = 0;
    job->samples = r.samples;
    job->rays = r.rays;
    job->nonfinite = r.nonfinite;
    job->finished_at = now_unix();
    ++job->version;
    persist(*job);
    notify();
  } catch (const std::exception& e) {
    std::lock_guard<std::mutex> lock(job->mutex);
    job->state = job->cancel ? JobState::cancelled : JobState::failed;
    if (!job->cancel)  // bad_alloc's what() says only "std::bad_alloc"
      job->message = dynamic_cast<const std::bad_alloc*>(&e)
                         ? "out of memory for a " + std::to_string(job->spec.params.width) + "x" +
                               std::to_string(job->spec.params.height) + " image; a smaller size needs less"
                         : e.what();
    job->finished_at = now_unix();
    ++job->version;
    persist(*job);
    notify();
  }
}

}  // namespace srv
