// The glTF metal-rough BSDF (pbr.h) and the GGX albedo tables its compensation reads (ggx.h).
#include "pbr.h"

#include "ggx.h"
#include "sheen.h"

namespace pt {

namespace ggx {
namespace {

// kAlbedoOne[j kTableMu + i] and kAlbedoDielectric[(k kTableRough + j) kTableMu + i] at table_mu(i),
// table_roughness(j), table_eta(k).
#include "ggx_tables.inc"

// Position x in [0, 1] on an axis of n samples: the lower index and the weight of the upper one.
inline int axis(float x, int n, float& frac) {
  const float f = clampf(x, 0, 1) * float(n - 1);
  const int i = std::min(int(f), n - 2);
  frac = f - float(i);
  return i;
}

// The mu axis is sqrt(mu) (table_mu).
inline float bilinear(const float* t, float mu, float roughness) {
  float fm, fr;
  const int i = axis(std::sqrt(std::max(0.0f, mu)), kTableMu, fm), j = axis(roughness, kTableRough, fr);
  const float a = t[j * kTableMu + i] * (1 - fm) + t[j * kTableMu + i + 1] * fm;
  const float b = t[(j + 1) * kTableMu + i] * (1 - fm) + t[(j + 1) * kTableMu + i + 1] * fm;
  return a * (1 - fr) + b * fr;
}

}  // namespace

float albedo_one(float mu, float roughness) { return bilinear(kAlbedoOne, mu, roughness); }

float albedo_dielectric(float mu, float roughness, float eta) {
  const float s = (eta - 1) / (eta + 1);
  float fk;
  const int k = axis((s - kTableMinSqrtF0) / (kTableMaxSqrtF0 - kTableMinSqrtF0), kTableEta, fk);
  const float* t = kAlbedoDielectric + k * kTableRough * kTableMu;
  return bilinear(t, mu, roughness) * (1 - fk) + bilinear(t + kTableRough * kTableMu, mu, roughness) * fk;
}

}  // namespace ggx

namespace {

// What every query at one wo needs: the lobes' weights and their Fresnel and compensation terms.
struct Lobes {
  float alpha = 1;
  Vec3 base;          // the base colour, clamped to [0, 1]
  bool flip = false;  // wo inside a transmissive material: the opaque lobes see the mirrored pair
  float eta = 1.5f;
  float f0 = 0.04f;   // the ior's head-on reflectance
  Vec3 spec_a, spec_b;  // specular Fresnel F' = a + b F(ior) (KHR_materials_specular's remap)
  Vec3 spec_comp;       // Turquin's 1 + F0 (1 - E) / E, specular layer
  Vec3 metal_comp;      // the same for the metal
  Vec3 metal_w, spec_w, diffuse_w, trans_w;  // each lobe's share of the material
  float coat = 0, coat_alpha = 1, coat_comp = 1;  // KHR_materials_clearcoat
  bool coat_tilted = false;                       // the coat has its own normal: its lobe in coat_frame
  Frame coat_frame;
  Vec3 sheen_w;                                   // KHR_materials_sheen: colour x albedo x what the coat leaves
  sheen::Ltc sheen_ltc;
  float p_metal = 0, p_spec = 0, p_diffuse = 0, p_trans = 0, p_coat = 0, p_sheen = 0;
};

// The clear coat's index (KHR_materials_clearcoat fixes it; Blender's importer sets the same).
constexpr float kCoatEta = 1.5f;

inline Vec3 lerp3(Vec3 a, Vec3 b, float t) { return a * (1 - t) + b * t; }
inline Vec3 mirrored(Vec3 w) { return Vec3(w.x, w.y, -w.z); }

Lobes prepare(const PbrParams& p, Vec3 wo) {
  Lobes l;
  const float roughness = clampf(p.roughness, 0, 1);
  l.alpha = ggx::alpha_of(roughness);
  l.flip = wo.z < 0;
  const float mu = std::min(1.0f, std::fabs(wo.z));
  const float metallic = clampf(p.metallic, 0, 1), trans = clampf(p.transmission, 0, 1);
  const Vec3 base = l.base = max(Vec3(0.0f), min(Vec3(1.0f), p.base));
  l.eta = std::max(ggx::min_eta(), p.ior);
  l.f0 = sqr((l.eta - 1) / (l.eta + 1));
  const float e1 = std::max(1e-4f, ggx::albedo_one(mu, roughness));
  const float ef = ggx::albedo_dielectric(mu, roughness, l.eta);

  // Specular layer: F' = spec (F0t + (1 - F0t) (F - F0) / (1 - F0)), linear in F.
  const float spec = std::max(0.0f, p.specular);
  const Vec3 f0t = min(Vec3(1.0f), p.specular_color * l.f0);
  const float inv = l.f0 < 1 ? 1 / (1 - l.f0) : 0.0f;
  l.spec_b = (Vec3(1.0f) - f0t) * (spec * inv);
  l.spec_a = f0t * spec - l.spec_b * l.f0;
  l.spec_comp = Vec3(1.0f) + f0t * spec * (1 / e1 - 1);
  const Vec3 spec_albedo = min(Vec3(1.0f), (l.spec_a * e1 + l.spec_b * ef) * l.spec_comp);
  // The base sees what the layer leaves; one scalar for the three channels, as Cycles layers.
  const float below = clampf(1 - max_component(spec_albedo), 0, 1);

  // The coat on top, then the sheen: each layer passes on what it does not reflect towards wo,
  // 1 - its directional albedo (as Cycles layers its closures, and the extensions' albedo scaling).
  float under = 1;
  l.coat = clampf(p.clearcoat, 0, 1);
  if (l.coat > 0) {
    const float rc = clampf(p.clearcoat_roughness, 0, 1);
    l.coat_alpha = ggx::alpha_of(rc);
    float mu_c = mu;
    if (p.coat_normal.z < 1 && !is_black(p.coat_normal)) {  // its own normal (a normal map's)
      l.coat_tilted = true;
      l.coat_frame = Frame(p.coat_normal);
      mu_c = std::min(1.0f, std::max(0.0f, l.coat_frame.to_local(l.flip ? mirrored(wo) : wo).z));
    }
    l.coat_comp = 1 + ggx::fresnel(1, kCoatEta) * (1 / std::max(1e-4f, ggx::albedo_one(mu_c, rc)) - 1);
    const float ec = mu_c > 0 ? std::min(1.0f, ggx::albedo_dielectric(mu_c, rc, kCoatEta) * l.coat_comp) : 0.0f;
    l.p_coat = l.coat * ec;
    under = 1 - l.coat * ec;
  }
  const Vec3 sheen_color = max(Vec3(0.0f), min(Vec3(1.0f), p.sheen_color));
  if (max_component(sheen_color) > 0) {
    const Vec3 wo_up = l.flip ? mirrored(wo) : wo;
    l.sheen_ltc = sheen::ltc(wo_up, p.sheen_roughness);
    const float es = sheen::albedo(mu, p.sheen_roughness);
    l.sheen_w = sheen_color * (es * under);
    l.p_sheen = luminance(sheen_color) * es * under;
    under *= 1 - max_component(sheen_color) * es;
  }

  l.metal_comp = Vec3(1.0f) + base * (1 / e1 - 1);
  l.metal_w = Vec3(metallic * under);
  l.spec_w = Vec3((1 - metallic) * (1 - trans) * under);
  l.diffuse_w = base * ((1 - metallic) * (1 - trans) * below * under);
  l.trans_w = Vec3((1 - metallic) * trans * under);
  // Expected weights towards wo pick the lobe to sample.
  const Vec3 metal_albedo = lerp3(base, Vec3(1.0f), ggx::schlick_weight(mu));
  l.p_metal = metallic * under * luminance(metal_albedo);
  l.p_spec = (1 - metallic) * (1 - trans) * under * luminance(spec_albedo);
  l.p_diffuse = luminance(l.diffuse_w);
  l.p_trans = (1 - metallic) * trans * under;
  const float total = l.p_metal + l.p_spec + l.p_diffuse + l.p_trans + l.p_coat + l.p_sheen;
  if (total > 0) {
    const float inv_total = 1 / total;
    l.p_metal *= inv_total, l.p_spec *= inv_total, l.p_diffuse *= inv_total, l.p_trans *= inv_total;
    l.p_coat *= inv_total, l.p_sheen *= inv_total;
  }
  return l;
}

// The opaque lobes (metal, specular, diffuse) for wo, wi both above the surface: f and the
// mixture's pdf share.
void opaque(const Lobes& l, Vec3 wo, Vec3 wi, Vec3& f, float& pdf) {
  if (wo.z <= 0 || wi.z <= 0) return;
  if (l.p_diffuse > 0) {
    f += l.diffuse_w * kInvPi;
    pdf += l.p_diffuse * wi.z * kInvPi;
  }
  if (l.p_sheen > 0) {  // f cos = colour x albedo x D
    const float d = sheen::density(l.sheen_ltc, wi);
    f += l.sheen_w * (d / wi.z);
    pdf += l.p_sheen * d;
  }
  const Vec3 h = normalize(wo + wi);
  if (l.p_coat > 0) {
    // In the coat's own frame where it has a normal map (both directions above the base too).
    const Vec3 wo_c = l.coat_tilted ? l.coat_frame.to_local(wo) : wo, wi_c = l.coat_tilted ? l.coat_frame.to_local(wi) : wi;
    const Vec3 h_c = l.coat_tilted ? l.coat_frame.to_local(h) : h;
    const float dc = wo_c.z > 0 && wi_c.z > 0 ? ggx::d(h_c, l.coat_alpha) : 0.0f;
    if (dc > 0) {
      // The integrator weighs f by the cosine to the shading normal; the coat's own cosine is to
      // its normal (as Cycles' closures each carry theirs): wi_c.z / wi.z turns one into the other.
      const float cosines = l.coat_tilted ? wi_c.z / wi.z : 1.0f;
      f += Vec3(l.coat * l.coat_comp * ggx::fresnel(dot(wo_c, h_c), kCoatEta) * dc * ggx::g2(wo_c, wi_c, l.coat_alpha) /
                (4 * wo_c.z * wi_c.z) * cosines);
      pdf += l.p_coat * ggx::g1(wo_c, l.coat_alpha) * dc / (4 * wo_c.z);
    }
  }
  if (l.p_metal <= 0 && l.p_spec <= 0) return;
  const float d = ggx::d(h, l.alpha);
  if (!(d > 0)) return;
  const float lobe = d * ggx::g2(wo, wi, l.alpha) / (4 * wo.z * wi.z);
  const float c = dot(wo, h);
  if (l.p_metal > 0) f += l.metal_w * l.metal_comp * lerp3(l.base, Vec3(1.0f), ggx::schlick_weight(c)) * lobe;
  if (l.p_spec > 0) f += l.spec_w * l.spec_comp * (l.spec_a + l.spec_b * ggx::fresnel(c, l.eta)) * lobe;
  const float pdf_h = ggx::g1(wo, l.alpha) * d / (4 * wo.z);  // reflection through a visible normal
  pdf += (l.p_metal + l.p_spec) * pdf_h;
}

// The rough dielectric (pbrt-v4's DielectricBxDF after Walter et al. 2007), radiance transport:
// f and its pdf given that this lobe was chosen.
void dielectric(const Lobes& l, Vec3 wo, Vec3 wi, Vec3& f, float& pdf) {
  const float co = wo.z, ci = wi.z;
  if (co == 0 || ci == 0) return;
  const bool reflect = co * ci > 0;
  const float etap = reflect ? 1 : (co > 0 ? l.eta : 1 / l.eta);
  Vec3 h = wi * etap + wo;
  if (length_squared(h) == 0) return;
  h = normalize(h);
  if (h.z < 0) h = -h;
  if (dot(h, wi) * ci < 0 || dot(h, wo) * co < 0) return;  // back-facing microfacets
  const float fr = ggx::fresnel(dot(wo, h), l.eta);
  const float d = ggx::d(h, l.alpha), g = ggx::g2(wo, wi, l.alpha);
  const float dv = ggx::d_visible(wo, h, l.alpha);
  if (reflect) {
    f += Vec3(d * g * fr / std::fabs(4 * ci * co));
    pdf += dv / (4 * std::fabs(dot(wo, h))) * fr;
    return;
  }
  const float denom = sqr(dot(wi, h) + dot(wo, h) / etap);
  if (!(denom > 0)) return;
  const float ft = d * (1 - fr) * g * std::fabs(dot(wi, h) * dot(wo, h) / (ci * co * denom)) / (etap * etap);
  f += l.base * ft;  // glTF tints what passes by the base colour
  pdf += dv * std::fabs(dot(wi, h)) / denom * (1 - fr);
}

void eval_all(const Lobes& l, Vec3 wo, Vec3 wi, Vec3& f, float& pdf) {
  f = Vec3(0.0f);
  pdf = 0;
  if (l.flip) opaque(l, mirrored(wo), mirrored(wi), f, pdf);
  else opaque(l, wo, wi, f, pdf);
  if (l.p_trans > 0) {
    Vec3 ft(0.0f);
    float pt = 0;
    dielectric(l, wo, wi, ft, pt);
    f += l.trans_w * ft;
    pdf += l.p_trans * pt;
  }
  if (!is_finite(f) || !std::isfinite(pdf)) f = Vec3(0.0f), pdf = 0;
}

}  // namespace

Vec3 pbr_eval(const PbrParams& p, Vec3 wo, Vec3 wi) {
  Vec3 f;
  float pdf;
  eval_all(prepare(p, wo), wo, wi, f, pdf);
  return f;
}

float pbr_pdf(const PbrParams& p, Vec3 wo, Vec3 wi) {
  Vec3 f;
  float pdf;
  eval_all(prepare(p, wo), wo, wi, f, pdf);
  return pdf;
}

PbrLobeWeights pbr_lobe_weights(const PbrParams& p, Vec3 wo) {
  const Lobes l = prepare(p, wo);
  return {l.p_metal, l.p_spec, l.p_diffuse, l.p_trans, l.p_coat, l.p_sheen};
}

bool pbr_sample(const PbrParams& p, Vec3 wo, float u_lobe, Vec2 u, BsdfSample& s) {
  s.delta = false;
  if (wo.z == 0) return false;
  const Lobes l = prepare(p, wo);
  const Vec3 wo_up = l.flip ? mirrored(wo) : wo;  // the opaque lobes' view
  Vec3 wi;
  float x = u_lobe;
  if (x < l.p_diffuse + l.p_sheen) {
    wi = sample_cosine_hemisphere(u);
    if (x >= l.p_diffuse) wi = sheen::sample(l.sheen_ltc, wi);
    if (l.flip) wi = mirrored(wi);
  } else if ((x -= l.p_diffuse + l.p_sheen) < l.p_metal + l.p_spec + l.p_coat) {
    if (x < l.p_metal + l.p_spec || !l.coat_tilted) {
      wi = reflect(wo_up, ggx::sample_visible(wo_up, x < l.p_metal + l.p_spec ? l.alpha : l.coat_alpha, u));
    } else {  // the coat's visible normals, in its frame
      const Vec3 wo_c = l.coat_frame.to_local(wo_up);
      if (wo_c.z <= 0) return false;
      const Vec3 wi_c = reflect(wo_c, ggx::sample_visible(wo_c, l.coat_alpha, u));
      if (wi_c.z <= 0) return false;  // below the coat: not in its lobe
      wi = l.coat_frame.to_world(wi_c);
    }
    if (wi.z <= 0) return false;
    if (l.flip) wi = mirrored(wi);
  } else {
    x -= l.p_metal + l.p_spec + l.p_coat;
    if (!(l.p_trans > 0)) return false;
    // Reflect or refract through a visible normal, in proportion to Fresnel (the remapped draw).
    const Vec3 h = ggx::sample_visible(wo, l.alpha, u);
    const float fr = ggx::fresnel(dot(wo, h), l.eta);
    if (clampf(x / l.p_trans, 0, 1) < fr) {
      wi = reflect(wo, h);
      if (wi.z * wo.z <= 0) return false;
    } else {
      float etap;
      if (!ggx::refract(wo, h, l.eta, etap, wi)) return false;
      if (wi.z * wo.z >= 0) return false;
    }
  }
  Vec3 f;
  float pdf;
  eval_all(l, wo, wi, f, pdf);
  if (!(pdf > 0) || is_black(f)) return false;
  s.wi = wi;
  s.pdf = pdf;
  s.weight = f * (std::fabs(wi.z) / pdf);
  return is_finite(s.weight);
}

}  // namespace pt
