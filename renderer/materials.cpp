// The one place that switches over MaterialType: BSDF eval / sample / pdf and emission.
// Frame conventions are in materials.h.
#include "materials.h"

#include <algorithm>

#include "pbr.h"
#include "sampling.h"

namespace pt {

const char* material_type_name(MaterialType type) {
  switch (type) {
    case MaterialType::diffuse: return "diffuse";
    case MaterialType::mirror: return "mirror";
    case MaterialType::glass: return "glass";
    case MaterialType::refraction: return "refraction";
    case MaterialType::microfacet: return "microfacet";
    case MaterialType::emission: return "emission";
    case MaterialType::pbr: return "pbr";
  }
  return "?";
}

bool is_delta(const Material& m) {
  return m.type == MaterialType::mirror || m.type == MaterialType::glass || m.type == MaterialType::refraction;
}

bool is_transmissive(const Material& m) {
  return m.type == MaterialType::glass || m.type == MaterialType::refraction ||
         (m.type == MaterialType::pbr && (m.pbr.transmission > 0 || m.pbr.transmission_tex.used()));
}

Vec3 feature_albedo(const Material& m) {
  Vec3 a;
  switch (m.type) {
    case MaterialType::microfacet: {  // F(0) = ((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2)
      auto f0 = [](float eta, float k) { return ((eta - 1) * (eta - 1) + k * k) / ((eta + 1) * (eta + 1) + k * k); };
      a = Vec3(f0(m.eta.x, m.k.x), f0(m.eta.y, m.k.y), f0(m.eta.z, m.k.z));
      break;
    }
    case MaterialType::emission: a = m.radiance; break;
    case MaterialType::pbr: a = m.pbr.unlit ? m.pbr.emissive : m.pbr.base + m.pbr.emissive; break;  // a lamp: its light's colour
    default: a = m.albedo;
  }
  auto unit = [](float v) { return v > 0 ? std::min(v, 1.0f) : 0.0f; };  // also NaN -> 0
  return Vec3(unit(a.x), unit(a.y), unit(a.z));
}

bool is_emissive(const Material& m) {
  if (m.type == MaterialType::pbr) return !is_black(m.pbr.emissive);
  return m.type == MaterialType::emission && !is_black(m.radiance);
}

float fresnel_dielectric(float cos_i, float eta_i, float eta_t) {
  // Index-matched: no interface. (Otherwise 1 - cos^2 rounds to 1 near grazing and reads as TIR.)
  if (eta_i == eta_t) return 0;
  cos_i = clampf(std::fabs(cos_i), 0.0f, 1.0f);
  float eta = eta_i / eta_t;
  float sin2_t = eta * eta * (1 - cos_i * cos_i);
  if (sin2_t >= 1) return 1;
  float cos_t = safe_sqrt(1 - sin2_t);
  float rs = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
  float rp = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
  float r = 0.5f * (rs * rs + rp * rp);
  return std::isfinite(r) ? clampf(r, 0.0f, 1.0f) : 1.0f;
}

Vec3 fresnel_conductor(float cos_i, Vec3 eta, Vec3 k) {
  // The course's air-conductor approximation (CS184 project 3-2, part 2).
  float c = clampf(std::fabs(cos_i), 0.0f, 1.0f), c2 = c * c;
  Vec3 out;
  for (int ch = 0; ch < 3; ++ch) {
    float n = eta[ch], kk = k[ch], nk = n * n + kk * kk;
    float rs = (nk - 2 * n * c + c2) / (nk + 2 * n * c + c2);
    float rp = (nk * c2 - 2 * n * c + 1) / (nk * c2 + 2 * n * c + 1);
    float r = 0.5f * (rs + rp);
    out[ch] = std::isfinite(r) ? clampf(r, 0.0f, 1.0f) : 1.0f;
  }
  return out;
}

float beckmann_d(Vec3 h, float alpha) {
  if (h.z <= 0) return 0;  // the chi+(h.n) factor of eq. 25: no back-facing microfacets
  float cos2 = h.z * h.z;
  float tan2 = (1 - cos2) / cos2;
  float a2 = alpha * alpha;
  float d = std::exp(-tan2 / a2) / (kPi * a2 * cos2 * cos2);
  return std::isfinite(d) ? d : 0;
}

float smith_lambda_beckmann(Vec3 w, float alpha) {
  float cos2 = w.z * w.z, sin2 = std::max(0.0f, 1 - cos2);
  if (sin2 == 0) return 0;
  float a = std::fabs(w.z) / (alpha * std::sqrt(sin2));  // 1 / (alpha tan theta)
  if (a > 8) return 0;                                  // Lambda underflows: no shadowing
  // erf(a) - 1 = -erfc(a): in float, erf(a) - 1 cancels to noise (even negative) from a ~ 3.
  return 0.5f * (std::exp(-a * a) / (a * std::sqrt(kPi)) - std::erfc(a));
}

namespace {

Vec3 microfacet_f(const Material& m, Vec3 wo, Vec3 wi) {
  if (wo.z <= 0 || wi.z <= 0) return Vec3(0.0f);
  Vec3 h = normalize(wo + wi);
  if (is_black(h)) return Vec3(0.0f);
  float g = 1 / (1 + smith_lambda_beckmann(wo, m.alpha) + smith_lambda_beckmann(wi, m.alpha));
  float d = beckmann_d(h, m.alpha);
  Vec3 f = fresnel_conductor(dot(wi, h), m.eta, m.k) * (g * d / (4 * wo.z * wi.z));
  return is_finite(f) ? f : Vec3(0.0f);
}

// Beckmann importance sampling of D(h) cos(theta_h) (Walter et al. 2007, eqs. 28-29).
float microfacet_pdf(const Material& m, Vec3 wo, Vec3 wi) {
  if (wo.z <= 0 || wi.z <= 0) return 0;
  Vec3 h = normalize(wo + wi);
  float wo_h = dot(wo, h);
  if (wo_h <= 0) return 0;
  float pdf = beckmann_d(h, m.alpha) * h.z / (4 * wo_h);
  return std::isfinite(pdf) ? pdf : 0;
}

}  // namespace

Vec3 eval_bsdf(const Material& m, Vec3 wo, Vec3 wi) {
  switch (m.type) {
    case MaterialType::diffuse:
      return diffuse_eval(m, wo, wi);
    case MaterialType::microfacet:
      return microfacet_f(m, wo, wi);
    case MaterialType::pbr:
      return pbr_eval(m.pbr, wo, wi);
    case MaterialType::mirror:
    case MaterialType::glass:
    case MaterialType::refraction:
    case MaterialType::emission:
      return Vec3(0.0f);
  }
  return Vec3(0.0f);
}

float bsdf_pdf(const Material& m, Vec3 wo, Vec3 wi) {
  switch (m.type) {
    case MaterialType::diffuse:
      return diffuse_pdf(wo, wi);
    case MaterialType::microfacet:
      return microfacet_pdf(m, wo, wi);
    case MaterialType::pbr:
      return pbr_pdf(m.pbr, wo, wi);
    case MaterialType::mirror:
    case MaterialType::glass:
    case MaterialType::refraction:
    case MaterialType::emission:
      return 0;
  }
  return 0;
}

bool sample_bsdf(const Material& m, Vec3 wo, float u_lobe, Vec2 u, BsdfSample& s) {
  s.delta = false;
  switch (m.type) {
    case MaterialType::diffuse:
      return diffuse_sample(m, wo, u, s);
    case MaterialType::microfacet: {
      if (wo.z <= 0) return false;
      float a2 = m.alpha * m.alpha;
      float tan2 = -a2 * std::log1p(-std::min(u.x, 0x1.fffffep-1f));
      float cos_h = 1 / std::sqrt(1 + tan2), sin_h = safe_sqrt(1 - cos_h * cos_h);
      float phi = 2 * kPi * u.y;
      Vec3 h(sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h);
      s.wi = reflect(wo, h);
      if (s.wi.z <= 0) return false;
      s.pdf = microfacet_pdf(m, wo, s.wi);
      if (!(s.pdf > 0)) return false;
      s.weight = microfacet_f(m, wo, s.wi) * (s.wi.z / s.pdf);
      return is_finite(s.weight);
    }
    case MaterialType::mirror: {
      s.wi = Vec3(-wo.x, -wo.y, wo.z);
      s.pdf = 1;
      s.delta = true;
      s.weight = m.albedo;
      if (m.schlick) {
        const float c = clampf(1 - std::fabs(wo.z), 0, 1), c2 = c * c;
        s.weight = m.albedo + (Vec3(1.0f) - m.albedo) * (c2 * c2 * c);
      }
      return true;
    }
    case MaterialType::glass:
    case MaterialType::refraction: {
      bool outside = wo.z > 0;
      float n_o = outside ? 1.0f : m.ior, n_t = outside ? m.ior : 1.0f;  // wo side, other side
      float eta = n_o / n_t;
      float cos_o = std::fabs(wo.z);
      float sin2_t = eta * eta * std::max(0.0f, 1 - cos_o * cos_o);
      float r = fresnel_dielectric(cos_o, n_o, n_t);
      s.delta = true;
      if (m.type == MaterialType::refraction) {
        if (sin2_t >= 1) return false;  // total internal reflection: refraction-only absorbs
        r = 0;
      }
      if (u_lobe < r) {
        s.wi = Vec3(-wo.x, -wo.y, wo.z);
        s.pdf = r;
        s.weight = m.albedo;  // r * reflectance / r
        return true;
      }
      float cos_t = safe_sqrt(1 - sin2_t);
      s.wi = Vec3(-eta * wo.x, -eta * wo.y, outside ? -cos_t : cos_t);
      s.pdf = 1 - r;
      // Radiance is compressed by (n_o / n_t)^2 across the interface (Veach 1997, section 5.2).
      s.weight = m.transmittance * (eta * eta);
      return s.pdf > 0;
    }
    case MaterialType::pbr:
      return pbr_sample(m.pbr, wo, u_lobe, u, s);
    case MaterialType::emission:
      return false;
  }
  return false;
}

Vec3 emitted_radiance(const Material& m, Vec3 wo) {
  if (m.type == MaterialType::pbr) return wo.z > 0 || (m.pbr.double_sided && wo.z < 0) ? m.pbr.emissive : Vec3(0.0f);
  if (wo.z <= 0) return Vec3(0.0f);
  return m.type == MaterialType::emission ? m.radiance : Vec3(0.0f);
}

}  // namespace pt
