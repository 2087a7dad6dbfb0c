// The film (film.h): per-pixel statistics, merging, images, and the error estimate.
#include "film.h"

#include <atomic>
#include <cstdio>
#include <stdexcept>

#include <sys/mman.h>

#include "caustics.h"
#include "film_pass.h"
#include "parallel.h"

namespace pt {

namespace {

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

// Course colouring: 0 = blue, 0.5 = green, 1 = red, by samples taken / spp.
Vec3 rate_colour(uint32_t count, int spp) {
  float r = float(count) / float(spp);
  return r <= 0.5f ? Vec3(0, 2 * r, 1 - 2 * r) : Vec3(2 * r - 1, 2 - 2 * r, 0);
}

Film::Film(int width, int height, int spp, const AdaptiveRule& rule, bool caustics, bool features)
    : m_w(width), m_h(height), m_spp(spp), m_rule(rule) {
  m_rule.batch = std::max(1u, m_rule.batch);
  const size_t n = size_t(width) * size_t(height);
  assign_zeroed(m_sum, n, Vec3(0.0f));
  assign_zeroed(m_s1, n, 0.0);
  assign_zeroed(m_s2, n, 0.0);
  assign_zeroed(m_half_s1, n, 0.0);
  assign_zeroed(m_half_n, n, 0u);
  assign_zeroed(m_count, n, 0u);
  assign_zeroed(m_done, n, uint8_t(0));
  if (caustics) {
    assign_zeroed(m_lt_sum, n, Vec3(0.0f));
    assign_zeroed(m_lt_s1, n, 0.0);
    assign_zeroed(m_lt_half_s1, n, 0.0);
  }
  if (features) {
    assign_zeroed(m_albedo_sum, n, Vec3(0.0f));
    assign_zeroed(m_normal_sum, n, Vec3(0.0f));
    assign_zeroed(m_half_sum, n, Vec3(0.0f));
    if (caustics) assign_zeroed(m_lt_half_sum, n, Vec3(0.0f));
  }
}

uint32_t Film::add_zero_samples(size_t i, uint32_t from, uint32_t to, bool& stopped) {
  stopped = false;
  if (!m_rule.enabled && from < to) {  // no stop test: only the last power of two in [from, to) is kept
    const uint32_t last = 1u << (31 - __builtin_clz((to - 1) | 1));  // the largest power of two <= max(to - 1, 1)
    if (to > 1 && last >= from) {
      m_half_s1[i] = m_s1[i];
      m_half_n[i] = last;
      if (!m_half_sum.empty()) m_half_sum[i] = m_sum[i];
    }
    m_count[i] = to;
    return to - from;
  }
  uint32_t s = from;
  while (s < to) {
    if (s > 0 && (s & (s - 1)) == 0) {
      m_half_s1[i] = m_s1[i];
      m_half_n[i] = s;
      if (!m_half_sum.empty()) m_half_sum[i] = m_sum[i];
    }
    const uint32_t n = ++s;
    if (m_rule.test_due(n) && m_rule.converged(m_s1[i], m_s2[i], n)) {
      stopped = true;
      break;
    }
  }
  m_count[i] = s;
  return s - from;
}

void Film::skip(const std::vector<uint8_t>& skip) {
  for (size_t i = 0; i < skip.size() && i < m_done.size(); ++i) m_done[i] |= skip[i];
}

bool Film::finished() const { return remaining() == 0; }

size_t Film::remaining() const {
  size_t n = 0;
  for (uint8_t d : m_done) n += d == 0;
  return n;
}

double Film::progress() const {
  double total = double(m_spp) * double(m_count.size()), done = 0;
  for (size_t i = 0; i < m_count.size(); ++i) done += m_done[i] ? m_spp : std::min<uint32_t>(m_count[i], uint32_t(m_spp));
  return total > 0 ? std::min(1.0, done / total) : 1.0;
}

Film::Work Film::work(const std::vector<Tile>& tiles, const std::vector<uint64_t>& tile_ns,
                      const std::vector<uint64_t>& tile_samples) const {
  Work w;
  const uint32_t spp = uint32_t(m_spp);
  auto add = [&](size_t i, double cost) {
    const uint32_t n = m_count[i];
    w.taken += n;
    w.reached = std::max(w.reached, n);
    if (m_done[i]) return;
    const uint32_t stop = m_rule.predicted_stop(m_s1[i], m_s2[i], n, spp), left = stop - std::min(n, spp);
    w.left += left;
    w.cost_left += cost * left;
    w.last_stop = std::max(w.last_stop, stop);
  };
  double ns = 0, samples = 0;
  if (tile_ns.size() == tiles.size() && tile_samples.size() == tiles.size())
    for (size_t t = 0; t < tiles.size(); ++t)
      if (tile_samples[t] > 0) ns += double(tile_ns[t]), samples += double(tile_samples[t]);
  if (!(ns > 0)) {
    for (size_t i = 0; i < m_count.size(); ++i) add(i, 1.0);
    return w;
  }
  for (size_t t = 0; t < tiles.size(); ++t) {
    const double cost = tile_samples[t] > 0 ? double(tile_ns[t]) / double(tile_samples[t]) * samples / ns : 1.0;
    for (int y = tiles[t].y0; y < tiles[t].y1; ++y)
      for (int x = tiles[t].x0; x < tiles[t].x1; ++x) add(size_t(y) * m_w + x, cost);
  }
  return w;
}

void Film::begin_light_paths() {
  if (m_lt_paths > 0 && m_lt_paths >= 2 * m_lt_half_paths) {
    m_lt_half_s1 = m_lt_s1;
    m_lt_half_paths = m_lt_paths;
    if (!m_lt_half_sum.empty()) m_lt_half_sum = m_lt_sum;
  }
}

void Film::add_splats(const std::vector<CausticSplat>& splats) {
  for (const CausticSplat& s : splats) {
    m_lt_sum[s.pixel] += s.value;
    m_lt_s1[s.pixel] += luminance(s.value);
  }
}

void Film::merge(const FilmPass& pass) {
  if (pass.width != m_w || pass.height != m_h) throw std::runtime_error("film pass of the wrong size");
  m_estimate.invalidate();
  uint64_t pass_samples = 0;
  for (uint32_t c : pass.samples) pass_samples += c;
  const bool to_half = m_half_samples <= m_other_samples;
  (to_half ? m_half_samples : m_other_samples) += pass_samples;
  if (!pass.caustic_sum.empty() && pass.light_paths > 0) {
    if (pass.caustic_sum.size() != m_sum.size()) throw std::runtime_error("film pass: caustics of the wrong size");
    if (m_lt_sum.empty()) {
      m_lt_sum.assign(m_sum.size(), Vec3(0.0f));
      m_lt_s1.assign(m_sum.size(), 0);
      m_lt_half_s1.assign(m_sum.size(), 0);
    }
    if (has_features() && m_lt_half_sum.empty()) m_lt_half_sum.assign(m_sum.size(), Vec3(0.0f));
    for (size_t i = 0; i < m_lt_sum.size(); ++i) {
      m_lt_sum[i] += pass.caustic_sum[i];
      double l = luminance(pass.caustic_sum[i]);
      m_lt_s1[i] += l;
      if (to_half) m_lt_half_s1[i] += l;
      if (to_half && !m_lt_half_sum.empty()) m_lt_half_sum[i] += pass.caustic_sum[i];
    }
    m_lt_paths += pass.light_paths;
    if (to_half) m_lt_half_paths += pass.light_paths;
  }
  // Features: a film that has them takes them from every pass (a pass without them adds none).
  const bool features = has_features() && pass.albedo_sum.size() == m_sum.size() && pass.normal_sum.size() == m_sum.size();
  for (size_t i = 0; i < m_sum.size(); ++i) {
    uint32_t c = pass.samples[i];
    if (c == 0) continue;
    if (features) {
      m_albedo_sum[i] += pass.albedo_sum[i];
      m_normal_sum[i] += pass.normal_sum[i];
      if (to_half) m_half_sum[i] += pass.sum[i];
    }
    double s1 = luminance(pass.sum[i]);
    m_sum[i] += pass.sum[i];
    m_s1[i] += s1;
    m_s2[i] += pass.lum2[i];
    const uint32_t before = m_count[i], n = m_count[i] += c;
    if (to_half) {
      m_half_s1[i] += s1;
      m_half_n[i] += c;
    }
    if (m_done[i]) continue;
    if (n >= uint32_t(m_spp) || (m_rule.test_due_within(before, n) && m_rule.converged(m_s1[i], m_s2[i], n)))
      m_done[i] = 1;
  }
}

FilmPass Film::to_pass(uint32_t first, uint32_t count) const {
  FilmPass out;
  out.width = m_w;
  out.height = m_h;
  out.first = first;
  out.count = count;
  out.sum = m_sum;
  out.lum2.assign(m_s2.begin(), m_s2.end());
  out.samples = m_count;
  out.caustic_sum = m_lt_sum;
  out.light_paths = m_lt_paths;
  out.albedo_sum = m_albedo_sum;
  out.normal_sum = m_normal_sum;
  return out;
}

void Film::save(BinaryWriter& out) const {
  // Bit 0: caustic sums; bit 1: features (a film saved before features existed reads as without).
  out.pod(int32_t(m_w)), out.pod(int32_t(m_h)), out.pod(int32_t(m_spp)),
      out.pod(uint8_t((has_caustics() ? 1 : 0) | (has_features() ? 2 : 0)));
  out.array(m_sum), out.array(m_s1), out.array(m_s2), out.array(m_half_s1), out.array(m_half_n);
  out.array(m_count), out.array(m_done);
  out.pod(m_half_samples), out.pod(m_other_samples);
  out.array(m_lt_sum), out.array(m_lt_s1), out.array(m_lt_half_s1);
  out.pod(m_lt_paths), out.pod(m_lt_half_paths);
  if (has_features()) out.array(m_albedo_sum), out.array(m_normal_sum), out.array(m_half_sum), out.array(m_lt_half_sum);
}

void Film::restore(BinaryReader& in) {
  const int32_t w = in.pod<int32_t>(), h = in.pod<int32_t>(), spp = in.pod<int32_t>();
  const uint8_t flags = in.pod<uint8_t>();
  const bool caustics = (flags & 1) != 0, features = (flags & 2) != 0;
  if (flags > 3) in.fail("unknown film flags " + std::to_string(flags));
  if (features != has_features())
    in.fail(features ? "a film with the denoiser's features (this render has none)"
                     : "a film without the denoiser's features (this render needs them)");
  // Splat sums come with the film: a merged film gains them with its first pass that has some.
  if (w != m_w || h != m_h) in.fail("a " + std::to_string(w) + "x" + std::to_string(h) + " film");
  if (spp < 1 || spp > m_spp)
    in.fail("a film of " + std::to_string(spp) + " spp, more than this render's " + std::to_string(m_spp) +
            " (a budget can grow, not shrink)");
  const size_t n = pixels(), lt = caustics ? n : 0;
  in.array(m_sum, n), in.array(m_s1, n), in.array(m_s2, n), in.array(m_half_s1, n), in.array(m_half_n, n);
  in.array(m_count, n), in.array(m_done, n);
  m_half_samples = in.pod<uint64_t>(), m_other_samples = in.pod<uint64_t>();
  in.array(m_lt_sum, lt), in.array(m_lt_s1, lt), in.array(m_lt_half_s1, lt);
  m_lt_paths = in.pod<uint64_t>(), m_lt_half_paths = in.pod<uint64_t>();
  if (features) {
    in.array(m_albedo_sum, n), in.array(m_normal_sum, n), in.array(m_half_sum, n);
    in.array(m_lt_half_sum, caustics ? n : 0);
    for (size_t i = 0; i < n; ++i)
      if (!is_finite(m_albedo_sum[i]) || !is_finite(m_normal_sum[i]) || !is_finite(m_half_sum[i]) ||
          (caustics && !is_finite(m_lt_half_sum[i])))
        in.fail("pixel " + std::to_string(i) + " holds impossible features");
  }
  for (size_t i = 0; i < n; ++i)
    if (m_count[i] > uint32_t(spp) || m_half_n[i] > m_count[i] || m_done[i] > 1 || !is_finite(m_sum[i]) ||
        !std::isfinite(m_s1[i]) || !std::isfinite(m_s2[i]) || !std::isfinite(m_half_s1[i]) ||
        (caustics && (!is_finite(m_lt_sum[i]) || !std::isfinite(m_lt_s1[i]) || !std::isfinite(m_lt_half_s1[i]))))
      in.fail("pixel " + std::to_string(i) + " holds impossible values");
  if (m_lt_half_paths > m_lt_paths) in.fail("more light paths in a part than in all");
  // A larger budget reopens the pixels the old one stopped, unless the adaptive rule stops them at
  // that count too: as a render with this budget from the start would have.
  if (spp < m_spp)
    for (size_t i = 0; i < n; ++i)
      if (m_done[i] && m_count[i] >= uint32_t(spp) && !(m_rule.test_due(m_count[i]) && m_rule.converged(m_s1[i], m_s2[i], m_count[i])))
        m_done[i] = 0;
  m_estimate.invalidate();
}

ImageRGB Film::image() const {
  return make_image(m_w, m_h, [this](size_t i) { return pixel_mean(i); });
}

ImageRGB Film::rate_image() const {
  return make_image(m_w, m_h, [this](size_t i) { return rate_colour(m_count[i], m_spp); });
}

ImageRGB Film::caustic_image() const {
  if (m_lt_paths == 0) return make_image(m_w, m_h, [](size_t) { return Vec3(0.0f); });
  return make_image(m_w, m_h, [this](size_t i) { return m_lt_sum[i] / float(m_lt_paths); });
}

FilmFeatures Film::features() const {
  FilmFeatures f;
  const bool any = has_features();
  f.albedo = make_image(m_w, m_h, [&](size_t i) { return any && m_count[i] ? m_albedo_sum[i] / float(m_count[i]) : Vec3(0.0f); });
  f.normal = make_image(m_w, m_h, [&](size_t i) { return any && m_count[i] ? m_normal_sum[i] / float(m_count[i]) : Vec3(0.0f); });
  return f;
}

bool Film::part_images(ImageRGB& first, ImageRGB& rest) const {
  if (!has_features()) return false;
  bool any = false;
  // The splats' parts: their first part's paths, and the rest (each part's mean over its own paths).
  const uint64_t lt_a = m_lt_half_paths, lt_b = m_lt_paths - m_lt_half_paths;
  const bool splats = !m_lt_half_sum.empty() && lt_a > 0 && lt_b > 0;
  first = make_image(m_w, m_h, [&](size_t i) {
    const uint32_t p = m_half_n[i];
    any |= p > 0 && p < m_count[i];
    Vec3 v = p ? m_half_sum[i] / float(p) : Vec3(0.0f);
    if (splats) v += m_lt_half_sum[i] / float(lt_a);
    else if (m_lt_paths > 0) v += m_lt_sum[i] / float(m_lt_paths);
    return v;
  });
  rest = make_image(m_w, m_h, [&](size_t i) {
    const uint32_t p = m_half_n[i], n = m_count[i];
    Vec3 v = n > p ? (m_sum[i] - m_half_sum[i]) / float(n - p) : Vec3(0.0f);
    if (splats) v += (m_lt_sum[i] - m_lt_half_sum[i]) / float(lt_b);
    else if (m_lt_paths > 0) v += m_lt_sum[i] / float(m_lt_paths);
    return v;
  });
  return any;
}

std::vector<float> Film::part_weights() const {
  std::vector<float> w(m_count.size(), 0.0f);
  for (size_t i = 0; i < w.size(); ++i) {
    const double n = m_count[i], p = m_half_n[i];
    if (p > 0 && p < n) w[i] = float(p * (n - p) / (n * n));
  }
  return w;
}

void Film::read_tile(const Tile& t, std::vector<Vec3>& out) const {
  out.clear();
  for (int y = t.y0; y < t.y1; ++y)
    for (int x = t.x0; x < t.x1; ++x) out.push_back(pixel_mean(size_t(y) * m_w + x));
}

void Film::read_tile_rate(const Tile& t, std::vector<Vec3>& out) const {
  out.clear();
  for (int y = t.y0; y < t.y1; ++y)
    for (int x = t.x0; x < t.x1; ++x) out.push_back(rate_colour(m_count[size_t(y) * m_w + x], m_spp));
}

void Film::read_tile_count(const Tile& t, std::vector<uint32_t>& out) const {
  out.clear();
  for (int y = t.y0; y < t.y1; ++y)
    out.insert(out.end(), m_count.begin() + size_t(y) * m_w + t.x0, m_count.begin() + size_t(y) * m_w + t.x1);
}

double Film::error_estimate(int threads) const {
  return m_estimate.get([this, threads] {
    return halves_error_estimate(m_w, m_count, m_half_n, m_s1, m_half_s1,
                                 {&m_lt_s1, &m_lt_half_s1, m_lt_paths, m_lt_half_paths}, threads);
  });
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
  parallel_indices(blocks, threads, [&](auto& take) {
    for (size_t b; take(b);) block(b * rows_per_block, std::min(h, (b + 1) * rows_per_block), sums[b], useds[b]);
  });
  double sum = 0;
  size_t used = 0;
  for (size_t b = 0; b < blocks; ++b) sum += sums[b], used += useds[b];
  return used ? sum / double(n_pixels) : INFINITY;
}

std::vector<Tile> tile_grid(int w, int h, int size) {
  std::vector<Tile> tiles;
  size = std::max(1, size);
  for (int y = 0; y < h; y += size)
    for (int x = 0; x < w; x += size) tiles.push_back({x, y, std::min(x + size, w), std::min(y + size, h)});
  return tiles;
}

std::string format_error_estimate(double error) {
  if (!std::isfinite(error)) return "n/a";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", error);
  return buf;
}


}  // namespace pt
