// The glTF material's layers (pbr.h): KHR_materials_clearcoat and KHR_materials_sheen over the
// base. A white coat over a white plastic and a white sheen over it keep the furnace's energy (what
// a layer reflects, the base beneath does not get); the sheen lobe is a density over the
// hemisphere; the coat adds its Fresnel reflection to a black base; no layer setting gains energy
// or gives NaN. Their sampling is in test_pbr.cpp's chi-square cases.
#include <gtest/gtest.h>

#include "bsdf_util.h"
#include "ggx.h"
#include "pbr.h"
#include "rng.h"
#include "sheen.h"

using namespace pt;
using namespace pt::bsdf_test;

namespace {

PbrParams plastic(Vec3 base, float roughness) {
  PbrParams p;
  p.base = base;
  p.metallic = 0;
  p.roughness = roughness;
  return p;
}

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

}  // namespace

TEST(PbrLayers, WhiteLayersOverWhitePlasticKeepTheFurnacesEnergy) {
  for (float coat_roughness : {0.0f, 0.3f, 1.0f})
    for (double theta : {0.0, 50.0, 80.0}) {
      PbrParams p = plastic(Vec3(1.0f), 0.5f);
      p.clearcoat = 1;
      p.clearcoat_roughness = coat_roughness;
      EXPECT_NEAR(albedo(p, dir_deg(theta), 200000, 3).y, 1.0, 0.015) << "coat roughness " << coat_roughness << ", theta " << theta;
    }
  for (float sheen_roughness : {0.1f, 0.5f, 1.0f})
    for (double theta : {0.0, 50.0, 80.0}) {
      PbrParams p = plastic(Vec3(1.0f), 0.5f);
      p.sheen_color = Vec3(1.0f);
      p.sheen_roughness = sheen_roughness;
      EXPECT_NEAR(albedo(p, dir_deg(theta), 200000, 5).y, 1.0, 0.02) << "sheen roughness " << sheen_roughness << ", theta " << theta;
    }
}

// The lobe's directions follow a density (a clamped cosine, linearly transformed) that integrates
// to at most 1 over the hemisphere: the rest of the transformed cosine falls below the horizon.
// Scaled by the fitted albedo, the sheen reflects what the paper's tables say.
TEST(PbrLayers, TheSheenLobeIsADensityOverTheHemisphere) {
  // Cosine-weighted estimates: smooth sheens concentrate at grazing angles, where they are noisy.
  for (float roughness : {0.2f, 0.4f, 0.7f, 1.0f})
    for (double theta : {0.0, 45.0, 75.0, 89.0}) {
      const Vec3 wo = dir_deg(theta);
      const sheen::Ltc l = sheen::ltc(wo, roughness);
      Pcg32 rng(7, 11);
      double sum = 0;
      const int n = 400000;
      for (int i = 0; i < n; ++i) {
        const Vec3 wi = sample_cosine_hemisphere(rng.next_2d());
        if (wi.z > 0) sum += sheen::density(l, wi) * kPi / wi.z;  // D / (cos / pi)
      }
      sum /= n;
      EXPECT_LE(sum, 1.02) << roughness << " " << theta;
      EXPECT_GE(sum, 0.5) << roughness << " " << theta;
      const float e = sheen::albedo(wo.z, roughness);
      EXPECT_TRUE(e >= 0 && e <= 1) << e;
    }
}

// A coat on a black base reflects its Fresnel share: 4% head on at ior 1.5, more at grazing; on
// half strength, half of that. A sheen colours what it reflects.
TEST(PbrLayers, TheCoatReflectsItsFresnelShare) {
  PbrParams black = plastic(Vec3(0.0f), 1.0f);
  black.specular = 0;
  EXPECT_LT(albedo(black, dir_deg(0), 50000, 9).y, 1e-6);
  PbrParams coat = black;
  coat.clearcoat = 1;
  coat.clearcoat_roughness = 0.05f;
  EXPECT_NEAR(albedo(coat, dir_deg(0), 200000, 9).y, 0.04, 0.004);
  EXPECT_GT(albedo(coat, dir_deg(80), 200000, 9).y, 0.3);
  coat.clearcoat = 0.5f;
  EXPECT_NEAR(albedo(coat, dir_deg(0), 200000, 9).y, 0.02, 0.003);
  PbrParams sheen = black;
  sheen.sheen_color = Vec3(1.0f, 0.5f, 0.0f);
  sheen.sheen_roughness = 0.5f;
  const Vec3 a = albedo(sheen, dir_deg(60), 200000, 9);
  EXPECT_GT(a.x, 0.05f);
  EXPECT_NEAR(a.y / a.x, 0.5, 0.01);
  EXPECT_EQ(a.z, 0.0f);
}

TEST(PbrLayers, NoEnergyGainAtAnyLimit) {
  for (float r : {0.0f, 0.5f, 1.0f})
    for (float coat : {0.0f, 1.0f, 7.0f})
      for (Vec3 sheen : {Vec3(0.0f), Vec3(1.0f), Vec3(30.0f, -1.0f, 1.0f)})
        for (float metallic : {0.0f, 1.0f}) {
          PbrParams p = plastic(Vec3(1.0f), r);
          p.metallic = metallic;
          p.clearcoat = coat;
          p.clearcoat_roughness = r;
          p.sheen_color = sheen;
          p.sheen_roughness = r;
          p.coat_normal = coat > 1 ? normalize(Vec3(0.6f, 0.2f, 0.5f)) : Vec3(0.0f);  // a coat normal map's tilt
          for (double theta : {0.0, 60.0, 89.9}) {
            const Vec3 a = albedo(p, dir_deg(theta), 20000, 13);
            ASSERT_TRUE(is_finite(a));
            EXPECT_LE(max_component(a), 1.02f) << "roughness " << r << " coat " << coat << " sheen " << sheen.x
                                               << " metallic " << metallic << " theta " << theta;
            EXPECT_GE(min_component(a), 0.0f);
          }
        }
}
