// The job queue: bounded, persistent (one folder per job in the data directory), rendering one
// job at a time (configurable) through the renderer's progressive session.
#pragma once

#include <atomic>
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "farm_security.h"
#include "image.h"
#include "job_spec.h"
#include "job_store.h"
#include "scene_library.h"

namespace srv {

class RenderBackend;
struct RenderResult;

// Seconds since the Unix epoch: the job timestamps' clock.
double now_unix_seconds();

// paused: stopped by a user with its film kept (its checkpoint); resumed, it queues again.
enum class JobState { queued, running, paused, done, failed, cancelled };
const char* job_state_name(JobState s);
bool parse_job_state(const std::string& s, JobState* out);
inline bool is_final(JobState s) { return s == JobState::done || s == JobState::failed || s == JobState::cancelled; }

constexpr int kMinRegion = 64;  // the smallest square an event stream sends as one tile event
// The side of the squares a job's event stream sends: whole render tiles, at least kMinRegion.
inline int stream_tile_size(int tile_size) { return tile_size * ((kMinRegion + tile_size - 1) / tile_size); }

struct ErrorPoint {
  double seconds, spp, error;
};

// One job. Fields below `mutex` are guarded by it; `changed` is signalled on every update.
struct Job {
  std::string id;
  JobSpec spec;
  std::string idempotency_key;
  std::atomic<bool> cancel{false};
  std::atomic<bool> pause{false};
  std::atomic<bool> halt{false};  // stops its render: set by a cancel, a pause or the server's shutdown

  mutable std::mutex mutex;
  std::condition_variable changed;
  uint64_t version = 1;  // bumps on every change; also the SSE event id
  JobState state = JobState::queued;
  std::string message;   // why it failed
  std::string stopped;   // why its last render ended (pt::stop_reason_name), "" before the first
  double created_at = 0, started_at = 0, finished_at = 0;  // unix seconds
  double progress = 0, elapsed = 0, eta = -1, error_estimate = -1;
  uint64_t samples = 0, rays = 0, nonfinite = 0;
  std::vector<ErrorPoint> history;
  uint64_t scene_hash = 0;  // the scene file's content when submitted (0: not known); continue needs the same
  uint64_t checkpoint_samples = 0;  // what the job's checkpoint holds (a restart shows these)
  double checkpoint_seconds = 0;
  std::vector<std::string> features;
  json view;  // the camera it renders from, as view_json writes it (null: not known)
  std::vector<std::string> warnings;  // what the scene's loader ignored or defaulted (its summary's)

  // The live image: linear RGB and its 8-bit display version. Clients are sent it in regions of at
  // least kMinRegion pixels a side whatever the render's tile size (tiles nest in regions), so
  // that what watching costs does not depend on a client's choice of tile size.
  int width = 0, height = 0, tile_size = 32, region_size = 64, regions_x = 0, regions_y = 0;
  std::vector<float> linear;
  std::vector<uint8_t> display;
  std::vector<uint32_t> counts;          // samples taken by each pixel (GET /pixels, samples.bin)
  std::vector<uint64_t> region_version;  // the job version that last changed each region
  uint64_t passes = 0;                   // passes published so far (the whole-image PNG's cache key)
  bool has_image = false;

  // Denoising (spec.denoise not "off"): the last denoised picture of the whole film, made at a pass
  // end (the raw tiles go on arriving while a pass runs) or at the end.
  struct Denoised {
    std::vector<float> linear;     // empty: none yet
    std::vector<uint8_t> display;
    uint64_t version = 0;          // the job version it was published at
    double spp = 0;                // the film's samples a pixel when it was made
    double seconds = 0, spent_seconds = 0;  // the last one's time; all of them together
    int frames = 0;
    bool final = false;            // the finished image's
    double noise = -1;             // its noise estimate (the denoised halves'); -1: none
    std::string warning;           // why the picture is raw (the denoiser failed)
  } denoised;
};

struct ManagerConfig {
  std::string data_dir = "data";
  std::vector<std::string> scene_dirs;
  size_t scene_cache_bytes = SceneLibrary::kDefaultCacheBytes;  // built scenes kept for later jobs
  int threads = 1;          // render threads per job
  int concurrency = 1;      // jobs rendering at once
  size_t max_queue = 32;    // queued jobs; more is refused
  SpecLimits limits;
  std::string queue = "embedded";  // or redis://host:port: render-workers do the rendering
  int units_in_flight = 4;         // Redis: sample passes queued ahead of the merges, per job
  double redis_timeout = 300;      // Redis: seconds a job waits for an unreachable Redis
  FarmOptions farm;                // Redis: the password file, the farm key, --insecure-farm
  double checkpoint_interval = 30; // seconds between a running job's checkpoints (0: every pass)
  size_t keep_jobs = 0;            // finished jobs kept; past it the oldest are deleted (0: all)
  uint64_t max_data_bytes = 0;     // the data folder's size past which finished jobs are deleted (0: no cap)
};

// A page of the job list: newest first, `limit` jobs created before the job `cursor` ("" for the
// newest), in `state` (all states when empty).
struct JobPage {
  std::vector<std::shared_ptr<Job>> jobs;
  std::string next_cursor;  // "" on the last page
};

// A denoised job (job_denoise.cpp): its status part (null when not denoised), its persisted record,
// and its image files (image.* denoised and image_raw.* raw, or image.* raw).
json denoise_json(const Job& job);
// Throws JobError(unsupported) naming the denoise field when the spec asks for a denoiser this
// server lacks (a 422 that says how to install it).
void require_denoiser(const JobSpec& spec);
void load_denoise(Job& job, const json& doc);
void store_job_images(const std::string& dir, const RenderResult& result, pt::Metadata meta);

class JobManager {
 public:
  explicit JobManager(ManagerConfig config);
  ~JobManager();

  // Reloads persisted jobs (re-queueing interrupted ones) and starts the workers.
  void start();
  // Stops the workers; a running job is put back in the queue on disk so a restart resumes it.
  void stop();

  // Validates and queues; returns the job and whether it was created (false: same idempotency key).
  std::pair<std::shared_ptr<Job>, bool> submit(const json& body, const std::string& idempotency_key);
  // Validates only (scene existence included); returns the normalised spec.
  JobSpec check(const json& body, uint64_t* scene_hash = nullptr, std::vector<std::string>* warnings = nullptr);
  std::shared_ptr<Job> get(const std::string& id) const;
  std::vector<std::shared_ptr<Job>> list() const;
  JobPage page(size_t limit, const std::string& cursor, const std::string& state) const;

  // ---- control (job_control.cpp); each throws JobError(not_found) for no such job ----
  // Cancels a queued, running or paused job and waits (a few seconds at most) for it to settle;
  // throws JobError(conflict) for a finished one.
  void cancel(const std::string& id);
  // A running job stops with its film kept (a checkpoint), a queued one leaves the queue: both are
  // then paused. Conflict for a finished job.
  void pause(const std::string& id);
  // A paused job queues again, to continue from its checkpoint. Conflict for any other state.
  void resume(const std::string& id);
  // Takes a done or cancelled job further from its film: `body` may raise `spp` and set a new
  // `target_error`, or a `time_limit` of more seconds. Conflict without a kept film.
  void continue_job(const std::string& id, const json& body);
  // Deletes a finished job and its files (true), or cancels a live one (false).
  bool remove(const std::string& id);
  // The data folder's size in bytes (job files, checkpoints included).
  uint64_t data_bytes() const;
  // Deletes an uploaded scene (SceneLibrary::remove_upload); conflict while a live job uses it.
  void delete_scene(const std::string& name);
  // Stores an uploaded scene (SceneLibrary::store_upload); 409 while a live job renders the name.
  std::pair<json, bool> store_scene(const std::string& name, const std::string& bytes);

  json status_json(const Job& job, bool with_history = true) const;  // job.mutex must be held
  // Distance from the job's camera through pixel (x, y) (top-left origin) to the first surface;
  // infinity when the ray escapes. What the page's click-to-focus sets the focal distance to.
  double focus_distance(const Job& job, double x, double y);
  const ManagerConfig& config() const { return m_config; }
  std::string backend_name() const;
  int live_workers() const;  // -1 for the embedded backend
  json farm() const;         // null for the embedded backend
  SceneLibrary& scenes() { return m_scenes; }
  std::string job_dir(const std::string& id) const;
  std::string checkpoint_path(const std::string& id) const { return job_dir(id) + "/checkpoint.bin"; }
  bool stopping() const { return m_stopping.load(); }

 private:
  void check_scene_unused(const std::string& name);  // JobError(conflict) while a live job renders it
  void worker_loop();
  void run_job(const std::shared_ptr<Job>& job);
  // Ends a render that stopped without finishing: paused, queued again (shutdown) or cancelled.
  void settle_stopped(Job& job, const RenderResult& result);  // job.mutex must be held
  void store_images(Job& job, const RenderResult& result);
  // Waits up to `seconds` for the job's state to satisfy `settled`.
  void wait_settled(Job& job, double seconds, bool (*settled)(JobState));
  // Deletes the oldest finished jobs past --keep-jobs or --max-data-mb.
  void enforce_retention();
  void delete_files(const std::string& id);
  void persist(Job& job);         // job.mutex must be held; a failure is logged
  void write_job_file(Job& job);  // job.mutex must be held; throws on failure
  void load_persisted();

  ManagerConfig m_config;
  std::unique_ptr<DataDirLock> m_lock;  // held from start() on: one server per data folder
  SceneLibrary m_scenes;
  std::unique_ptr<RenderBackend> m_backend;
  mutable std::mutex m_mutex;
  std::condition_variable m_queue_cv;
  std::map<std::string, std::shared_ptr<Job>> m_jobs;
  std::map<std::string, std::string> m_idempotency;  // key -> job id
  std::deque<std::shared_ptr<Job>> m_queue;
  std::vector<std::thread> m_workers;
  std::atomic<bool> m_stopping{false};
};

}  // namespace srv
