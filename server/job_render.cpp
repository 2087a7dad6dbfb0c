// A job's render through the renderer's one render lifecycle (pt::run_render_job), for both
// backends: the pass source's tiles, passes and checkpoints go to the job's sink, and what goes
// wrong with a checkpoint goes to the log, naming the job.
#include <algorithm>
#include <cstdio>
#include <memory>

#include "jobs.h"
#include "render_backend.h"
#include "render_job.h"

namespace srv {

namespace {

RenderReport report_of(const pt::PassSource& source, pt::ProgressEstimate& estimate, double error) {
  const double t = source.seconds();
  estimate.update(source, t, error);
  const pt::RenderCounts n = source.counts();
  return {estimate.progress(t), n.samples, n.rays, n.nonfinite, error, estimate.remaining_seconds(t)};
}

}  // namespace

RenderResult render_job(pt::PassSource& source, const Job& job, JobSink& sink, const std::atomic<bool>& stop,
                        const CheckpointPlan& plan, const std::string& fingerprint,
                        const std::function<void(bool resumed)>& started) {
  const pt::RunLimits limits{job.spec.time_limit, job.spec.target_error};
  std::unique_ptr<pt::Checkpointer> checkpoints;
  if (!plan.path.empty()) checkpoints = std::make_unique<pt::Checkpointer>(plan.path, fingerprint, plan.interval);
  pt::ProgressEstimate estimate(limits);
  pt::RenderJobEvents events;
  events.started = [&](bool resumed) {
    if (resumed)
      std::fprintf(stderr, "render-server: job %s: resuming from its checkpoint (%.1f spp a pixel, %.2f s rendered)\n",
                   job.id.c_str(), double(source.counts().samples) / double(source.film().pixels()), source.seconds());
    started(resumed);
  };
  events.tile = [&](const pt::Tile& t) {
    thread_local std::vector<pt::Vec3> mean;
    thread_local std::vector<uint32_t> count;
    source.film().read_tile(t, mean);
    source.film().read_tile_count(t, count);
    sink.tile(t, mean, count);
  };
  // Denoised pictures at pass ends (fast quality), while they cost at most a tenth of the render
  // time so far; the first failure ends them (the job renders on, raw, saying why).
  const bool denoising = job.spec.denoise != DenoiseMode::off;
  const int threads = std::max(1, job.spec.params.threads);
  double denoise_spent = 0;
  bool denoise_failed = false;
  auto spp_of = [&] { return double(source.counts().samples) / double(std::max<size_t>(1, source.film().pixels())); };
  events.pass = [&](const pt::PassReport& r) {
    sink.pass(report_of(source, estimate, r.error));
    if (!denoising || denoise_failed || !r.completed || source.finished() || denoise_spent > 0.1 * source.seconds()) return;
    const pt::DenoisedFilm d = pt::denoise_film(source.film(), pt::DenoiseQuality::preview, threads, false);
    denoise_spent += d.seconds;
    denoise_failed = !d.ok;
    sink.denoised(d, spp_of(), false);
  };
  events.checkpointed = [&] { sink.checkpointed(source.counts().samples, source.seconds()); };
  // Another render's or a damaged checkpoint: render from the start, saying so.
  events.restore_failed = [&](const std::exception& e) {
    std::fprintf(stderr, "render-server: job %s: %s; rendering from the start\n", job.id.c_str(), e.what());
  };
  // A checkpoint that cannot be written (a full disk) costs the resume, not the render.
  events.save_failed = [&](const std::exception& e) {
    std::fprintf(stderr, "render-server: job %s: %s\n", job.id.c_str(), e.what());
  };
  RenderResult result;
  result.why = pt::run_render_job(source, limits, checkpoints.get(), &stop, events);
  result.image = source.film().image();
  // The finished image (or what a user cancelled: it is stored too); not a pause or a shutdown.
  const bool kept = result.why != pt::StopReason::cancelled || job.cancel;
  if (denoising && kept && source.counts().samples > 0) {
    const bool final = job.spec.denoise == DenoiseMode::final;
    result.denoised = pt::denoise_film(source.film(), final ? pt::DenoiseQuality::final : pt::DenoiseQuality::preview,
                                       threads, final);
    sink.denoised(result.denoised, spp_of(), true);
  }
  result.report = report_of(source, estimate, source.error_estimate());
  result.seconds = source.seconds();
  return result;
}

}  // namespace srv
