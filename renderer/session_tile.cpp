// A tile's samples for one pass: camera rays, the path loop (one path at a time, or many paths
// in Embree packets), and the per-pixel statistics every estimate and stop rule reads.
#include <algorithm>

#include "session.h"

namespace pt {

bool sobol_draws_in_lanes(const RenderScene& scene, const RenderParams& params) {
  return scene.loop.lanes && params.sampler == SamplerKind::sobol && Sampler::lanes_available();
}

Vec2 RenderSession::sensor_sample(int fx, int fy_up, Sampler& rng) const {
  const RenderParams& p = m_params;
  Vec2 jitter = p.spp == 1 ? Vec2{0.5f, 0.5f} : rng.next_2d();  // -s 1: the pixel centre
  return {(fx + jitter.x) / p.width, (fy_up + jitter.y) / p.height};
}

void RenderSession::camera_ray(int fx, int fy_up, Sampler& rng, Ray& r) const {
  const Camera& cam = m_scene.camera;
  Vec2 s = sensor_sample(fx, fy_up, rng);
  Vec2 lens = cam.lens_radius > 0 ? rng.next_2d() : Vec2{0.5f, 0.5f};  // a pinhole needs none
  cam.generate_ray(s.x, s.y, lens, r);
}

void RenderSession::render_tile(const Tile& t, int target, const std::atomic<bool>* cancel, uint64_t& rays,
                                uint64_t& samples, uint64_t& nonfinite) {
  const RenderParams& p = m_params;
  const int w = width();
  if (packets_apply(m_scene, p)) {
    if (PathBatchTracer many = path_batch_tracer_for(m_scene.features.bits, m_path)) {
      render_tile_batched(t, target, cancel, rays, samples, nonfinite, many);
      return;
    }
  }
  const PathTracer trace = path_tracer_for(m_scene.features.bits);
  for (int y = t.y0; y < t.y1; ++y) {
    if (stop_requested(cancel)) return;
    uint64_t row_credit = 0;  // one update of the shared counter per row: see render_tile_batched
    for (int x = t.x0; x < t.x1; ++x) {
      size_t i = size_t(y) * w + x;
      if (m_film.done(i)) continue;
      int fx = m_frame_x0 + x, fy_top = m_frame_y0 + y;
      int fy_up = p.height - 1 - fy_top;  // course pixel rows count from the bottom
      uint64_t pixel_index = uint64_t(fy_top) * p.width + fx;
      const bool background = background_pixel(i, x, y);
      uint32_t before = m_film.count(i);
      while (m_film.count(i) < uint32_t(target)) {
        uint32_t s = m_film.count(i);
        if ((s & 15) == 15 && stop_requested(cancel)) break;
        Vec3 l(0.0f);
        if (background) {
          ++rays;  // the camera ray the path loop would have cast and missed
        } else {
          Sampler rng(p.sampler, p.seed, pixel_index, m_first_sample + s);
          Ray ray;
          camera_ray(fx, fy_up, rng, ray);
          l = trace(m_scene, m_path, ray, rng, rays);
        }
        ++samples;
        if (m_film.add_sample(i, s, l, nonfinite)) {
          m_film.set_done(i);
          break;
        }
      }
      if (m_film.count(i) >= uint32_t(p.spp)) m_film.set_done(i);
      row_credit += m_film.done(i) ? uint64_t(p.spp) - before : uint64_t(m_film.count(i) - before);
    }
    m_budget_done.fetch_add(row_credit, std::memory_order_relaxed);
  }
}

// The same samples as render_tile's loop, gathered into batches of jobs (pixel, sample) that the
// batch tracer runs together, then added to the pixels in each pixel's sample order: the images
// equal the scalar loop's up to the packet kernel's rounding of a few hits. With adaptive sampling
// a pixel's jobs stop at its next stop test, so rounds over the tile continue the pixels it
// leaves running.
void RenderSession::render_tile_batched(const Tile& t, int target, const std::atomic<bool>* cancel, uint64_t& rays,
                                        uint64_t& samples, uint64_t& nonfinite, PathBatchTracer trace) {
  const RenderParams& p = m_params;
  const AdaptiveRule& rule = m_film.rule();
  const int w = width();
  constexpr size_t kJobs = 2048;  // paths per batch: bounds memory and the latency of a cancel
  const bool lens = m_scene.camera.lens_radius > 0;
  // With Sobol draws in lanes, the camera's draws come from each job's pixel base and sample index
  // (Sampler::sobol_draws), and its sampler starts past them.
  const bool sobol_lanes = sobol_draws_in_lanes(m_scene, p);
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
      Sampler::next_2d_many(rngs.data(), n, draws.data(), m_scene.loop.lanes);
    }
    for (size_t k = 0; k < n; ++k) {
      sensor_x[k] = (sensor_x[k] + draws[k].x) / float(p.width);
      sensor_y[k] = (sensor_y[k] + draws[k].y) / float(p.height);
    }
    if (lens && sobol_lanes) Sampler::sobol_draws(job_base.data(), job_sample.data(), n, camera_draws, draws.data());
    else if (lens) Sampler::next_2d_many(rngs.data(), n, draws.data(), m_scene.loop.lanes);
    if (camera_rays.size() < n) camera_rays.resize(n);  // kept between flushes: no zeroing
    m_scene.camera.generate_rays(sensor_x.data(), sensor_y.data(), draws.data(), n, camera_rays.data());
    out.resize(n);
    if (n) trace(m_scene, m_path, camera_rays.data(), rngs.data(), n, out.data(), rays);
    samples += n;
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
        if (background_pixel(i, x, y)) {  // zeros of its own: no job, no ray (but counted as the camera ray it would be)
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
