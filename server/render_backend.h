// The job service's queue interface: where a job's samples are computed. The job manager owns a
// job's state and files; a backend renders and reports through a JobSink. Two backends exist: the
// embedded one renders in this process (the default), the Redis one hands sample passes to
// render-worker processes on any number of machines (see docs/scale-out.md).
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farm_security.h"
#include "film_denoise.h"
#include "session.h"

namespace srv {

class SceneLibrary;
struct Job;

struct RenderReport {
  double progress = 0;  // fraction of the work done (pt::ProgressEstimate)
  uint64_t samples = 0, rays = 0, nonfinite = 0;
  double error = INFINITY;  // the error estimate (relMSE) after the last merged pass
  double eta = -1;          // seconds left (pt::ProgressEstimate); negative when unknown
};

class JobSink {
 public:
  virtual ~JobSink() = default;
  // Once, before any tile: the film size and the scene's feature set, and the rendering time a
  // checkpoint restored (0 for a fresh render). Throws if the job was cancelled meanwhile.
  virtual void started(int width, int height, const std::vector<std::string>& features, double resumed_seconds) = 0;
  // A tile's pixels (mean radiance and samples taken, row by row) changed. May be called from
  // several threads.
  virtual void tile(const pt::Tile& t, const std::vector<pt::Vec3>& mean, const std::vector<uint32_t>& count) = 0;
  // After each pass (a doubling pass, or a merged worker pass).
  virtual void pass(const RenderReport& r) = 0;
  // A checkpoint now holds `samples` taken in `seconds` of rendering: what a restart resumes from.
  virtual void checkpointed(uint64_t samples, double seconds) = 0;
  // A denoised picture of the film at `spp` samples a pixel (at a pass end, or `final`), or why
  // there is none (d.ok false: the picture stays raw).
  virtual void denoised(const pt::DenoisedFilm& d, double spp, bool final) = 0;
};

struct RenderResult {
  pt::StopReason why = pt::StopReason::finished;
  pt::ImageRGB image;
  RenderReport report;
  double seconds = 0;  // rendering time
  pt::DenoisedFilm denoised;  // the finished image denoised (a job that asks for it; ok when it worked)
};

// Where a job's render keeps its checkpoints (renderer/checkpoint.h): a render starts from the file
// when it holds this job's film, saves it at pass ends every `interval` seconds, and always when it
// ends, so that a restart, a pause or a continue takes it on exactly.
struct CheckpointPlan {
  std::string path;  // "" for none
  double interval = 30;
};

// A job's render on `source` through the renderer's render lifecycle (renderer/render_job.h):
// checkpoints at `plan` for the render `fingerprint` names, tiles, passes and checkpoints reported
// to `sink`. `started` tells the sink the film's size and the scene's features (each backend knows
// them its own way), before the first pass, with whether a checkpoint was restored.
RenderResult render_job(pt::PassSource& source, const Job& job, JobSink& sink, const std::atomic<bool>& stop,
                        const CheckpointPlan& plan, const std::string& fingerprint,
                        const std::function<void(bool resumed)>& started);

class RenderBackend {
 public:
  virtual ~RenderBackend() = default;
  // Renders the job until its budget, error target or time limit, or until `stop` is set (then
  // the result says cancelled). Throws for a job that cannot render (bad scene, lost queue).
  virtual RenderResult render(const Job& job, JobSink& sink, const std::atomic<bool>& stop,
                              const CheckpointPlan& checkpoint) = 0;
  // "embedded" or the queue's URL, for logs and /api/health.
  virtual std::string name() const = 0;
  // Render workers seen in the last few seconds; -1 where the backend has none (embedded).
  virtual int live_workers() { return -1; }
  // The farm's workers, refused results and security (FarmLedger, /api/health); null where there is none.
  virtual nlohmann::json farm() { return nullptr; }
};

// The embedded backend: renders in this process with `threads` threads.
std::unique_ptr<RenderBackend> make_embedded_backend(SceneLibrary& scenes, int threads);
// The Redis backend: `url` is redis://host:port. Throws when Redis cannot be reached at start; a
// job waits out an unreachable Redis (a restart) for up to `redis_timeout` seconds, then fails.
// `farm`: the password file, the farm key and --insecure-farm (farm_security.h); a non-loopback
// Redis without a key or --insecure-farm, or Redis refusing the credentials, throws.
std::unique_ptr<RenderBackend> make_redis_backend(SceneLibrary& scenes, const std::string& url, int units_in_flight,
                                                  double redis_timeout, const FarmOptions& farm);

}  // namespace srv
