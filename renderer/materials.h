// BSDFs for the closed set of materials: eval / sample / pdf in a local shading frame.
//
// Conventions (used everywhere): the frame's z axis is the shading normal; wo (towards the viewer)
// and wi (towards the light) both point away from the surface; f(wo, wi) excludes the cosine.
// For glass and refraction z > 0 is outside (the side the normal points to).
#pragma once

#include "lane_math.h"
#include "math.h"
#include "sampling.h"
#include "scene.h"

namespace pt {

struct BsdfSample {
  Vec3 wi;
  Vec3 weight;      // f * |cos(wi)| / pdf: what the path throughput is multiplied by
  float pdf = 0;    // solid-angle pdf, or the discrete lobe probability for delta lobes
  bool delta = false;
};

// The Lambertian lobe (lane_physics.inc, which the lanes share), inline so that integrators
// specialised for diffuse-only scenes call it directly; the switches in materials.cpp use it too.
inline Vec3 diffuse_eval(const Material& m, Vec3 wo, Vec3 wi) { return lane1::diffuse_eval(m.albedo, wo, wi); }
using lane1::diffuse_pdf;  // one function for path_step and the lanes' text at width 1
inline bool diffuse_sample(const Material& m, Vec3 wo, Vec2 u, BsdfSample& s) {
  s.delta = false;
  s.weight = m.albedo;  // (albedo / pi) * cos / (cos / pi)
  return lane1::diffuse_sample(wo, u, s.wi, s.pdf);
}

// The shading normals at a hit seen from wo (world space): opaque surfaces are two-sided, so their
// normals turn to the viewer, and a shading normal facing away falls back to the geometric one
// (lane1::face_viewer). Transmissive surfaces keep theirs (z > 0 is outside). Camera and light
// paths both use it, so that they agree on every vertex they share.
[[gnu::always_inline]] inline void face_viewer(Vec3 wo, bool transmissive, Vec3& ng, Vec3& ns) {
  if (!transmissive) lane1::face_viewer(wo, ng, ns);
}

// True when the material has only delta lobes (no eval, no light sampling).
bool is_delta(const Material& m);
// True when light can pass through (the frame must not be flipped towards wo).
bool is_transmissive(const Material& m);
Vec3 eval_bsdf(const Material& m, Vec3 wo, Vec3 wi);
float bsdf_pdf(const Material& m, Vec3 wo, Vec3 wi);
// Samples wi given two uniform numbers for the direction and one for the lobe choice.
bool sample_bsdf(const Material& m, Vec3 wo, float u_lobe, Vec2 u, BsdfSample& s);
// Radiance an emissive surface sends towards wo (local frame; the front side, wo.z > 0, emits, and
// the back too for a double-sided glTF material).
Vec3 emitted_radiance(const Material& m, Vec3 wo);
bool is_emissive(const Material& m);
// The denoiser's albedo feature of a non-delta material (Intel Open Image Denoise's "albedo"
// image): its colour independent of light and view, in [0, 1]. Diffuse colour, a conductor's
// normal-incidence Fresnel reflectance, a glTF material's base colour, an emitter's colour.
Vec3 feature_albedo(const Material& m);

// Fresnel reflectance of a dielectric interface for unpolarised light; cos_i on the side of
// index eta_i. Returns 1 under total internal reflection.
float fresnel_dielectric(float cos_i, float eta_i, float eta_t);
// Fresnel reflectance of an air-conductor interface with complex index eta + i k (per channel).
Vec3 fresnel_conductor(float cos_i, Vec3 eta, Vec3 k);
// Beckmann normal distribution and Smith shadowing (Walter et al. 2007, eqs. 25 and 27).
float beckmann_d(Vec3 h, float alpha);
float smith_lambda_beckmann(Vec3 w, float alpha);

}  // namespace pt
