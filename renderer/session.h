// The render session: one progressive, cancellable render of a RenderScene into a Film, in passes
// of tiles on the render threads (session.cpp), each tile's samples by the path loop (session_tile.cpp).
// It is a PassSource: the driver (driver.h) decides the passes and when to stop.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <vector>

#include "background_mask.h"
#include "caustics.h"
#include "driver.h"
#include "film.h"
#include "film_pass.h"
#include "integrator.h"
#include "render_scene.h"

namespace pt {

struct SessionStats {
  uint64_t samples = 0, rays = 0, nonfinite = 0;
  uint64_t light_paths = 0;  // caustic light paths traced (caustics.h)
  double seconds = 0;
  // CPU time the render threads spent in passes, summed over threads: against threads x seconds it
  // tells a slow host (threads that waited for a core) from a slow render (bench_scaling).
  double cpu_seconds = 0;
  int passes = 0;
};

// The film's adaptive rule as the options set it.
AdaptiveRule adaptive_rule(const RenderParams& params);

class RenderSession : public PassSource {
 public:
  RenderSession(const RenderScene& scene, const RenderParams& params);

  // Advances every unfinished pixel to `target_spp` samples (adaptive pixels may stop early).
  // `on_tile` runs on worker threads after each finished tile. Returns false if cancelled or past
  // the deadline.
  bool render_pass(int target_spp, const std::atomic<bool>* cancel = nullptr, const TileCallback& on_tile = {});
  // Renders passes of doubling size up to params.spp (run_progressive without limits); `on_progress`
  // after each tile. True when it finished.
  bool render_all(const std::atomic<bool>* cancel = nullptr, const std::function<void()>& on_progress = {});

  // PassSource
  bool advance(int target_spp, const std::atomic<bool>* cancel, const TileCallback& on_tile) override {
    return render_pass(target_spp, cancel, on_tile);
  }
  void set_deadline(std::chrono::steady_clock::time_point t) override { m_deadline = t; }
  const Film& film() const override { return m_film; }
  double seconds() const override { return m_seconds; }
  // Estimated relative MSE of the image (Film::error_estimate), on the render threads.
  double error_estimate() const override { return m_film.error_estimate(m_params.threads); }
  bool finished() const override { return m_film.finished(); }
  // Each sample left weighted by its tile's time per sample in the last pass that reached it.
  Film::Work work() const override;
  double light_seconds() const override { return m_light_seconds; }  // since this object began
  RenderCounts counts() const override { return {m_samples.load(), m_rays.load(), m_nonfinite.load()}; }
  const std::vector<Tile>& tiles() const override { return m_tiles; }
  void save(BinaryWriter& out) const override;
  void restore(BinaryReader& in) override;

  const RenderParams& params() const { return m_params; }
  const RenderScene& scene() const { return m_scene; }
  int width() const { return m_film.width(); }
  int height() const { return m_film.height(); }
  // Fraction of the sample budget done (converged pixels count as complete); safe during a pass.
  double progress() const;
  ImageRGB image() const { return m_film.image(); }
  ImageRGB rate_image() const { return m_film.rate_image(); }
  SessionStats stats() const;

  // For one share of a distributed render: sample indices start at `first` (so disjoint ranges
  // merge into the single-machine image; the caustic light paths follow the same share) and pixels
  // whose `skip` byte is set are left out. Call before the first pass.
  void set_sample_range(uint32_t first, const std::vector<uint8_t>& skip);
  // True when every camera ray of frame pixel (fx, fy_up) (y up, as the course counts rows) misses
  // the scene, so that its samples are black without a ray query (background_mask.h).
  bool sees_only_background(int fx, int fy_up) const { return m_background.sees_only_background(fx, fy_up); }

 private:
  void order_tiles_by_cost();  // m_tile_order from m_tile_ns, ties in raster order
  void trace_caustics(int target_spp, const std::atomic<bool>* cancel);
  uint64_t light_paths_for(uint64_t samples) const;
  // session_tile.cpp: a tile's samples up to target_spp, in packets or path by path.
  void render_tile(const Tile& t, int target_spp, const std::atomic<bool>* cancel, uint64_t& rays,
                   uint64_t& samples, uint64_t& nonfinite);

  const RenderScene& m_scene;
  RenderParams m_params;
  int m_frame_x0, m_frame_y0;  // film origin inside the full frame, top-left
  // What the path loop reads of the options, and whether the session's light tracer renders the
  // caustic paths (caustics.h), which the loop then leaves out.
  PathSettings m_path;
  Film m_film;
  BackgroundMask m_background;  // pixels whose samples are black without a ray query
  uint32_t m_first_sample = 0;
  std::vector<Tile> m_tiles;
  // The order threads take tiles in: the costliest first (the last pass's time, at first the
  // pixels that see the scene), so that the pass does not end waiting on one thread's last big
  // tile (longest-processing-time-first; R. L. Graham, "Bounds on multiprocessing timing
  // anomalies", SIAM J. Appl. Math. 17, 1969). The image does not depend on the order.
  std::vector<uint32_t> m_tile_order;
  std::vector<uint64_t> m_tile_ns;  // each tile's render time in the last pass that reached it
  std::vector<uint64_t> m_tile_samples;  // and the samples it took there
  CausticFilm m_caustic_film;
  // Light paths traced so far. A pass cut short keeps the chunks done in order and traces the rest
  // when it resumes (m_lt_partial), so that a cancelled or checkpointed render ends on the same sums.
  uint64_t m_lt_issued = 0;
  bool m_lt_partial = false;
  std::atomic<uint64_t> m_samples{0}, m_rays{0}, m_nonfinite{0};
  std::atomic<uint64_t> m_budget_done{0};  // pixel-samples done, converged pixels counted in full
  std::atomic<uint64_t> m_cpu_ns{0};      // SessionStats::cpu_seconds
  double m_seconds = 0, m_light_seconds = 0;
  int m_passes = 0;
  std::chrono::steady_clock::time_point m_deadline = std::chrono::steady_clock::time_point::max();
  bool stop_requested(const std::atomic<bool>* cancel) const {
    return (cancel && cancel->load(std::memory_order_relaxed)) || std::chrono::steady_clock::now() >= m_deadline;
  }
};

// Renders one pass for a share of a distributed render (set_sample_range) and returns its sums.
// `skip` (one byte per pixel, may be empty) marks converged pixels; `cancel` stops early (the pass
// then holds what was done and comes back marked incomplete).
FilmPass render_film_pass(const RenderScene& scene, const RenderParams& params, uint32_t first, uint32_t count,
                          const std::vector<uint8_t>& skip, const std::atomic<bool>* cancel, bool* complete = nullptr);

}  // namespace pt
