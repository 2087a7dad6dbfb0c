// The sheen lobe of KHR_materials_sheen: the "Charlie" microfibre distribution (Estevez & Kulla
// 2017, "Production Friendly Microfacet Sheen BRDF") with Neubelt & Pettineo's visibility term
// (2013, "Crafting a Next-Gen Material Pipeline for The Order: 1886"), as the extension's
// specification gives them, and its directional albedo for layering the base beneath it.
// Local frame: z is the shading normal.
#pragma once

#include "math.h"

namespace pt::sheen {

// Alpha = roughness^2, kept off 0 where D's exponent 1/alpha would overflow.
inline float alpha_of(float roughness) { return std::max(0.02f, roughness * roughness); }

// D(h) = (2 + 1/alpha) sin(theta_h)^(1/alpha) / (2 pi).
inline float d(Vec3 h, float alpha) {
  const float sin2 = std::max(0.0f, 1 - h.z * h.z);
  const float inv = 1 / alpha;
  return (2 + inv) * std::pow(sin2, 0.5f * inv) * (0.5f * kInvPi);
}

// V = 1 / (4 (n.l + n.v - n.l n.v)): the lobe is f = colour D V.
inline float v(float cos_o, float cos_i) { return 1 / (4 * (cos_i + cos_o - cos_i * cos_o)); }

inline float lobe(Vec3 wo, Vec3 wi, float alpha) {
  if (wo.z <= 0 || wi.z <= 0) return 0;
  return d(normalize(wo + wi), alpha) * v(wo.z, wi.z);
}

// The lobe's directional albedo with a white colour at cos(theta_o) = mu and roughness r,
// integrated once per process on first use (only scenes with sheen pay) and read bilinearly.
float albedo(float mu, float roughness);

}  // namespace pt::sheen
