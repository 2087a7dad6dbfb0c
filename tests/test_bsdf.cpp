// BSDFs: pdf normalisation, sampling against the pdf (chi-square at significance 1e-3, fixed
// seeds), sample weights, reciprocity, energy conservation, Fresnel terms, Beckmann / Smith, and
// the delta lobes (mirror, glass, refraction).
#include "materials.h"

#include <gtest/gtest.h>

#include <ostream>
#include <string>
#include <vector>

#include "rng.h"
#include "sampling.h"
#include "stat_util.h"

using namespace pt;
using pt::test::chi2_test;
using pt::test::SphereBins;

namespace {

constexpr double kAlpha = 1e-3;
constexpr double kDeg = M_PI / 180;

// Course conductor constants (CS184 project 3-2).
const Vec3 kSilverEta(0.059193f, 0.059881f, 0.047366f), kSilverK(4.1283f, 3.5892f, 2.8132f);
const Vec3 kAluminiumEta(1.3352f, 1.0109f, 0.68955f), kAluminiumK(7.3398f, 6.6157f, 5.6471f);
// eta = 0, k = 1 makes the course's conductor Fresnel exactly 1: all energy loss is then D and G.
const Vec3 kWhiteEta(0, 0, 0), kWhiteK(1, 1, 1);

Material diffuse(Vec3 albedo) {
  Material m;
  m.type = MaterialType::diffuse;
  m.albedo = albedo;
  return m;
}
Material conductor(float alpha, Vec3 eta, Vec3 k) {
  Material m;
  m.type = MaterialType::microfacet;
  m.alpha = alpha;
  m.eta = eta;
  m.k = k;
  return m;
}
Material dielectric(MaterialType type, float ior, Vec3 albedo = Vec3(1.0f), Vec3 transmittance = Vec3(1.0f)) {
  Material m;
  m.type = type;
  m.ior = ior;
  m.albedo = albedo;
  m.transmittance = transmittance;
  return m;
}

// Direction at polar angle theta (degrees) from +z and azimuth phi (radians).
Vec3 dir_deg(double theta_deg, double phi = 0.7) {
  double t = theta_deg * kDeg;
  return Vec3(float(std::sin(t) * std::cos(phi)), float(std::sin(t) * std::sin(phi)), float(std::cos(t)));
}

bool near_rel(float a, float b, float rel, float abs_tol = 1e-7f) {
  return std::fabs(a - b) <= rel * std::max(std::fabs(a), std::fabs(b)) + abs_tol;
}
bool near_rel(Vec3 a, Vec3 b, float rel, float abs_tol = 1e-7f) {
  return near_rel(a.x, b.x, rel, abs_tol) && near_rel(a.y, b.y, rel, abs_tol) && near_rel(a.z, b.z, rel, abs_tol);
}
std::string str(Vec3 v) {
  return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

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
  SphereBins bins(24, 48);
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

// ---- mirror ----------------------------------------------------------------------------------

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
