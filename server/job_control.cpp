// What users do to a job after submitting it (cancel, pause, resume, continue, delete), the job
// list's pages, and the retention that keeps the data folder bounded.
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "driver.h"
#include "job_store.h"
#include "jobs.h"
#include "request_policy.h"

namespace srv {

namespace {

std::shared_ptr<Job> must_get(const JobManager& jobs, const std::string& id) {
  auto job = jobs.get(id);
  if (!job) throw JobError(JobErrorKind::not_found, "no job '" + id + "'");
  return job;
}

JobError wrong_state(const Job& job, const std::string& doing) {
  return JobError(JobErrorKind::conflict, "cannot " + doing + " a job that is " + job_state_name(job.state));
}

// Sizes of the regular files in `dir` (not following links): a job folder holds no sub-folders.
uint64_t folder_bytes(const std::string& dir) {
  uint64_t bytes = 0;
  if (DIR* d = opendir(dir.c_str())) {
    while (dirent* e = readdir(d)) {
      struct stat st;
      if (::lstat((dir + "/" + e->d_name).c_str(), &st) == 0 && S_ISREG(st.st_mode)) bytes += uint64_t(st.st_size);
    }
    closedir(d);
  }
  return bytes;
}

}  // namespace

void JobManager::wait_settled(Job& job, double seconds, bool (*settled)(JobState)) {
  std::unique_lock<std::mutex> lock(job.mutex);
  job.changed.wait_for(lock, std::chrono::duration<double>(seconds), [&] { return settled(job.state); });
}

void JobManager::cancel(const std::string& id) {
  auto job = must_get(*this, id);
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    std::lock_guard<std::mutex> jl(job->mutex);
    if (is_final(job->state)) throw JobError(JobErrorKind::conflict, std::string("job is already ") + job_state_name(job->state));
    job->cancel = true;  // a render stops within a few samples and its worker marks the job cancelled
    job->halt = true;
    auto it = std::find(m_queue.begin(), m_queue.end(), job);
    if (job->state == JobState::paused || it != m_queue.end()) {  // nothing renders it
      if (it != m_queue.end()) m_queue.erase(it);
      job->state = JobState::cancelled;
      job->stopped = pt::stop_reason_name(pt::StopReason::cancelled);
      job->eta = -1;
      job->finished_at = now_unix_seconds();
      ++job->version;
      persist(*job);
      job->changed.notify_all();
      return;
    }
  }
  wait_settled(*job, 10, is_final);  // so that the answer says cancelled
}

void JobManager::pause(const std::string& id) {
  auto job = must_get(*this, id);
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    std::lock_guard<std::mutex> jl(job->mutex);
    if (is_final(job->state)) throw wrong_state(*job, "pause");
    if (job->state == JobState::paused) return;
    job->pause = true;
    job->halt = true;
    auto it = std::find(m_queue.begin(), m_queue.end(), job);
    if (it != m_queue.end()) {  // waiting: it leaves the queue
      m_queue.erase(it);
      job->state = JobState::paused;
      job->eta = -1;
      ++job->version;
      persist(*job);
      job->changed.notify_all();
      return;
    }
  }
  // Rendering (or being started): the render stops at once, saves its film and its worker marks it paused.
  wait_settled(*job, 10, [](JobState s) { return s == JobState::paused || is_final(s); });
}

void JobManager::resume(const std::string& id) {
  auto job = must_get(*this, id);
  std::lock_guard<std::mutex> lock(m_mutex);
  if (m_stopping) throw JobError(JobErrorKind::shutting_down, "the server is shutting down");
  std::lock_guard<std::mutex> jl(job->mutex);
  if (job->state != JobState::paused) throw wrong_state(*job, "resume");
  job->pause = false;
  job->halt = false;
  job->state = JobState::queued;
  ++job->version;
  persist(*job);
  m_queue.push_back(job);
  m_queue_cv.notify_one();
  job->changed.notify_all();
}

void JobManager::continue_job(const std::string& id, const json& body) {
  auto job = must_get(*this, id);
  if (!body.is_object()) throw JobError(JobErrorKind::invalid, "the body must be a JSON object");
  for (auto it = body.begin(); it != body.end(); ++it)
    if (it.key() != "spp" && it.key() != "target_error" && it.key() != "time_limit")
      throw JobError(JobErrorKind::invalid, "'" + it.key() + "' cannot change when a job continues: only spp, "
                     "target_error and time_limit can", it.key());
  // The film goes on only over the scene it was rendered from.
  uint64_t scene_hash = 0;
  try {
    scene_hash = m_scenes.check(job->spec.scene);
  } catch (const JobError& e) {
    throw JobError(JobErrorKind::conflict, "the job's scene cannot continue: " + std::string(e.what()), "scene");
  }
  std::lock_guard<std::mutex> lock(m_mutex);
  if (m_stopping) throw JobError(JobErrorKind::shutting_down, "the server is shutting down");
  if (job->scene_hash != 0 && job->scene_hash != scene_hash)
    throw JobError(JobErrorKind::conflict, "scene '" + job->spec.scene + "' has changed since this job rendered it: "
                   "its film cannot continue over another scene (submit a new job)", "scene");
  if (m_queue.size() >= m_config.max_queue)
    throw JobError(JobErrorKind::queue_full, "the queue is full (" + std::to_string(m_config.max_queue) + " jobs waiting); retry later");
  std::lock_guard<std::mutex> jl(job->mutex);
  if (job->state != JobState::done && job->state != JobState::cancelled) throw wrong_state(*job, "continue");
  if (!is_regular_file(checkpoint_path(job->id)))
    throw JobError(JobErrorKind::conflict, "the job's film was not kept (it finished before films were kept, or "
                   "its checkpoint was lost): submit it again");
  // The new spec is the old one with these fields, validated as a submission is.
  json spec = job_spec_to_json(job->spec);
  const int old_spp = job->spec.params.spp;
  const bool budget_spent = job->state == JobState::done && job->stopped == pt::stop_reason_name(pt::StopReason::finished);
  if (body.contains("spp")) spec["spp"] = body["spp"];
  else if (budget_spent && (body.contains("target_error") || body.contains("time_limit")))
    // The target or the limit decides how far it goes, up to the server's largest budget.
    spec["spp"] = int(std::min<double>(m_config.limits.max_spp, std::floor(m_config.limits.max_pixel_samples /
                  (double(job->spec.params.width) * job->spec.params.height))));
  // A limit that ended the render would end it again at once: it goes unless given anew.
  if (body.contains("target_error")) spec["target_error"] = body["target_error"];
  else if (job->stopped == pt::stop_reason_name(pt::StopReason::target_error)) spec["target_error"] = 0;
  if (body.contains("time_limit")) spec["time_limit"] = body["time_limit"];
  else if (job->stopped == pt::stop_reason_name(pt::StopReason::time_limit)) spec["time_limit"] = 0;
  JobSpec next = parse_job_spec(spec, m_config.limits);
  if (next.params.spp < old_spp)
    throw JobError(JobErrorKind::invalid, "spp must be at least the job's " + std::to_string(old_spp) + " (a budget can grow, not shrink)", "spp");
  if (budget_spent && next.params.spp == old_spp)
    throw JobError(JobErrorKind::invalid, "the job has spent its " + std::to_string(old_spp) + " spp: give a larger spp, "
                   "a target_error or a time_limit", "spp");
  // A time limit counts from now: the seconds already rendered are added to it.
  if (body.contains("time_limit") && next.time_limit > 0) next.time_limit += job->elapsed;
  job->spec = next;
  job->cancel = false, job->pause = false, job->halt = false;
  job->state = JobState::queued;
  job->finished_at = 0;
  job->eta = -1;
  job->message.clear();
  ++job->version;
  persist(*job);
  m_queue.push_back(job);
  m_queue_cv.notify_one();
  job->changed.notify_all();
}

bool JobManager::remove(const std::string& id) {
  auto job = must_get(*this, id);
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    std::lock_guard<std::mutex> jl(job->mutex);
    if (is_final(job->state)) {
      m_jobs.erase(job->id);
      if (!job->idempotency_key.empty()) m_idempotency.erase(job->idempotency_key);
      delete_files(job->id);
      job->changed.notify_all();  // its watchers end
      return true;
    }
  }
  cancel(id);  // a live job is cancelled, as before; deleted, it goes
  return false;
}

// job.json goes first: a folder without it is an unacknowledged job, which a restart removes.
void JobManager::delete_files(const std::string& id) {
  const std::string dir = job_dir(id);
  std::remove((dir + "/job.json").c_str());
  if (DIR* d = opendir(dir.c_str())) {
    while (dirent* e = readdir(d)) {
      std::string name = e->d_name;
      if (name != "." && name != "..") std::remove((dir + "/" + name).c_str());
    }
    closedir(d);
  }
  if (::rmdir(dir.c_str()) != 0) std::fprintf(stderr, "render-server: cannot remove %s\n", dir.c_str());
}

// A queued, running or paused job renders the scene it was submitted with: its file stays as it is.
void JobManager::check_scene_unused(const std::string& name) {
  std::lock_guard<std::mutex> lock(m_mutex);
  for (auto& kv : m_jobs) {
    std::lock_guard<std::mutex> jl(kv.second->mutex);
    if (kv.second->spec.scene == name && !is_final(kv.second->state))
      throw JobError(JobErrorKind::conflict, "job " + kv.first + " (" + job_state_name(kv.second->state) +
                     ") renders '" + name + "': wait for it or cancel it first", "name");
  }
}

std::pair<json, bool> JobManager::store_scene(const std::string& name, const std::string& bytes) {
  check_scene_unused(name);
  return m_scenes.store_upload(name, bytes);
}

void JobManager::delete_scene(const std::string& name) {
  check_scene_unused(name);
  m_scenes.remove_upload(name);
}

uint64_t JobManager::data_bytes() const {
  std::vector<std::string> ids;
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    for (auto& kv : m_jobs) ids.push_back(kv.first);
  }
  uint64_t bytes = 0;
  for (const std::string& id : ids) bytes += folder_bytes(job_dir(id));
  return bytes + folder_bytes(m_config.data_dir + "/scenes");
}

void JobManager::enforce_retention() {
  if (m_config.keep_jobs == 0 && m_config.max_data_bytes == 0) return;
  // Finished jobs, oldest first (ids sort by creation time); never a queued, running or paused one.
  std::vector<std::pair<std::string, uint64_t>> finished;
  uint64_t total = 0;
  {
    std::lock_guard<std::mutex> lock(m_mutex);
    for (auto& kv : m_jobs) {
      const uint64_t bytes = m_config.max_data_bytes ? folder_bytes(job_dir(kv.first)) : 0;
      total += bytes;
      std::lock_guard<std::mutex> jl(kv.second->mutex);
      if (is_final(kv.second->state)) finished.push_back({kv.first, bytes});
    }
  }
  // The newest finished job stays whatever its size: it is the image someone is waiting for.
  if (!finished.empty()) finished.pop_back();
  size_t excess = m_config.keep_jobs && finished.size() + 1 > m_config.keep_jobs ? finished.size() + 1 - m_config.keep_jobs : 0;
  for (const auto& [id, bytes] : finished) {
    const bool over = m_config.max_data_bytes && total > m_config.max_data_bytes;
    if (excess == 0 && !over) break;
    try {
      if (remove(id)) {
        std::fprintf(stderr, "render-server: job %s deleted (retention: %s)\n", id.c_str(),
                     excess ? "--keep-jobs" : "--max-data-mb");
        total -= std::min(total, bytes);
        if (excess) --excess;
      }
    } catch (const JobError&) {  // continued or deleted meanwhile
    }
  }
}

JobPage JobManager::page(size_t limit, const std::string& cursor, const std::string& state) const {
  JobState wanted = JobState::queued;
  if (!state.empty() && !parse_job_state(state, &wanted))
    throw JobError(JobErrorKind::invalid, "state must be queued, running, paused, done, failed or cancelled", "state");
  JobPage out;
  std::lock_guard<std::mutex> lock(m_mutex);
  auto it = cursor.empty() ? m_jobs.end() : m_jobs.lower_bound(cursor);  // ids sort by creation time
  while (it != m_jobs.begin()) {
    --it;
    if (!state.empty()) {
      std::lock_guard<std::mutex> jl(it->second->mutex);
      if (it->second->state != wanted) continue;
    }
    if (out.jobs.size() == limit) {
      out.next_cursor = out.jobs.back()->id;
      break;
    }
    out.jobs.push_back(it->second);
  }
  return out;
}

}  // namespace srv
