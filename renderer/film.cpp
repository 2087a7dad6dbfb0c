#include "film.h"

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace pt {

namespace {

constexpr char kMagic[8] = {'P', 'T', 'F', 'I', 'L', 'M', '2', 0};

struct Header {
  char magic[8];
  uint32_t width, height, first, count;
  uint64_t rays, nonfinite;
  double seconds;
  uint64_t light_paths;
  uint32_t has_caustics, unused;  // caustic sums follow the sample counts
};

template <class T>
void append(std::string& out, const std::vector<T>& v) {
  out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

template <class T>
void extract(const std::string& in, size_t& at, std::vector<T>& v, size_t n) {
  v.resize(n);
  std::memcpy(v.data(), in.data() + at, n * sizeof(T));
  at += n * sizeof(T);
}

}  // namespace

// The hosts we run on are little-endian; the encoding is the in-memory layout behind a header.
static_assert(sizeof(Vec3) == 12, "Vec3 must be three packed floats");

std::string FilmPass::encode() const {
  Header h;
  std::memcpy(h.magic, kMagic, sizeof kMagic);
  h.width = uint32_t(width);
  h.height = uint32_t(height);
  h.first = first;
  h.count = count;
  h.rays = rays;
  h.nonfinite = nonfinite;
  h.seconds = seconds;
  h.light_paths = light_paths;
  h.has_caustics = caustic_sum.empty() ? 0 : 1;
  h.unused = 0;
  std::string out(reinterpret_cast<const char*>(&h), sizeof h);
  append(out, sum);
  append(out, lum2);
  append(out, samples);
  append(out, caustic_sum);
  return out;
}

FilmPass FilmPass::decode(const std::string& bytes, int expect_width, int expect_height) {
  Header h;
  if (bytes.size() < sizeof h) throw std::runtime_error("film pass: " + std::to_string(bytes.size()) + " bytes is too short");
  std::memcpy(&h, bytes.data(), sizeof h);
  if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) throw std::runtime_error("film pass: not a PTFILM2 buffer");
  if (h.has_caustics > 1) throw std::runtime_error("film pass: bad caustics flag");
  if (int(h.width) != expect_width || int(h.height) != expect_height)
    throw std::runtime_error("film pass: " + std::to_string(h.width) + "x" + std::to_string(h.height) + " film, expected " +
                             std::to_string(expect_width) + "x" + std::to_string(expect_height));
  size_t n = size_t(h.width) * h.height;
  if (bytes.size() != sizeof h + n * (sizeof(Vec3) + sizeof(float) + sizeof(uint32_t) + h.has_caustics * sizeof(Vec3)))
    throw std::runtime_error("film pass: " + std::to_string(bytes.size()) + " bytes does not match a " +
                             std::to_string(h.width) + "x" + std::to_string(h.height) + " film");
  FilmPass p;
  p.width = int(h.width);
  p.height = int(h.height);
  p.first = h.first;
  p.count = h.count;
  p.rays = h.rays;
  p.nonfinite = h.nonfinite;
  p.seconds = h.seconds;
  p.light_paths = h.light_paths;
  size_t at = sizeof h;
  extract(bytes, at, p.sum, n);
  extract(bytes, at, p.lum2, n);
  extract(bytes, at, p.samples, n);
  if (h.has_caustics) extract(bytes, at, p.caustic_sum, n);
  for (size_t i = 0; i < n; ++i)
    if (p.samples[i] > p.count || !is_finite(p.sum[i]) || !std::isfinite(p.lum2[i]) ||
        (h.has_caustics && !is_finite(p.caustic_sum[i])))
      throw std::runtime_error("film pass: pixel " + std::to_string(i) + " holds impossible values");
  return p;
}

FilmPass render_film_pass(const RenderScene& scene, const RenderParams& params, uint32_t first, uint32_t count,
                          const std::vector<uint8_t>& skip, const std::atomic<bool>* cancel, bool* complete) {
  RenderParams p = params;
  p.adaptive = false;  // convergence is judged on the merged statistics, not per pass
  RenderSession session(scene, p);
  session.set_sample_range(first, skip);
  bool ok = session.render_pass(int(count), cancel);
  if (complete) *complete = ok;
  FilmPass out;
  out.width = session.width();
  out.height = session.height();
  out.first = first;
  out.count = count;
  out.sum = session.pixel_sums();
  out.lum2.assign(session.pixel_lum2_sums().begin(), session.pixel_lum2_sums().end());
  out.samples = session.pixel_counts();
  out.caustic_sum = session.caustic_sums();
  SessionStats st = session.stats();
  out.light_paths = st.light_paths;
  out.rays = st.rays;
  out.nonfinite = st.nonfinite;
  out.seconds = st.seconds;
  return out;
}

FilmAccumulator::FilmAccumulator(const RenderParams& params, int width, int height)
    : m_params(params), m_w(width), m_h(height) {
  size_t n = size_t(width) * height;
  m_sum.assign(n, Vec3(0.0f));
  m_s1.assign(n, 0);
  m_s2.assign(n, 0);
  m_count.assign(n, 0);
  m_half_s1.assign(n, 0);
  m_half_n.assign(n, 0);
  m_done.assign(n, 0);
  m_remaining = n;
}

Vec3 FilmAccumulator::pixel_mean(size_t i) const {
  return pixel_estimate(m_sum[i], m_count[i], m_lt_sum, m_lt_paths, i);
}

void FilmAccumulator::merge(const FilmPass& pass) {
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
    for (size_t i = 0; i < m_lt_sum.size(); ++i) {
      m_lt_sum[i] += pass.caustic_sum[i];
      double l = luminance(pass.caustic_sum[i]);
      m_lt_s1[i] += l;
      if (to_half) m_lt_half_s1[i] += l;
    }
    m_lt_paths += pass.light_paths;
    if (to_half) m_lt_half_paths += pass.light_paths;
  }
  const int batch = std::max(1, m_params.adaptive_batch);
  for (size_t i = 0; i < m_sum.size(); ++i) {
    uint32_t c = pass.samples[i];
    if (c == 0) continue;
    double s1 = luminance(pass.sum[i]);
    m_sum[i] += pass.sum[i];
    m_s1[i] += s1;
    m_s2[i] += pass.lum2[i];
    uint32_t n = m_count[i] += c;
    if (to_half) {
      m_half_s1[i] += s1;
      m_half_n[i] += c;
    }
    if (m_done[i]) continue;
    bool done = n >= uint32_t(m_params.spp);
    // The course's test (95% confidence half-width within tolerance x mean), on merged sums.
    if (!done && m_params.adaptive && n > uint32_t(batch))
      done = confidence_reached(m_s1[i], m_s2[i], n, m_params.adaptive_tolerance);
    if (done) {
      m_done[i] = 1;
      --m_remaining;
    }
  }
  m_samples += pass_samples;
  m_rays += pass.rays;
  m_nonfinite += pass.nonfinite;
}

double FilmAccumulator::progress() const {
  double total = double(m_params.spp) * m_w * m_h, done = 0;
  for (size_t i = 0; i < m_count.size(); ++i) done += m_done[i] ? m_params.spp : std::min<uint32_t>(m_count[i], m_params.spp);
  return total > 0 ? std::min(1.0, done / total) : 1.0;
}

double FilmAccumulator::error_estimate() const {
  // As the session's, with the two halves made of whole passes.
  return m_estimate.get([this] {
    return halves_error_estimate(m_w, m_count, m_half_n, m_s1, m_half_s1,
                                 {&m_lt_s1, &m_lt_half_s1, m_lt_paths, m_lt_half_paths});
  });
}

ImageRGB FilmAccumulator::image() const {
  return make_image(m_w, m_h, [this](size_t i) { return pixel_mean(i); });
}

void FilmAccumulator::read_tile(const Tile& t, std::vector<Vec3>& out) const {
  out.clear();
  for (int y = t.y0; y < t.y1; ++y)
    for (int x = t.x0; x < t.x1; ++x) {
      out.push_back(pixel_mean(size_t(y) * m_w + x));
    }
}

std::string pack_mask(const std::vector<uint8_t>& mask) {
  std::string bits((mask.size() + 7) / 8, '\0');
  for (size_t i = 0; i < mask.size(); ++i)
    if (mask[i]) bits[i / 8] = char(uint8_t(bits[i / 8]) | (1u << (i % 8)));
  return bits;
}

std::vector<uint8_t> unpack_mask(const std::string& bits, size_t pixels) {
  std::vector<uint8_t> mask(pixels, 0);
  for (size_t i = 0; i < pixels && i / 8 < bits.size(); ++i) mask[i] = (uint8_t(bits[i / 8]) >> (i % 8)) & 1;
  return mask;
}

}  // namespace pt
