// Materials, directions and comparisons shared by the BSDF tests (test_bsdf.cpp, the smooth
// lobes and the Fresnel terms; test_bsdf_delta.cpp, mirror, glass, refraction and emission).
#pragma once

#include <algorithm>
#include <cmath>
#include <string>

#include "materials.h"

namespace pt {
namespace bsdf_test {

constexpr double kDeg = M_PI / 180;

// Course conductor constants (CS184 project 3-2).
inline const Vec3 kSilverEta(0.059193f, 0.059881f, 0.047366f), kSilverK(4.1283f, 3.5892f, 2.8132f);
inline const Vec3 kAluminiumEta(1.3352f, 1.0109f, 0.68955f), kAluminiumK(7.3398f, 6.6157f, 5.6471f);
// eta = 0, k = 1 makes the course's conductor Fresnel exactly 1: all energy loss is then D and G.
inline const Vec3 kWhiteEta(0, 0, 0), kWhiteK(1, 1, 1);

inline Material diffuse(Vec3 albedo) {
  Material m;
  m.type = MaterialType::diffuse;
  m.albedo = albedo;
  return m;
}
inline Material conductor(float alpha, Vec3 eta, Vec3 k) {
  Material m;
  m.type = MaterialType::microfacet;
  m.alpha = alpha;
  m.eta = eta;
  m.k = k;
  return m;
}
inline Material dielectric(MaterialType type, float ior, Vec3 albedo = Vec3(1.0f), Vec3 transmittance = Vec3(1.0f)) {
  Material m;
  m.type = type;
  m.ior = ior;
  m.albedo = albedo;
  m.transmittance = transmittance;
  return m;
}

// Direction at polar angle theta (degrees) from +z and azimuth phi (radians).
inline Vec3 dir_deg(double theta_deg, double phi = 0.7) {
  double t = theta_deg * kDeg;
  return Vec3(float(std::sin(t) * std::cos(phi)), float(std::sin(t) * std::sin(phi)), float(std::cos(t)));
}

inline bool near_rel(float a, float b, float rel, float abs_tol = 1e-7f) {
  return std::fabs(a - b) <= rel * std::max(std::fabs(a), std::fabs(b)) + abs_tol;
}
inline bool near_rel(Vec3 a, Vec3 b, float rel, float abs_tol = 1e-7f) {
  return near_rel(a.x, b.x, rel, abs_tol) && near_rel(a.y, b.y, rel, abs_tol) && near_rel(a.z, b.z, rel, abs_tol);
}
inline std::string str(Vec3 v) {
  return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

}  // namespace bsdf_test
}  // namespace pt
