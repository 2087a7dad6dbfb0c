// The embedded backend (the default): renders a job in this process through the renderer's
// progressive session, publishing every finished tile, and checkpointing its film so that a
// restart, a pause or a continue takes the render on where it stood.
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
    pt::RenderSession session(*scene, p);
    std::string fingerprint;
    if (!plan.path.empty()) {
      std::string scene_bytes;
      if (!read_file(m_scenes.resolve(job.spec.scene), scene_bytes)) throw std::runtime_error("the scene file is gone");
      fingerprint = pt::render_fingerprint(scene_bytes, p);
    }
    return render_job(session, job, sink, stop, plan, fingerprint, [&](bool resumed) {
      sink.started(session.width(), session.height(), feature_names(scene->features), resumed ? session.seconds() : 0.0);
    });
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
