// Texture lookups: wrap modes as OpenGL defines them (glTF 2.0 samplers use its enums), bilinear
// filtering between texel centres, sRGB decode through a 256-entry table (colour textures only).
#include "texture.h"

#include <array>
#include <cmath>

namespace pt {

namespace {

const std::array<float, 256>& srgb_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
      double c = i / 255.0;
      t[size_t(i)] = float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return t;
  }();
  return table;
}

// Texel index i of a row or column of n texels under a wrap mode (OpenGL 4.6, section 8.14.2).
inline int wrap(int i, int n, TextureWrap mode) {
  switch (mode) {
    case TextureWrap::repeat: {
      int r = i % n;
      return r < 0 ? r + n : r;
    }
    case TextureWrap::clamp: return i < 0 ? 0 : (i >= n ? n - 1 : i);
    case TextureWrap::mirror: {
      int period = 2 * n, r = i % period;
      if (r < 0) r += period;
      return r < n ? r : period - 1 - r;
    }
  }
  return 0;
}

inline size_t texel_index(const TextureDesc& t, int x, int y) {
  return size_t(wrap(y, t.height, t.wrap_t)) * size_t(t.width) + size_t(wrap(x, t.width, t.wrap_s));
}

inline Vec3 texel(const TextureDesc& t, int x, int y) {
  const uint8_t* p = &t.texels[3 * texel_index(t, x, y)];
  if (!t.srgb) return Vec3(p[0], p[1], p[2]) * (1 / 255.0f);  // data: linear
  const auto& lut = srgb_table();
  return Vec3(lut[p[0]], lut[p[1]], lut[p[2]]);
}

}  // namespace

float srgb8_to_linear(uint8_t code) { return srgb_table()[code]; }

uint8_t linear_to_srgb8(float v) {
  if (!(v > 0)) return 0;
  if (v >= 1) return 255;
  double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(double(v), 1 / 2.4) - 0.055;
  return uint8_t(std::lround(255 * s));
}

// `fetch(x, y)` at uv, bilinear between texel centres unless the texture is `nearest`.
template <class Fetch>
auto filter(const TextureDesc& t, Vec2 uv, Fetch fetch) {
  // Far-out or non-finite coordinates would overflow the texel index: read them at 0.
  float u = std::isfinite(uv.x) && std::fabs(uv.x) < 1e6f ? uv.x : 0.0f;
  float v = std::isfinite(uv.y) && std::fabs(uv.y) < 1e6f ? uv.y : 0.0f;
  float fx = u * t.width - 0.5f, fy = v * t.height - 0.5f;  // texel centres at half-integers
  if (t.nearest) return fetch(int(std::floor(fx + 0.5f)), int(std::floor(fy + 0.5f)));
  int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  float tx = fx - float(x0), ty = fy - float(y0);
  return (fetch(x0, y0) * (1 - tx) + fetch(x0 + 1, y0) * tx) * (1 - ty) +
         (fetch(x0, y0 + 1) * (1 - tx) + fetch(x0 + 1, y0 + 1) * tx) * ty;
}

Vec3 eval_texture(const TextureDesc& t, Vec2 uv) {
  if (t.width <= 0 || t.height <= 0 || t.texels.size() < 3 * size_t(t.width) * size_t(t.height)) return Vec3(1.0f);
  return filter(t, uv, [&](int x, int y) { return texel(t, x, y); });
}

float eval_texture_alpha(const TextureDesc& t, Vec2 uv) {
  if (t.width <= 0 || t.height <= 0 || t.alpha.size() < size_t(t.width) * size_t(t.height)) return 1.0f;
  return filter(t, uv, [&](int x, int y) { return float(t.alpha[texel_index(t, x, y)]) * (1 / 255.0f); });
}

Vec3 texture_mean(const TextureDesc& t) {
  size_t n = size_t(t.width) * size_t(t.height);
  if (n == 0 || t.texels.size() < 3 * n) return Vec3(1.0f);
  const auto& lut = srgb_table();
  double sum[3] = {0, 0, 0};
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) sum[c] += lut[t.texels[3 * i + size_t(c)]];
  return Vec3(float(sum[0] / double(n)), float(sum[1] / double(n)), float(sum[2] / double(n)));
}

}  // namespace pt
