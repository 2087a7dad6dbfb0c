// Image tests of the lights test_render.cpp does not render: a spot light and the ambient sky,
// each in a scene whose every pixel has an analytic value. The residual (render minus that value,
// pixel by pixel) must average zero within its own noise; test_lights.cpp checks the sampling.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "collada.h"
#include "session.h"
#include "test_util.h"

using namespace pt;
using test::RegionStats;
using test::diffuse_sphere_scene;

namespace {

RenderParams params(int spp, int max_depth) {
  RenderParams p;
  p.file_camera = true;
  p.width = p.height = 64;
  p.adaptive = false;
  p.threads = 2;
  p.spp = spp;
  p.max_depth = max_depth;
  return p;
}

// The unit direction of the pinhole ray through the centre of pixel (x, y), top row first.
Vec3 pixel_direction(const Camera& cam, int x, int y) {
  return normalize(cam.pinhole_ray((x + 0.5f) / cam.width, 1 - (y + 0.5f) / cam.height).d);
}

// Statistics of render - expected over the pixels where `expected` gives a value (>= 0).
template <class Expected>
RegionStats residual(const ImageRGB& img, Expected expected, double& mean_expected) {
  ImageRGB r;
  r.width = 0;
  r.height = 1;
  mean_expected = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      double e = expected(x, y);
      if (e < 0) continue;
      r.pixels.push_back(Vec3(float(luminance(img.at(x, y)) - e)));
      mean_expected += e;
      ++r.width;
    }
  if (r.width) mean_expected /= r.width;
  return test::region_stats(r, 0, 0, r.width, 1);
}

}  // namespace

// A spot at the centre of a closed diffuse sphere (albedo rho, radius R = 1), aimed where the
// camera beside it looks: the wall point at angle theta from the axis receives E = I cos^e(theta)
// / R^2 inside the cone (its normal faces the spot), so with direct light only (m = 1) the pixel
// shows rho / pi * I cos^e(theta) inside the 12 degree half angle and black outside.
TEST(SpotRender, FallOffInsideADiffuseSphereMatchesTheFormula) {
  const float rho = 0.6f, intensity = 5, exponent = 3;
  const std::string spot = "<spot><color>5 5 5</color><falloff_angle>24</falloff_angle><falloff_exponent>3"
                           "</falloff_exponent></spot>";
  SceneDesc desc = parse_collada(diffuse_sphere_scene(rho, 0, 30, spot), "spot.dae");
  ASSERT_EQ(desc.lights.size(), 1u);
  ASSERT_EQ(desc.lights[0].type, LightType::spot);
  RenderParams p = params(16, 1);
  auto rs = make_render_scene(desc, p);
  RenderSession s(*rs, p);
  s.render_all();
  ASSERT_EQ(s.stats().nonfinite, 0u);
  ImageRGB img = s.image();
  const double cutoff = 12 * M_PI / 180, margin = 1 * M_PI / 180;  // a pixel spans about 0.5 degree
  auto theta = [&](int x, int y) { return std::acos(std::clamp(double(-pixel_direction(rs->camera, x, y).z), -1.0, 1.0)); };
  double mean_expected = 0;
  RegionStats inside = residual(img, [&](int x, int y) {
    double t = theta(x, y);
    return t < cutoff - margin ? rho / M_PI * intensity * std::pow(std::cos(t), exponent) : -1.0;
  }, mean_expected);
  ASSERT_GT(inside.n, 300);
  EXPECT_NEAR(inside.mean, 0, 4.5 * inside.stderr_ + 1e-4 * mean_expected) << "expected mean " << mean_expected;
  EXPECT_GT(mean_expected, 0.8);  // rho / pi * 5 * cos^3(< 11 deg) is 0.91 to 0.95
  double outside_expected = 0;
  RegionStats outside = residual(img, [&](int x, int y) { return theta(x, y) > cutoff + margin ? 0.0 : -1.0; },
                                 outside_expected);
  ASSERT_GT(outside.n, 1000);
  EXPECT_EQ(outside.mean, 0.0) << "light outside the cone";
  EXPECT_EQ(outside.stderr_, 0.0);
}

// The ambient light is a sky of radiance C over the upper hemisphere. A surface tilted by alpha
// from +y sees the part of it above its own horizon, irradiance E = pi C (1 + cos alpha) / 2 (the
// isotropic-sky view factor: Duffie & Beckman, "Solar Engineering of Thermal Processes", 4th ed.,
// sec. 2.16); a lone convex sphere does not shadow itself for such directions, so its pixel with
// normal n shows rho C (1 + n_y) / 2 at any depth.
TEST(AmbientRender, DiffuseSphereUnderTheSkyMatchesTheFormula) {
  const float rho = 0.7f, sky = 2;
  SceneDesc desc = parse_collada(diffuse_sphere_scene(rho, 20, 7, "<ambient><color>2 2 2</color></ambient>"), "ambient.dae");
  ASSERT_EQ(desc.lights.size(), 1u);
  ASSERT_EQ(desc.lights[0].type, LightType::ambient);
  for (int m : {1, 3}) {
    RenderParams p = params(64, m);
    auto rs = make_render_scene(desc, p);
    RenderSession s(*rs, p);
    s.render_all();
    ASSERT_EQ(s.stats().nonfinite, 0u);
    ImageRGB img = s.image();
    const Vec3 eye = rs->camera.position;
    double mean_expected = 0;
    // Pixels whose centre ray meets the sphere well inside its outline (n_z > 0.3), so that the
    // whole pixel lies on it.
    RegionStats r = residual(img, [&](int x, int y) {
      Vec3 d = pixel_direction(rs->camera, x, y);
      double b = dot(eye, d), c = dot(eye, eye) - 1, disc = b * b - c;
      if (disc <= 0) return -1.0;
      Vec3 n = eye + d * float(-b - std::sqrt(disc));  // the hit point is its own normal
      return n.z > 0.3f ? rho * sky * (1 + n.y) / 2 : -1.0;
    }, mean_expected);
    ASSERT_GT(r.n, 1000) << "depth " << m;
    EXPECT_NEAR(r.mean, 0, 4.5 * r.stderr_ + 1e-3 * mean_expected) << "depth " << m << ", expected mean " << mean_expected;
    EXPECT_LT(4.5 * r.stderr_, 0.02 * mean_expected) << "too noisy to catch a wrong sky";
    // Camera rays do not see the ambient light itself (path_vertex.h, as the course): the
    // background is black above the horizon (top rows) and below it.
    EXPECT_EQ(test::region_stats(img, 0, 0, 64, 2).mean, 0.0) << "depth " << m;
    EXPECT_EQ(test::region_stats(img, 0, 62, 64, 64).mean, 0.0) << "depth " << m;
  }
}
