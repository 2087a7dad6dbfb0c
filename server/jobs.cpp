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

#include "image.h"
#include "job_sink.h"
#include "job_store.h"
#include "render_backend.h"
#include "request_policy.h"
#include "scene_file.h"
#include "version.h"

namespace srv {

double now_unix_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

namespace {

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

// Why a done job's stored images cannot be served ("" when both read back whole at the job's size).
std::string stored_image_problem(const std::string& dir, const JobSpec& spec) {
  int w = spec.params.cell_w > 0 ? spec.params.cell_w : spec.params.width;
  int h = spec.params.cell_w > 0 ? spec.params.cell_h : spec.params.height;
  for (const char* name : {"image.png", "image.exr"}) {
    std::string path = dir + "/" + name;
    if (!is_regular_file(path)) return std::string(name) + " is missing, empty or not a regular file";
    std::string why = pt::check_image_file(path, w, h);
    if (!why.empty()) return std::string(name) + ": " + why;
  }
  return "";
}

bool valid_job_id(const std::string& id) {
  if (id.empty() || id.size() > 40) return false;
  for (char c : id)
    if (!std::isxdigit((unsigned char)c)) return false;
  return true;
}

}  // namespace

const char* job_state_name(JobState s) {
  switch (s) {
    case JobState::queued: return "queued";
    case JobState::running: return "running";
    case JobState::paused: return "paused";
    case JobState::done: return "done";
    case JobState::failed: return "failed";
    case JobState::cancelled: return "cancelled";
  }
  return "?";
}

bool parse_job_state(const std::string& s, JobState* out) {
  for (JobState st : {JobState::queued, JobState::running, JobState::paused, JobState::done, JobState::failed,
                      JobState::cancelled})
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
json JobManager::farm() const { return m_backend ? m_backend->farm() : json(); }

std::string JobManager::job_dir(const std::string& id) const { return m_config.data_dir + "/jobs/" + id; }

void JobManager::start() {
  try {
    make_dirs(m_config.data_dir + "/jobs");
  } catch (const std::exception& e) {
    throw std::runtime_error("data directory '" + m_config.data_dir + "' is not writable (" + e.what() + ")");
  }
  m_lock = std::make_unique<DataDirLock>(m_config.data_dir);
  make_dirs(m_config.data_dir + "/scenes");  // uploaded scenes
  m_scenes.set_upload_dir(m_config.data_dir + "/scenes");
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
    m_backend = make_redis_backend(m_scenes, m_config.queue, m_config.units_in_flight, m_config.redis_timeout, m_config.farm);
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
    for (auto& kv : m_jobs) {
      kv.second->halt = true;  // a running render stops; run_job puts it back in the queue
      kv.second->changed.notify_all();
    }
  }
  for (auto& w : m_workers)
    if (w.joinable()) w.join();
}

JobSpec JobManager::check(const json& body, uint64_t* scene_hash, std::vector<std::string>* warnings) {
  JobSpec spec = parse_job_spec(body, m_config.limits);
  require_denoiser(spec);
  // A scene that does not load is refused here (422) rather than accepted as a job that fails.
  const uint64_t hash = m_scenes.check(spec.scene, warnings);
  if (scene_hash) *scene_hash = hash;
  return spec;
}

std::pair<std::shared_ptr<Job>, bool> JobManager::submit(const json& body, const std::string& key) {
  uint64_t scene_hash = 0;
  std::vector<std::string> warnings;
  JobSpec spec = check(body, &scene_hash, &warnings);
  std::lock_guard<std::mutex> lock(m_mutex);
  if (m_stopping) throw JobError(JobErrorKind::shutting_down, "the server is shutting down");
  if (!key.empty()) {
    auto it = m_idempotency.find(key);
    if (it != m_idempotency.end()) {
      auto job = m_jobs.at(it->second);
      if (job_spec_to_json(job->spec) != job_spec_to_json(spec))
        throw JobError(JobErrorKind::conflict, "Idempotency-Key was used for a different job", "Idempotency-Key");
      return {job, false};
    }
  }
  if (m_queue.size() >= m_config.max_queue)
    throw JobError(JobErrorKind::queue_full, "the queue is full (" + std::to_string(m_config.max_queue) + " jobs waiting); retry later");
  auto job = std::make_shared<Job>();
  job->id = new_job_id();
  job->spec = spec;
  job->scene_hash = scene_hash;
  job->view = view_json(m_scenes.view(spec.scene, spec.params));
  job->warnings = std::move(warnings);
  job->idempotency_key = key;
  job->created_at = now_unix_seconds();
  {
    // Stored before it is acknowledged: a job the client was told about survives a crash.
    std::lock_guard<std::mutex> jl(job->mutex);
    try {
      make_dirs(job_dir(job->id));
      write_job_file(*job);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "render-server: job %s: %s\n", job->id.c_str(), e.what());
      rmdir(job_dir(job->id).c_str());
      std::string why = e.what();
      throw JobError(JobErrorKind::no_storage, "the data directory cannot store the job (" + why.substr(why.rfind(": ") + 2) + ")");
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

json JobManager::status_json(const Job& j, bool with_history) const {
  json s{{"id", j.id},
         {"url", "/api/jobs/" + j.id},
         {"state", job_state_name(j.state)},
         {"spec", job_spec_to_json(j.spec)},
         {"progress", j.progress},
         {"samples", j.samples},
         {"spp_done", j.width > 0 ? double(j.samples) / (double(j.width) * j.height) : 0.0},
         {"elapsed", j.elapsed},
         // Only a live job has an ETA: a cancelled or paused one is not on its way anywhere.
         {"eta", j.eta >= 0 && (j.state == JobState::running || j.state == JobState::queued) ? json(j.eta) : json(nullptr)},
         {"error_estimate", j.error_estimate >= 0 ? json(j.error_estimate) : json(nullptr)},
         {"nonfinite_samples", j.nonfinite},
         {"rays", j.rays},
         {"created_at", j.created_at},
         {"started_at", j.started_at > 0 ? json(j.started_at) : json(nullptr)},
         {"finished_at", j.finished_at > 0 ? json(j.finished_at) : json(nullptr)},
         {"width", j.spec.params.cell_w > 0 ? j.spec.params.cell_w : j.spec.params.width},
         {"height", j.spec.params.cell_h > 0 ? j.spec.params.cell_h : j.spec.params.height},
         {"tile_size", j.spec.params.tile_size},
         {"stream_tile_size", stream_tile_size(j.spec.params.tile_size)},
         {"features", j.features},
         {"view", j.view},
         {"warnings", j.warnings},
         {"images", {{"png", "/api/jobs/" + j.id + "/image.png"}, {"exr", "/api/jobs/" + j.id + "/image.exr"}}},
         {"denoise", denoise_json(j)},
         {"events", "/api/jobs/" + j.id + "/events"}};
  if (!j.message.empty()) s["message"] = j.message;
  if (!j.stopped.empty()) s["stopped"] = j.stopped;
  // A kept film (its checkpoint): a done or cancelled job can be continued, a paused one resumed.
  s["can_continue"] = (j.state == JobState::done || j.state == JobState::cancelled) &&
                      is_regular_file(checkpoint_path(j.id));
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
  if (!(x >= 0 && x <= p.width)) throw JobError(JobErrorKind::invalid, "x must lie inside the " + size + " image", "x");
  if (!(y >= 0 && y <= p.height)) throw JobError(JobErrorKind::invalid, "y must lie inside the " + size + " image", "y");
  std::shared_ptr<const pt::SceneBase> base;
  try {
    base = m_scenes.load(job.spec.scene);
  } catch (const JobError& e) {  // the scene file is gone: the job is fine, its scene is not
    throw JobError(JobErrorKind::scene_broken, "the job's scene no longer loads: " + std::string(e.what()), "scene");
  } catch (const pt::SceneError& e) {
    throw JobError(JobErrorKind::scene_broken, "the job's scene no longer loads: " + to_valid_utf8(e.what()), "scene");
  }
  p.env_map.clear();
  auto scene = pt::make_view(*base, p);
  return pt::autofocus_distance(*scene, float(x / p.width), float(1 - y / p.height));
}

void JobManager::write_job_file(Job& j) {
  json doc = status_json(j);
  doc["idempotency_key"] = j.idempotency_key;
  doc["scene_hash"] = j.scene_hash;
  doc["checkpoint"] = {{"samples", j.checkpoint_samples}, {"seconds", j.checkpoint_seconds}};
  write_file_atomic(job_dir(j.id) + "/job.json", dump_json(doc, 1));
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
  while (dirent* e = readdir(d)) {
    struct stat st;
    if (!valid_job_id(e->d_name)) continue;
    if (::lstat((root + "/" + e->d_name).c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
      std::fprintf(stderr, "render-server: skipping %s/%s: not a folder\n", root.c_str(), e->d_name);
    else
      ids.push_back(e->d_name);
  }
  closedir(d);
  std::sort(ids.begin(), ids.end());  // ids sort by creation time: the queue keeps its order
  int temp_files = 0;
  for (const std::string& id : ids) {
    temp_files += remove_temp_files(root + "/" + id);
    std::string text, why;
    if (!read_file(root + "/" + id + "/job.json", text, &why)) {
      // Empty: killed between mkdir and job.json (never acknowledged). Anything else (a FIFO, a
      // link) is not ours to read: skipped, said once.
      if (::rmdir((root + "/" + id).c_str()) != 0)
        std::fprintf(stderr, "render-server: skipping %s/%s/job.json: %s\n", root.c_str(), id.c_str(), why.c_str());
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
      if (st == JobState::done) {
        // A done job counts only with images that read back whole at its size (a disk that filled
        // up may have left a truncated file behind a successful write): otherwise it renders again.
        std::string problem = stored_image_problem(root + "/" + id, job->spec);
        if (!problem.empty()) {
          std::fprintf(stderr, "render-server: job %s: %s; rendering it again\n", id.c_str(), problem.c_str());
          st = JobState::queued;
        }
      }
      if (st == JobState::running) st = JobState::queued;  // interrupted: run again, from its checkpoint
      job->state = st;
      {  // every job's counts and history: a resumed one shows its checkpoint's until its first pass
        job->stopped = to_valid_utf8(doc.value("stopped", ""));
        job->message = to_valid_utf8(doc.value("message", ""));
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
        load_denoise(*job, doc);
        for (const json& w : doc.value("warnings", json::array()))
          if (w.is_string()) job->warnings.push_back(to_valid_utf8(w.get<std::string>()));
        if (doc.contains("features"))
          for (const json& f : doc["features"])
            if (f.is_string()) job->features.push_back(to_valid_utf8(f.get<std::string>()));
        try {  // the camera it rendered from, checked as a camera field is
          if (doc.contains("view") && !doc["view"].is_null()) job->view = camera_pose_json(parse_camera(doc["view"]));
        } catch (const JobError&) {
        }
        job->width = job->spec.params.width;
        job->height = job->spec.params.height;
        if (doc.contains("scene_hash") && doc["scene_hash"].is_number_unsigned()) job->scene_hash = doc["scene_hash"];
        if (doc.contains("checkpoint") && doc["checkpoint"].is_object()) {
          job->checkpoint_samples = doc["checkpoint"].value("samples", uint64_t(0));
          job->checkpoint_seconds = doc["checkpoint"].value("seconds", 0.0);
        }
        if (st == JobState::queued) {  // interrupted: it shows what its checkpoint holds, what it resumes from
          const bool kept = is_regular_file(checkpoint_path(id));
          job->samples = kept ? job->checkpoint_samples : 0;
          job->elapsed = kept ? job->checkpoint_seconds : 0;
          while (!job->history.empty() && !(job->history.back().seconds <= job->elapsed)) job->history.pop_back();
          job->eta = -1, job->finished_at = 0;
        }
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

void JobManager::run_job(const std::shared_ptr<Job>& job) {
  try {
    // One flag stops the render: a user's cancel or pause, or the server's shutdown, set it
    // directly (the time limit and the error target are the backend's).
    job->halt = job->cancel || job->pause || m_stopping;
    JobStateSink sink(*job, [this](Job& j) { persist(j); });
    RenderResult result =
        m_backend->render(*job, sink, job->halt, {checkpoint_path(job->id), m_config.checkpoint_interval});
    if (result.why == pt::StopReason::cancelled) {
      if (job->cancel) store_images(*job, result);  // what a cancelled job had rendered can be downloaded
      std::lock_guard<std::mutex> lock(job->mutex);
      settle_stopped(*job, result);
      return;
    }
    // Finished (sample budget, error target or time limit): images first, then the state.
    store_images(*job, result);
    const RenderReport& r = result.report;
    {
      std::lock_guard<std::mutex> lock(job->mutex);
      job->state = JobState::done;
      job->stopped = pt::stop_reason_name(result.why);
      job->progress = 1;
      job->eta = -1;
      job->samples = r.samples;
      job->rays = r.rays;
      job->nonfinite = r.nonfinite;
      job->finished_at = now_unix_seconds();
      ++job->version;
      persist(*job);
    }
    job->changed.notify_all();
  } catch (const std::exception& e) {
    {
      std::lock_guard<std::mutex> lock(job->mutex);
      job->state = job->cancel ? JobState::cancelled : JobState::failed;
      if (!job->cancel)  // bad_alloc's what() says only "std::bad_alloc"
        job->message = dynamic_cast<const std::bad_alloc*>(&e)
                           ? "out of memory for a " + std::to_string(job->spec.params.width) + "x" +
                                 std::to_string(job->spec.params.height) + " image; a smaller size needs less"
                           : to_valid_utf8(e.what());
      job->eta = -1;
      job->finished_at = now_unix_seconds();
      ++job->version;
      persist(*job);
    }
    job->changed.notify_all();
  }
  enforce_retention();
}

void JobManager::settle_stopped(Job& job, const RenderResult& result) {
  job.eta = -1;
  job.samples = result.report.samples;
  if (job.cancel) {
    job.state = JobState::cancelled;
    job.stopped = pt::stop_reason_name(pt::StopReason::cancelled);
    job.finished_at = now_unix_seconds();
  } else if (job.pause) {
    job.state = JobState::paused;
  } else {
    job.state = JobState::queued;  // the server is stopping: a restart continues it from its checkpoint
  }
  ++job.version;
  persist(job);
  job.changed.notify_all();
}

// Each file is read back and compared before its rename (pt::write_image); a write that fails for
// want of a descriptor (a connection flood) is retried rather than losing the render.
void JobManager::store_images(Job& job, const RenderResult& result) {
  const pt::ImageRGB& img = result.image;
  if (img.pixels.empty()) return;
  const RenderReport& r = result.report;
  pt::Metadata meta{{"pathtracer:version", pt::version_text("render-server")},
                    {"pathtracer:scene", job.spec.scene},
                    {"pathtracer:job", job.id},
                    {"pathtracer:spec", dump_json(job_spec_to_json(job.spec))},
                    {"pathtracer:achieved_spp", std::to_string(double(r.samples) / (double(img.width) * img.height))},
                    {"pathtracer:wall_seconds", std::to_string(result.seconds)},
                    {"pathtracer:error_estimate", std::to_string(r.error)},
                    {"pathtracer:seed", std::to_string(job.spec.params.seed)},
                    {"pathtracer:nonfinite_samples", std::to_string(r.nonfinite)},
                    {"pathtracer:stopped", pt::stop_reason_name(result.why)},
                    {"pathtracer:backend", m_backend->name()}};
  if (!job.view.is_null()) meta.push_back({"pathtracer:view", dump_json(job.view)});  // whatever framed it
  try {
    store_job_images(job_dir(job.id), result, meta);  // denoised (and raw), or raw
    std::string counts;
    {
      std::lock_guard<std::mutex> lock(job.mutex);
      if (job.counts.size() == img.pixels.size()) counts = encode_sample_counts(job.counts);
    }
    if (!counts.empty())
      retry_without_descriptors([&] { write_file_atomic(job_dir(job.id) + "/samples.bin", counts); });
  } catch (const std::exception& e) {  // a full disk or a vanished data directory: the job fails, saying so
    std::string why = e.what(), dir = job_dir(job.id) + "/";
    for (size_t at; (at = why.find(dir)) != std::string::npos;) why.erase(at, dir.size());  // no server paths
    throw std::runtime_error("cannot store the " + std::string(job.cancel ? "cancelled job's" : "finished") +
                             " image: " + why);
  }
}

}  // namespace srv
