// The GGX (Trowbridge-Reitz) microfacet distribution for the glTF material (pbr.cpp): isotropic
// D, the height-correlated Smith masking-shadowing, visible-normal sampling, the dielectric
// Fresnel term in pbrt's convention, and the directional albedo tables that the multiple-
// scattering compensation and the layering read. Local frame: z is the shading normal.
#pragma once

#include "math.h"

namespace pt::ggx {

// The smallest alpha the lobes take: below it D overflows float at the peak. A roughness of 0
// renders as alpha 1e-3, a blur of about 0.06 degrees.
constexpr float kMinAlpha = 1e-3f;

inline float alpha_of(float roughness) { return std::max(kMinAlpha, roughness * roughness); }

// D(h) (Walter et al. 2007, eq. 33), for h in the upper hemisphere.
inline float d(Vec3 h, float alpha) {
  if (h.z <= 0) return 0;
  const float a2 = alpha * alpha, c2 = h.z * h.z;
  const float den = c2 * (a2 - 1) + 1;
  return a2 / (kPi * den * den);
}

// Smith's Lambda (Heitz 2014, eq. 72), for w on either side.
inline float lambda(Vec3 w, float alpha) {
  const float c2 = w.z * w.z;
  if (c2 >= 1) return 0;
  const float tan2 = (1 - c2) / std::max(c2, 1e-12f);
  return 0.5f * (std::sqrt(1 + alpha * alpha * tan2) - 1);
}
inline float g1(Vec3 w, float alpha) { return 1 / (1 + lambda(w, alpha)); }
// Height-correlated masking-shadowing (Heitz 2014, eq. 99).
inline float g2(Vec3 wo, Vec3 wi, float alpha) { return 1 / (1 + lambda(wo, alpha) + lambda(wi, alpha)); }

// The density of visible normals seen from wo, D_wo(h) = G1(wo) max(0, wo.h) D(h) / |wo.z|
// (Heitz 2018, eq. 1), with wo taken on the upper side.
inline float d_visible(Vec3 wo, Vec3 h, float alpha) {
  const float c = std::fabs(wo.z);
  if (c == 0) return 0;
  const Vec3 up = wo.z < 0 ? -wo : wo;
  return g1(up, alpha) * std::max(0.0f, dot(up, h)) * d(h, alpha) / c;
}

// A visible normal from wo (Heitz 2018, "Sampling the GGX Distribution of Visible Normals",
// JCGT 7(4)), wo taken on the upper side; the normal is in the upper hemisphere.
inline Vec3 sample_visible(Vec3 wo, float alpha, Vec2 u) {
  if (wo.z < 0) wo = -wo;
  const Vec3 vh = normalize(Vec3(alpha * wo.x, alpha * wo.y, wo.z));
  const float len2 = vh.x * vh.x + vh.y * vh.y;
  const Vec3 t1 = len2 > 0 ? Vec3(-vh.y, vh.x, 0) / std::sqrt(len2) : Vec3(1, 0, 0);
  const Vec3 t2 = cross(vh, t1);
  const float r = std::sqrt(u.x), phi = 2 * kPi * u.y;
  const float p1 = r * std::cos(phi);
  const float s = 0.5f * (1 + vh.z);
  const float p2 = (1 - s) * safe_sqrt(1 - p1 * p1) + s * r * std::sin(phi);
  const Vec3 nh = t1 * p1 + t2 * p2 + vh * safe_sqrt(1 - p1 * p1 - p2 * p2);
  return normalize(Vec3(alpha * nh.x, alpha * nh.y, std::max(1e-7f, nh.z)));
}

// Fresnel reflectance of a dielectric for relative index eta = n_inside / n_outside, with cos_i
// measured on the side the light comes from (negative: from inside), as pbrt-v4's FrDielectric.
inline float fresnel(float cos_i, float eta) {
  cos_i = clampf(cos_i, -1, 1);
  if (cos_i < 0) eta = 1 / eta, cos_i = -cos_i;
  const float sin2_t = (1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) return 1;
  const float cos_t = safe_sqrt(1 - sin2_t);
  const float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  const float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return clampf(0.5f * (r_par * r_par + r_perp * r_perp), 0, 1);
}

// Refraction of wo about the microfacet normal h (on wo's side or not) with eta = n_inside /
// n_outside; false under total internal reflection. etap: the ratio across the interface as
// crossed (pbrt-v4's Refract).
inline bool refract(Vec3 wo, Vec3 h, float eta, float& etap, Vec3& wi) {
  float cos_i = dot(h, wo);
  if (cos_i < 0) eta = 1 / eta, cos_i = -cos_i, h = -h;
  const float sin2_t = std::max(0.0f, 1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) return false;
  const float cos_t = safe_sqrt(1 - sin2_t);
  wi = -wo / eta + (cos_i / eta - cos_t) * h;
  etap = eta;
  return true;
}

inline float schlick_weight(float cos) {
  const float m = clampf(1 - cos, 0, 1), m2 = m * m;
  return m2 * m2 * m;
}

// Directional albedo of the single-scattering reflection lobe at cos(theta_o) = mu, roughness r
// (alpha = r^2): with F = 1 (albedo_one), and with the dielectric Fresnel of index eta
// (albedo_dielectric). Tabulated at build time (renderer/tools/ggx_tables_gen.cpp) on these axes,
// read bilinearly (pbr.cpp).
constexpr int kTableMu = 32, kTableRough = 32, kTableEta = 17;
// The index axis: sqrt(F0) evenly from 0.005 to 0.8, an ior from 1.01 to 9. Below 1.01 the
// lobes take 1.01: at ior 1 the reflectance near grazing jumps from 1 to 0, which no table
// between two indices follows (and 1.01 reflects 2.5e-5 head on).
constexpr float kTableMinSqrtF0 = 0.005f, kTableMaxSqrtF0 = 0.8f;
// mu = x^2 with x even: grazing angles, where the Fresnel term climbs to 1, get the finer steps.
inline float table_mu(int i) { return std::max(1e-4f, sqr(float(i) / float(kTableMu - 1))); }
inline float table_roughness(int j) { return float(j) / float(kTableRough - 1); }
inline float table_eta(int k) {
  const float s = kTableMinSqrtF0 + (kTableMaxSqrtF0 - kTableMinSqrtF0) * float(k) / float(kTableEta - 1);
  return (1 + s) / (1 - s);
}
inline float min_eta() { return table_eta(0); }
float albedo_one(float mu, float roughness);
float albedo_dielectric(float mu, float roughness, float eta);

}  // namespace pt::ggx
