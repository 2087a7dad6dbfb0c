// Warps from the unit square to directions and points, their pdfs, and discrete distributions.
#pragma once

#include <vector>

#include "lane_math.h"
#include "math.h"

namespace pt {

// The warps the lanes share (sampling.h's part of lane_physics.inc), at width 1.
using lane1::cosine_hemisphere_pdf;
using lane1::sample_concentric_disk;
using lane1::sample_cosine_hemisphere;
using lane1::sincos_quarter;

inline Vec3 sample_uniform_hemisphere(Vec2 u) {
  float z = u.x;
  float r = safe_sqrt(1 - z * z);
  float phi = 2 * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
inline float uniform_hemisphere_pdf() { return 0.5f * kInvPi; }

inline Vec3 sample_uniform_sphere(Vec2 u) {
  float z = 1 - 2 * u.x;
  float r = safe_sqrt(1 - z * z);
  float phi = 2 * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
inline float uniform_sphere_pdf() { return 0.25f * kInvPi; }

// Uniform barycentrics on a triangle (Heitz, "A Low-Distortion Map Between Triangle and Square", 2019).
inline Vec2 sample_uniform_triangle(Vec2 u) {
  float b0, b1;
  if (u.x < u.y) {
    b0 = u.x / 2;
    b1 = u.y - b0;
  } else {
    b1 = u.y / 2;
    b0 = u.x - b1;
  }
  return {b0, b1};
}

// Power heuristic with beta = 2 (Veach 1997, section 9.2): lane_physics.inc.
using lane1::power_heuristic;

// Piecewise-constant 1D distribution over n bins of [0, 1).
class Distribution1D {
 public:
  Distribution1D() = default;
  explicit Distribution1D(const std::vector<float>& weights) {
    size_t n = weights.size();
    m_func = weights;
    m_cdf.assign(n + 1, 0.0);
    for (size_t i = 0; i < n; ++i)
      m_cdf[i + 1] = m_cdf[i] + double(std::isfinite(weights[i]) && weights[i] > 0 ? weights[i] : 0);
    m_total = m_cdf[n];
    if (m_total > 0)
      for (size_t i = 1; i <= n; ++i) m_cdf[i] /= m_total;
    else
      for (size_t i = 1; i <= n; ++i) m_cdf[i] = double(i) / double(n);
  }
  size_t size() const { return m_func.size(); }
  double total() const { return m_total; }
  // Discrete sample: returns the bin and its probability; u is remapped to [0,1) within the bin.
  size_t sample_discrete(float u, float* prob, float* u_remapped = nullptr) const {
    if (m_func.empty()) {  // nothing to choose from: probability 0, callers skip
      if (prob) *prob = 0;
      if (u_remapped) *u_remapped = 0;
      return 0;
    }
    size_t lo = 0, hi = m_func.size();
    while (lo + 1 < hi) {  // last i with cdf[i] <= u
      size_t mid = (lo + hi) / 2;
      if (m_cdf[mid] <= u) lo = mid; else hi = mid;
    }
    double width = m_cdf[lo + 1] - m_cdf[lo];
    if (prob) *prob = float(width);
    if (u_remapped) *u_remapped = width > 0 ? clampf(float((u - m_cdf[lo]) / width), 0.0f, 0x1.fffffep-1f) : 0.0f;
    return lo;
  }
  float discrete_pdf(size_t i) const { return i + 1 < m_cdf.size() ? float(m_cdf[i + 1] - m_cdf[i]) : 0.0f; }

 private:
  std::vector<float> m_func;
  std::vector<double> m_cdf;
  double m_total = 0;
};

}  // namespace pt
