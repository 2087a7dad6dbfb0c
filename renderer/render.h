// RenderParams (the one source of render options), the render scene built from a SceneDesc, and
// the progressive, cancellable render session that the CLI, the server and the window share.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "accel.h"
#include "camera.h"
#include "caustics.h"
#include "image.h"
#include "lights.h"
#include "sampler.h"
#include "scene.h"

namespace pt {

struct RenderParams {
  int spp = 1;                     // -s: camera rays per pixel
  int light_samples = 1;           // -l: samples per area / environment / ambient light
  int max_depth = 1;               // -m: maximum ray depth (bounces; each specular event uses one)
  int threads = 1;                 // -t
  float lens_radius = 0;           // -b (the course calls it aperture)
  float focal_distance = 4.7f;     // -d
  int width = 800, height = 600;   // -r
  bool adaptive = true;            // -a: on by default, as in the course
  int adaptive_batch = 32;
  float adaptive_tolerance = 0.05f;
  bool hemisphere = false;         // -H: uniform hemisphere direct lighting
  std::string env_map;             // -e: lat-long OpenEXR environment
  std::string camera_file;         // -c
  bool file_camera = false;        // --file-camera: the scene's camera as authored
  bool keep_fov = false;           // --keep-fov: -r scales the course's view instead of cropping it
  int cell_x = 0, cell_y = 0, cell_w = 0, cell_h = 0;  // -p: window, bottom-left origin; w = 0: full frame
  uint64_t seed = 0;               // --seed
  int tile_size = 32;
  bool generic = false;            // --generic: the path loop with every feature (for comparisons)
  bool ray_packets = true;         // --no-ray-packets: trace paths one at a time, not in Embree packets
  bool simd_lanes = true;          // --no-simd-lanes: packets' diffuse vertices and sample draws one at a time
  SamplerKind sampler = SamplerKind::sobol;  // --sampler: sobol (Owen-scrambled) or independent
  bool caustic_tracing = true;     // --no-caustic-tracing: caustics by light tracing where it applies
  // Set by RenderSession, not by users: its light tracer renders the caustic paths (caustics.h),
  // so the path loop leaves them out.
  bool caustics_light_traced = false;

  // Throws std::invalid_argument naming the field when a value is out of range.
  void validate() const;
};

// Feature bits the path loop is specialised on: a scene pays only for what it has.
enum FeatureBits : uint32_t {
  kFeatDelta = 1,        // mirror, glass or refraction materials
  kFeatMicrofacet = 2,   // microfacet materials
  kFeatInfinite = 4,     // ambient or environment lights (escaping rays look them up)
  kFeatAll = 7,
};

struct SceneFeatures {
  std::vector<std::string> materials, lights;
  bool spheres = false, meshes = false, environment = false, thin_lens = false;
  bool adaptive = false, shading_normals = false;
  bool caustic_tracing = false;  // caustics by light tracing (caustics.h)
  uint32_t bits = kFeatAll;  // which specialised path loop runs
};

// The view-independent part of a render scene: built once per scene file and shared read-only by
// every view of it (the server keeps one per file content). It keeps no vertex arrays of the file:
// only the BVH and what a view needs (the file's camera and the geometry bounds).
struct SceneBase {
  std::vector<Material> materials;  // the file's, then one emission material per area-light panel
  std::vector<Light> lights;        // without the environment map (that is a render option)
  std::shared_ptr<const Accel> accel;
  SceneFeatures features;           // what the file contains; a view adds the options' features
  size_t triangle_count = 0, sphere_count = 0;
  CameraDesc camera;                // what make_camera reads of the file
  Bounds3 bounds;
  std::vector<CausticTarget> caustic_targets;  // bounds of the delta-material geometry
  std::vector<Bounds3> object_bounds;  // each mesh, sphere and light panel, padded as Accel pads its bounds
  std::string source;

  // Bytes held for rendering: BVH and geometry (Accel::memory_bytes), lights, materials.
  size_t memory_bytes() const;
};

struct RenderScene {
  std::vector<Material> materials;
  std::vector<Light> lights;
  std::vector<int> infinite_lights;  // ambient / environment, looked up when rays escape
  int environment_light = -1;        // visible to camera rays
  std::shared_ptr<const EnvironmentMap> environment;
  std::shared_ptr<const Accel> accel;  // shared with the SceneBase and its other views
  Camera camera;
  SceneFeatures features;
  size_t triangle_count = 0, sphere_count = 0;
  // What the caustic light tracer samples: delta geometry to aim at, area and mesh lights by power.
  std::vector<CausticTarget> caustic_targets;
  std::vector<Bounds3> object_bounds;  // from SceneBase: what the background mask projects
  std::vector<int> caustic_lights;
  Distribution1D caustic_light_distribution;
};

// Builds what the integrator needs from the file's description: lights (area lights also as
// visible panels, emissive meshes as mesh lights), the environment map, the camera, the BVH.
// The same as make_view(make_scene_base(desc), params).
std::unique_ptr<RenderScene> make_render_scene(const SceneDesc& desc, const RenderParams& params);
// The expensive, options-independent part: lights, materials, the BVH, the feature analysis.
SceneBase make_scene_base(const SceneDesc& desc);
// One view of a shared base for a set of options: the camera, the environment map, the options'
// features. Cheap (copies materials and lights); the view shares the base's BVH.
std::unique_ptr<RenderScene> make_view(const SceneBase& base, const RenderParams& params);
// The camera part of the render options (what make_render_scene passes to make_camera).
CameraParams camera_params(const RenderParams& params);

// Distance along the pinhole ray through sensor point (sx, sy) (y up) to the first surface, or
// infinity: what autofocus sets the focal distance to, as in the course.
float autofocus_distance(const RenderScene& scene, float sx, float sy);

// One camera path's radiance (integrator.cpp), by the generic loop. `rays` counts every ray cast.
Vec3 trace_path(const RenderScene& scene, const RenderParams& params, Ray ray, class Sampler& rng, uint64_t& rays);
// The path loop specialised for a set of feature bits (one instantiation per combination).
using PathTracer = Vec3 (*)(const RenderScene&, const RenderParams&, Ray, class Sampler&, uint64_t&);
PathTracer path_tracer_for(uint32_t feature_bits);
// The same paths, many at once: traces camera_rays[0, n) with samplers rngs[0, n) (each already
// past its pixel and lens draws) and writes each path's radiance to out[i]. Rays go to Embree in
// packets (Accel::intersect_many). nullptr where the scalar loop must run (-H).
using PathBatchTracer = void (*)(const RenderScene&, const RenderParams&, const Ray* camera_rays, class Sampler* rngs,
                                 size_t n, Vec3* out, uint64_t& rays);
PathBatchTracer path_batch_tracer_for(uint32_t feature_bits, const RenderParams& params);
// Whether the batched loop takes its diffuse vertices four at a time in SSE2 lanes
// (diffuse_lanes.h): packets, every light an area light (rectangle or mesh), and not --no-simd-lanes.
bool diffuse_lanes_apply(const RenderScene& scene, const RenderParams& params);
// Whether packets take their Sobol draws eight at a time (Sampler::next_2d_many / sobol_draws):
// the Sobol sampler, lanes not turned off, and a CPU with AVX2.
bool sobol_draws_in_lanes(const RenderParams& params);

// The course's adaptive-sampling test for one pixel with n > 1 luminance samples of sum s1 and
// sum of squares s2: the 95% confidence half-width is within tolerance x mean. Shared by the
// session and the scale-out's merged film.
inline bool confidence_reached(double s1, double s2, uint32_t n, double tolerance) {
  double mu = s1 / n;
  double var = std::max(0.0, (s2 - s1 * s1 / n) / (n - 1));
  return 1.96 * std::sqrt(var / n) <= tolerance * mu;
}

// The error estimate both the session and the scale-out's merged film report: from per-pixel
// sample counts n, luminance sums s1, and the count and sum of a first part of each pixel's samples,
// on a film `width` pixels wide (row-major).
// Light-traced splats (caustics.h) add their own variance, estimated the same way from the
// per-pixel splat luminance sums of n light paths and of the first half_n of them.
struct SplatStats {
  const std::vector<double>* s1 = nullptr;
  const std::vector<double>* half_s1 = nullptr;
  uint64_t n = 0, half_n = 0;
};
// An error estimate as the CLI's summary and the window show it: "%.3g", or "n/a" while it is
// infinite (before any pixel has two samples). The CSV log keeps "inf", which parsers read.
std::string format_error_estimate(double error);

double halves_error_estimate(int width, const std::vector<uint32_t>& count, const std::vector<uint32_t>& half_n,
                             const std::vector<double>& s1, const std::vector<double>& half_s1,
                             const SplatStats& splats = {}, int threads = 1);

// The last error estimate of statistics that have not changed since. A render's callers ask
// again after its last pass (the CLI's summary line and EXR header, the job's final report), and
// each estimate reads every pixel's statistics and its neighbours'. Whoever changes the
// statistics calls invalidate(); get() is safe from several threads at once.
class CachedEstimate {
 public:
  CachedEstimate() = default;
  // A copy starts empty (its owner's statistics are copied beside it; the next get() computes).
  CachedEstimate(const CachedEstimate&) {}
  CachedEstimate& operator=(const CachedEstimate&) {
    invalidate();
    return *this;
  }
  void invalidate() {
    std::lock_guard<std::mutex> lock(m_mutex);
    m_valid = false;
  }
  template <class Compute>
  double get(Compute compute) const {
    std::lock_guard<std::mutex> lock(m_mutex);
    if (!m_valid) {
      m_value = compute();
      m_valid = true;
      ++m_computed;
    }
    return m_value;
  }
  uint64_t times_computed() const {  // for tests: each estimate is paid once
    std::lock_guard<std::mutex> lock(m_mutex);
    return m_computed;
  }

 private:
  mutable std::mutex m_mutex;
  mutable bool m_valid = false;
  mutable double m_value = 0;
  mutable uint64_t m_computed = 0;
};

// A pixel's radiance: the mean of its camera samples plus, where caustics are light traced, its
// splat sum over every light path traced (caustics.h). The session and the merged film both use it.
inline Vec3 pixel_estimate(Vec3 sum, uint32_t count, const std::vector<Vec3>& splat_sums, uint64_t light_paths,
                           size_t i) {
  Vec3 v = count ? sum / float(count) : Vec3(0.0f);
  if (light_paths > 0) v += splat_sums[i] / float(light_paths);
  return v;
}

struct Tile {
  int x0, y0, x1, y1;  // film pixels, top-left origin, half-open
};

struct SessionStats {
  uint64_t samples = 0, rays = 0, nonfinite = 0;
  uint64_t light_paths = 0;  // caustic light paths traced (caustics.h)
  double seconds = 0;
  // CPU time the render threads spent in passes, summed over threads: against threads x seconds it
  // tells a slow host (threads that waited for a core) from a slow render (bench_scaling).
  double cpu_seconds = 0;
  int passes = 0;
};

class RenderSession {
 public:
  RenderSession(const RenderScene& scene, const RenderParams& params);

  // Advances every unfinished pixel to `target_spp` samples (adaptive pixels may stop early).
  // `on_tile` runs on worker threads after each finished tile. Returns false if cancelled.
  using TileCallback = std::function<void(const Tile&)>;
  bool render_pass(int target_spp, const std::atomic<bool>* cancel = nullptr, const TileCallback& on_tile = {});
  // Passes also stop (as if cancelled) once this steady-clock time has passed.
  void set_deadline(std::chrono::steady_clock::time_point t) { m_deadline = t; }
  // Renders passes of doubling size up to params.spp; `on_pass` after each pass.
  bool render_all(const std::atomic<bool>* cancel = nullptr, const std::function<void()>& on_progress = {});

  const RenderParams& params() const { return m_params; }
  const RenderScene& scene() const { return m_scene; }
  int width() const { return m_w; }
  int height() const { return m_h; }
  bool finished() const;
  // Fraction of the sample budget done (converged pixels count as complete).
  double progress() const;
  ImageRGB image() const;        // mean radiance per pixel
  ImageRGB rate_image() const;   // the course's sample-rate colouring
  // The light-traced caustics alone (caustics.h), part of image(); black when they are path traced.
  ImageRGB caustic_image() const;
  // Estimated relative MSE of the image, without a reference (see render.cpp); infinite until
  // some pixel has two samples to compare. Computed once for the statistics of each pass.
  double error_estimate() const;
  uint64_t error_estimates_computed() const { return m_estimate.times_computed(); }
  SessionStats stats() const;
  const std::vector<Tile>& tiles() const { return m_tiles; }
  // Mean radiance of a tile's pixels, row by row. Safe inside on_tile for that tile (its worker
  // has finished it for this pass) and whenever no pass is running.
  void read_tile(const Tile& t, std::vector<Vec3>& out) const;
  // The rate image's colours for a tile's pixels, row by row; safe where read_tile is.
  void read_tile_rate(const Tile& t, std::vector<Vec3>& out) const;

  // For one share of a distributed render: sample indices start at `first` (so disjoint ranges
  // merge into the single-machine image; the caustic light paths follow the same share) and pixels
  // whose `skip` byte is set are left out. Call before the first pass.
  void set_sample_range(uint32_t first, const std::vector<uint8_t>& skip);
  // Per-pixel sums of what was rendered: radiance, luminance squared, and sample counts.
  const std::vector<Vec3>& pixel_sums() const { return m_sum; }
  const std::vector<double>& pixel_lum2_sums() const { return m_s2; }
  const std::vector<uint32_t>& pixel_counts() const { return m_count; }
  // Light-traced caustic splat sums per pixel (empty when caustics are path traced) over
  // stats().light_paths light paths.
  const std::vector<Vec3>& caustic_sums() const { return m_lt_sum; }
  // True when every camera ray of frame pixel (fx, fy_up) (y up, as the course counts rows) misses
  // the scene, so that its samples are black without a ray query (see find_scene_rectangle).
  bool sees_only_background(int fx, int fy_up) const {
    if (!m_background_rect) return false;
    int x = fx - m_frame_x0, y = (m_params.height - 1 - fy_up) - m_frame_y0;
    if (!m_background.empty() && x >= 0 && y >= 0 && x < m_w && y < m_h) return m_background[size_t(y) * m_w + x];
    return outside_scene_rectangle(fx, fy_up);
  }
  // Objects whose own projected rectangles refine the scene's (find_scene_rectangle).
  static constexpr size_t kMaxMaskedObjects = 256;

 private:
  void find_scene_rectangle();
  void order_tiles_by_cost();  // m_tile_order from m_tile_ns, ties in raster order
  bool outside_scene_rectangle(int fx, int fy_up) const { return outside_scene_columns(fx) || outside_scene_rows(fy_up); }
  bool outside_scene_columns(int fx) const { return fx + 1 < m_scene_u0 || fx > m_scene_u1; }
  bool outside_scene_rows(int fy_up) const { return fy_up + 1 < m_scene_v0 || fy_up > m_scene_v1; }
  // sees_only_background for film pixel i = y m_w + x, from the mask where there is one (the tile
  // loops ask once per pixel and pass).
  bool background_pixel(size_t i, int x, int y) const {
    if (!m_background.empty()) return m_background[i] != 0;
    return sees_only_background(m_frame_x0 + x, m_params.height - 1 - (m_frame_y0 + y));
  }
  void trace_caustics(int target_spp, const std::atomic<bool>* cancel);
  uint64_t light_paths_for(uint64_t samples) const;
  Vec3 pixel_mean(size_t i) const;
  // render_tile.cpp: a tile's samples up to target_spp, path by path or in packets.
  void render_tile(const Tile& t, int target_spp, const std::atomic<bool>* cancel, uint64_t& rays,
                   uint64_t& samples, uint64_t& nonfinite);
  void render_tile_batched(const Tile& t, int target_spp, const std::atomic<bool>* cancel, uint64_t& rays,
                           uint64_t& samples, uint64_t& nonfinite, PathBatchTracer trace);
  // Adds sample s of pixel i; true when the course's adaptive test stops the pixel there.
  bool add_sample(size_t i, uint32_t s, Vec3 l, uint64_t& samples, uint64_t& nonfinite);
  uint32_t add_zero_samples(size_t i, uint32_t from, uint32_t to, bool& stopped);
  // The pixel sample's point on the sensor (its jitter draw), and its camera ray (+ the lens draw).
  Vec2 sensor_sample(int fx, int fy_up, Sampler& rng) const;
  void camera_ray(int fx, int fy_up, Sampler& rng, Ray& r) const;

  const RenderScene& m_scene;
  RenderParams m_params;
  int m_w, m_h;            // film size (the cell for -p)
  int m_frame_x0, m_frame_y0;  // film origin inside the full frame, top-left
  // Pixels whose every camera ray misses the scene (frame pixel coordinates, y up): outside this
  // rectangle a sample is black and costs no ray query. Off (empty) for a visible environment.
  bool m_background_rect = false;
  float m_scene_u0 = 0, m_scene_u1 = 0, m_scene_v0 = 0, m_scene_v1 = 0;
  double m_scene_pixels = -1;  // the projected bounds' area within the full frame (-1: unknown)
  // Film pixels that see only background: outside the rectangle, or inside it where no object's
  // own rectangle reaches. Empty without a rectangle, or for films over 2^24 pixels (the
  // rectangle alone decides there).
  std::vector<uint8_t> m_background;
  uint32_t m_first_sample = 0;
  std::vector<Tile> m_tiles;
  // The order threads take tiles in: the costliest first (the last pass's time, at first the
  // pixels that see the scene), so that the pass does not end waiting on one thread's last big
  // tile (longest-processing-time-first; R. L. Graham, "Bounds on multiprocessing timing
  // anomalies", SIAM J. Appl. Math. 17, 1969). The image does not depend on the order.
  std::vector<uint32_t> m_tile_order;
  std::vector<uint64_t> m_tile_ns;  // each tile's render time in the last pass that reached it
  std::vector<Vec3> m_sum;
  std::vector<double> m_s1, m_s2;   // luminance sums for adaptive sampling (the course's test)
  // The luminance sum at the last power-of-two sample count P below the current count n: the
  // error estimate compares the mean of samples [0, P) with that of [P, n).
  std::vector<double> m_half_s1;
  std::vector<uint32_t> m_half_n;
  std::vector<uint32_t> m_count;
  std::vector<uint8_t> m_done;
  // Caustics by light tracing (caustics.h): per-pixel splat sums over m_lt_paths light paths, their
  // luminance, and the luminance sums at the last halving (as m_half_s1 for camera samples).
  CausticFilm m_caustic_film;
  std::vector<Vec3> m_lt_sum;
  std::vector<double> m_lt_s1, m_lt_half_s1;
  uint64_t m_lt_paths = 0, m_lt_half_paths = 0, m_lt_issued = 0;
  std::atomic<uint64_t> m_samples{0}, m_rays{0}, m_nonfinite{0};
  std::atomic<uint64_t> m_budget_done{0};  // pixel-samples done, converged pixels counted in full
  std::atomic<uint64_t> m_cpu_ns{0};      // SessionStats::cpu_seconds
  double m_seconds = 0;
  int m_passes = 0;
  CachedEstimate m_estimate;  // error_estimate() of the statistics since the last pass
  std::chrono::steady_clock::time_point m_deadline = std::chrono::steady_clock::time_point::max();
  bool stop_requested(const std::atomic<bool>* cancel) const {
    return (cancel && cancel->load(std::memory_order_relaxed)) || std::chrono::steady_clock::now() >= m_deadline;
  }
};

// Halting conditions shared by the CLI, the server and the window.
struct RunLimits {
  double time_limit = 0;     // seconds of rendering; 0 = none
  double target_error = 0;   // stop once error_estimate() <= this; 0 = none
};
// Seconds left of a progressive render `elapsed` seconds in: from the sample budget (`progress`,
// the fraction done), or sooner from the error estimate `error` measured at `error_seconds`, which
// an unbiased estimator's relative MSE lowers as 1/time towards limits.target_error (not a
// sample fraction: most of the budget may never be needed), or sooner still from the time limit.
// Negative while none of them says anything (no progress, no limit). The CLI's progress bar and
// the job service's ETA both use it.
double remaining_seconds(double elapsed, double progress, double error, double error_seconds, const RunLimits& limits);
enum class StopReason { finished, target_error, time_limit, cancelled };
const char* stop_reason_name(StopReason r);
struct PassReport {
  int target_spp;   // samples per pixel this pass aimed for
  double seconds;   // rendering time so far
  double error;     // error_estimate() after the pass
};
// The samples per pixel the pass after one that reached `target` aims for: twice as many (1, 2, 4,
// ... spp), or, towards an error target, where the estimate's 1/spp decay meets it when that comes
// sooner (a doubling could overshoot it by up to the render's whole time so far).
int next_pass_target(int target, int spp, double error, double target_error);
// The progressive driver: passes of next_pass_target's sample counts until every pixel is done,
// the error target or time limit is reached, or `cancel` is set. `on_pass` runs after each pass
// (also the last, partial one).
StopReason run_progressive(RenderSession& session, const RunLimits& limits, const std::atomic<bool>* cancel = nullptr,
                           const RenderSession::TileCallback& on_tile = {},
                           const std::function<void(const PassReport&)>& on_pass = {});

}  // namespace pt
