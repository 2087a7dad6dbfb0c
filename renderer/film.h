// The film: per-pixel statistics of a render, the one adaptive stop rule, the error estimate, and
// merging. The session adds samples to it one by one; the scale-out's server merges workers'
// passes into it (FilmPass, film_pass.h). Both read images, tiles and the estimate from here.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "binary_io.h"
#include "image.h"
#include "math.h"

namespace pt {

struct FilmPass;
struct CausticSplat;

struct Tile {
  int x0, y0, x1, y1;  // film pixels, top-left origin, half-open
};

// A w x h film cut into tiles of `size` pixels a side (the last row and column clipped), row by
// row from the top-left: the session's passes and the scale-out's merges cut it the same way.
std::vector<Tile> tile_grid(int w, int h, int size);

// The course's sample-rate colour of a pixel (linear, before tone mapping): 0 samples blue,
// spp / 2 green, spp red. The rate image and the window's rate legend both use it.
Vec3 rate_colour(uint32_t count, int spp);

// The course's adaptive sampling (../shared/notes/cs184-spec.md): a pixel is tested after sample n
// when n > 1 and n - 1 is a multiple of the batch, and stops once the 95% confidence half-width of
// its luminance is within tolerance x mean. Where samples arrive in blocks (merged passes), a
// block that crosses a test count is tested at its end.
struct AdaptiveRule {
  bool enabled = true;
  uint32_t batch = 32;
  double tolerance = 0.05;

  bool test_due(uint32_t n) const { return enabled && n > 1 && (n - 1) % batch == 0; }
  // The first count after c at which a test is due.
  uint32_t next_test(uint32_t c) const { return 1 + batch * ((std::max(c, 1u) + batch - 1) / batch); }
  bool test_due_within(uint32_t before, uint32_t after) const { return enabled && next_test(before) <= after; }
  // The test itself, for n > 1 luminance samples of sum s1 and sum of squares s2.
  bool converged(double s1, double s2, uint32_t n) const {
    double mu = s1 / n;
    double var = std::max(0.0, (s2 - s1 * s1 / n) / (n - 1));
    return 1.96 * std::sqrt(var / n) <= tolerance * mu;
  }
  // The count at which a running pixel of n samples (sums s1, s2) is expected to stop within a
  // budget of spp: the test above solved for n, n >= (1.96 sigma / (tolerance mu))^2, on its
  // statistics so far, at the first test due there and after n. The budget where nothing can be
  // said yet (n < 2) or the test cannot pass (a mean <= 0 with spread).
  uint32_t predicted_stop(double s1, double s2, uint32_t n, uint32_t spp) const {
    if (n >= spp) return n;
    if (!enabled || n < 2) return spp;
    const double mu = s1 / n, var = std::max(0.0, (s2 - s1 * s1 / n) / (n - 1));
    double need = 0;  // no spread: the next test passes (for a mean >= 0)
    if (var > 0 || mu < 0) {
      if (!(mu > 0 && tolerance > 0)) return spp;
      const double z = 1.96 / tolerance;
      need = z * z * var / (mu * mu);
    }
    if (!(need < double(spp))) return spp;
    uint32_t at = next_test(n);
    if (need > at) at = 1 + batch * uint32_t((std::ceil(need) - 1 + batch - 1) / batch);
    return std::min(at, spp);
  }
};

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

// Light-traced splats' share of the error estimate: per-pixel splat luminance sums of n light
// paths and of a first part half_n of them.
struct SplatStats {
  const std::vector<double>* s1 = nullptr;
  const std::vector<double>* half_s1 = nullptr;
  uint64_t n = 0, half_n = 0;
};
// Relative MSE of the pixel means without a reference, from per-pixel sample counts, luminance
// sums, and the count and sum of a part of each pixel's samples, on a film `width` pixels wide
// (row-major); infinite until some pixel has two parts to compare. See film.cpp.
double halves_error_estimate(int width, const std::vector<uint32_t>& count, const std::vector<uint32_t>& half_n,
                             const std::vector<double>& s1, const std::vector<double>& half_s1,
                             const SplatStats& splats = {}, int threads = 1);
// An error estimate as the CLI's summary and the window show it: "%.3g", or "n/a" while it is
// infinite (before any pixel has two samples). The CSV log keeps "inf", which parsers read.
std::string format_error_estimate(double error);

// What the denoiser reads of a film beside its image (denoiser.h): per-pixel mean albedo and
// normal, and the image of each of the error estimate's two parts of the samples.
struct FilmFeatures {
  ImageRGB albedo, normal;
};

class Film {
 public:
  // A width x height film for `spp` samples a pixel; `caustics`: it also sums light-traced splats;
  // `features`: it also sums the denoiser's features and keeps the colour of its first part.
  Film(int width, int height, int spp, const AdaptiveRule& rule, bool caustics, bool features = false);

  int width() const { return m_w; }
  int height() const { return m_h; }
  size_t pixels() const { return m_count.size(); }
  int spp() const { return m_spp; }
  const AdaptiveRule& rule() const { return m_rule; }

  // ---- one sample at a time (the session's tiles; each pixel belongs to one thread) ----
  // Adds sample s (the pixel's count so far) of pixel i; true when the adaptive rule stops the pixel
  // there. A non-finite sample counts as black and in `nonfinite`.
  bool add_sample(size_t i, uint32_t s, Vec3 l, uint64_t& nonfinite) {
    if (!is_finite(l)) {  // dropped and counted; a bug to fix at its source
      ++nonfinite;
      l = Vec3(0.0f);
    }
    if (s > 0 && (s & (s - 1)) == 0) {  // s samples so far, a power of two: keep their sum
      m_half_s1[i] = m_s1[i];
      m_half_n[i] = s;
      if (!m_half_sum.empty()) m_half_sum[i] = m_sum[i];
    }
    m_sum[i] += l;
    double lum = luminance(l);
    m_s1[i] += lum;
    m_s2[i] += lum * lum;
    uint32_t n = ++m_count[i];
    return m_rule.test_due(n) && m_rule.converged(m_s1[i], m_s2[i], n);
  }
  // Black samples [from, to) of pixel i (it sees only background): add_sample with l = 0 for each.
  // Stops after the first adaptive test that passes (then `stopped`); returns the samples added.
  uint32_t add_zero_samples(size_t i, uint32_t from, uint32_t to, bool& stopped);
  // The denoiser's features of one sample of pixel i (with its add_sample); non-finite ones count as 0.
  void add_features(size_t i, Vec3 albedo, Vec3 normal) {
    m_albedo_sum[i] += is_finite(albedo) ? albedo : Vec3(0.0f);
    m_normal_sum[i] += is_finite(normal) ? normal : Vec3(0.0f);
  }
  bool has_features() const { return !m_albedo_sum.empty(); }
  uint32_t count(size_t i) const { return m_count[i]; }
  bool done(size_t i) const { return m_done[i] != 0; }
  void set_done(size_t i) { m_done[i] = 1; }
  const std::vector<uint8_t>& done_mask() const { return m_done; }
  // Marks pixels whose `skip` byte is set as done (a share of a distributed render leaves them out).
  void skip(const std::vector<uint8_t>& skip);
  bool finished() const;     // every pixel done
  size_t remaining() const;  // pixels still taking samples
  // Fraction of the sample budget done, converged pixels counted in full: the budget's share, not
  // the render's (ProgressEstimate, driver.h, counts the work left).
  double progress() const;
  // Samples taken, those the running pixels are expected to take still (predicted_stop), the
  // most any pixel has (the last pass's count) and the latest predicted stop (0: none runs).
  struct Work {
    uint64_t taken = 0, left = 0;
    double cost_left = 0;  // `left`, each sample weighted by its tile's cost (1 without)
    uint32_t reached = 0, last_stop = 0;
  };
  // One pass over the per-pixel arrays: call between passes. Where `tiles` (which cover the film)
  // come with the time and samples each took in its last pass, a sample left costs its tile's time
  // per sample over the mean of the tiles that took samples.
  Work work(const std::vector<Tile>& tiles = {}, const std::vector<uint64_t>& tile_ns = {},
            const std::vector<uint64_t>& tile_samples = {}) const;

  // ---- light-traced caustics (caustics.h) ----
  bool has_caustics() const { return !m_lt_sum.empty(); }
  // Before a pass's light paths: the error estimate's first part becomes the paths so far once
  // they are at least twice those of the last part (as add_sample's powers of two).
  void begin_light_paths();
  void add_splats(const std::vector<CausticSplat>& splats);
  void add_light_paths(uint64_t n) { m_lt_paths += n; }
  uint64_t light_paths() const { return m_lt_paths; }

  // ---- whole passes ----
  // Adds a pass of the same size (throws std::runtime_error otherwise). The error estimate's two
  // parts are made of whole passes, each pass going to the smaller part; the adaptive rule tests a
  // pixel whose pass crossed a test count.
  void merge(const FilmPass& pass);
  // The film's sums for sample range [first, first + count), as a worker sends them.
  FilmPass to_pass(uint32_t first, uint32_t count) const;

  // ---- checkpoints ----
  // Every statistic, so that a restored film continues exactly where this one stands.
  void save(BinaryWriter& out) const;
  // Reads what save() wrote for a film of this size, budget and kind; throws std::runtime_error
  // (BinaryReader's) on anything that does not fit: another size, impossible counts, non-finite sums.
  void restore(BinaryReader& in);

  // ---- reading ----
  // A pixel's radiance: the mean of its camera samples plus its splat sum over every light path.
  Vec3 pixel_mean(size_t i) const {
    Vec3 v = m_count[i] ? m_sum[i] / float(m_count[i]) : Vec3(0.0f);
    if (m_lt_paths > 0) v += m_lt_sum[i] / float(m_lt_paths);
    return v;
  }
  ImageRGB image() const;
  ImageRGB rate_image() const;     // the course's sample-rate colouring
  ImageRGB caustic_image() const;  // the light-traced caustics alone; black without them
  // The mean albedo and normal (has_features(); black images otherwise).
  FilmFeatures features() const;
  // The images of the error estimate's two parts of each pixel's samples (has_features()): false
  // until some pixel has both.
  bool part_images(ImageRGB& first, ImageRGB& rest) const;
  // Per pixel, the weight p (n - p) / n^2 that turns the squared difference of the two parts'
  // means into the variance of the whole mean (halves_error_estimate); 0 where a part is empty.
  std::vector<float> part_weights() const;
  // Mean radiance / rate colours of a tile's pixels, row by row. Safe while other tiles render.
  void read_tile(const Tile& t, std::vector<Vec3>& out) const;
  void read_tile_rate(const Tile& t, std::vector<Vec3>& out) const;
  // Samples taken by each of a tile's pixels, row by row.
  void read_tile_count(const Tile& t, std::vector<uint32_t>& out) const;
  // Estimated relative MSE of image() (halves_error_estimate), computed once for each state of the
  // statistics; call invalidate_estimate() after changing them.
  double error_estimate(int threads = 1) const;
  void invalidate_estimate() { m_estimate.invalidate(); }
  uint64_t error_estimates_computed() const { return m_estimate.times_computed(); }

 private:
  int m_w, m_h, m_spp;
  AdaptiveRule m_rule;
  std::vector<Vec3> m_sum;
  std::vector<double> m_s1, m_s2;  // luminance sums and sums of squares
  // The part of each pixel's samples the error estimate compares with the rest: added one by one,
  // those up to the last power of two below the count; merged, whole passes.
  std::vector<double> m_half_s1;
  std::vector<uint32_t> m_half_n;
  std::vector<uint32_t> m_count;
  std::vector<uint8_t> m_done;
  uint64_t m_half_samples = 0, m_other_samples = 0;  // merged passes' samples in either part
  // Caustic splat sums over m_lt_paths light paths, their luminance, and the first part's.
  std::vector<Vec3> m_lt_sum;
  std::vector<double> m_lt_s1, m_lt_half_s1;
  uint64_t m_lt_paths = 0, m_lt_half_paths = 0;
  // With features: albedo and normal sums, and the first part's colour sum (and splat sum).
  std::vector<Vec3> m_albedo_sum, m_normal_sum, m_half_sum, m_lt_half_sum;
  CachedEstimate m_estimate;
};

}  // namespace pt
