// BSDFs: pdf normalisation, sampling against the pdf (chi-square at significance 1e-3, fixed
// seeds), sample weights, reciprocity, energy conservation, Fresnel terms and Beckmann / Smith.
// The delta lobes (mirror, glass, refraction) and emission: test_bsdf_delta.cpp.
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
using pt::test::chi2_test;
using pt::test::SphereBins;

namespace {

// Its 20 chi-square tests (4 materials x 5 angles) fail by chance together with probability 0.01.
const double kAlpha = pt::test::sidak_alpha(0.01, 20);

// ---- non-delta BSDFs -------------------------------------------------------------------------

struct Case {
  std::string name;
  Material m;
};
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }
std::string case_name(const testing::TestParamInfo<Case>& info) { return info.param.name; }

const char* const kAlphaNames[] = {"005", "025", "05"};
const float kAlphas[] = {0.05f, 0.25f, 0.5f};

// Sampling and pdf do not depend on the conductor's eta and k: one case per roughness.
std::vector<Case> sampling_cases() {
  std::vector<Case> c = {{"Diffuse", diffuse({0.8f, 0.5f, 0.2f})}};
  for (int i = 0; i < 3; ++i)
    c.push_back({std::string("Beckmann") + kAlphaNames[i], conductor(kAlphas[i], kSilverEta, kSilverK)});
  return c;
}
std::vector<Case> smooth_cases() {
  std::vector<Case> c = {{"DiffuseColoured", diffuse({0.8f, 0.5f, 0.2f})}, {"DiffuseWhite", diffuse(Vec3(1.0f))}};
  for (int i = 0; i < 3; ++i) {
    c.push_back({std::string("Silver") + kAlphaNames[i], conductor(kAlphas[i], kSilverEta, kSilverK)});
    c.push_back({std::string("Aluminium") + kAlphaNames[i], conductor(kAlphas[i], kAluminiumEta, kAluminiumK)});
    c.push_back({std::string("WhiteConductor") + kAlphaNames[i], conductor(kAlphas[i], kWhiteEta, kWhiteK)});
  }
  return c;
}

// Quadrature over wi through the half vector: wi = reflect(wo, h), d omega_i = 4 (wo.h) d omega_h
// (Walter et al. 2007, eq. 14). A grid uniform in wi cannot resolve a narrow glossy lobe at grazing
// wo (its azimuthal width shrinks like cos(theta_o)), but in h the Beckmann lobe stays a round
// blob around the normal. theta_h = (pi/2) s^2 with s on a midpoint grid puts the points there.
// Half vectors with wo.h <= 0 are skipped: they reflect below the surface (wi.z < 0), and every
// wi above the surface has exactly one h with h.z > 0 and wo.h > 0.
template <class Visit>
void halfvector_quadrature(Vec3 wo, int ns, int np, Visit visit) {
  double ds = 1.0 / ns, dp = 2 * M_PI / np;
  std::vector<double> cp(np), sp(np);
  for (int j = 0; j < np; ++j) {
    cp[j] = std::cos((j + 0.5) * dp);
    sp[j] = std::sin((j + 0.5) * dp);
  }
  for (int i = 0; i < ns; ++i) {
    double s = (i + 0.5) * ds, t = M_PI / 2 * s * s, dt = M_PI * s * ds, st = std::sin(t), ct = std::cos(t);
    for (int j = 0; j < np; ++j) {
      double hx = st * cp[j], hy = st * sp[j], hz = ct;
      double woh = wo.x * hx + wo.y * hy + wo.z * hz;
      if (woh <= 0) continue;
      Vec3 wi(float(2 * woh * hx - wo.x), float(2 * woh * hy - wo.y), float(2 * woh * hz - wo.z));
      visit(wi, 4 * woh * st * dt * dp);
    }
  }
}

// Per-bin integrals of bsdf_pdf(wo, .) over the sphere bins: in wi for diffuse, through the half
// vector for the microfacet model.
std::vector<double> pdf_per_bin(const Material& m, Vec3 wo, const SphereBins& bins) {
  if (m.type != MaterialType::microfacet)
    return bins.integrate([&](Vec3 wi) { return bsdf_pdf(m, wo, wi); }, 8, 6);
  std::vector<double> out(bins.size(), 0.0);
  halfvector_quadrature(wo, 1800, 720, [&](Vec3 wi, double dw) {
    float pdf = bsdf_pdf(m, wo, wi);
    if (pdf != 0) out[bins.index(wi)] += pdf * dw;
  });
  return out;
}

// Checks one sample against bsdf_pdf and eval_bsdf; returns false (once reporting why) if not.
bool check_sample(const Material& m, Vec3 wo, const BsdfSample& s, int& failures) {
  std::string why;
  if (s.delta || !is_finite(s.wi) || std::fabs(length(s.wi) - 1) > 1e-5f || s.wi.z <= 0) {
    why = "delta, not unit length or below the surface: wi = " + str(s.wi);
  } else {
    float pdf = bsdf_pdf(m, wo, s.wi);
    Vec3 expect = eval_bsdf(m, wo, s.wi) * (s.wi.z / pdf);
    if (!(s.pdf > 0) || !near_rel(s.pdf, pdf, 1e-5f))
      why = "pdf " + std::to_string(s.pdf) + " != bsdf_pdf " + std::to_string(pdf);
    else if (!is_finite(s.weight) || !near_rel(s.weight, expect, 1e-4f, 1e-6f))
      why = "weight " + str(s.weight) + " != f cos / pdf = " + str(expect);
  }
  if (why.empty()) return true;
  if (failures++ == 0) ADD_FAILURE() << "wo = " << str(wo) << ": " << why;
  return false;
}

class SmoothSampling : public testing::TestWithParam<Case> {};
class SmoothBsdf : public testing::TestWithParam<Case> {};

// Outgoing directions from normal incidence to grazing.
const double kThetas[] = {0, 30, 60, 80, 89};

// bsdf_pdf integrates to the fraction of sample_bsdf calls that succeed (1 where sampling cannot
// fail), the sampled directions follow bsdf_pdf (chi-square over (theta, phi) bins, the failures
// as one more cell), and each sample's pdf and weight agree with bsdf_pdf and eval_bsdf.
TEST_P(SmoothSampling, SamplesFollowPdf) {
  const Material& m = GetParam().m;
  // A narrow lobe gets finer bins (about 2 degrees for alpha 0.05): coarse ones would hide its shape.
  const bool narrow = m.type == MaterialType::microfacet && m.alpha < 0.1f;
  SphereBins bins(narrow ? 96 : 24, narrow ? 96 : 48);
  for (double theta : kThetas) {
    Vec3 wo = dir_deg(theta);
    SCOPED_TRACE(testing::Message() << "theta_o = " << theta);
    const int n = 200000;
    std::vector<double> observed(bins.size() + 1, 0.0);
    Pcg32 rng(uint64_t(theta) + 100, 1);
    int failures = 0;
    for (int i = 0; i < n; ++i) {
      float u_lobe = rng.next_float();
      Vec2 u = rng.next_2d();
      BsdfSample s;
      if (!sample_bsdf(m, wo, u_lobe, u, s)) {
        observed[bins.size()] += 1;
        continue;
      }
      observed[bins.index(s.wi)] += 1;
      check_sample(m, wo, s, failures);
    }
    EXPECT_EQ(failures, 0) << "samples inconsistent with bsdf_pdf / eval_bsdf";

    std::vector<double> expected = pdf_per_bin(m, wo, bins);
    double integral = test::sum(expected);
    double success = 1 - observed[bins.size()] / n;
    double sigma = std::sqrt(std::max(success * (1 - success), 1.0 / n) / n);
    EXPECT_LE(integral, 1 + 1e-3) << "pdf integrates to more than 1";
    EXPECT_NEAR(integral, success, 5 * sigma + 1e-3) << "pdf integral vs fraction of successful samples";
    if (m.type == MaterialType::diffuse) {
      EXPECT_NEAR(integral, 1.0, 1e-3);
      EXPECT_EQ(observed[bins.size()], 0);
    }
    for (double& e : expected) e *= n;
    expected.push_back(std::max(0.0, n * (1 - integral)));
    auto r = chi2_test(observed, expected, kAlpha);
    EXPECT_TRUE(r.passed) << r.message;
  }
}

// The same normalisation by plain quadrature in wi (no change of variables), where a uniform
// (theta, phi) grid resolves the lobe.
TEST_P(SmoothSampling, PdfIntegralInSolidAngle) {
  const Material& m = GetParam().m;
  bool narrow = m.type == MaterialType::microfacet && m.alpha < 0.1f;
  int nt = narrow ? 768 : 256, np = 4 * nt;
  for (double theta : {0.0, 45.0}) {
    Vec3 wo = dir_deg(theta);
    double dt = (M_PI / 2) / nt, dp = 2 * M_PI / np, integral = 0;
    for (int i = 0; i < nt; ++i) {
      double t = (i + 0.5) * dt, st = std::sin(t), ct = std::cos(t);
      for (int j = 0; j < np; ++j) {
        double p = (j + 0.5) * dp;
        Vec3 wi(float(st * std::cos(p)), float(st * std::sin(p)), float(ct));
        integral += bsdf_pdf(m, wo, wi) * st * dt * dp;
      }
    }
    const int n = 200000;
    Pcg32 rng(uint64_t(theta) + 200, 1);
    int ok = 0;
    for (int i = 0; i < n; ++i) {
      BsdfSample s;
      float ul = rng.next_float();
      ok += sample_bsdf(m, wo, ul, rng.next_2d(), s);
    }
    double success = double(ok) / n, sigma = std::sqrt(std::max(success * (1 - success), 1.0 / n) / n);
    EXPECT_NEAR(integral, success, 5 * sigma + 1e-3) << "theta_o = " << theta;
  }
}

INSTANTIATE_TEST_SUITE_P(Materials, SmoothSampling, testing::ValuesIn(sampling_cases()), case_name);

TEST_P(SmoothBsdf, Reciprocity) {
  const Material& m = GetParam().m;
  Pcg32 rng(7, 2);
  int nonzero = 0;
  for (int i = 0; i < 20000; ++i) {
    Vec3 a = sample_uniform_hemisphere(rng.next_2d()), b = sample_uniform_hemisphere(rng.next_2d());
    // A quarter of the pairs near the mirror configuration, where glossy lobes peak.
    if (i % 4 == 0) b = normalize(reflect(a, Vec3(0, 0, 1)) + Vec3(0.05f * rng.next_float(), 0, 0));
    Vec3 fab = eval_bsdf(m, a, b), fba = eval_bsdf(m, b, a);
    ASSERT_TRUE(is_finite(fab) && min_component(fab) >= 0) << str(fab);
    // h = normalize(wo + wi) is ill-conditioned when wo + wi is short (grazing back-scatter):
    // wo.h and wi.h (the Fresnel argument) then differ by float rounding of the unit vectors,
    // about 1e-7 / |wo + wi|.
    float rel = 1e-4f + 1e-6f / std::max(1e-6f, length(a + b));
    ASSERT_TRUE(near_rel(fab, fba, rel, 1e-7f)) << "wo = " << str(a) << ", wi = " << str(b) << ": "
                                                  << str(fab) << " vs " << str(fba);
    if (!is_black(fab)) ++nonzero;
  }
  EXPECT_GT(nonzero, 1000);
}

// Reflection-only BSDFs: nothing below the surface, on either side.
TEST_P(SmoothBsdf, NothingBelowTheSurface) {
  const Material& m = GetParam().m;
  Pcg32 rng(8, 2);
  for (int i = 0; i < 2000; ++i) {
    Vec3 up = sample_uniform_hemisphere(rng.next_2d()), down = -sample_uniform_hemisphere(rng.next_2d());
    EXPECT_TRUE(is_black(eval_bsdf(m, up, down)));
    EXPECT_TRUE(is_black(eval_bsdf(m, down, up)));
    EXPECT_EQ(bsdf_pdf(m, up, down), 0.0f);
    EXPECT_EQ(bsdf_pdf(m, down, up), 0.0f);
    BsdfSample s;
    EXPECT_FALSE(sample_bsdf(m, down, rng.next_float(), rng.next_2d(), s));
  }
  EXPECT_FALSE(is_delta(m));
  EXPECT_FALSE(is_transmissive(m));
}

// Directional albedo: the mean sample weight (a Monte Carlo estimate of the integral of f cos
// over wi) is at most 1 within its standard error, and agrees with a quadrature of f cos.
// Every sample's weight is also checked against eval * cos / pdf.
TEST_P(SmoothBsdf, AlbedoAtMostOne) {
  const Material& m = GetParam().m;
  for (double theta : {0.0, 30.0, 60.0, 80.0, 85.0, 89.0, 89.9}) {
    Vec3 wo = dir_deg(theta, 2.1);
    SCOPED_TRACE(testing::Message() << "theta_o = " << theta);
    const int n = 50000;
    Pcg32 rng(uint64_t(theta * 10) + 300, 3);
    double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
    int failures = 0;
    for (int i = 0; i < n; ++i) {
      BsdfSample s;
      float u_lobe = rng.next_float();
      Vec2 u = rng.next_2d();
      if (!sample_bsdf(m, wo, u_lobe, u, s) || !check_sample(m, wo, s, failures)) continue;
      for (int c = 0; c < 3; ++c) {
        sum[c] += s.weight[c];
        sum2[c] += double(s.weight[c]) * s.weight[c];
      }
    }
    EXPECT_EQ(failures, 0);
    double quad[3] = {0, 0, 0};
    if (m.type == MaterialType::microfacet) {
      halfvector_quadrature(wo, 400, 160, [&](Vec3 wi, double dw) {
        Vec3 f = eval_bsdf(m, wo, wi) * std::max(0.0f, wi.z);
        for (int c = 0; c < 3; ++c) quad[c] += f[c] * dw;
      });
    } else {
      SphereBins bins(24, 48);
      for (int c = 0; c < 3; ++c)
        quad[c] = test::sum(bins.integrate([&](Vec3 wi) { return eval_bsdf(m, wo, wi)[c] * std::max(0.0f, wi.z); }, 8, 6));
    }
    for (int c = 0; c < 3; ++c) {
      double mean = sum[c] / n, var = std::max(0.0, sum2[c] / n - mean * mean), se = std::sqrt(var / n);
      EXPECT_LE(mean, 1 + 5 * se + 1e-6) << "channel " << c << ": albedo " << mean << " +- " << se;
      EXPECT_LE(quad[c], 1 + 1e-3) << "channel " << c << ": quadrature albedo";
      EXPECT_NEAR(mean, quad[c], 5 * se + 2e-3 * quad[c] + 1e-6) << "channel " << c;
      if (m.type == MaterialType::diffuse) EXPECT_NEAR(quad[c], m.albedo[c], 1e-3);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Materials, SmoothBsdf, testing::ValuesIn(smooth_cases()), case_name);

// A white Lambertian surface reflects everything: uniform hemisphere sampling of f cos (which
// does not use the BSDF's own sampling) gives albedo 1 within its standard error.
TEST(Diffuse, WhiteAlbedoIsOne) {
  Material m = diffuse(Vec3(1.0f));
  for (double theta : {0.0, 45.0, 89.0}) {
    Vec3 wo = dir_deg(theta);
    Pcg32 rng(uint64_t(theta) + 400, 3);
    const int n = 200000;
    double sum = 0, sum2 = 0, wsum = 0;
    for (int i = 0; i < n; ++i) {
      Vec3 wi = sample_uniform_hemisphere(rng.next_2d());
      double v = eval_bsdf(m, wo, wi).y * wi.z / uniform_hemisphere_pdf();
      sum += v;
      sum2 += v * v;
      BsdfSample s;
      float ul = rng.next_float();
      if (sample_bsdf(m, wo, ul, rng.next_2d(), s)) wsum += s.weight.y;
    }
    double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
    EXPECT_NEAR(mean, 1.0, 5 * se) << "theta_o = " << theta;
    EXPECT_NEAR(wsum / n, 1.0, 1e-4) << "theta_o = " << theta;
  }
}

// ---- microfacet ------------------------------------------------------------------------------

// eval_bsdf is the Cook-Torrance form F(wi.h) D(h) G / (4 cos_o cos_i) with the height-
// correlated Smith G = 1 / (1 + Lambda(wo) + Lambda(wi)) (Walter et al. 2007, eq. 20; Heitz 2014).
TEST(Microfacet, MatchesCookTorranceFormula) {
  Pcg32 rng(9, 4);
  for (float alpha : {0.05f, 0.25f, 0.5f}) {
    Material m = conductor(alpha, kAluminiumEta, kAluminiumK);
    for (int i = 0; i < 2000; ++i) {
      Vec3 wo = sample_uniform_hemisphere(rng.next_2d()), wi = sample_uniform_hemisphere(rng.next_2d());
      if (wo.z < 1e-3f || wi.z < 1e-3f) continue;
      Vec3 h = normalize(wo + wi);
      double g = 1 / (1 + double(smith_lambda_beckmann(wo, alpha)) + smith_lambda_beckmann(wi, alpha));
      Vec3 expect = fresnel_conductor(dot(wi, h), m.eta, m.k) *
                    float(beckmann_d(h, alpha) * g / (4 * double(wo.z) * wi.z));
      Vec3 f = eval_bsdf(m, wo, wi);
      ASSERT_TRUE(near_rel(f, expect, 1e-4f, 1e-9f)) << str(f) << " vs " << str(expect);
    }
  }
}

// Integral of D(h) cos(theta_h) over the hemisphere is 1 (Walter et al. 2007, eq. 4).
TEST(Beckmann, NormalisedProjectedArea) {
  for (float alpha : {0.05f, 0.1f, 0.25f, 0.5f, 1.0f}) {
    const int n = 200000;
    double dt = (M_PI / 2) / n, integral = 0;
    for (int i = 0; i < n; ++i) {
      double t = (i + 0.5) * dt;
      Vec3 h(float(std::sin(t)), 0, float(std::cos(t)));
      integral += beckmann_d(h, alpha) * std::cos(t) * std::sin(t) * dt * 2 * M_PI;
    }
    EXPECT_NEAR(integral, 1.0, 1e-3) << "alpha = " << alpha;
    EXPECT_EQ(beckmann_d(Vec3(0.6f, 0, -0.8f), alpha), 0.0f);
    EXPECT_EQ(beckmann_d(Vec3(1, 0, 0), alpha), 0.0f);
  }
}

// Smith's Lambda is defined by the projected area of the microsurface towards w:
// integral of D(m) max(0, w.m) dm = cos(theta) (1 + Lambda(w)) (Heitz 2014, eq. 17).
TEST(Beckmann, SmithLambdaMatchesProjectedArea) {
  for (float alpha : {0.05f, 0.25f, 0.5f}) {
    // D is negligible (below exp(-50)) beyond tan(theta_m) = alpha sqrt(50).
    double tmax = std::min(M_PI / 2, std::atan(alpha * std::sqrt(50.0)));
    const int nt = 1000, np = 500;
    double dt = tmax / nt, dp = M_PI / np;  // phi in [0, pi], doubled by symmetry
    for (double theta : {0.0, 30.0, 60.0, 80.0, 89.0}) {
      Vec3 w = dir_deg(theta, 0);
      double lhs = 0;
      for (int i = 0; i < nt; ++i) {
        double t = (i + 0.5) * dt, st = std::sin(t), ct = std::cos(t);
        for (int j = 0; j < np; ++j) {
          double p = (j + 0.5) * dp;
          Vec3 mm(float(st * std::cos(p)), float(st * std::sin(p)), float(ct));
          double proj = std::max(0.0, double(dot(w, mm)));
          if (proj > 0) lhs += beckmann_d(mm, alpha) * proj * st * dt * dp * 2;
        }
      }
      double rhs = w.z * (1 + double(smith_lambda_beckmann(w, alpha)));
      EXPECT_NEAR(lhs, rhs, 2e-3 * rhs) << "alpha = " << alpha << ", theta = " << theta;
    }
  }
}

TEST(Beckmann, SmithLambdaZeroAtNormalGrowsTowardGrazing) {
  for (float alpha : {0.05f, 0.25f, 0.5f}) {
    EXPECT_EQ(smith_lambda_beckmann(Vec3(0, 0, 1), alpha), 0.0f);
    float prev = 0;
    for (int i = 0; i <= 899; ++i) {
      float l = smith_lambda_beckmann(dir_deg(i * 0.1), alpha);
      ASSERT_TRUE(std::isfinite(l) && l >= prev) << "alpha = " << alpha << ", theta = " << i * 0.1;
      prev = l;
    }
    EXPECT_GT(smith_lambda_beckmann(dir_deg(89.9), alpha), 1.0f) << "alpha = " << alpha;
    EXPECT_GT(smith_lambda_beckmann(dir_deg(89.9), alpha), smith_lambda_beckmann(dir_deg(60), alpha));
  }
  // Closed form at a = 1 / (alpha tan theta) = 1: (erf(1) - 1 + exp(-1) / sqrt(pi)) / 2.
  double a1 = 0.5 * (std::erf(1.0) - 1 + std::exp(-1.0) / std::sqrt(M_PI));
  Vec3 w = normalize(Vec3(0.5f, 0, 1));  // tan theta = 0.5
  EXPECT_NEAR(smith_lambda_beckmann(w, 2.0f), a1, 1e-5);
}

// ---- Fresnel ---------------------------------------------------------------------------------

// Unpolarised dielectric Fresnel reflectance from the angles (Hecht, Optics, section 4.6.2).
double fresnel_reference(double cos_i, double n1, double n2) {
  double ti = std::acos(cos_i), st = n1 / n2 * std::sin(ti);
  if (st >= 1) return 1;
  if (ti == 0) return std::pow((n1 - n2) / (n1 + n2), 2);
  double tt = std::asin(st);
  double rs = std::sin(ti - tt) / std::sin(ti + tt), rp = std::tan(ti - tt) / std::tan(ti + tt);
  return 0.5 * (rs * rs + rp * rp);
}

TEST(Fresnel, DielectricNormalIncidence) {
  for (float n : {1.33f, 1.5f, 2.4f}) {
    double r0 = std::pow((1.0 - n) / (1.0 + n), 2);
    EXPECT_NEAR(fresnel_dielectric(1, 1, n), r0, 1e-6);
    EXPECT_NEAR(fresnel_dielectric(1, n, 1), r0, 1e-6);
    EXPECT_NEAR(fresnel_dielectric(-1, 1, n), r0, 1e-6);  // the sign of cos_i does not matter
  }
  EXPECT_NEAR(fresnel_dielectric(1, 1, 1.5f), 0.04, 1e-6);
}

TEST(Fresnel, DielectricMatchesReferenceAndIsReciprocal) {
  for (float n : {1.33f, 1.5f, 2.4f})
    for (int deg = 0; deg <= 90; ++deg) {
      double c = std::cos(deg * kDeg);
      EXPECT_NEAR(fresnel_dielectric(float(c), 1, n), fresnel_reference(c, 1, n), 2e-5) << n << " " << deg;
      EXPECT_NEAR(fresnel_dielectric(float(c), n, 1), fresnel_reference(c, n, 1), 2e-5) << n << " " << deg;
      // Same interface seen from the other side along the refracted ray.
      double st = std::sin(deg * kDeg) / n;
      if (deg < 90) {
        float ct = float(std::sqrt(1 - st * st));
        EXPECT_NEAR(fresnel_dielectric(float(c), 1, n), fresnel_dielectric(ct, n, 1), 2e-5) << n << " " << deg;
      }
    }
}

TEST(Fresnel, DielectricTotalInternalReflectionAndGrazing) {
  for (float n : {1.33f, 1.5f, 2.4f}) {
    double critical = std::asin(1.0 / n) / kDeg;
    for (double deg = critical + 0.05; deg <= 90; deg += 0.5)
      EXPECT_EQ(fresnel_dielectric(float(std::cos(deg * kDeg)), n, 1), 1.0f) << n << " " << deg;
    EXPECT_LT(fresnel_dielectric(float(std::cos((critical - 1) * kDeg)), n, 1), 1.0f);
    EXPECT_EQ(fresnel_dielectric(0, 1, n), 1.0f);
    EXPECT_GT(fresnel_dielectric(1e-4f, 1, n), 0.999f);
    EXPECT_GT(fresnel_dielectric(float(std::cos(89 * kDeg)), 1, n), 0.85f);
    // Reflectance grows from the Brewster angle to grazing.
    float prev = 0;
    for (double deg = std::atan(n) / kDeg; deg <= 90; deg += 0.25) {
      float f = fresnel_dielectric(float(std::cos(deg * kDeg)), 1, n);
      EXPECT_GE(f, prev) << n << " " << deg;
      prev = f;
    }
  }
}

TEST(Fresnel, IndexMatchedInterfaceReflectsNothing) {
  EXPECT_EQ(fresnel_dielectric(0.0f, 1, 1), 0.0f);
  EXPECT_EQ(fresnel_dielectric(1e-5f, 1.5f, 1.5f), 0.0f);
  for (int i = 0; i <= 1000; ++i) {
    float c = i / 1000.0f;
    EXPECT_NEAR(fresnel_dielectric(c, 1, 1), 0.0f, 1e-6f) << "cos = " << c;
    EXPECT_NEAR(fresnel_dielectric(c, 1.5f, 1.5f), 0.0f, 1e-6f) << "cos = " << c;
  }
}

TEST(Fresnel, ConductorInUnitIntervalAndOneAtGrazing) {
  const Vec3 etas[] = {kSilverEta, kAluminiumEta}, ks[] = {kSilverK, kAluminiumK};
  for (int mtl = 0; mtl < 2; ++mtl) {
    for (int i = 0; i <= 1000; ++i) {
      float c = i / 1000.0f;
      Vec3 f = fresnel_conductor(c, etas[mtl], ks[mtl]);
      ASSERT_TRUE(is_finite(f) && min_component(f) >= 0 && max_component(f) <= 1) << c << " " << str(f);
    }
    Vec3 g = fresnel_conductor(0, etas[mtl], ks[mtl]);
    for (int ch = 0; ch < 3; ++ch) {
      EXPECT_NEAR(g[ch], 1.0f, 1e-6f);
      EXPECT_GT(fresnel_conductor(1e-3f, etas[mtl], ks[mtl])[ch], 0.99f);
      // Normal incidence: ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2).
      double n = etas[mtl][ch], k = ks[mtl][ch];
      double r0 = ((n - 1) * (n - 1) + k * k) / ((n + 1) * (n + 1) + k * k);
      EXPECT_NEAR(fresnel_conductor(1, etas[mtl], ks[mtl])[ch], r0, 1e-5);
      EXPECT_NEAR(fresnel_conductor(-1, etas[mtl], ks[mtl])[ch], r0, 1e-5);
    }
  }
  // Course values: silver reflects ~0.95-0.98, aluminium ~0.87-0.93 at normal incidence.
  EXPECT_GT(min_component(fresnel_conductor(1, kSilverEta, kSilverK)), 0.9f);
  EXPECT_GT(min_component(fresnel_conductor(1, kAluminiumEta, kAluminiumK)), 0.85f);
}

}  // namespace
