// A tile's samples for one pass: camera rays, the path loop (many paths in Embree packets, or one
// path at a time), and the per-pixel statistics every estimate and stop rule reads.
#include <algorithm>

#include "loop_forms.h"
#include "session.h"

namespace pt {

bool sobol_draws_in_lanes(const RenderParams& params) {
  return forms::lanes() && params.sampler == SamplerKind::sobol && Sampler::lanes_available();
}

// A tile's samples gathered into batches of jobs (pixel, sample) that the path tracer runs together
// (in a pool of packets, or one path after another: the same samples, whose images differ only by
// the packet kernel's rounding of a few hits), then added to the pixels in each pixel's sample
// order. With adaptive sampling a pixel's jobs stop at its next stop test, so rounds over the tile
// continue the pixels it leaves running.
void RenderSession::render_tile(const Tile& t, int target, const std::atomic<bool>* cancel, uint64_t& rays,
                                uint64_t& samples, uint64_t& nonfinite) {
  const RenderParams& p = m_params;
  const PathTracer trace = path_tracer_for(m_scene.features.bits, m_path, packets_apply(p));
  const AdaptiveRule& rule = m_film.rule();
  const int w = width();
  constexpr size_t kJobs = 2048;  // paths per batch: bounds memory and the latency of a cancel
  const bool lens = m_scene.camera.lens_radius > 0;
  // With Sobol draws in lanes, the camera's draws come from each job's pixel base and sample index
  // (Sampler::sobol_draws), and its sampler starts past them.
  const bool sobol_lanes = sobol_draws_in_lanes(p);
  const uint32_t camera_draws = (p.spp == 1 ? 0 : 1) + (lens ? 1 : 0);
  // The batch's arrays, kept on the thread from tile to tile: fresh pages for every tile cost a
  // visible part of a pass.
  struct Job {
    uint32_t pixel, sample;
  };
  static thread_local std::vector<Job> jobs;
  static thread_local std::vector<Sampler> rngs;
  // Camera rays are made at the flush: each job's pixel corner, then its sensor and lens draws for
  // all jobs at once, then the rays in lanes (generate_rays).
  static thread_local std::vector<float> sensor_x, sensor_y;
  static thread_local std::vector<uint32_t> job_base, job_sample;
  static thread_local std::vector<Vec2> draws;
  static thread_local std::vector<Ray> camera_rays;
  static thread_local std::vector<Vec3> out;
  static thread_local std::vector<PathFeatures> features;  // only where the film keeps them
  const bool with_features = m_film.has_features();
  // The job arrays are written by index up to `njobs`: sized once per tile for a full batch plus
  // one pixel's samples, which push_back's capacity checks would otherwise test at every store.
  const size_t capacity = kJobs + size_t(std::max(target, 1));
  if (jobs.size() < capacity) {
    jobs.resize(capacity);
    rngs.resize(capacity, Sampler(p.sampler, p.seed, 0, 0));
    sensor_x.resize(capacity);
    sensor_y.resize(capacity);
    job_base.resize(capacity);
    job_sample.resize(capacity);
  }
  size_t njobs = 0;
  // The tile's progress credit: every sample added, and the rest of a pixel's budget when an
  // adaptive stop ends it here.
  const uint64_t samples_before = samples;
  uint64_t stopped_credit = 0;

  bool stopped = false;
  auto flush = [&] {
    const size_t n = njobs;
    draws.resize(n);
    if (p.spp == 1) {  // sensor_sample: the pixel centre
      std::fill(draws.begin(), draws.end(), Vec2{0.5f, 0.5f});
    } else if (sobol_lanes) {
      Sampler::sobol_draws(job_base.data(), job_sample.data(), n, 1, draws.data());
    } else {
      Sampler::next_2d_many(rngs.data(), n, draws.data());
    }
    for (size_t k = 0; k < n; ++k) {
      sensor_x[k] = (sensor_x[k] + draws[k].x) / float(p.width);
      sensor_y[k] = (sensor_y[k] + draws[k].y) / float(p.height);
    }
    if (lens && sobol_lanes) Sampler::sobol_draws(job_base.data(), job_sample.data(), n, camera_draws, draws.data());
    else if (lens) Sampler::next_2d_many(rngs.data(), n, draws.data());
    if (camera_rays.size() < n) camera_rays.resize(n);  // kept between flushes: no zeroing
    m_scene.camera.generate_rays(sensor_x.data(), sensor_y.data(), draws.data(), n, camera_rays.data());
    out.resize(n);
    if (with_features) features.resize(n);
    if (n) trace(m_scene, m_path, camera_rays.data(), rngs.data(), n, out.data(), with_features ? features.data() : nullptr, rays);
    samples += n;
    if (with_features)
      for (size_t k = 0; k < n; ++k) m_film.add_features(jobs[k].pixel, features[k].albedo, features[k].normal);
    for (size_t k = 0; k < n; ++k)  // job k traced camera ray k
      if (m_film.add_sample(jobs[k].pixel, jobs[k].sample, out[k], nonfinite)) {
        m_film.set_done(jobs[k].pixel);
        stopped_credit += uint64_t(p.spp) - m_film.count(jobs[k].pixel);
      }
    njobs = 0;
    stopped = stop_requested(cancel);
  };
  for (bool again = true; again && !stopped;) {
    again = false;
    for (int y = t.y0; y < t.y1 && !stopped; ++y) {
      for (int x = t.x0; x < t.x1 && !stopped; ++x) {
        size_t i = size_t(y) * w + x;
        uint32_t c = m_film.count(i);
        if (m_film.done(i) || c >= uint32_t(target)) continue;
        uint32_t end = uint32_t(target);
        if (rule.enabled) {  // up to the pixel's next stop test
          uint32_t test = rule.next_test(c);
          if (test < end) end = test, again = true;
        }
        if (m_background.film_pixel(i, x, y)) {  // zeros of its own: no job, no ray (but counted as the camera ray it would be)
          bool stop;
          uint32_t added = m_film.add_zero_samples(i, c, end, stop);
          rays += added;
          samples += added;
          if (stop) {
            m_film.set_done(i);
            stopped_credit += uint64_t(p.spp) - m_film.count(i);
          }
          continue;
        }
        const int fx = m_frame_x0 + x, fy_top = m_frame_y0 + y;
        const int fy_up = p.height - 1 - fy_top;  // course pixel rows count from the bottom
        const uint64_t pixel_index = uint64_t(fy_top) * p.width + fx;
        const uint32_t base = Sampler::pixel_base(p.seed, pixel_index);
        for (uint32_t s = c; s < end; ++s, ++njobs) {
          Job& job = jobs[njobs];  // fields stored one by one: a braced temporary is copied
          job.pixel = uint32_t(i);  // with one wide load of narrow stores, which stalls
          job.sample = s;
          const uint32_t index = m_first_sample + s;
          rngs[njobs] = Sampler(p.sampler, p.seed, pixel_index, index, base, sobol_lanes ? camera_draws : 0);
          job_base[njobs] = base;
          job_sample[njobs] = index;
          sensor_x[njobs] = float(fx);
          sensor_y[njobs] = float(fy_up);
        }
        if (njobs >= kJobs) flush();
      }
    }
    if (njobs) flush();
  }
  for (int y = t.y0; y < t.y1; ++y)
    for (int x = t.x0; x < t.x1; ++x) {
      size_t i = size_t(y) * w + x;
      if (m_film.count(i) >= uint32_t(p.spp)) m_film.set_done(i);
    }
  // The credit in one update: the counter is shared by the threads, and an atomic add per pixel
  // would move its cache line between cores a thousand times a tile.
  const uint64_t credit = samples - samples_before + stopped_credit;
  m_budget_done.fetch_add(credit, std::memory_order_relaxed);
}

}  // namespace pt
