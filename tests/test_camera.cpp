// Camera placement (course framing, authored, settings file) and thin-lens geometry.
#include "camera.h"
#include "loop_forms.h"

#include <gtest/gtest.h>

#include <cstring>

#include "collada.h"
#include "lane_math.h"
#include "render_scene.h"
#include "rng.h"
#include "simd.h"
#include "test_util.h"

using namespace pt;

namespace {

float dist(Vec3 a, Vec3 b) { return length(a - b); }

}  // namespace

TEST(Camera, CourseFramingOrbitsTheBoundingBox) {
  SceneDesc s = test::camera_box_scene();
  Camera c = make_camera(s, CameraParams());
  // Centre (0, 0.75, 0), diagonal sqrt(4 + 2.25 + 4) = 3.2016, distance 1.5 x that = 4.802.
  EXPECT_NEAR(c.position.x, 0, 1e-5);
  EXPECT_NEAR(c.position.y, 0.75, 1e-5);
  EXPECT_NEAR(c.position.z, 1.5 * std::sqrt(10.25), 1e-4);
  Ray r = c.pinhole_ray(0.5f, 0.5f);
  EXPECT_NEAR(r.d.z, -1, 1e-6);
}

TEST(Camera, ResizeKeepsThePixelAngle) {
  SceneDesc s = test::camera_box_scene();
  CameraParams p;
  Camera full = make_camera(s, p);
  p.width = 400;
  p.height = 300;
  Camera half = make_camera(s, p);
  EXPECT_NEAR(half.tan_half_w, full.tan_half_w / 2, 1e-6);
  EXPECT_NEAR(half.tan_half_h, full.tan_half_h / 2, 1e-6);
  // The centre pixel of the crop sees what the centre pixel of the full frame sees.
  Ray a = full.pinhole_ray(0.5f, 0.5f), b = half.pinhole_ray(0.5f, 0.5f);
  EXPECT_LT(dist(a.d, b.d), 1e-6);
  // The 800x600 fit: 49.13 degree xfov at 4:3 gives the vertical 600 px span.
  EXPECT_NEAR(std::atan(full.tan_half_w) * 2 * 180 / kPi, 49.13434, 0.01);
}

TEST(Camera, ThinLensRaysFromOnePixelMeetOnTheFocalPlane) {
  SceneDesc s = test::camera_box_scene();
  CameraParams p;
  p.lens_radius = 0.25f;
  p.focal_distance = 3.0f;
  Camera c = make_camera(s, p);
  Vec3 view = -c.back;
  for (Vec2 px : {Vec2{0.5f, 0.5f}, Vec2{0.1f, 0.8f}, Vec2{0.93f, 0.07f}}) {
    Vec3 first;
    Pcg32 rng(7, 1);
    for (int k = 0; k < 64; ++k) {
      Ray r = c.generate_ray(px.x, px.y, rng.next_2d());
      // Lens origins lie on the lens disk of the given radius around the camera.
      EXPECT_LE(dist(r.o, c.position), p.lens_radius * 1.0001f);
      EXPECT_NEAR(dot(r.o - c.position, view), 0, 1e-5);
      float t = (p.focal_distance - dot(r.o - c.position, view)) / dot(r.d, view);
      Vec3 hit = r.o + r.d * t;
      if (k == 0) first = hit;
      else EXPECT_LT(dist(hit, first), 2e-5f) << "pixel " << px.x << "," << px.y;
    }
    // ... and that point is where the pinhole ray through the pixel crosses the plane.
    Ray pin = c.pinhole_ray(px.x, px.y);
    Vec3 on_plane = pin.o + pin.d * (p.focal_distance / dot(pin.d, view));
    EXPECT_LT(dist(on_plane, first), 2e-5f);
  }
}

// What light tracing splats by: the sensor point whose ray from a given lens point passes through
// a world point, for points at every depth (in front of and behind the plane of focus).
TEST(Camera, SensorPointInvertsGenerateRay) {
  SceneDesc s = test::camera_box_scene();
  for (float radius : {0.0f, 0.25f}) {
    CameraParams p;
    p.lens_radius = radius;
    p.focal_distance = 3.0f;
    Camera c = make_camera(s, p);
    Pcg32 rng(11, 3);
    for (int k = 0; k < 200; ++k) {
      Vec2 px = rng.next_2d(), lens = rng.next_2d();
      Ray r = c.generate_ray(px.x, px.y, lens);
      Vec3 point = r.o + r.d * (0.5f + 8 * rng.next_float());
      float sx, sy;
      Vec3 origin;
      ASSERT_TRUE(c.sensor_point(point, lens, sx, sy, origin));
      EXPECT_NEAR(sx, px.x, 2e-5f) << "lens radius " << radius;
      EXPECT_NEAR(sy, px.y, 2e-5f) << "lens radius " << radius;
      EXPECT_LT(dist(origin, r.o), 1e-5f);
    }
    float sx, sy;
    Vec3 origin;
    EXPECT_FALSE(c.sensor_point(c.position + c.back, {0.5f, 0.5f}, sx, sy, origin)) << "behind the camera";
  }
}

TEST(Camera, ZeroLensRadiusIsExactlyThePinhole) {
  SceneDesc s = test::camera_box_scene();
  CameraParams p;
  p.lens_radius = 0;
  Camera c = make_camera(s, p);
  Pcg32 rng(3, 4);
  for (int k = 0; k < 16; ++k) {
    Vec2 px = rng.next_2d();
    Ray a = c.generate_ray(px.x, px.y, rng.next_2d()), b = c.pinhole_ray(px.x, px.y);
    EXPECT_EQ(a.o, b.o);
    EXPECT_EQ(a.d, b.d);
  }
}

TEST(Camera, FileCameraUsesTheAuthoredPose) {
  SceneDesc s = test::camera_box_scene();
  CameraParams p;
  p.file_camera = true;
  Camera c = make_camera(s, p);
  // Course matrix: camera at z = 3 (Z-up file) -> (0, 0, 3) Y-up... translation (0, 3, 0) in
  // the file maps to (-0, 0, 3); it looks along the file's -z axis mapped to Y-up.
  EXPECT_NEAR(c.position.z, 3, 1e-5);
  EXPECT_NEAR(c.position.y, 0, 1e-5);
  Ray r = c.pinhole_ray(0.5f, 0.5f);
  EXPECT_NEAR(r.d.z, -1, 1e-5);
  EXPECT_NEAR(std::atan(c.tan_half_w) * 2 * 180 / kPi, 49.13434, 0.01);
  EXPECT_FLOAT_EQ(c.tmin, 0.1f);
  EXPECT_FLOAT_EQ(c.tmax, 100.0f);
}

TEST(Camera, SettingsFileRoundTrip) {
  SceneDesc s = test::camera_box_scene();
  CameraParams p;
  p.width = 320;
  p.height = 200;
  Camera a = make_camera(s, p);
  std::string path = test::temp_dir() + "/cam_settings.txt";
  write_camera_settings(a, path);
  p.settings_file = path;
  Camera b = make_camera(s, p);
  for (Vec2 px : {Vec2{0.5f, 0.5f}, Vec2{0.0f, 1.0f}, Vec2{0.7f, 0.2f}}) {
    Ray ra = a.pinhole_ray(px.x, px.y), rb = b.pinhole_ray(px.x, px.y);
    EXPECT_LT(dist(ra.o, rb.o), 1e-4f);
    EXPECT_LT(dist(ra.d, rb.d), 1e-4f);
  }
}

TEST(Camera, BadSettingsFileNamesTheField) {
  std::string path = test::temp_dir() + "/cam_bad.txt";
  FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr) << path;
  std::fputs("30 20 1.5 0.1 100\n0 0 0 1 1 1\n1 2 oops\n", f);
  std::fclose(f);
  CameraParams p;
  p.settings_file = path;
  try {
    make_camera(test::camera_box_scene(), p);
    FAIL() << "expected an error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("cam_bad.txt"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("distance"), std::string::npos) << e.what();
  }
}

TEST(Camera, CBdragonDefaultFocusIsOnTheDragon) {
  PT_REQUIRE_SHARED_SCENE(path, "CBdragon.dae");
  SceneDesc s = load_collada(path);
  Camera c = make_camera(s, CameraParams());
  // The dragon's nearest and farthest points along the view axis bracket the course's -d 4.5.
  Vec3 view = -c.back;
  float lo = kInf, hi = -kInf;
  for (const MeshDesc& m : s.meshes) {
    if (m.indices.size() < 3000) continue;  // the box walls and light quad are small meshes
    for (const Vec3& v : m.positions) {
      float z = dot(v - c.position, view);
      lo = std::min(lo, z);
      hi = std::max(hi, z);
    }
  }
  EXPECT_LT(lo, 4.5f);
  EXPECT_GT(hi, 4.5f);
}

TEST(Camera, KeepFovScalesTheCourseViewInsteadOfCropping) {
  SceneDesc s = test::camera_box_scene();
  CameraParams p;
  Camera full = make_camera(s, p);
  p.width = 480;
  p.height = 360;
  p.keep_fov = true;
  Camera scaled = make_camera(s, p);
  EXPECT_NEAR(scaled.tan_half_w, full.tan_half_w, 1e-6);
  EXPECT_NEAR(scaled.tan_half_h, full.tan_half_h, 1e-6);
  p.keep_fov = false;
  Camera cropped = make_camera(s, p);
  EXPECT_NEAR(cropped.tan_half_w, full.tan_half_w * 0.6f, 1e-6);
}

// A 480x360 course camera turned so that every axis mixes x, y and z: the lanes' sums must run in
// the scalar order to give its bits.
Camera tilted_camera(Vec3 back) {
  CameraParams cp;
  cp.width = 480;
  cp.height = 360;
  Camera c = make_camera(test::camera_box_scene(), cp);
  Frame tilted(normalize(back));
  c.right = tilted.s, c.up = tilted.t, c.back = tilted.n;
  return c;
}

// Camera rays eight at a time in AVX2 and four in SSE2 (render_tile's batches) must be
// pinhole_ray's bits, for any count (eight-wide groups, then four-wide, then the tail one by one)
// and sensor points on and off the sensor. Without AVX2 both rounds check the SSE2 lanes.
TEST(Camera, PinholeRaysInLanesAreThePinholeRaysBits) {
  Camera c = tilted_camera(Vec3(0.3f, -0.5f, 0.8f));
  Pcg32 rng(7, 11);
  for (bool avx2 : {true, false}) {
    forms::Scoped forms;
    forms->avx2 = avx2;
    for (size_t n : {size_t(0), size_t(1), size_t(4), size_t(7), size_t(13), size_t(1001)}) {
      SCOPED_TRACE(testing::Message() << (avx2 ? "AVX2 where the CPU has it" : "SSE2") << ", " << n << " rays");
      std::vector<float> sx(n), sy(n);
      for (size_t i = 0; i < n; ++i) {
        sx[i] = 1.4f * rng.next_float() - 0.2f;
        sy[i] = 1.4f * rng.next_float() - 0.2f;
      }
      if (n > 2) sx[1] = sy[1] = 0.5f, sx[2] = 0, sy[2] = 1;  // the centre and a corner exactly
      std::vector<Ray> lanes(n);
      c.pinhole_rays(sx.data(), sy.data(), n, lanes.data());
      for (size_t i = 0; i < n; ++i) {
        Ray one = c.pinhole_ray(sx[i], sy[i]);
        SCOPED_TRACE(i);
        EXPECT_EQ(lanes[i].o, one.o);
        EXPECT_EQ(lanes[i].d, one.d);
        EXPECT_EQ(lanes[i].tmin, one.tmin);
        EXPECT_EQ(lanes[i].tmax, one.tmax);
      }
    }
  }
}

// generate_rays in lanes (both widths, as above) against generate_ray: a thin lens (and one
// focused at 0, where the lens centre's ray falls back to the pinhole direction), lens samples at
// the disk map's centre and edges, and a pinhole (which ignores the lens samples).
TEST(Camera, ThinLensRaysInLanesAreGenerateRaysBits) {
  Camera c = tilted_camera(Vec3(-0.6f, 0.2f, 0.7f));
  Pcg32 rng(3, 5);
  for (bool avx2 : {true, false}) {
    forms::Scoped forms;
    forms->avx2 = avx2;
    for (auto [radius, focus] : {std::pair{0.2f, 3.5f}, std::pair{0.3f, 0.0f}, std::pair{0.0f, 4.7f}}) {
      c.lens_radius = radius, c.focal_distance = focus;
      for (size_t n : {size_t(0), size_t(3), size_t(8), size_t(13), size_t(1001)}) {
        std::vector<float> sx(n), sy(n);
        std::vector<Vec2> lens(n);
        for (size_t i = 0; i < n; ++i) {
          sx[i] = 1.4f * rng.next_float() - 0.2f;
          sy[i] = 1.4f * rng.next_float() - 0.2f;
          lens[i] = rng.next_2d();
        }
        if (n > 7) {
          lens[1] = {0.5f, 0.5f};  // the lens centre
          lens[2] = {0, 0.5f}, lens[3] = {0.5f, 0.9999999f}, lens[4] = {0, 0};  // edges and a corner
          lens[5] = {0.75f, 0.75f}, sx[5] = sy[5] = 0.5f;  // a diagonal, through the sensor centre
        }
        std::vector<Ray> lanes(n);
        c.generate_rays(sx.data(), sy.data(), lens.data(), n, lanes.data());
        for (size_t i = 0; i < n; ++i) {
          Ray one = c.generate_ray(sx[i], sy[i], lens[i]);
          SCOPED_TRACE(testing::Message() << (avx2 ? "AVX2 where the CPU has it" : "SSE2") << ", radius " << radius
                                          << " focus " << focus << " ray " << i);
          ASSERT_EQ(std::memcmp(&lanes[i].o, &one.o, sizeof one.o), 0);
          ASSERT_EQ(std::memcmp(&lanes[i].d, &one.d, sizeof one.d), 0);
          ASSERT_EQ(lanes[i].tmin, one.tmin);
          ASSERT_EQ(lanes[i].tmax, one.tmax);
        }
      }
    }
  }
}

// --frame-scene keeps the course's view direction and fits the field of view to the projected
// bounds: all of the box is in the image, and a 5% narrower view would cut some of it off.
TEST(Camera, FrameSceneFitsTheProjectedBoundsToTheImage) {
  SceneDesc s = test::camera_box_scene();
  CameraParams p;
  p.width = 480;
  p.height = 360;
  const Camera course = make_camera(s, p);
  p.frame_scene = true;
  const Camera fitted = make_camera(s, p);
  EXPECT_EQ(length(fitted.position - course.position), 0.0f);
  EXPECT_EQ(length(fitted.back - course.back), 0.0f);
  const Bounds3 b = s.geometry_bounds();
  EXPECT_FLOAT_EQ(visible_bounds_fraction(fitted, b), 1.0f);
  Camera tighter = fitted;
  tighter.tan_half_w *= 0.95f, tighter.tan_half_h *= 0.95f;
  EXPECT_LT(visible_bounds_fraction(tighter, b), 0.99f);
  // The course's crop at a small size shows only part of it.
  p.frame_scene = false;
  p.width = 160;
  p.height = 120;
  EXPECT_LT(visible_bounds_fraction(make_camera(s, p), b), 0.9f);
  // Pixels stay square.
  EXPECT_NEAR(fitted.tan_half_w / fitted.tan_half_h, 480.0 / 360.0, 1e-5);
}

// Autofocus sets the depth along the view axis of what the click hits (the thin lens focuses on a
// plane at that depth), checked against geometry whose depth we know, off the centre of the view.
TEST(Camera, AutofocusOffCentreIsTheHitsDepthAlongTheViewAxis) {
  SceneDesc s;
  MeshDesc wall;  // a wall at z = 0 facing +z, far wider than the view
  wall.positions = {{-50, -50, 0}, {50, -50, 0}, {50, 50, 0}, {-50, 50, 0}};
  wall.indices = {0, 1, 2, 0, 2, 3};
  wall.tri_material = {0, 0};
  s.meshes.push_back(wall);
  SphereDesc ball;  // a sphere of radius 0.5 in front of the wall, up and to the right
  ball.center = Vec3(3, 2, 4);
  ball.radius = 0.5f;
  ball.material = 0;
  s.spheres.push_back(ball);
  s.materials.push_back(Material());
  LightDesc light;
  light.type = LightType::point;
  light.position = Vec3(0, 0, 20);
  light.color = Vec3(1.0f);
  s.lights.push_back(light);
  RenderParams params;
  auto scene = make_render_scene(s, params);
  Camera& c = scene->camera;  // looking down -z from z = 10
  c.position = Vec3(0, 0, 10), c.right = Vec3(1, 0, 0), c.up = Vec3(0, 1, 0), c.back = Vec3(0, 0, 1);
  c.tan_half_w = 0.8f, c.tan_half_h = 0.6f;
  // The wall: depth 10 wherever it is clicked, the corners too (the ray's length there is 12.8).
  for (float sx : {0.5f, 0.1f, 0.9f})
    for (float sy : {0.5f, 0.1f, 0.95f}) EXPECT_NEAR(autofocus_distance(*scene, sx, sy), 10.0f, 1e-4f) << sx << " " << sy;
  // The sphere, clicked at its centre's image: the ray meets it |C - O| - r along, at depth
  // (|C - O| - r) cos(angle) with cos = 6 / |C - O|.
  const Vec3 to = ball.center - c.position;  // (3, 2, -6)
  const float sx = 0.5f + 0.5f * (to.x / 6) / c.tan_half_w, sy = 0.5f + 0.5f * (to.y / 6) / c.tan_half_h;
  const float expect = (length(to) - 0.5f) * 6 / length(to);
  EXPECT_NEAR(autofocus_distance(*scene, sx, sy), expect, 1e-4f);
  EXPECT_GT(length(to) - 0.5f - expect, 0.7f);  // the distance along the ray would be this far off
}
