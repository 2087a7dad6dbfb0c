// The embedded backend (the default): renders a job in this process through the renderer's
// progressive session, publishing every finished tile.
#include <chrono>

#include "jobs.h"
#include "render_backend.h"
#include "scene_library.h"

namespace srv {

namespace {

class EmbeddedBackend : public RenderBackend {
 public:
  EmbeddedBackend(SceneLibrary& scenes, int threads) : m_scenes(scenes), m_threads(std::max(1, threads)) {}

  std::string name() const override { return "embedded"; }

  RenderResult render(const Job& job, JobSink& sink, const std::atomic<bool>& stop) override {
    auto base = m_scenes.load(job.spec.scene);  // shared with every job on this scene
    pt::RenderParams p = job.spec.params;
    p.threads = m_threads;
    auto scene = pt::make_view(*base, p);
    pt::RenderSession session(*scene, p);
    sink.started(session.width(), session.height(), feature_names(scene->features));

    auto on_tile = [&](const pt::Tile& t) {
      thread_local std::vector<pt::Vec3> buf;
      session.film().read_tile(t, buf);
      sink.tile(t, buf);
    };
    pt::ProgressEstimate estimate({job.spec.time_limit, job.spec.target_error});
    auto report = [&](double error) {
      pt::SessionStats st = session.stats();
      estimate.update(session, st.seconds, error);
      return RenderReport{estimate.progress(st.seconds), st.samples, st.rays, st.nonfinite, error,
                          estimate.remaining_seconds(st.seconds)};
    };
    auto on_pass = [&](const pt::PassReport& r) { sink.pass(report(r.error)); };
    RenderResult result;
    result.why = pt::run_progressive(session, {job.spec.time_limit, job.spec.target_error}, &stop, on_tile, on_pass);
    // The time limit cut a pass short: its unfinished tiles never reached on_tile, so publish every
    // tile once more and the event stream ends on the same picture as image.png.
    if (result.why == pt::StopReason::time_limit)
      for (const pt::Tile& t : session.tiles()) on_tile(t);
    result.image = session.image();
    result.report = report(session.error_estimate());
    result.seconds = session.stats().seconds;
    return result;
  }

 private:
  SceneLibrary& m_scenes;
  int m_threads;
};

}  // namespace

std::unique_ptr<RenderBackend> make_embedded_backend(SceneLibrary& scenes, int threads) {
  return std::make_unique<EmbeddedBackend>(scenes, threads);
}

}  // namespace srv
