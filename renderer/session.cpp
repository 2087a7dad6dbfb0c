// The render session (session.h): tiles, passes on the render threads, and the light tracer's share
// of each pass.
#include "session.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <time.h>

#include "materials.h"
#include "parallel.h"
#include "sampler.h"

namespace pt {

namespace {
// This thread's CPU time in nanoseconds (CLOCK_THREAD_CPUTIME_ID): what it ran, not what it waited.
uint64_t thread_cpu_ns() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return uint64_t(t.tv_sec) * 1000000000u + uint64_t(t.tv_nsec);
}
}  // namespace

AdaptiveRule adaptive_rule(const RenderParams& params) {
  return {params.adaptive, uint32_t(std::max(1, params.adaptive_batch)), params.adaptive_tolerance};
}

namespace {
int film_width(const RenderParams& p) { return p.cell_w > 0 ? p.cell_w : p.width; }
int film_height(const RenderParams& p) { return p.cell_w > 0 ? p.cell_h : p.height; }
}  // namespace

RenderSession::RenderSession(const RenderScene& scene, const RenderParams& params)
    : m_scene(scene),
      m_params((params.validate(), params)),
      m_frame_x0(params.cell_w > 0 ? params.cell_x : 0),
      // the cell's bottom-left origin, as a top-left one
      m_frame_y0(params.cell_w > 0 ? params.height - (params.cell_y + params.cell_h) : 0),
      m_path(params, caustic_tracing_applies(scene, params)),
      m_film(film_width(params), film_height(params), params.spp, adaptive_rule(params), m_path.caustics_light_traced,
             params.features) {
  const int w = width(), h = height();
  if (m_path.caustics_light_traced) m_caustic_film = {params.width, params.height, m_frame_x0, m_frame_y0, w, h};
  m_tiles = tile_grid(w, h, params.tile_size);
  m_background = BackgroundMask(scene, params, m_frame_x0, m_frame_y0, w, h);
  // Before any pass, a tile's cost is its pixels that see the scene.
  m_tile_ns.assign(m_tiles.size(), 0);
  m_tile_samples.assign(m_tiles.size(), 0);
  for (size_t t = 0; t < m_tiles.size(); ++t) {
    const Tile& tile = m_tiles[t];
    uint64_t seen = 0;
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x) seen += !m_background.film_pixel(size_t(y) * w + x, x, y);
    m_tile_ns[t] = seen;
  }
  order_tiles_by_cost();
}

void RenderSession::order_tiles_by_cost() {
  m_tile_order.resize(m_tiles.size());
  for (size_t t = 0; t < m_tiles.size(); ++t) m_tile_order[t] = uint32_t(t);
  std::stable_sort(m_tile_order.begin(), m_tile_order.end(),
                   [&](uint32_t a, uint32_t b) { return m_tile_ns[a] > m_tile_ns[b]; });
}

// Light paths per sample and pixel of the area where the scene's bounds project (background_mask.h),
// so that the splats per pixel do not depend on the framing. The light paths are aimed at the delta
// geometry and most of them splat, so few are needed: on CBspheres at 480x360 (m = 5, 64 spp; the
// scene covers 57520 pixels) 0.045 / 0.09 / 0.19 / 0.38 / 1.5 paths per scene pixel gave
// efficiencies 1/(relMSE x s) of 415 / 454 / 461 / 410 / 239, against 95 without light tracing
// (docs/performance.md). At most one light path per camera sample of the frame: a crop of a
// large view would otherwise pay for splats that land outside it.
constexpr double kLightPathsPerScenePixel = 0.15, kMaxLightPathsPerSample = 1.0;

// The pass's share of caustic light paths, before its tiles so that tiles published during the
// pass include them. Splats are merged in path order: images do not depend on the thread count.
// The light paths that go with camera samples [0, samples): counted on the full frame, so a cell
// (-p) traces the frame's paths and keeps its own splats (it renders exactly its window of the
// full frame), and a share of sample indices (set_sample_range) its share of light paths.
uint64_t RenderSession::light_paths_for(uint64_t samples) const {
  const double frame = double(m_params.width) * m_params.height;
  const double scene = m_background.scene_pixels() >= 0 ? m_background.scene_pixels() : frame;
  const double per_sample = std::min(kMaxLightPathsPerSample * frame, kLightPathsPerScenePixel * scene);
  return uint64_t(std::ceil(per_sample * double(samples)));
}

void RenderSession::trace_caustics(int target, const std::atomic<bool>* cancel) {
  uint64_t want = light_paths_for(uint64_t(m_first_sample) + uint64_t(target));
  if (want <= m_lt_issued) return;
  if (!m_lt_partial) m_film.begin_light_paths();  // once a pass, as an uninterrupted pass does
  // Chunks of paths run on the threads in waves; each wave's splats are merged in path order before
  // the next, which bounds the memory they take whatever the pass's size.
  constexpr uint64_t kChunk = 1024, kWave = 64;
  const uint64_t first = m_lt_issued, count = want - first;
  const uint64_t chunks = (count + kChunk - 1) / kChunk;
  std::vector<std::vector<CausticSplat>> splats(size_t(std::min(chunks, kWave)));
  std::vector<uint8_t> finished(splats.size());
  uint64_t merged = 0;  // chunks merged, in order: a cut keeps these and traces the rest on resume
  for (uint64_t wave = 0; wave < chunks && !stop_requested(cancel); wave += kWave) {
    const size_t in_wave = size_t(std::min(kWave, chunks - wave));
    for (auto& s : splats) s.clear();
    std::fill(finished.begin(), finished.end(), 0);
    parallel_indices(in_wave, m_params.threads, [&](auto& take) {
      const uint64_t cpu_start = thread_cpu_ns();
      uint64_t rays = 0;
      for (size_t c; take(c) && !stop_requested(cancel);) {
        uint64_t b = first + (wave + c) * kChunk, e = std::min(first + count, b + kChunk);
        trace_caustic_paths(m_scene, m_params, m_caustic_film, b, e - b, splats[c], rays);
        finished[c] = 1;
      }
      m_rays += rays;
      m_cpu_ns += thread_cpu_ns() - cpu_start;
    });
    size_t c = 0;
    for (; c < in_wave && finished[c]; ++c, ++merged) {
      m_film.add_splats(splats[c]);
      m_film.add_light_paths(std::min(kChunk, count - (wave + c) * kChunk));
    }
    if (c < in_wave) break;  // cut: the chunks after the first unfinished one are traced again
  }
  m_lt_issued = first + std::min(count, merged * kChunk);
  m_lt_partial = m_lt_issued < want;
}

bool RenderSession::render_pass(int target_spp, const std::atomic<bool>* cancel, const TileCallback& on_tile) {
  target_spp = std::min(target_spp, m_params.spp);
  auto start = std::chrono::steady_clock::now();
  m_film.invalidate_estimate();
  if (m_path.caustics_light_traced) {
    trace_caustics(target_spp, cancel);
    m_light_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  parallel_indices(m_tile_order.size(), m_params.threads, [&](auto& take) {
    const uint64_t cpu_start = thread_cpu_ns();
    uint64_t rays = 0, samples = 0, nonfinite = 0;
    for (size_t k; take(k);) {
      if (stop_requested(cancel)) break;
      const uint32_t ti = m_tile_order[k];
      const auto t0 = std::chrono::steady_clock::now();
      const uint64_t samples_before = samples;
      render_tile(m_tiles[ti], target_spp, cancel, rays, samples, nonfinite);
      m_tile_ns[ti] = uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0).count());
      m_tile_samples[ti] = samples - samples_before;
      if (on_tile && !stop_requested(cancel)) on_tile(m_tiles[ti]);
    }
    m_rays += rays;
    m_samples += samples;
    m_nonfinite += nonfinite;
    m_cpu_ns += thread_cpu_ns() - cpu_start;
  });
  order_tiles_by_cost();
  m_film.invalidate_estimate();  // also for an estimate someone asked for while the pass ran
  m_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ++m_passes;
  return !stop_requested(cancel);
}

bool RenderSession::render_all(const std::atomic<bool>* cancel, const std::function<void()>& on_progress) {
  TileCallback tiles = on_progress ? TileCallback([&](const Tile&) { on_progress(); }) : TileCallback();
  return run_progressive(*this, RunLimits(), cancel, tiles) == StopReason::finished;
}

FilmPass render_film_pass(const RenderScene& scene, const RenderParams& params, uint32_t first, uint32_t count,
                          const std::vector<uint8_t>& skip, const std::atomic<bool>* cancel, bool* complete) {
  RenderParams p = params;
  p.adaptive = false;  // convergence is judged on the merged statistics, not per pass
  RenderSession session(scene, p);
  session.set_sample_range(first, skip);
  bool ok = session.render_pass(int(count), cancel);
  if (complete) *complete = ok;
  FilmPass out = session.film().to_pass(first, count);
  SessionStats st = session.stats();
  out.rays = st.rays;
  out.nonfinite = st.nonfinite;
  out.seconds = st.seconds;
  return out;
}

double RenderSession::progress() const {
  double total = double(m_params.spp) * double(m_film.pixels());
  return total > 0 ? std::min(1.0, double(m_budget_done.load()) / total) : 1.0;
}

Film::Work RenderSession::work() const { return m_film.work(m_tiles, m_tile_ns, m_tile_samples); }

void RenderSession::set_sample_range(uint32_t first, const std::vector<uint8_t>& skip) {
  m_first_sample = first;
  if (m_path.caustics_light_traced) m_lt_issued = light_paths_for(first);
  m_film.skip(skip);
}

void RenderSession::save(BinaryWriter& out) const {
  out.pod(m_first_sample), out.pod(m_lt_issued), out.pod(uint8_t(m_lt_partial));
  out.pod(m_samples.load()), out.pod(m_rays.load()), out.pod(m_nonfinite.load()), out.pod(m_cpu_ns.load());
  out.pod(m_seconds), out.pod(int32_t(m_passes));
  m_film.save(out);
}

void RenderSession::restore(BinaryReader& in) {
  if (in.pod<uint32_t>() != m_first_sample) in.fail("another share of the samples");
  m_lt_issued = in.pod<uint64_t>();
  const uint8_t partial = in.pod<uint8_t>();
  if (partial > 1) in.fail("an impossible light-path state");
  m_lt_partial = partial != 0;
  m_samples = in.pod<uint64_t>(), m_rays = in.pod<uint64_t>(), m_nonfinite = in.pod<uint64_t>();
  m_cpu_ns = in.pod<uint64_t>();
  m_seconds = in.pod<double>();
  m_passes = in.pod<int32_t>();
  if (!(m_seconds >= 0 && m_seconds < 1e12) || m_passes < 0) in.fail("impossible render time or pass count");
  m_film.restore(in);
  uint64_t credit = 0;  // as the tiles count progress: a done pixel's whole budget, else its samples
  for (size_t i = 0; i < m_film.pixels(); ++i) credit += m_film.done(i) ? uint64_t(m_params.spp) : m_film.count(i);
  m_budget_done = credit;
}

SessionStats RenderSession::stats() const {
  SessionStats s;
  s.samples = m_samples.load();
  s.rays = m_rays.load();
  s.nonfinite = m_nonfinite.load();
  s.light_paths = m_film.light_paths();
  s.seconds = m_seconds;
  s.cpu_seconds = double(m_cpu_ns.load()) * 1e-9;
  s.passes = m_passes;
  return s;
}

}  // namespace pt
