// The wire form of a film pass (film_pass.h).
#include "film_pass.h"

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
  uint32_t has_caustics;  // caustic sums follow the sample counts
  uint32_t has_features;  // then albedo and normal sums (a pass from before features: 0 here)
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
  h.has_features = albedo_sum.empty() ? 0 : 1;
  std::string out(reinterpret_cast<const char*>(&h), sizeof h);
  append(out, sum);
  append(out, lum2);
  append(out, samples);
  append(out, caustic_sum);
  if (h.has_features) append(out, albedo_sum), append(out, normal_sum);
  return out;
}

FilmPass FilmPass::decode(const std::string& bytes, int expect_width, int expect_height) {
  Header h;
  if (bytes.size() < sizeof h) throw std::runtime_error("film pass: " + std::to_string(bytes.size()) + " bytes is too short");
  std::memcpy(&h, bytes.data(), sizeof h);
  if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) throw std::runtime_error("film pass: not a PTFILM2 buffer");
  if (h.has_caustics > 1) throw std::runtime_error("film pass: bad caustics flag");
  if (h.has_features > 1) throw std::runtime_error("film pass: bad features flag");
  if (int(h.width) != expect_width || int(h.height) != expect_height)
    throw std::runtime_error("film pass: " + std::to_string(h.width) + "x" + std::to_string(h.height) + " film, expected " +
                             std::to_string(expect_width) + "x" + std::to_string(expect_height));
  size_t n = size_t(h.width) * h.height;
  if (bytes.size() != sizeof h + n * (sizeof(Vec3) + sizeof(float) + sizeof(uint32_t) + h.has_caustics * sizeof(Vec3) +
                                      h.has_features * 2 * sizeof(Vec3)))
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
  if (h.has_features) extract(bytes, at, p.albedo_sum, n), extract(bytes, at, p.normal_sum, n);
  // A feature mean is in [0, 1] (albedo) or [-1, 1] (normal): a sum beyond its samples is forged.
  auto feature_ok = [&](size_t i) {
    if (!h.has_features) return true;
    const Vec3 a = p.albedo_sum[i], nn = p.normal_sum[i];
    const float c = float(p.samples[i]) * 1.0001f + 1e-3f;
    return is_finite(a) && is_finite(nn) && std::fabs(a.x) <= c && std::fabs(a.y) <= c && std::fabs(a.z) <= c &&
           std::fabs(nn.x) <= c && std::fabs(nn.y) <= c && std::fabs(nn.z) <= c;
  };
  for (size_t i = 0; i < n; ++i) {
    if (p.samples[i] > p.count)
      throw std::runtime_error("film pass: pixel " + std::to_string(i) + " holds " + std::to_string(p.samples[i]) +
                               " samples, more than the pass's " + std::to_string(p.count));
    if (!is_finite(p.sum[i]) || !std::isfinite(p.lum2[i]) ||
        (h.has_caustics && !is_finite(p.caustic_sum[i])) || !feature_ok(i))
      throw std::runtime_error("film pass: pixel " + std::to_string(i) + " holds impossible values");
  }
  return p;
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
