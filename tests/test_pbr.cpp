// The glTF metal-rough BSDF (pbr.h): sampling against the pdf for each lobe and their mix
// (chi-square at significance 1e-3, fixed seeds), sample weights against eval / pdf, white
// furnaces (a white rough metal and a white dielectric keep their energy within 1%), no energy
// gain at any parameter limit, the GGX tables against brute-force integrals, transmission.
#include "pbr.h"

#include <gtest/gtest.h>

#include <ostream>
#include <string>
#include <vector>

#include "bsdf_util.h"
#include "ggx.h"
#include "rng.h"
#include "stat_util.h"

using namespace pt;
using namespace pt::bsdf_test;
using pt::test::chi2_test;
using pt::test::SphereBins;

namespace {

// The file's 43 chi-square tests (13 lobes from three or four angles) fail by chance together with
// probability 0.01.
const double kAlpha = pt::test::sidak_alpha(0.01, 43);

PbrParams params(Vec3 base, float metallic, float roughness, float transmission = 0, float ior = 1.5f) {
  PbrParams p;
  p.base = base;
  p.metallic = metallic;
  p.roughness = roughness;
  p.transmission = transmission;
  p.ior = ior;
  return p;
}

PbrParams coated(PbrParams p, float coat, float roughness) {
  p.clearcoat = coat;
  p.clearcoat_roughness = roughness;
  return p;
}

PbrParams sheened(PbrParams p, Vec3 colour, float roughness) {
  p.sheen_color = colour;
  p.sheen_roughness = roughness;
  return p;
}

PbrParams tilted(PbrParams p, Vec3 coat_normal) {  // the coat's own normal, in the shading frame
  p.coat_normal = coat_normal;
  return p;
}

struct Case {
  std::string name;
  PbrParams p;
};
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }
std::string case_name(const testing::TestParamInfo<Case>& info) { return info.param.name; }

// Each lobe alone, then mixes: a plastic (specular over diffuse), a half metal, rough glass,
// everything at once, and the clear coat and sheen layers over them.
std::vector<Case> cases() {
  return {
      {"Metal", params({0.9f, 0.6f, 0.3f}, 1, 0.5f)},
      {"RoughMetal", params({0.9f, 0.6f, 0.3f}, 1, 1.0f)},
      {"Plastic", params({0.2f, 0.4f, 0.8f}, 0, 0.4f)},
      {"BlackPlastic", params({0, 0, 0}, 0, 0.6f)},
      {"HalfMetal", params({0.8f, 0.8f, 0.8f}, 0.5f, 0.5f)},
      {"RoughGlass", params({1, 1, 1}, 0, 0.5f, 1)},
      {"DenseRoughGlass", params({0.9f, 1, 0.8f}, 0, 0.7f, 1, 2.4f)},
      {"Everything", params({0.7f, 0.5f, 0.3f}, 0.3f, 0.6f, 0.5f)},
      {"CoatedPlastic", coated(params({0.2f, 0.4f, 0.8f}, 0, 0.5f), 1, 0.35f)},
      {"CoatedMetal", coated(params({0.9f, 0.6f, 0.3f}, 1, 0.6f), 0.7f, 0.3f)},
      {"Sheen", sheened(params({0.3f, 0.1f, 0.1f}, 0, 0.8f), {0.8f, 0.6f, 0.4f}, 0.5f)},
      {"CoatSheenGlass", coated(sheened(params({0.7f, 0.5f, 0.3f}, 0.3f, 0.6f, 0.5f), Vec3(0.5f), 0.3f), 0.5f, 0.2f)},
      {"TiltedCoat", tilted(coated(params({0.2f, 0.4f, 0.8f}, 0, 0.5f), 1, 0.35f), normalize(Vec3(0.3f, 0.1f, 0.95f)))},
  };
}

class PbrSampling : public testing::TestWithParam<Case> {};

// Sampled directions follow pbr_pdf over the whole sphere (transmission goes below), pdf
// integrates to the fraction of successful samples, and each sample's pdf and weight agree with
// pbr_pdf and pbr_eval. From outside at three angles, and from inside for the glass.
TEST_P(PbrSampling, SamplesFollowThePdf) {
  const PbrParams& p = GetParam().p;
  // A narrow lobe (a coat or base at roughness 0.3 or less, alpha <= 0.09) gets bins of about 2
  // degrees in theta: 6 degrees would hold all of it in a few.
  const bool narrow = p.roughness <= 0.3f || (p.clearcoat > 0 && p.clearcoat_roughness <= 0.3f);
  SphereBins bins(narrow ? 96 : 32, narrow ? 96 : 48);
  std::vector<Vec3> wos = {dir_deg(0), dir_deg(45), dir_deg(80)};
  if (p.transmission > 0) wos.push_back(-dir_deg(30));
  for (Vec3 wo : wos) {
    SCOPED_TRACE(testing::Message() << "wo = " << str(wo));
    const int n = 300000;
    std::vector<double> observed(size_t(bins.size()) + 1, 0.0);
    Pcg32 rng(uint64_t(1000 * std::fabs(wo.z) + (wo.z < 0 ? 5000 : 7)), 3);  // a seed per wo, inside too
    int bad = 0;
    for (int i = 0; i < n; ++i) {
      const float ul = rng.next_float();
      const Vec2 u = rng.next_2d();
      BsdfSample s;
      if (!pbr_sample(p, wo, ul, u, s)) {
        observed.back() += 1;
        continue;
      }
      observed[size_t(bins.index(s.wi))] += 1;
      const float pdf = pbr_pdf(p, wo, s.wi);
      const Vec3 expect = pbr_eval(p, wo, s.wi) * (std::fabs(s.wi.z) / pdf);
      if (s.delta || !near_rel(s.pdf, pdf, 1e-4f) || !near_rel(s.weight, expect, 1e-3f, 1e-6f)) {
        if (bad++ == 0) ADD_FAILURE() << "sample " << str(s.wi) << ": pdf " << s.pdf << " vs " << pdf << ", weight "
                                      << str(s.weight) << " vs " << str(expect);
      }
    }
    EXPECT_EQ(bad, 0);
    std::vector<double> expected = bins.integrate([&](Vec3 wi) { return pbr_pdf(p, wo, wi); }, 10, 8);
    const double integral = test::sum(expected), success = 1 - observed.back() / n;
    const double sigma = std::sqrt(std::max(success * (1 - success), 1.0 / n) / n);
    EXPECT_LE(integral, 1 + 2e-3) << "the pdf integrates to more than 1";
    EXPECT_NEAR(integral, success, 5 * sigma + 2e-3) << "pdf integral vs the fraction of successful samples";
    for (double& e : expected) e *= n;
    expected.push_back(std::max(0.0, n * (1 - integral)));
    const auto r = chi2_test(observed, expected, kAlpha);
    EXPECT_TRUE(r.passed) << r.message;
  }
}

INSTANTIATE_TEST_SUITE_P(Lobes, PbrSampling, testing::ValuesIn(cases()), case_name);

// The directional albedo at wo: the mean sample weight (per channel), by importance sampling.
Vec3 albedo(const PbrParams& p, Vec3 wo, int n, uint64_t seed) {
  Pcg32 rng(seed, 5);
  Vec3 sum(0.0f);
  for (int i = 0; i < n; ++i) {
    const float ul = rng.next_float();
    BsdfSample s;
    if (pbr_sample(p, wo, ul, rng.next_2d(), s)) sum += s.weight;
  }
  return sum / float(n);
}

// White furnaces: single-scattering GGX loses up to a third of the light at roughness 1; the
// compensation gives it back. A white metal and a white plastic reflect everything, within 1%.
TEST(PbrFurnace, WhiteSurfacesKeepTheirEnergy) {
  for (float metallic : {1.0f, 0.0f})
    for (float roughness : {0.1f, 0.4f, 0.7f, 1.0f})
      for (double theta : {0.0, 40.0, 70.0, 85.0}) {
        const Vec3 a = albedo(params(Vec3(1.0f), metallic, roughness), dir_deg(theta), 200000, 11);
        EXPECT_NEAR(a.y, 1.0, 0.01) << "metallic " << metallic << ", roughness " << roughness << ", theta " << theta;
      }
}

// What single scattering loses, for scale: without compensation the white rough metal would keep
// E(mu); the table says so and the brute-force integral agrees.
TEST(PbrFurnace, TheTablesMatchBruteForceIntegrals) {
  for (float roughness : {0.2f, 0.37f, 0.4f, 0.6f, 1.0f})
    for (double theta : {0.0, 50.0, 80.0}) {
      const Vec3 wo = dir_deg(theta);
      const float alpha = ggx::alpha_of(roughness);
      double e1 = 0, ef = 0;
      const int n = 400000;
      Pcg32 rng(3, 9);
      for (int i = 0; i < n; ++i) {
        const Vec3 h = ggx::sample_visible(wo, alpha, rng.next_2d());
        const Vec3 wi = reflect(wo, h);
        if (wi.z <= 0) continue;
        const double w = ggx::g2(wo, wi, alpha) / ggx::g1(wo, alpha);
        e1 += w;
        ef += w * ggx::fresnel(dot(wo, h), 1.5f);
      }
      e1 /= n, ef /= n;
      EXPECT_NEAR(ggx::albedo_one(wo.z, roughness), e1, 0.003) << roughness << " " << theta;
      EXPECT_NEAR(ggx::albedo_dielectric(wo.z, roughness, 1.5f), ef, 0.002) << roughness << " " << theta;
      if (roughness == 1.0f) EXPECT_LT(e1, 0.9) << "rough GGX loses energy to single scattering";
    }
}

// No parameter, however extreme, makes a surface reflect more than it receives or gives NaN.
TEST(PbrFurnace, NoEnergyGainAtAnyLimit) {
  std::vector<PbrParams> ps;
  for (float r : {0.0f, 1e-4f, 0.02f, 1.0f})
    for (float ior : {1.0f, 1.0001f, 1.5f, 4.0f, 1000.0f})
      for (float spec : {0.0f, 1.0f}) {
        PbrParams p = params(Vec3(1.0f), 0, r, 0, ior);
        p.specular = spec;
        p.specular_color = Vec3(2.0f);  // over 1: F0 is clamped
        ps.push_back(p);
        ps.push_back(params(Vec3(1.0f), 1, r, 0, ior));
        ps.push_back(params(Vec3(1.0f), 0, r, 1, ior));
      }
  PbrParams wild = params(Vec3(5, -1, 1e30f), 2, -1, 3, -2);  // out-of-range factors are clamped
  ps.push_back(wild);
  for (const PbrParams& p : ps)
    for (double theta : {0.0, 60.0, 89.9}) {
      const Vec3 a = albedo(p, dir_deg(theta), 20000, 17);
      ASSERT_TRUE(is_finite(a)) << "roughness " << p.roughness << " ior " << p.ior;
      EXPECT_LE(max_component(a), 1.02f) << "roughness " << p.roughness << " ior " << p.ior << " metallic "
                                         << p.metallic << " transmission " << p.transmission << " theta " << theta;
      EXPECT_GE(min_component(a), 0.0f);
    }
}

// The specular layer is there: a black plastic reflects the Fresnel share (4% head on at ior
// 1.5, more at grazing) and a white diffuse under it the rest; at metallic 0.5 the material is
// the average of the two, not either (glTF 2.0, Appendix B: mix(dielectric, metal, metallic)).
TEST(PbrMix, PlasticsReflectAndMetallicBlends) {
  const Vec3 head_on = dir_deg(0);
  const Vec3 black = albedo(params(Vec3(0.0f), 0, 0.3f), head_on, 200000, 23);
  EXPECT_NEAR(black.y, 0.04, 0.006) << "the dielectric specular layer";
  const Vec3 grazing = albedo(params(Vec3(0.0f), 0, 0.3f), dir_deg(80), 200000, 23);
  EXPECT_GT(grazing.y, 0.15) << "Fresnel brightens the layer at grazing angles";
  const Vec3 wi = dir_deg(30, 2.0);
  const Vec3 wo = dir_deg(35, 2.0 + M_PI);
  const PbrParams half = params({0.9f, 0.5f, 0.1f}, 0.5f, 0.4f);
  const Vec3 f = pbr_eval(half, wo, wi);
  const Vec3 f0 = pbr_eval(params({0.9f, 0.5f, 0.1f}, 0, 0.4f), wo, wi);
  const Vec3 f1 = pbr_eval(params({0.9f, 0.5f, 0.1f}, 1, 0.4f), wo, wi);
  EXPECT_TRUE(near_rel(f, (f0 + f1) * 0.5f, 1e-4f)) << str(f) << " vs " << str((f0 + f1) * 0.5f);
}

// Rough glass sends light through (tinted by the base colour) and, white, keeps its energy:
// reflection plus transmission near 1 (radiance entering is compressed by 1 / eta^2, so the
// transmitted energy is the weight times eta^2).
TEST(PbrGlass, RoughGlassTransmitsAndConserves) {
  const PbrParams glass = params(Vec3(1.0f), 0, 0.3f, 1, 1.5f);
  Pcg32 rng(31, 1);
  double reflected = 0, transmitted = 0;
  const int n = 200000;
  const Vec3 wo = dir_deg(20);
  for (int i = 0; i < n; ++i) {
    BsdfSample s;
    const float ul = rng.next_float();
    if (!pbr_sample(glass, wo, ul, rng.next_2d(), s)) continue;
    // Radiance entering glass is compressed by 1 / 1.5^2; count energy, not radiance.
    if (s.wi.z > 0) reflected += s.weight.y;
    else transmitted += s.weight.y * 1.5 * 1.5;
  }
  reflected /= n, transmitted /= n;
  EXPECT_NEAR(reflected, 0.045, 0.015) << "Fresnel reflection near normal incidence";
  EXPECT_GT(transmitted, 0.9);
  EXPECT_NEAR(reflected + transmitted, 1.0, 0.05) << "single scattering keeps most of it at roughness 0.3";
  const PbrParams tinted = params({1, 0.5f, 0.25f}, 0, 0.3f, 1, 1.5f);
  const Vec3 through = pbr_eval(tinted, wo, dir_deg(170));
  EXPECT_NEAR(through.y / through.x, 0.5, 1e-4);
  EXPECT_NEAR(through.z / through.x, 0.25, 1e-4);
}

// Visible-normal sampling gives normals in proportion to D_wo (its pdf integrates to 1).
TEST(Ggx, VisibleNormalDensityIntegratesToOne) {
  for (float alpha : {0.05f, 0.3f, 1.0f})
    for (double theta : {0.0, 60.0, 85.0}) {
      const Vec3 wo = dir_deg(theta);
      SphereBins bins(64, 64);
      const auto per_bin = bins.integrate([&](Vec3 h) { return ggx::d_visible(wo, h, alpha); }, 16, 8);
      EXPECT_NEAR(test::sum(per_bin), 1.0, alpha < 0.1f ? 0.02 : 0.005) << alpha << " " << theta;
    }
}

}  // namespace

namespace {

// glTF's smooth untextured metals are the exact mirror with Schlick's Fresnel: the base colour
// head on, white at grazing. The course's mirror (schlick false) keeps its constant reflectance.
TEST(PbrMirror, SmoothMetalsFollowSchlick) {
  Material m;
  m.type = MaterialType::mirror;
  m.albedo = Vec3(0.9f, 0.6f, 0.2f);
  m.schlick = true;
  BsdfSample s;
  ASSERT_TRUE(sample_bsdf(m, dir_deg(0), 0.5f, Vec2{0.5f, 0.5f}, s));
  EXPECT_TRUE(near_rel(s.weight, m.albedo, 1e-6f));
  ASSERT_TRUE(sample_bsdf(m, dir_deg(89), 0.5f, Vec2{0.5f, 0.5f}, s));
  EXPECT_GT(s.weight.z, 0.9f);
  m.schlick = false;
  ASSERT_TRUE(sample_bsdf(m, dir_deg(89), 0.5f, Vec2{0.5f, 0.5f}, s));
  EXPECT_EQ(s.weight.z, 0.2f);
}

}  // namespace
