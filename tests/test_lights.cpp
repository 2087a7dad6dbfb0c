// Light sampling (renderer/lights.h) with the checks the BSDFs get in test_bsdf.cpp: sampled
// directions follow the solid-angle pdf (chi-square at significance 1e-3, fixed seeds), that pdf
// integrates to 1 over the sphere, each sample agrees with area_light_pdf / infinite_light_pdf /
// infinite_light_radiance, and point and spot lights give the values derived by hand. Lights come
// from a SceneDesc through make_render_scene, as a scene file's do.
#include "lights.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "bsdf_util.h"
#include "session.h"
#include "rng.h"
#include "stat_util.h"

using namespace pt;
using pt::bsdf_test::near_rel;
using pt::bsdf_test::str;
using pt::test::chi2_test;

namespace {

// Its 8 chi-square tests fail by chance together with probability 0.01.
const double kAlpha = pt::test::sidak_alpha(0.01, 8);
constexpr int kSamples = 200000;

// The render scene of `desc` with `lights` added; a small far sphere keeps the scene non-empty.
std::unique_ptr<RenderScene> scene_with(std::vector<LightDesc> lights, SceneDesc desc = {}) {
  desc.lights = std::move(lights);
  desc.materials.push_back(Material{});  // diffuse
  desc.spheres.push_back({"far", Vec3(0, -100, 0), 0.1f, int(desc.materials.size()) - 1});
  RenderParams p;
  p.width = p.height = 8;
  return make_render_scene(desc, p);
}

// Direction bins on the cone of half angle theta_max around `axis` (pi: the whole sphere), uniform
// in theta and phi; index -1 for a direction outside the cone.
struct ConeBins {
  Frame frame;
  double theta_max;
  int n_theta, n_phi;
  ConeBins(Vec3 axis, double tmax, int nt, int np) : frame(normalize(axis)), theta_max(tmax), n_theta(nt), n_phi(np) {}
  int size() const { return n_theta * n_phi; }
  int index(Vec3 w) const {
    Vec3 l = frame.to_local(w);
    double len = std::sqrt(double(l.x) * l.x + double(l.y) * l.y + double(l.z) * l.z);
    double theta = std::acos(std::clamp(double(l.z) / len, -1.0, 1.0));
    if (theta >= theta_max) return -1;
    double phi = std::atan2(double(l.y), double(l.x));
    if (phi < 0) phi += 2 * M_PI;
    int it = std::min(int(theta / theta_max * n_theta), n_theta - 1);
    int ip = std::min(int(phi / (2 * M_PI) * n_phi), n_phi - 1);
    return it * n_phi + ip;
  }
  // Per-bin integrals of a solid-angle pdf, midpoint rule with sub x sub points a bin.
  template <class Pdf>
  std::vector<double> integrate(Pdf pdf, int sub) const {
    std::vector<double> out(size(), 0.0);
    int nt = n_theta * sub, np = n_phi * sub;
    double dt = theta_max / nt, dp = 2 * M_PI / np;
    for (int i = 0; i < nt; ++i) {
      double t = (i + 0.5) * dt, st = std::sin(t), ct = std::cos(t);
      for (int j = 0; j < np; ++j) {
        double p = (j + 0.5) * dp;
        Vec3 w = frame.to_world(Vec3(float(st * std::cos(p)), float(st * std::sin(p)), float(ct)));
        out[(i / sub) * n_phi + j / sub] += double(pdf(w)) * st * dt * dp;
      }
    }
    return out;
  }
};

// One triangle of an emitter, its emitting normal (the winding's, as for mesh lights) derived here.
struct Tri {
  Vec3 a, b, c, n;
  Tri(Vec3 a_, Vec3 b_, Vec3 c_) : a(a_), b(b_), c(c_), n(normalize(cross(b_ - a_, c_ - a_))) {}
  double area() const { return 0.5 * length(cross(b - a, c - a)); }
};

// Where the ray p + t w (t > 0) meets the triangle: Moller & Trumbore, "Fast, minimum storage
// ray-triangle intersection", JGT 2(1), 1997.
bool hit(const Tri& tri, Vec3 p, Vec3 w, Vec3& q) {
  Vec3 e1 = tri.b - tri.a, e2 = tri.c - tri.a, s = cross(w, e2);
  double det = dot(e1, s);
  if (std::fabs(det) < 1e-12) return false;
  Vec3 d = p - tri.a;
  double u = dot(d, s) / det;
  Vec3 r = cross(d, e1);
  double v = dot(w, r) / det, t = dot(e2, r) / det;
  if (u < 0 || v < 0 || u + v > 1 || t <= 0) return false;
  q = p + w * float(t);
  return true;
}

// The solid-angle pdf of sampling direction w from p: area_light_pdf at the emitter point w sees,
// where the emitter faces p (the triangles do not overlap as seen from p), else 0.
float direction_pdf(const Light& light, const std::vector<Tri>& tris, Vec3 p, Vec3 w) {
  for (const Tri& t : tris) {
    Vec3 q;
    if (hit(t, p, w, q) && dot(w, t.n) < 0) return area_light_pdf(light, p, q, t.n);
  }
  return 0;
}

// Midpoints of the n^2 congruent sub-triangles of the standard subdivision, each with its area.
template <class Visit>
void triangle_quadrature(const Tri& t, int n, Visit visit) {
  Vec3 e1 = (t.b - t.a) / float(n), e2 = (t.c - t.a) / float(n);
  double da = t.area() / (double(n) * n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; i + j < n; ++j) {
      visit(t.a + e1 * (i + 1.0f / 3) + e2 * (j + 1.0f / 3), da);
      if (i + j < n - 1) visit(t.a + e1 * (i + 2.0f / 3) + e2 * (j + 2.0f / 3), da);
    }
}

// Expected share of sampled directions in each bin: the pdf times the Jacobian cos / d^2 summed
// over the emitter's surface (a smooth integrand, unlike the pdf over directions with its edges).
std::vector<double> expected_per_bin(const Light& light, const std::vector<Tri>& tris, Vec3 p, const ConeBins& bins,
                                     std::vector<double>& outside) {
  std::vector<double> out(bins.size(), 0.0);
  outside.assign(1, 0.0);
  for (const Tri& t : tris)
    triangle_quadrature(t, 600, [&](Vec3 q, double da) {
      Vec3 d = q - p;
      double d2 = dot(d, d);
      Vec3 w = d / std::sqrt(float(d2));
      double cos_l = -dot(w, t.n);
      if (cos_l <= 0) return;
      double share = area_light_pdf(light, p, q, t.n) * cos_l / d2 * da;
      int b = bins.index(w);
      (b < 0 ? outside[0] : out[b]) += share;
    });
  return out;
}

struct AreaCase {
  Light light;
  std::vector<Tri> tris;
};

// Samples `light` from p: every sample checked against the geometry and area_light_pdf, the
// directions binned. Returns the observed counts, the last cell for failed samples.
std::vector<double> sample_area_light(const AreaCase& c, Vec3 p, const ConeBins& bins, uint64_t seed) {
  std::vector<double> observed(bins.size() + 1, 0.0);
  Pcg32 rng(seed, 3);
  int failures = 0;
  for (int i = 0; i < kSamples; ++i) {
    LightSample s;
    if (!sample_light(c.light, p, rng.next_2d(), s)) {
      observed.back() += 1;
      continue;
    }
    int b = bins.index(s.wi);
    observed[b < 0 ? bins.size() : size_t(b)] += 1;
    std::string why;
    float pdf = direction_pdf(c.light, c.tris, p, s.wi);
    if (std::fabs(length(s.wi) - 1) > 1e-5f || !near_rel(s.wi, normalize(s.point - p), 1e-5f, 1e-6f))
      why = "wi " + str(s.wi) + " does not point at the sampled point " + str(s.point);
    else if (!near_rel(s.pdf, pdf, 1e-3f))
      why = "pdf " + std::to_string(s.pdf) + " != the pdf of its direction " + std::to_string(pdf);
    else if (s.radiance != c.light.color || s.infinite)
      why = "radiance " + str(s.radiance) + " is not the light's colour, or the sample says infinite";
    if (!why.empty() && failures++ == 0) ADD_FAILURE() << "sample " << i << ": " << why;
  }
  EXPECT_EQ(failures, 0);
  return observed;
}

// The chi-square test and the pdf's integral over directions for one area light seen from p.
void check_area_light(const AreaCase& c, Vec3 p, const ConeBins& bins, uint64_t seed, int sub) {
  std::vector<double> observed = sample_area_light(c, p, bins, seed), outside;
  std::vector<double> expected = expected_per_bin(c.light, c.tris, p, bins, outside);
  EXPECT_NEAR(test::sum(expected) + outside[0], 1.0, 1e-3) << "pdf x Jacobian over the surface";
  ASSERT_EQ(outside[0], 0.0) << "the bins must hold the whole light";
  EXPECT_EQ(observed.back(), 0) << "samples failed, or fell outside the light, though all of it faces p";
  for (double& e : expected) e *= kSamples;
  expected.push_back(0);
  auto r = chi2_test(observed, expected, kAlpha);
  EXPECT_TRUE(r.passed) << r.message;
  // The same normalisation as a plain quadrature over directions (the pdf has edges there: 2e-3).
  std::vector<double> per_bin = bins.integrate([&](Vec3 w) { return direction_pdf(c.light, c.tris, p, w); }, sub);
  EXPECT_NEAR(test::sum(per_bin), 1.0, 2e-3) << "integral of the solid-angle pdf";
}

// A 0.8 x 0.5 panel at y = 1 facing down, as a scene's area light.
AreaCase rect_case(std::unique_ptr<RenderScene>& scene) {
  LightDesc l;
  l.type = LightType::area;
  l.color = Vec3(5, 4, 3);
  l.position = Vec3(0, 1, 0);
  l.direction = Vec3(0, -1, 0);
  l.dim_x = Vec3(0.8f, 0, 0);
  l.dim_y = Vec3(0, 0, 0.5f);
  scene = scene_with({l});
  AreaCase c{scene->lights[0], {}};
  Vec3 p00(-0.4f, 1, -0.25f), p10(0.4f, 1, -0.25f), p11(0.4f, 1, 0.25f), p01(-0.4f, 1, 0.25f);
  c.tris = {Tri(p00, p10, p11), Tri(p00, p11, p01)};  // wound to face -y
  return c;
}

}  // namespace

TEST(RectLight, BuiltFromTheSceneAsDescribed) {
  std::unique_ptr<RenderScene> scene;
  AreaCase c = rect_case(scene);
  EXPECT_EQ(c.light.kind, LightKind::rect);
  EXPECT_FLOAT_EQ(c.light.area, 0.4f);
  for (const Tri& t : c.tris) EXPECT_TRUE(near_rel(t.n, Vec3(0, -1, 0), 1e-6f)) << str(t.n);
}

// Seen from straight below, from the side (grazing cosines, where a missing cos in the pdf shows)
// and from far off.
TEST(RectLight, DirectionsFollowThePdf) {
  std::unique_ptr<RenderScene> scene;
  AreaCase c = rect_case(scene);
  const Vec3 points[] = {Vec3(0, 0, 0), Vec3(0.9f, 0.6f, 0.4f), Vec3(-2, -3, 1)};
  for (int k = 0; k < 3; ++k) {
    SCOPED_TRACE(testing::Message() << "p = " << str(points[k]));
    Vec3 axis = normalize(Vec3(0, 1, 0) - points[k]);
    double theta = 0;
    for (const Tri& t : c.tris)
      for (Vec3 v : {t.a, t.b, t.c}) theta = std::max(theta, std::acos(double(dot(axis, normalize(v - points[k])))));
    check_area_light(c, points[k], ConeBins(axis, std::min(M_PI, theta * 1.05), 8, 16), 10 + k, 64);
  }
}

// A one-sided emitter: nothing is sampled from behind it.
TEST(RectLight, NothingFromBehind) {
  std::unique_ptr<RenderScene> scene;
  AreaCase c = rect_case(scene);
  Pcg32 rng(5, 1);
  for (int i = 0; i < 1000; ++i) {
    LightSample s;
    EXPECT_FALSE(sample_light(c.light, Vec3(0.1f, 2, 0), rng.next_2d(), s));
  }
}

// Two emissive triangles of areas 0.5 and 1.5 in different directions from p (one above, one to
// the side): triangles are picked in proportion to area, points uniformly on each.
TEST(MeshLight, DirectionsFollowThePdf) {
  SceneDesc desc;
  Material em;
  em.type = MaterialType::emission;
  em.radiance = Vec3(2, 3, 4);
  desc.materials = {em};
  MeshDesc m;
  m.name = "emitter";
  m.positions = {{-0.5f, 1, -0.5f}, {0.5f, 1, -0.5f}, {-0.5f, 1, 0.5f}, {1.5f, 0, -1}, {1.5f, 0, 1}, {1.5f, 1.5f, 0}};
  m.indices = {0, 1, 2, 3, 4, 5};
  m.tri_material = {0, 0};
  desc.meshes.push_back(m);
  auto scene = scene_with({}, desc);
  ASSERT_EQ(scene->lights.size(), 1u);
  AreaCase c{scene->lights[0], {Tri(m.positions[0], m.positions[1], m.positions[2]),
                                Tri(m.positions[3], m.positions[4], m.positions[5])}};
  EXPECT_EQ(c.light.kind, LightKind::mesh);
  EXPECT_FLOAT_EQ(c.light.area, 2.0f);  // 0.5 + 1.5
  EXPECT_TRUE(near_rel(c.tris[0].n, Vec3(0, -1, 0), 1e-6f) && near_rel(c.tris[1].n, Vec3(-1, 0, 0), 1e-6f));
  uint64_t seed = 20;
  for (Vec3 p : {Vec3(0, 0, 0), Vec3(0.3f, -0.5f, 0.6f)}) {
    SCOPED_TRACE(testing::Message() << "p = " << str(p));
    check_area_light(c, p, ConeBins(Vec3(0, 0, 1), M_PI, 24, 48), seed++, 64);
  }
  // Which triangle each sample came from: a quarter and three quarters, by area.
  Pcg32 rng(21, 1);
  double on_small = 0;
  for (int i = 0; i < kSamples; ++i) {
    Vec3 q, n;
    sample_area_light_point(c.light, rng.next_2d(), q, n);
    on_small += n == c.light.triangle_normals[0];
  }
  auto r = chi2_test({on_small, kSamples - on_small}, {0.25 * kSamples, 0.75 * kSamples}, kAlpha);
  EXPECT_TRUE(r.passed) << r.message;
}

// Intensity I at distance d: I / d^2 arriving, pdf 1 (a delta light), from the light's position.
TEST(PointLight, InverseSquareByHand) {
  LightDesc l;
  l.type = LightType::point;
  l.color = Vec3(3, 6, 9);
  l.position = Vec3(1, 2, 3);
  auto scene = scene_with({l});
  const Light& light = scene->lights[0];
  EXPECT_TRUE(light.is_delta());
  LightSample s;
  ASSERT_TRUE(sample_light(light, Vec3(2, 4, 5), Vec2{0.3f, 0.7f}, s));  // d = |(1, 2, 2)| = 3
  EXPECT_TRUE(near_rel(s.radiance, Vec3(3.0f / 9, 6.0f / 9, 1), 1e-6f)) << str(s.radiance);
  EXPECT_TRUE(near_rel(s.wi, Vec3(-1.0f / 3, -2.0f / 3, -2.0f / 3), 1e-6f)) << str(s.wi);
  EXPECT_EQ(s.pdf, 1.0f);
  EXPECT_EQ(s.point, l.position);
  EXPECT_FALSE(s.infinite);
  ASSERT_TRUE(sample_light(light, Vec3(1, 2, 1), Vec2{0.9f, 0.1f}, s));  // d = 2, straight below in z
  EXPECT_TRUE(near_rel(s.radiance, Vec3(0.75f, 1.5f, 2.25f), 1e-6f)) << str(s.radiance);
}

// A spot of full cone angle 60 degrees (COLLADA falloff_angle) and fall-off exponent 2, 3 units
// away: I cos^2(theta) / 9 inside the 30 degree half angle, nothing outside. By hand:
// cos 20 deg = 0.9396926, squared 0.8830222, / 9 = 0.09811358; cos 29 deg = 0.8746197, squared
// 0.7649596, / 9 = 0.08499551.
TEST(SpotLight, FallOffAndCutOffByHand) {
  LightDesc l;
  l.type = LightType::spot;
  l.color = Vec3(4, 2, 1);
  l.position = Vec3(0, 2, 0);
  l.direction = Vec3(0, -1, 0);
  l.spot_angle_deg = 60;
  l.spot_exponent = 2;
  LightDesc flat = l;
  flat.spot_exponent = 0;
  auto scene = scene_with({l, flat});
  const Light& spot = scene->lights[0];
  EXPECT_NEAR(spot.cos_cutoff, 0.8660254f, 1e-6f);  // cos 30 deg: half the full angle
  auto at = [&](double deg) {
    double t = deg * M_PI / 180;
    return l.position + Vec3(float(3 * std::sin(t)), float(-3 * std::cos(t)), 0);
  };
  struct Case {
    double deg, expected;
  } cases[] = {{0, 1.0 / 9}, {20, 0.09811358}, {29, 0.08499551}};
  for (const Case& c : cases) {
    LightSample s;
    ASSERT_TRUE(sample_light(spot, at(c.deg), Vec2{0.5f, 0.5f}, s)) << c.deg;
    EXPECT_TRUE(near_rel(s.radiance, l.color * float(c.expected), 2e-6f)) << c.deg << " deg: " << str(s.radiance);
    EXPECT_TRUE(near_rel(s.wi, normalize(l.position - at(c.deg)), 1e-6f)) << c.deg;
    EXPECT_EQ(s.pdf, 1.0f);
  }
  LightSample s;
  EXPECT_FALSE(sample_light(spot, at(31), Vec2{0.5f, 0.5f}, s)) << "outside the cone";
  EXPECT_FALSE(sample_light(spot, l.position + Vec3(0, 1, 0), Vec2{0.5f, 0.5f}, s)) << "behind the spot";
  // Exponent 0: no fall-off inside the cone, the same cut-off.
  ASSERT_TRUE(sample_light(scene->lights[1], at(25), Vec2{0.5f, 0.5f}, s));
  EXPECT_TRUE(near_rel(s.radiance, l.color / 9.0f, 1e-6f)) << str(s.radiance);
  EXPECT_FALSE(sample_light(scene->lights[1], at(31), Vec2{0.5f, 0.5f}, s));
}

// Irradiance E travelling along `direction`: it arrives from -direction, pdf 1, at infinity.
TEST(DirectionalLight, ArrivesAgainstItsDirection) {
  LightDesc l;
  l.type = LightType::directional;
  l.color = Vec3(1, 2, 3);
  l.direction = Vec3(0, -1, 0);
  auto scene = scene_with({l});
  LightSample s;
  ASSERT_TRUE(sample_light(scene->lights[0], Vec3(5, 5, 5), Vec2{0.2f, 0.8f}, s));
  EXPECT_EQ(s.wi, Vec3(0, 1, 0));
  EXPECT_EQ(s.radiance, l.color);
  EXPECT_EQ(s.pdf, 1.0f);
  EXPECT_TRUE(s.infinite);
}

// The ambient light is a sky of constant radiance over the upper hemisphere (+y), sampled
// uniformly there: pdf 1 / (2 pi) above the horizon, 0 below.
TEST(AmbientLight, UniformOverTheUpperHemisphere) {
  LightDesc l;
  l.type = LightType::ambient;
  l.color = Vec3(0.5f, 0.6f, 0.7f);
  auto scene = scene_with({l});
  const Light& light = scene->lights[0];
  ConeBins bins(Vec3(0, 1, 0), M_PI, 16, 32);  // theta from +y: the horizon is a bin edge
  std::vector<double> observed(bins.size(), 0.0);
  Pcg32 rng(30, 1);
  int failures = 0;
  for (int i = 0; i < kSamples; ++i) {
    LightSample s;
    bool ok = sample_light(light, Vec3(0, 0, 0), rng.next_2d(), s);
    observed[bins.index(s.wi)] += 1;
    bool agrees = ok && s.infinite && s.radiance == l.color && near_rel(s.pdf, float(0.5 / M_PI), 1e-6f) &&
                  infinite_light_pdf(light, s.wi) == s.pdf && infinite_light_radiance(light, s.wi) == s.radiance &&
                  std::fabs(length(s.wi) - 1) < 1e-5f;
    if (!agrees && failures++ == 0) ADD_FAILURE() << "sample " << i << ": wi " << str(s.wi) << " pdf " << s.pdf;
  }
  EXPECT_EQ(failures, 0);
  std::vector<double> expected = bins.integrate([&](Vec3 w) { return infinite_light_pdf(light, w); }, 8);
  EXPECT_NEAR(test::sum(expected), 1.0, 1e-4);
  for (double& e : expected) e *= kSamples;
  auto r = chi2_test(observed, expected, kAlpha);
  EXPECT_TRUE(r.passed) << r.message;
  EXPECT_EQ(infinite_light_radiance(light, Vec3(0, -1, 0)), Vec3(0.0f));
  EXPECT_EQ(infinite_light_pdf(light, normalize(Vec3(1, -0.01f, 0))), 0.0f);
}

// ---- the environment map ----

namespace {

// The course's lat-long mapping, as lights.h states it: theta = acos(y), phi = atan2(-z, x) + pi,
// u = phi / 2 pi, v = theta / pi; and its inverse.
Vec2 env_uv(Vec3 d) {
  double theta = std::acos(std::clamp(double(d.y), -1.0, 1.0)), phi = std::atan2(-double(d.z), double(d.x)) + M_PI;
  return Vec2{float(phi / (2 * M_PI)), float(theta / M_PI)};
}
Vec3 env_dir(double u, double v) {
  double theta = M_PI * v, phi = 2 * M_PI * u;
  return Vec3(float(-std::sin(theta) * std::cos(phi)), float(std::cos(theta)), float(std::sin(theta) * std::sin(phi)));
}

// A 32 x 16 sky: a gradient, a sun 200 times brighter and a black band that must never be sampled.
EnvironmentMap test_sky() {
  const int w = 32, h = 16;
  std::vector<Vec3> texels(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Vec3 t(0.1f + 0.02f * x, 0.2f, 0.3f + 0.01f * y);
      if (x >= 20 && x < 23 && y >= 3 && y < 5) t = Vec3(40, 38, 30);
      if (y == 12) t = Vec3(0.0f);
      texels[size_t(y) * w + x] = t;
    }
  return EnvironmentMap(w, h, texels);
}

}  // namespace

// Texels as bins: the sampled directions against the pdf integrated over each texel's solid angle
// (d omega = 2 pi^2 sin(theta) du dv), every sample consistent with pdf() and lookup().
TEST(EnvironmentLight, DirectionsFollowThePdf) {
  EnvironmentMap map = test_sky();
  Light light;
  light.kind = LightKind::environment;
  light.env = &map;
  const int w = map.width(), h = map.height(), sub = 6;
  std::vector<double> expected(size_t(w) * h, 0.0);
  for (int y = 0; y < h * sub; ++y) {
    double v = (y + 0.5) / (h * sub), dv = 1.0 / (h * sub);
    for (int x = 0; x < w * sub; ++x) {
      double u = (x + 0.5) / (w * sub), du = 1.0 / (w * sub);
      expected[size_t(y / sub) * w + x / sub] += map.pdf(env_dir(u, v)) * 2 * M_PI * M_PI * std::sin(M_PI * v) * du * dv;
    }
  }
  EXPECT_NEAR(test::sum(expected), 1.0, 1e-3) << "integral of the solid-angle pdf";
  std::vector<double> observed(expected.size(), 0.0);
  Pcg32 rng(40, 1);
  int failures = 0;
  for (int i = 0; i < kSamples; ++i) {
    LightSample s;
    if (!sample_light(light, Vec3(0, 0, 0), rng.next_2d(), s)) {
      if (failures++ == 0) ADD_FAILURE() << "sample " << i << " failed";
      continue;
    }
    Vec2 uv = env_uv(s.wi);
    observed[size_t(std::min(int(uv.y * h), h - 1)) * w + std::min(int(uv.x * w), w - 1)] += 1;
    // Near a pole sin(theta) = 1 - y^2 loses digits: float rounding of y moves it by ~1e-7 / sin^2.
    float rel = 1e-3f + 1e-6f / std::max(1e-12f, 1 - s.wi.y * s.wi.y);
    bool agrees = s.infinite && std::fabs(length(s.wi) - 1) < 1e-5f && near_rel(s.pdf, map.pdf(s.wi), rel) &&
                  near_rel(infinite_light_pdf(light, s.wi), s.pdf, rel) && s.radiance == map.lookup(s.wi) &&
                  infinite_light_radiance(light, s.wi) == s.radiance;
    if (!agrees && failures++ == 0)
      ADD_FAILURE() << "sample " << i << ": wi " << str(s.wi) << " pdf " << s.pdf << " vs pdf() " << map.pdf(s.wi);
  }
  EXPECT_EQ(failures, 0);
  for (double& e : expected) e *= kSamples;
  auto r = chi2_test(observed, expected, kAlpha);
  EXPECT_TRUE(r.passed) << r.message;
}

// Within a row the pdf follows luminance; and on a uniform sky of height h the pdf at a row's
// centre is h sin(pi / 2h) / (2 pi^2) (sum_y sin(pi (y + 1/2) / h) = 1 / sin(pi / 2h)), for h = 8:
// 8 x 0.19509032 / 19.7392088 = 0.07906721, near 1 / (4 pi) = 0.07957747.
TEST(EnvironmentLight, PdfFollowsLuminanceByHand) {
  EnvironmentMap uniform(16, 8, std::vector<Vec3>(16 * 8, Vec3(2.0f)));
  for (int y = 0; y < 8; ++y)
    for (double u : {0.01, 0.3, 0.77})
      EXPECT_NEAR(uniform.pdf(env_dir(u, (y + 0.5) / 8)), 0.07906721, 2e-6) << "row " << y << " u " << u;
  EnvironmentMap sky = test_sky();
  Vec3 sun = env_dir(21.5 / 32, 3.5 / 16), beside = env_dir(24.5 / 32, 3.5 / 16), black = env_dir(5.5 / 32, 12.5 / 16);
  float ratio = luminance(Vec3(40, 38, 30)) / luminance(Vec3(0.1f + 0.02f * 24, 0.2f, 0.3f + 0.01f * 3));
  EXPECT_NEAR(sky.pdf(sun) / sky.pdf(beside), ratio, 1e-4 * ratio);
  EXPECT_EQ(sky.pdf(black), 0.0f);
  EXPECT_TRUE(near_rel(sky.lookup(sun), Vec3(40, 38, 30), 1e-4f));  // a texel's centre reads that texel
}
