// The embedded backend (the default): renders a job in this process through the renderer's
// progressive session, publishing every finished tile, and checkpointing its film so that a
// restart, a pause or a continue takes the render on where it stood.
#include <chrono>
#include <cstdio>
#include <memory>

#include "checkpoint.h"
#include "job_store.h"
#include "jobs.h"
#include "render_backend.h"
#include "scene_library.h"

namespace srv {

namespace {

class EmbeddedBackend : public RenderBackend {
 public:
  EmbeddedBackend(SceneLibrary& scenes, int threads) : m_scenes(scenes), m_threads(std::max(1, threads)) {}

  std::string name() const override { return "embedded"; }

  RenderResult render(const Job& job, JobSink& sink, const std::atomic<bool>& stop,
                      const CheckpointPlan& plan) override {
    auto base = m_scenes.load(job.spec.scene);  // shared with every job on this scene
    pt::RenderParams p = job.spec.params;
    p.threads = m_threads;
    auto scene = pt::make_view(*base, p);
    const pt::RunLimits limits{job.spec.time_limit, job.spec.target_error};
    auto session = std::make_unique<pt::RenderSession>(*scene, p);
    auto driver = std::make_unique<pt::ProgressiveDriver>(*session, limits);
    std::unique_ptr<pt::Checkpointer> checkpoints;
    bool resumed = false;
    if (!plan.path.empty()) {
      std::string scene_bytes;
      if (!read_file(m_scenes.resolve(job.spec.scene), scene_bytes)) throw std::runtime_error("the scene file is gone");
      checkpoints = std::make_unique<pt::Checkpointer>(plan.path, pt::render_fingerprint(scene_bytes, p), plan.interval);
      try {
        resumed = checkpoints->restore(*session, *driver);
      } catch (const std::exception& e) {  // another render's or a damaged file: start over, saying so
        std::fprintf(stderr, "render-server: job %s: %s; rendering from the start\n", job.id.c_str(), e.what());
        session = std::make_unique<pt::RenderSession>(*scene, p);
        driver = std::make_unique<pt::ProgressiveDriver>(*session, limits);
      }
    }
    sink.started(session->width(), session->height(), feature_names(scene->features),
                 resumed ? session->seconds() : 0.0);

    auto on_tile = [&](const pt::Tile& t) {
      thread_local std::vector<pt::Vec3> buf;
      thread_local std::vector<uint32_t> count;
      session->film().read_tile(t, buf);
      session->film().read_tile_count(t, count);
      sink.tile(t, buf, count);
    };
    pt::ProgressEstimate estimate({job.spec.time_limit, job.spec.target_error});
    auto report = [&](double error) {
      pt::SessionStats st = session->stats();
      estimate.update(*session, st.seconds, error);
      return RenderReport{estimate.progress(st.seconds), st.samples, st.rays, st.nonfinite, error,
                          estimate.remaining_seconds(st.seconds)};
    };
    if (resumed) {  // the checkpoint's picture and counts, before the first new pass
      std::fprintf(stderr, "render-server: job %s: resuming from its checkpoint (%.1f spp a pixel, %.2f s rendered)\n",
                   job.id.c_str(), double(session->stats().samples) / double(session->film().pixels()),
                   session->seconds());
      for (const pt::Tile& t : session->tiles()) on_tile(t);
      sink.pass(report(session->error_estimate()));
    }
    RenderResult result;
    while (!driver->done()) {
      const pt::PassReport r = driver->step(&stop, on_tile);
      sink.pass(report(r.error));
      if (!r.completed) break;  // stopped (the next step would resume it) or the time limit
      if (checkpoints) save(*checkpoints, *session, *driver, job, sink, false);
    }
    result.why = driver->done() ? driver->reason() : pt::StopReason::cancelled;
    // However it ended, the film is kept: a pause, a restart or a continue takes it from here.
    if (checkpoints) save(*checkpoints, *session, *driver, job, sink, true);
    // The time limit cut a pass short: its unfinished tiles never reached on_tile, so publish every
    // tile once more and the event stream ends on the same picture as image.png.
    if (result.why != pt::StopReason::finished)
      for (const pt::Tile& t : session->tiles()) on_tile(t);
    result.image = session->image();
    result.report = report(session->error_estimate());
    result.seconds = session->stats().seconds;
    return result;
  }

 private:
  // A checkpoint that cannot be written (a full disk) costs the resume, not the render.
  static void save(pt::Checkpointer& c, const pt::RenderSession& s, const pt::ProgressiveDriver& d, const Job& job,
                   JobSink& sink, bool force) {
    try {
      if (c.after_pass(s, d, force)) sink.checkpointed(s.stats().samples, s.seconds());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "render-server: job %s: %s\n", job.id.c_str(), e.what());
    }
  }

  SceneLibrary& m_scenes;
  int m_threads;
};

}  // namespace

std::unique_ptr<RenderBackend> make_embedded_backend(SceneLibrary& scenes, int threads) {
  return std::make_unique<EmbeddedBackend>(scenes, threads);
}

}  // namespace srv
