// The delta BSDFs (mirror, glass, refraction: directions, Fresnel choice, expected throughput)
// and emission.
#include "materials.h"

#include <gtest/gtest.h>

#include <ostream>
#include <string>
#include <vector>

#include "bsdf_util.h"
#include "rng.h"
#include "sampling.h"
#include "stat_util.h"

using namespace pt;
using namespace pt::bsdf_test;

namespace {

TEST(Mirror, PerfectReflection) {
  Material m;
  m.type = MaterialType::mirror;
  m.albedo = Vec3(0.9f, 0.7f, 0.3f);
  EXPECT_TRUE(is_delta(m));
  EXPECT_FALSE(is_transmissive(m));
  Pcg32 rng(10, 5);
  for (int i = 0; i < 10000; ++i) {
    Vec3 wo = sample_uniform_hemisphere(rng.next_2d());
    BsdfSample s;
    ASSERT_TRUE(sample_bsdf(m, wo, rng.next_float(), rng.next_2d(), s));
    EXPECT_TRUE(s.delta);
    EXPECT_LT(length(s.wi - reflect(wo, Vec3(0, 0, 1))), 1e-6f);
    EXPECT_NEAR(dot(s.wi, Vec3(0, 0, 1)), wo.z, 1e-6f);
    EXPECT_EQ(s.weight, m.albedo);
    EXPECT_EQ(s.pdf, 1.0f);
    EXPECT_TRUE(is_black(eval_bsdf(m, wo, s.wi)));
    EXPECT_EQ(bsdf_pdf(m, wo, s.wi), 0.0f);
  }
}

// ---- glass and refraction --------------------------------------------------------------------

const float kIors[] = {1.33f, 1.5f, 2.4f};
const Vec3 kAlbedo(0.6f, 0.5f, 0.4f), kTransmittance(0.9f, 0.8f, 0.7f);
constexpr float kLastU = 0x1.fffffep-1f;

// Checks a refracted sample: Snell's law, in the plane of incidence on the other side, pdf and
// the radiance factor (n_wo_side / n_other_side)^2 times the transmittance.
void check_refraction(const Material& m, Vec3 wo, const BsdfSample& s, float expected_pdf) {
  bool outside = wo.z > 0;
  float n_o = outside ? 1.0f : m.ior, n_t = outside ? m.ior : 1.0f;
  ASSERT_TRUE(is_finite(s.wi) && is_finite(s.weight));
  EXPECT_TRUE(s.delta);
  EXPECT_NEAR(length(s.wi), 1.0f, 1e-5f);
  EXPECT_LT(s.wi.z * wo.z, 0) << "not on the other side";
  float sin_o = std::sqrt(wo.x * wo.x + wo.y * wo.y), sin_t = std::sqrt(s.wi.x * s.wi.x + s.wi.y * s.wi.y);
  EXPECT_NEAR(n_o * sin_o, n_t * sin_t, 1e-5f) << "Snell's law";
  EXPECT_NEAR(wo.x * s.wi.y - wo.y * s.wi.x, 0.0f, 1e-5f) << "out of the plane of incidence";
  EXPECT_LE(wo.x * s.wi.x + wo.y * s.wi.y, 1e-6f) << "refracted to the same side of the normal";
  EXPECT_NEAR(s.pdf, expected_pdf, 1e-5f);
  Vec3 expect = m.transmittance * ((n_o / n_t) * (n_o / n_t));
  EXPECT_TRUE(near_rel(s.weight, expect, 1e-5f)) << str(s.weight) << " vs " << str(expect);
}

void check_reflection(const Material& m, Vec3 wo, const BsdfSample& s, float expected_pdf) {
  ASSERT_TRUE(is_finite(s.wi) && is_finite(s.weight));
  EXPECT_TRUE(s.delta);
  EXPECT_LT(length(s.wi - Vec3(-wo.x, -wo.y, wo.z)), 1e-6f);
  EXPECT_NEAR(s.pdf, expected_pdf, 1e-5f);
  EXPECT_EQ(s.weight, m.albedo);
}

TEST(Glass, FlagsAndNoSmoothPart) {
  for (MaterialType t : {MaterialType::glass, MaterialType::refraction}) {
    Material m = dielectric(t, 1.5f);
    EXPECT_TRUE(is_delta(m));
    EXPECT_TRUE(is_transmissive(m));
    EXPECT_TRUE(is_black(eval_bsdf(m, dir_deg(30), dir_deg(150))));
    EXPECT_EQ(bsdf_pdf(m, dir_deg(30), dir_deg(150)), 0.0f);
  }
}

// Refracted directions for both materials, from outside and from inside below the critical angle.
TEST(Glass, RefractionObeysSnellsLaw) {
  for (MaterialType t : {MaterialType::glass, MaterialType::refraction})
    for (float ior : kIors) {
      Material m = dielectric(t, ior, kAlbedo, kTransmittance);
      double critical = std::asin(1 / ior) / kDeg;
      for (int side = 0; side < 2; ++side)
        for (double deg = 0; deg < (side == 0 ? 89.5 : critical - 0.5); deg += 0.5)
          for (double phi : {0.0, 1.0, 2.5, 4.0}) {
            Vec3 wo = dir_deg(deg, phi);
            if (side == 1) wo.z = -wo.z;
            SCOPED_TRACE(testing::Message() << "type " << int(t) << ", ior " << ior << ", side " << side
                                            << ", theta " << deg);
            float n_o = side == 0 ? 1.0f : ior, n_t = side == 0 ? ior : 1.0f;
            float f = fresnel_dielectric(wo.z, n_o, n_t);
            BsdfSample s;
            ASSERT_TRUE(sample_bsdf(m, wo, kLastU, {0.3f, 0.6f}, s));
            check_refraction(m, wo, s, t == MaterialType::glass ? 1 - f : 1.0f);
          }
    }
}

// Glass picks reflection with probability F: the empirical frequency matches fresnel_dielectric
// within binomial noise, and each lobe has its own weight and pdf.
TEST(Glass, ReflectionProbabilityIsFresnel) {
  for (float ior : kIors) {
    Material m = dielectric(MaterialType::glass, ior, kAlbedo, kTransmittance);
    double critical = std::asin(1 / ior) / kDeg;
    for (int side = 0; side < 2; ++side)
      for (double frac : {0.0, 0.3, 0.6, 0.85, 0.97, 0.995}) {
        double deg = frac * (side == 0 ? 90 : critical);
        Vec3 wo = dir_deg(deg, 1.3);
        if (side == 1) wo.z = -wo.z;
        float n_o = side == 0 ? 1.0f : ior, n_t = side == 0 ? ior : 1.0f;
        double f = fresnel_dielectric(wo.z, n_o, n_t);
        SCOPED_TRACE(testing::Message() << "ior " << ior << ", side " << side << ", theta " << deg << ", F " << f);
        const int n = 20000;
        Pcg32 rng(uint64_t(deg * 100) + side, 6);
        int reflected = 0;
        for (int i = 0; i < n; ++i) {
          BsdfSample s;
          ASSERT_TRUE(sample_bsdf(m, wo, rng.next_float(), rng.next_2d(), s));
          if (s.wi.z * wo.z > 0) {
            ++reflected;
            check_reflection(m, wo, s, float(f));
          } else {
            check_refraction(m, wo, s, float(1 - f));
          }
          if (HasFailure()) return;
        }
        double sigma = std::sqrt(f * (1 - f) / n);
        EXPECT_NEAR(double(reflected) / n, f, 5 * sigma + 1.0 / n);
      }
  }
}

// Beyond the critical angle inside the medium: glass always reflects, refraction-only absorbs.
TEST(Glass, TotalInternalReflection) {
  for (float ior : kIors) {
    double critical = std::asin(1 / ior) / kDeg;
    Material glass = dielectric(MaterialType::glass, ior, kAlbedo, kTransmittance);
    Material refr = dielectric(MaterialType::refraction, ior, kAlbedo, kTransmittance);
    for (double deg = critical + 0.05; deg < 90; deg += 0.25)
      for (float ul : {0.0f, 0.5f, 0.999f, kLastU}) {
        Vec3 wo = dir_deg(deg, 0.4);
        wo.z = -wo.z;
        SCOPED_TRACE(testing::Message() << "ior " << ior << ", theta " << deg << ", u_lobe " << ul);
        BsdfSample s;
        ASSERT_TRUE(sample_bsdf(glass, wo, ul, {0.5f, 0.5f}, s));
        check_reflection(glass, wo, s, 1.0f);
        EXPECT_FALSE(sample_bsdf(refr, wo, ul, {0.5f, 0.5f}, s));
      }
  }
}

TEST(Refraction, NeverReflects) {
  Pcg32 rng(14, 2);
  for (float ior : kIors) {
    Material m = dielectric(MaterialType::refraction, ior, kAlbedo, kTransmittance);
    int sampled = 0;
    for (int i = 0; i < 20000; ++i) {
      Vec3 wo = sample_uniform_sphere(rng.next_2d());
      BsdfSample s;
      float ul = rng.next_float();
      if (!sample_bsdf(m, wo, ul, rng.next_2d(), s)) {
        // Only total internal reflection may fail.
        float sin2 = 1 - wo.z * wo.z;
        EXPECT_TRUE(wo.z < 0 && ior * ior * sin2 >= 1 - 1e-5f) << str(wo);
        continue;
      }
      ++sampled;
      ASSERT_TRUE(is_finite(s.weight) && is_finite(s.wi));
      ASSERT_LT(s.wi.z * wo.z, 0) << "reflected: wo " << str(wo) << ", wi " << str(s.wi);
    }
    EXPECT_GT(sampled, 10000);
  }
}

// Energy: averaged over the lobe choice, the throughput of white glass is 1 once the radiance
// factor (n_o / n_t)^2 of refraction is taken out, and F albedo + (1 - F) transmittance in general.
TEST(Glass, ExpectedThroughput) {
  for (float ior : kIors)
    for (bool white : {true, false}) {
      Material m = white ? dielectric(MaterialType::glass, ior) : dielectric(MaterialType::glass, ior, kAlbedo, kTransmittance);
      for (int side = 0; side < 2; ++side)
        for (double deg : {0.0, 30.0, 60.0, 85.0, 89.5}) {
          Vec3 wo = dir_deg(deg, 2.0);
          if (side == 1) wo.z = -wo.z;
          float n_o = side == 0 ? 1.0f : ior, n_t = side == 0 ? ior : 1.0f;
          double f = fresnel_dielectric(wo.z, n_o, n_t);
          const int n = 20000;
          Pcg32 rng(uint64_t(deg) * 7 + side, 8);
          double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
          for (int i = 0; i < n; ++i) {
            BsdfSample s;
            ASSERT_TRUE(sample_bsdf(m, wo, rng.next_float(), rng.next_2d(), s));
            ASSERT_TRUE(is_finite(s.weight));
            Vec3 w = s.weight;
            if (s.wi.z * wo.z < 0) w = w / ((n_o / n_t) * (n_o / n_t));
            for (int c = 0; c < 3; ++c) {
              sum[c] += w[c];
              sum2[c] += double(w[c]) * w[c];
            }
          }
          for (int c = 0; c < 3; ++c) {
            double mean = sum[c] / n, se = std::sqrt(std::max(0.0, sum2[c] / n - mean * mean) / n);
            double expect = f * m.albedo[c] + (1 - f) * m.transmittance[c];
            SCOPED_TRACE(testing::Message() << "ior " << ior << ", side " << side << ", theta " << deg);
            EXPECT_LE(mean, 1 + 5 * se + 1e-6);
            EXPECT_NEAR(mean, expect, 5 * se + 1e-5);
            if (white) EXPECT_NEAR(mean, 1.0, 1e-5);
          }
        }
    }
}

// ---- emission --------------------------------------------------------------------------------

TEST(Emission, FrontSideOnlyAndNoScattering) {
  Material m;
  m.type = MaterialType::emission;
  m.radiance = Vec3(2, 3, 4);
  EXPECT_TRUE(is_emissive(m));
  EXPECT_EQ(emitted_radiance(m, dir_deg(30)), m.radiance);
  EXPECT_TRUE(is_black(emitted_radiance(m, dir_deg(150))));
  BsdfSample s;
  EXPECT_FALSE(sample_bsdf(m, dir_deg(30), 0.5f, {0.5f, 0.5f}, s));
  EXPECT_TRUE(is_black(eval_bsdf(m, dir_deg(30), dir_deg(40))));
  EXPECT_TRUE(is_black(emitted_radiance(diffuse(Vec3(1.0f)), dir_deg(30))));
  m.radiance = Vec3(0.0f);
  EXPECT_FALSE(is_emissive(m));
}

}  // namespace
