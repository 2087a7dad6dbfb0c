// The progressive, cancellable session (tiles, passes, adaptive sampling, per-pixel statistics,
// error estimate). The outer loop belongs to the caller; the scene it renders comes from
// render_scene.cpp.
#include "render.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include <sys/mman.h>
#include <time.h>

#include "materials.h"
#include "sampler.h"

namespace pt {

namespace {
// This thread's CPU time in nanoseconds (CLOCK_THREAD_CPUTIME_ID): what it ran, not what it waited.
uint64_t thread_cpu_ns() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return uint64_t(t.tv_sec) * 1000000000u + uint64_t(t.tv_nsec);
}
// A zero-filled per-pixel array. A 1920x1080 session's come to about 95 MB, and faulting them in
// 4 KiB pages took about 65 ms of kernel time per session (perf stat: 24k page faults). Asked for
// transparent huge pages before the first touch, the kernel maps 2 MiB at a fault where it can
// (THP "madvise" or "always"); elsewhere the advice is ignored.
template <class T>
void assign_zeroed(std::vector<T>& v, size_t n, const T& zero) {
  v.reserve(n);
#ifdef MADV_HUGEPAGE
  constexpr uintptr_t kHuge = uintptr_t(2) << 20;
  const uintptr_t lo = (reinterpret_cast<uintptr_t>(v.data()) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t hi = (reinterpret_cast<uintptr_t>(v.data()) + n * sizeof(T)) & ~(kHuge - 1);
  if (hi >= lo + 2 * kHuge) madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_HUGEPAGE);
#endif
  v.assign(n, zero);
}

}  // namespace

RenderSession::RenderSession(const RenderScene& scene, const RenderParams& params) : m_scene(scene), m_params(params) {
  params.validate();
  if (params.cell_w > 0) {
    m_w = params.cell_w;
    m_h = params.cell_h;
    m_frame_x0 = params.cell_x;
    m_frame_y0 = params.height - (params.cell_y + params.cell_h);  // bottom-left origin -> top-left
  } else {
    m_w = params.width;
    m_h = params.height;
    m_frame_x0 = m_frame_y0 = 0;
  }
  size_t n = size_t(m_w) * m_h;
  assign_zeroed(m_sum, n, Vec3(0.0f));
  assign_zeroed(m_s1, n, 0.0);
  assign_zeroed(m_s2, n, 0.0);
  assign_zeroed(m_half_s1, n, 0.0);
  assign_zeroed(m_half_n, n, 0u);
  assign_zeroed(m_count, n, 0u);
  assign_zeroed(m_done, n, uint8_t(0));
  m_params.caustics_light_traced = caustic_tracing_applies(scene, params);
  if (m_params.caustics_light_traced) {
    m_caustic_film = {params.width, params.height, m_frame_x0, m_frame_y0, m_w, m_h};
    assign_zeroed(m_lt_sum, n, Vec3(0.0f));
    assign_zeroed(m_lt_s1, n, 0.0);
    assign_zeroed(m_lt_half_s1, n, 0.0);
  }
  int ts = params.tile_size;
  for (int y = 0; y < m_h; y += ts)
    for (int x = 0; x < m_w; x += ts) m_tiles.push_back({x, y, std::min(x + ts, m_w), std::min(y + ts, m_h)});
  find_scene_rectangle();
  // Before any pass, a tile's cost is its pixels that see the scene.
  m_tile_ns.assign(m_tiles.size(), 0);
  for (size_t t = 0; t < m_tiles.size(); ++t) {
    const Tile& tile = m_tiles[t];
    uint64_t seen = 0;
    for (int y = tile.y0; y < tile.y1; ++y) {
      if (m_background.empty()) {
        for (int x = tile.x0; x < tile.x1; ++x) seen += !background_pixel(size_t(y) * m_w + x, x, y);
        continue;
      }
      const uint8_t* row = m_background.data() + size_t(y) * m_w;
      for (int x = tile.x0; x < tile.x1; ++x) seen += row[x] == 0;
    }
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

// Where the scene's (padded) bounding box projects on the sensor of a camera in front of it. The
// box is convex and wholly in front, so every pinhole ray that can hit it passes inside the box
// spanned by its eight projected corners; a pixel wholly outside (with a pixel of margin) sees only
// background. Without an environment seen by the camera, background is exactly black and the
// path loop would stop at its first, missed query: the sample is black and counts one ray.
// A thin lens sees a point at depth z from lens point l at sensor position p/z - l (1/z - 1/f)
// (camera.cpp's ray through the focus point p f / z): the rectangle grows by the lens radius times
// the largest |1/z - 1/f| over the box, which a corner (the nearest or farthest) attains.
namespace {

// The frame-pixel rectangle (y up, unclipped, without margin) holding box [lo, hi] as the camera
// sees it, or false when a corner lies beside or behind the camera (no rectangle holds it).
bool project_box(const Camera& cam, int width, int height, Vec3 lo, Vec3 hi, float r[4]) {
  const bool lens = cam.lens_radius > 0;
  float u0 = kInf, u1 = -kInf, v0 = kInf, v1 = -kInf, blur = 0;
  for (int c = 0; c < 8; ++c) {
    Vec3 corner(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
    Vec3 v = corner - cam.position;
    float z = -dot(v, cam.back);
    if (!(z > 1e-3f * length(v))) return false;
    float u = (dot(v, cam.right) / (z * cam.tan_half_w) + 1) * 0.5f * float(width);
    float w = (dot(v, cam.up) / (z * cam.tan_half_h) + 1) * 0.5f * float(height);
    if (!std::isfinite(u) || !std::isfinite(w)) return false;
    u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, w), v1 = std::max(v1, w);
    if (lens) blur = std::max(blur, cam.lens_radius * std::fabs(1 / z - 1 / cam.focal_distance));
  }
  if (lens) {  // blur is in sensor units (tan); pixels per unit differ along x and y
    float bu = blur * 0.5f * float(width) / cam.tan_half_w, bv = blur * 0.5f * float(height) / cam.tan_half_h;
    if (!std::isfinite(bu) || !std::isfinite(bv)) return false;
    u0 -= bu, u1 += bu, v0 -= bv, v1 += bv;
  }
  r[0] = u0, r[1] = u1, r[2] = v0, r[3] = v1;
  return true;
}

}  // namespace

void RenderSession::find_scene_rectangle() {
  const Camera& cam = m_scene.camera;
  Vec3 lo, hi;
  if (!m_scene.accel || !m_scene.accel->hit_bounds(lo, hi)) return;
  if (!(cam.tan_half_w > 0) || !(cam.tan_half_h > 0)) return;
  if (cam.lens_radius > 0 && !(cam.focal_distance > 0 && std::isfinite(cam.focal_distance))) return;
  float r[4];
  if (!project_box(cam, m_params.width, m_params.height, lo, hi, r)) return;
  m_scene_u0 = r[0] - 1, m_scene_u1 = r[1] + 1, m_scene_v0 = r[2] - 1, m_scene_v1 = r[3] + 1;
  // The caustic light paths are counted on this area, clipped to the full frame (not to a crop or
  // cell window, so that windows trace the frame's paths): a box around a close camera projects far
  // past the frame, and light paths only splat inside it.
  auto clipped = [](float a, float b, float size) {
    return std::max(0.0, double(std::min(b, size)) - double(std::max(a, 0.0f)));
  };
  m_scene_pixels = clipped(m_scene_u0, m_scene_u1, float(m_params.width)) * clipped(m_scene_v0, m_scene_v1, float(m_params.height));
  m_background_rect = m_scene.environment_light < 0;
  if (!m_background_rect || size_t(m_w) * m_h > (size_t(1) << 24)) return;

  // Within the rectangle, the pixels no object's own rectangle reaches (the sky above an open
  // floor), for a bounded number of objects: the mask starts as "no object" and each object's
  // rectangle clears its rows' spans. Without that (no objects, too many, or one that does not
  // project), the rectangle alone decides.
  const auto& objects = m_scene.object_bounds;
  bool by_objects = !objects.empty() && objects.size() <= kMaxMaskedObjects;
  m_background.assign(size_t(m_w) * m_h, by_objects ? 1 : 0);
  for (size_t k = 0; k < objects.size() && by_objects; ++k) {
    const Bounds3& b = objects[k];
    if (!project_box(cam, m_params.width, m_params.height, b.lo, b.hi, r)) {
      by_objects = false;
      std::fill(m_background.begin(), m_background.end(), uint8_t(0));
      break;
    }
    // Film pixels whose frame pixel [fx, fx + 1] x [fy, fy + 1] meets the rectangle grown by a pixel.
    auto px = [](float v, int size) { return int(std::clamp(v, -4.0f, float(size) + 4)); };
    int fx0 = px(std::floor(r[0] - 2), m_params.width), fx1 = px(std::ceil(r[1] + 1), m_params.width);
    int fy0 = px(std::floor(r[2] - 2), m_params.height), fy1 = px(std::ceil(r[3] + 1), m_params.height);
    int x0 = std::max(fx0 - m_frame_x0, 0), x1 = std::min(fx1 - m_frame_x0, m_w - 1);
    if (x0 > x1) continue;
    for (int fy_up = std::max(fy0, 0); fy_up <= std::min(fy1, m_params.height - 1); ++fy_up) {
      int y = (m_params.height - 1 - fy_up) - m_frame_y0;
      if (y < 0 || y >= m_h) continue;
      uint8_t* row = m_background.data() + size_t(y) * m_w;
      std::fill(row + x0, row + x1 + 1, uint8_t(0));
    }
  }
  // Then the rectangle, which is a product of a column range and a row range.
  std::vector<uint8_t> column_outside(static_cast<size_t>(m_w));
  for (int x = 0; x < m_w; ++x) column_outside[size_t(x)] = outside_scene_columns(m_frame_x0 + x);
  for (int y = 0; y < m_h; ++y) {
    uint8_t* row = m_background.data() + size_t(y) * m_w;
    if (outside_scene_rows(m_params.height - 1 - (m_frame_y0 + y))) std::fill(row, row + m_w, uint8_t(1));
    else
      for (int x = 0; x < m_w; ++x) row[x] |= column_outside[size_t(x)];
  }
}

// Light paths per sample and pixel of the area where the scene's bounds project (find_scene_rectangle),
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
  const double scene = m_scene_pixels >= 0 ? m_scene_pixels : frame;
  const double per_sample = std::min(kMaxLightPathsPerSample * frame, kLightPathsPerScenePixel * scene);
  return uint64_t(std::ceil(per_sample * double(samples)));
}

void RenderSession::trace_caustics(int target, const std::atomic<bool>* cancel) {
  uint64_t want = light_paths_for(uint64_t(m_first_sample) + uint64_t(target));
  if (want <= m_lt_issued) return;
  if (m_lt_paths > 0 && m_lt_paths >= 2 * m_lt_half_paths) {  // the error estimate's halves
    m_lt_half_s1 = m_lt_s1;
    m_lt_half_paths = m_lt_paths;
  }
  // Chunks of paths run on the threads in waves; each wave's splats are merged in path order before
  // the next, which bounds the memory they take whatever the pass's size.
  constexpr uint64_t kChunk = 1024, kWave = 64;
  const uint64_t first = m_lt_issued, count = want - first;
  m_lt_issued = want;  // paths of a cancelled chunk are skipped, not retried: they stay independent
  const uint64_t chunks = (count + kChunk - 1) / kChunk;
  std::vector<std::vector<CausticSplat>> splats(size_t(std::min(chunks, kWave)));
  std::vector<uint8_t> finished(splats.size());
  for (uint64_t wave = 0; wave < chunks && !stop_requested(cancel); wave += kWave) {
    const size_t in_wave = size_t(std::min(kWave, chunks - wave));
    for (auto& s : splats) s.clear();
    std::fill(finished.begin(), finished.end(), 0);
    std::atomic<size_t> next{0};
    auto worker = [&]() {
      const uint64_t cpu_start = thread_cpu_ns();
      uint64_t rays = 0;
      for (size_t c; (c = next.fetch_add(1)) < in_wave && !stop_requested(cancel);) {
        uint64_t b = first + (wave + c) * kChunk, e = std::min(first + count, b + kChunk);
        trace_caustic_paths(m_scene, m_params, m_caustic_film, b, e - b, splats[c], rays);
        finished[c] = 1;
      }
      m_rays += rays;
      m_cpu_ns += thread_cpu_ns() - cpu_start;
    };
    int nthreads = std::max(1, std::min<int>(m_params.threads, int(in_wave)));
    std::vector<std::thread> pool;
    for (int i = 1; i < nthreads; ++i) pool.emplace_back(worker);
    worker();
    for (auto& t : pool) t.join();
    for (size_t c = 0; c < in_wave; ++c) {
      if (!finished[c]) continue;
      for (const CausticSplat& s : splats[c]) {
        m_lt_sum[s.pixel] += s.value;
        m_lt_s1[s.pixel] += luminance(s.value);
      }
      m_lt_paths += std::min(kChunk, count - (wave + c) * kChunk);
    }
  }
}

bool RenderSession::render_pass(int target_spp, const std::atomic<bool>* cancel, const TileCallback& on_tile) {
  target_spp = std::min(target_spp, m_params.spp);
  auto start = std::chrono::steady_clock::now();
  m_estimate.invalidate();
  if (m_params.caustics_light_traced) trace_caustics(target_spp, cancel);
  std::atomic<size_t> next{0};
  auto worker = [&]() {
    const uint64_t cpu_start = thread_cpu_ns();
    uint64_t rays = 0, samples = 0, nonfinite = 0;
    for (;;) {
      const size_t k = next.fetch_add(1);
      if (k >= m_tile_order.size()) break;
      if (stop_requested(cancel)) break;
      const uint32_t ti = m_tile_order[k];
      const auto t0 = std::chrono::steady_clock::now();
      render_tile(m_tiles[ti], target_spp, cancel, rays, samples, nonfinite);
      m_tile_ns[ti] = uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0).count());
      if (on_tile && !stop_requested(cancel)) on_tile(m_tiles[ti]);
    }
    m_rays += rays;
    m_samples += samples;
    m_nonfinite += nonfinite;
    m_cpu_ns += thread_cpu_ns() - cpu_start;
  };
  int nthreads = std::max(1, std::min<int>(m_params.threads, int(m_tiles.size())));
  std::vector<std::thread> pool;
  for (int i = 1; i < nthreads; ++i) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  order_tiles_by_cost();
  m_estimate.invalidate();  // also for an estimate someone asked for while the pass ran
  m_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ++m_passes;
  return !stop_requested(cancel);
}

bool RenderSession::render_all(const std::atomic<bool>* cancel, const std::function<void()>& on_progress) {
  TileCallback tiles = on_progress ? TileCallback([&](const Tile&) { on_progress(); }) : TileCallback();
  return run_progressive(*this, RunLimits(), cancel, tiles) == StopReason::finished;
}

const char* stop_reason_name(StopReason r) {
  switch (r) {
    case StopReason::finished: return "finished";
    case StopReason::target_error: return "error target reached";
    case StopReason::time_limit: return "time limit reached";
    case StopReason::cancelled: return "cancelled";
  }
  return "?";
}

double remaining_seconds(double elapsed, double progress, double error, double error_seconds, const RunLimits& limits) {
  double eta = progress > 0 ? elapsed * (1 - progress) / progress : -1;
  auto sooner = [&eta](double t) { eta = eta < 0 ? t : std::min(eta, t); };
  if (limits.target_error > 0 && std::isfinite(error) && error > 0)
    sooner(std::max(0.0, error_seconds * error / limits.target_error - elapsed));
  if (limits.time_limit > 0) sooner(std::max(0.0, limits.time_limit - elapsed));
  return eta;
}

int next_pass_target(int target, int spp, double error, double target_error) {
  int next = std::min(spp, target * 2);
  if (target_error > 0 && std::isfinite(error) && error > target_error) {
    // error ~ 1/spp: the count where it meets the target, 5% past it so that noise in the estimate
    // rarely needs one more pass, and at least a quarter more than now so that passes stay few.
    const double needed = std::ceil(double(target) * (error / target_error) * 1.05);
    const double least = double(target) + std::max(1.0, std::floor(target / 4.0));
    if (needed < double(next)) next = int(std::max(needed, least));
  }
  return std::min(next, spp);
}

StopReason run_progressive(RenderSession& s, const RunLimits& limits, const std::atomic<bool>* cancel,
                           const RenderSession::TileCallback& on_tile,
                           const std::function<void(const PassReport&)>& on_pass) {
  auto start = std::chrono::steady_clock::now();
  if (limits.time_limit > 0)
    s.set_deadline(start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                               std::chrono::duration<double>(limits.time_limit)));
  const int spp = s.params().spp;
  StopReason reason = StopReason::finished;
  for (int target = 1;;) {
    bool completed = s.render_pass(target, cancel, on_tile);
    double err = s.error_estimate();
    if (on_pass) on_pass({target, s.stats().seconds, err});
    if (!completed) {
      reason = (cancel && cancel->load()) ? StopReason::cancelled : StopReason::time_limit;
      break;
    }
    if (limits.target_error > 0 && err <= limits.target_error) {
      reason = StopReason::target_error;
      break;
    }
    if (s.finished() || target >= spp) break;
    target = next_pass_target(target, spp, err, limits.target_error);
  }
  s.set_deadline(std::chrono::steady_clock::time_point::max());
  return reason;
}

bool RenderSession::finished() const {
  for (uint8_t d : m_done)
    if (!d) return false;
  return true;
}

double RenderSession::progress() const {
  double total = double(m_params.spp) * m_w * m_h;
  return total > 0 ? std::min(1.0, double(m_budget_done.load()) / total) : 1.0;
}

void RenderSession::read_tile(const Tile& t, std::vector<Vec3>& out) const {
  out.clear();
  for (int y = t.y0; y < t.y1; ++y)
    for (int x = t.x0; x < t.x1; ++x) {
      out.push_back(pixel_mean(size_t(y) * m_w + x));
    }
}

Vec3 RenderSession::pixel_mean(size_t i) const {
  return pixel_estimate(m_sum[i], m_count[i], m_lt_sum, m_lt_paths, i);
}

void RenderSession::set_sample_range(uint32_t first, const std::vector<uint8_t>& skip) {
  m_first_sample = first;
  if (m_params.caustics_light_traced) m_lt_issued = light_paths_for(first);
  for (size_t i = 0; i < skip.size() && i < m_done.size(); ++i) m_done[i] |= skip[i];
}

float autofocus_distance(const RenderScene& scene, float sx, float sy) {
  Ray r = scene.camera.pinhole_ray(sx, sy);
  SurfaceHit hit;
  return scene.accel->intersect(r, hit) ? hit.t : kInf;
}

ImageRGB RenderSession::image() const {
  return make_image(m_w, m_h, [this](size_t i) { return pixel_mean(i); });
}

ImageRGB RenderSession::caustic_image() const {
  if (m_lt_paths == 0) return make_image(m_w, m_h, [](size_t) { return Vec3(0.0f); });
  return make_image(m_w, m_h, [this](size_t i) { return m_lt_sum[i] / float(m_lt_paths); });
}

// Course colouring: 0 = blue, 0.5 = green, 1 = red, by samples taken / spp.
static Vec3 rate_colour(uint32_t count, int spp) {
  float r = float(count) / float(spp);
  return r <= 0.5f ? Vec3(0, 2 * r, 1 - 2 * r) : Vec3(2 * r - 1, 2 - 2 * r, 0);
}

ImageRGB RenderSession::rate_image() const {
  return make_image(m_w, m_h, [this](size_t i) { return rate_colour(m_count[i], m_params.spp); });
}

void RenderSession::read_tile_rate(const Tile& t, std::vector<Vec3>& out) const {
  out.clear();
  for (int y = t.y0; y < t.y1; ++y)
    for (int x = t.x0; x < t.x1; ++x) out.push_back(rate_colour(m_count[size_t(y) * m_w + x], m_params.spp));
}

namespace {

// A 3x3 neighbourhood's level, from its nine pixel means: the median, and the mean of the eight
// below the largest (one firefly cannot lift it). The median by the 19 compare-exchanges of the
// classic median-of-9 network (Paeth, Graphics Gems, 1990), branch-free.
struct NeighbourhoodLevel {
  double median, trimmed_mean;
};
inline NeighbourhoodLevel neighbourhood_level(const double in[9]) {
  double v[9], sum = 0, top = in[0];
#pragma GCC unroll 9
  for (int k = 0; k < 9; ++k) v[k] = in[k], sum += in[k], top = std::max(top, in[k]);
  auto sort2 = [&](int i, int j) {
    double lo = std::min(v[i], v[j]), hi = std::max(v[i], v[j]);
    v[i] = lo, v[j] = hi;
  };
  sort2(1, 2), sort2(4, 5), sort2(7, 8), sort2(0, 1), sort2(3, 4), sort2(6, 7), sort2(1, 2), sort2(4, 5);
  sort2(7, 8), sort2(0, 3), sort2(5, 8), sort2(4, 7), sort2(3, 6), sort2(1, 4), sort2(2, 5), sort2(4, 7);
  sort2(4, 2), sort2(6, 4), sort2(4, 2);
  return {v[4], (sum - top) / 8};
}

}  // namespace

double halves_error_estimate(int width, const std::vector<uint32_t>& count, const std::vector<uint32_t>& half_n,
                             const std::vector<double>& s1, const std::vector<double>& half_s1,
                             const SplatStats& splats, int threads) {
  // Relative MSE of the pixel means: mean over pixels of Var[mean] / (mu^2 + eps) (relMSE as in
  // Rousselle et al. 2011, eps keeping black pixels finite). Var[mean] comes from comparing the
  // mean A of samples [0, P) with the mean B of [P, n):
  // E[(A - B)^2] P (n - P) / n^2 = sigma^2 / n for independent samples, and unlike the sample
  // variance it also sees the faster convergence of stratified (Sobol) samples, each half of
  // which is itself well stratified.
  // mu stands for the pixel's true mean, which the true relMSE divides by. The pixel's own mean is
  // a poor stand-in both ways (docs/performance.md, "Error estimate"):
  // - above its neighbourhood, a mean lifted by one half's rare bright sample divides its own
  //   error away (CBspheres at m = 100 fell to 0.6 of the truth): mu is at most the larger of the
  //   neighbourhood's median and the smaller half's mean;
  // - a small, noisy mean of few samples inflates the ratio (E[1/mu^2] > 1/E[mu]^2: CBdragon 7x
  //   the truth at 2 spp): mu is lifted towards the neighbourhood's level, its mean without its
  //   largest value, but no further than one standard error above the pixel's own mean, so a
  //   pixel that is surely darker than its neighbours (an edge) keeps its own mean, and the lift
  //   fades as samples accumulate.
  // It runs between passes, in blocks of rows on the render's threads; each block keeps its rows'
  // means (and the rows on either side) in a buffer, and the blocks' sums are added in block order,
  // so the estimate does not depend on the thread count.
  const size_t n_pixels = count.size();
  const bool with_splats = splats.n > 0;
  const double splat_n = double(splats.n);
  auto mean_at = [&](size_t i) {
    double m = count[i] ? s1[i] / count[i] : 0.0;
    if (with_splats) m += (*splats.s1)[i] / splat_n;
    return m;
  };
  // A film that is not width x rows (none is, but the caller passes width and pixels apart) is
  // read as one row.
  size_t w = size_t(std::max(1, width)), h = n_pixels / w;
  if (w * h != n_pixels) w = std::max<size_t>(1, n_pixels), h = n_pixels ? 1 : 0;
  auto block = [&](size_t y0, size_t y1, double& block_sum, size_t& block_used) {
    double sum = 0;
    size_t used = 0;
    const size_t r0 = y0 > 0 ? y0 - 1 : 0, r1 = std::min(h, y1 + 1);  // rows kept: y0 - 1 .. y1
    std::vector<double> means((r1 - r0) * w);
    for (size_t y = r0; y < r1; ++y)
      for (size_t x = 0; x < w; ++x) means[(y - r0) * w + x] = mean_at(y * w + x);
    for (size_t y = y0; y < y1; ++y) {
      const double* rows[3] = {&means[((y > 0 ? y - 1 : y) - r0) * w], &means[(y - r0) * w],
                               &means[((y + 1 < h ? y + 1 : y) - r0) * w]};  // edges repeat
      for (size_t x = 0; x < w; ++x) {
        const size_t i = y * w + x;
        uint32_t n = count[i], p = half_n[i];
        if (n < 2 || p == 0 || p >= n) continue;
        ++used;
        if (s1[i] == 0 && half_s1[i] == 0 && !with_splats) continue;  // a black pixel adds exactly 0
        double a = half_s1[i] / p, b = (s1[i] - half_s1[i]) / (n - p);
        double var_mean = (a - b) * (a - b) * double(p) * double(n - p) / (double(n) * n);
        if (with_splats) {
          double sp = double(splats.half_n), t1 = (*splats.s1)[i];
          if (sp > 0 && sp < splat_n) {
            double sa = (*splats.half_s1)[i] / sp, sb = (t1 - (*splats.half_s1)[i]) / (splat_n - sp);
            var_mean += (sa - sb) * (sa - sb) * sp * (splat_n - sp) / (splat_n * splat_n);
          }
        }
        const size_t xl = x > 0 ? x - 1 : x, xr = x + 1 < w ? x + 1 : x;
        const double v[9] = {rows[0][xl], rows[0][x], rows[0][xr], rows[1][xl], rows[1][x],
                             rows[1][xr], rows[2][xl], rows[2][x], rows[2][xr]};
        const double own = v[4];
        const NeighbourhoodLevel level = neighbourhood_level(v);
        double mu = std::min(own, std::max(level.median, std::min(a, b)));
        mu = std::max(mu, std::min(level.trimmed_mean, own + std::sqrt(var_mean)));
        sum += var_mean / (mu * mu + kRelMseEpsilon);
      }
    }
    block_sum = sum, block_used = used;
  };
  const size_t rows_per_block = std::max<size_t>(1, (size_t(1) << 14) / w);  // starting a thread costs about what a few thousand pixels do
  const size_t blocks = (h + rows_per_block - 1) / rows_per_block;
  std::vector<double> sums(blocks, 0.0);
  std::vector<size_t> useds(blocks, 0);
  std::atomic<size_t> next{0};
  auto worker = [&] {
    for (size_t b; (b = next.fetch_add(1)) < blocks;)
      block(b * rows_per_block, std::min(h, (b + 1) * rows_per_block), sums[b], useds[b]);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::min<int>(threads, int(blocks)); ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  double sum = 0;
  size_t used = 0;
  for (size_t b = 0; b < blocks; ++b) sum += sums[b], used += useds[b];
  return used ? sum / double(n_pixels) : INFINITY;
}

std::string format_error_estimate(double error) {
  if (!std::isfinite(error)) return "n/a";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", error);
  return buf;
}

double RenderSession::error_estimate() const {
  // P, the first half's size, is the last power of two below n.
  return m_estimate.get([this] {
    return halves_error_estimate(m_w, m_count, m_half_n, m_s1, m_half_s1,
                                 {&m_lt_s1, &m_lt_half_s1, m_lt_paths, m_lt_half_paths}, m_params.threads);
  });
}

SessionStats RenderSession::stats() const {
  SessionStats s;
  s.samples = m_samples.load();
  s.rays = m_rays.load();
  s.nonfinite = m_nonfinite.load();
  s.light_paths = m_lt_paths;
  s.seconds = m_seconds;
  s.cpu_seconds = double(m_cpu_ns.load()) * 1e-9;
  s.passes = m_passes;
  return s;
}

}  // namespace pt
