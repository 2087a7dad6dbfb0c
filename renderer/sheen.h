// The sheen lobe of KHR_materials_sheen as Blender's Cycles renders it: the microfibre sheen of
// Zeltner, Burley & Chiang 2022 ("Practical Multiple-Scattering Sheen Using Linearly Transformed
// Cosines"), a linearly transformed clamped cosine whose two coefficients and directional albedo
// are the paper's published rational and Gaussian fits in cos(theta_o) and roughness. The
// extension's Charlie lobe with Neubelt's visibility was measured against Cycles first: rims up to
// 9% brighter, and an albedo that climbs to 3 at grazing angles (docs/gltf.md).
// Local frame: z is the shading normal.
#pragma once

#include "math.h"

namespace pt::sheen {

// The fits hold for roughness in [0.01, 1].
inline float roughness_of(float r) { return clampf(r, 0.01f, 1); }

// The lobe's directional albedo at cos(theta_o) = mu.
inline float albedo(float mu, float r) {
  const float x = clampf(mu, 0, 1), y = roughness_of(r);
  const float s = y * (0.0206607f + 1.58491f * y) / (0.0379424f + y * (1.32227f + y));
  const float m = y * (-0.193854f + y * (-1.14885f + y * (1.7932f - 0.95943f * y * y))) / (0.046391f + y);
  const float o = y * (0.000654023f + (-0.0207818f + 0.119681f * y) * y) / (1.26264f + y * (-1.92021f + y));
  const float g = std::exp(-0.5f * sqr((x - m) / s)) / (s * std::sqrt(2 * kPi)) + o;
  return clampf(g, 0, 1);
}

// The inverse transform's coefficients: w' = (a w.x + b w.z, a w.y, w.z) in the frame whose x axis
// is wo's azimuth.
struct Ltc {
  float a = 1, b = 0;
  Vec3 x{1, 0, 0}, y{0, 1, 0};  // the frame's tangent axes
};

inline Ltc ltc(Vec3 wo, float r) {
  Ltc l;
  const float mu = clampf(wo.z, 0, 1), y = roughness_of(r);
  l.a = (2.58126f * mu + 0.813703f * y) * y / (1 + 0.310327f * mu * mu + 2.60994f * mu * y);
  l.b = std::sqrt(1 - mu) * (y - 1) * y * y * y / (0.0000254053f + 1.71228f * mu - 1.71506f * mu * y + 1.34174f * y * y);
  const float len = std::sqrt(wo.x * wo.x + wo.y * wo.y);
  if (len > 1e-7f) {
    l.x = Vec3(wo.x / len, wo.y / len, 0);
    l.y = Vec3(-l.x.y, l.x.x, 0);
  }
  return l;
}

// The density of directions the lobe reflects into: D(wi) = D_o(M^-1 wi / |M^-1 wi|) |M^-1| /
// |M^-1 wi|^3 with D_o the clamped cosine / pi (Heitz et al. 2016, eq. 2). f cos(theta_i) =
// colour x albedo x D.
inline float density(const Ltc& l, Vec3 wi) {
  if (wi.z <= 0) return 0;
  const float u = dot(wi, l.x), v = dot(wi, l.y);
  const Vec3 w(l.a * u + l.b * wi.z, l.a * v, wi.z);
  const float len2 = length_squared(w);
  return w.z * kInvPi * sqr(l.a / len2);
}

// A direction with density D from a clamped-cosine sample c: wi = M c / |M c|.
inline Vec3 sample(const Ltc& l, Vec3 c) {
  const Vec3 w((c.x - c.z * l.b) / l.a, c.y / l.a, c.z);
  const Vec3 d = normalize(w);
  return l.x * d.x + l.y * d.y + Vec3(0, 0, d.z);
}

}  // namespace pt::sheen
