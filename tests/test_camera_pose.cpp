// An explicit camera pose (CameraPose: the job service's camera field, the CLI's --camera): it
// replaces the framing, a job's resolved view posted back renders the same view, bad poses are
// refused by name, and a checkpoint tells two poses apart.
#include <gtest/gtest.h>

#include <cmath>

#include "camera.h"
#include "checkpoint.h"
#include "options.h"
#include "test_util.h"

using namespace pt;

namespace {

CameraParams sized(int w, int h) {
  CameraParams p;
  p.width = w;
  p.height = h;
  return p;
}

void expect_near(Vec3 a, Vec3 b, float tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

CameraPose pose_of(Vec3 position, Vec3 target, float vfov = 0) {
  CameraPose p;
  p.set = true;
  p.position = position;
  p.target = target;
  p.vfov_deg = vfov;
  return p;
}

}  // namespace

TEST(CameraPose, ReplacesTheFramingAndKeepsItsFieldOfView) {
  const SceneDesc s = test::camera_box_scene();
  CameraParams p = sized(320, 240);
  const Camera framed = make_camera(s, p);
  p.pose = pose_of(Vec3(3, 1, 2), Vec3(0, 0.5f, 0));
  const Camera c = make_camera(s, p);
  expect_near(c.position, Vec3(3, 1, 2), 1e-6f);
  expect_near(c.target, Vec3(0, 0.5f, 0), 1e-6f);
  EXPECT_FLOAT_EQ(c.screen_distance, framed.screen_distance);  // no vfov: the framing's
  // The image centre looks at the target, and image up has no sideways tilt (world up +Y).
  const Ray r = c.pinhole_ray(0.5f, 0.5f);
  expect_near(normalize(r.d), normalize(Vec3(0, 0.5f, 0) - Vec3(3, 1, 2)), 1e-5f);
  EXPECT_NEAR(c.right.y, 0, 1e-6);
  EXPECT_GT(c.up.y, 0);
}

TEST(CameraPose, TheSameVfovIsTheSameViewAtAnySize) {
  // What the page's half-size sweeps rely on: a smaller copy of the view, not a crop of it.
  const SceneDesc s = test::camera_box_scene();
  CameraParams big = sized(320, 240), small = sized(160, 120);
  big.pose = small.pose = pose_of(Vec3(0, 2, 5), Vec3(0, 0.5f, 0), 30);
  const Camera a = make_camera(s, big), b = make_camera(s, small);
  EXPECT_NEAR(vertical_fov_deg(a), 30, 1e-4);
  EXPECT_NEAR(vertical_fov_deg(b), 30, 1e-4);
  for (float sx : {0.0f, 0.25f, 1.0f})
    for (float sy : {0.0f, 0.75f, 1.0f}) expect_near(a.pinhole_ray(sx, sy).d, b.pinhole_ray(sx, sy).d, 1e-6f);
}

TEST(CameraPose, AResolvedViewPostedBackIsTheSameCamera) {
  // A job's status shows the camera it renders from; the page orbits from it and posts it back.
  const SceneDesc s = test::camera_box_scene();
  for (bool frame : {false, true}) {
    CameraParams p = sized(200, 100);
    p.frame_scene = frame;
    const Camera framed = make_camera(s, p);
    p.pose = pose_of(framed.position, framed.target, vertical_fov_deg(framed));
    p.pose.up = framed.up;
    const Camera posed = make_camera(s, p);
    for (float sx : {0.0f, 0.3f, 1.0f})
      for (float sy : {0.0f, 0.6f, 1.0f}) {
        const Ray a = framed.pinhole_ray(sx, sy), b = posed.pinhole_ray(sx, sy);
        expect_near(a.o, b.o, 1e-6f);
        expect_near(a.d, b.d, 1e-5f);
      }
  }
}

TEST(CameraPose, UpTiltsTheImage) {
  const SceneDesc s = test::camera_box_scene();
  CameraParams p = sized(100, 100);
  p.pose = pose_of(Vec3(0, 0, 5), Vec3(0, 0, 0));
  p.pose.up = Vec3(1, 0, 0);  // a quarter turn: image up is world +X
  const Camera c = make_camera(s, p);
  expect_near(c.up, Vec3(1, 0, 0), 1e-6f);
  expect_near(c.right, Vec3(0, -1, 0), 1e-6f);
}

TEST(CameraPose, APoseDropsTheFilesClipRange) {
  // A glTF camera's znear / zfar fit where it was authored, not where the user moved it.
  SceneDesc s = test::camera_box_scene();
  s.camera.present = true;
  s.camera.as_authored = true;
  s.camera.yfov_deg = 40;
  s.camera.znear = 2;
  s.camera.zfar = 3;
  s.camera.world = Mat4::identity();
  CameraParams p = sized(100, 100);
  p.pose = pose_of(Vec3(0, 0, 50), Vec3(0, 0, 0));
  const Camera c = make_camera(s, p);
  EXPECT_EQ(c.tmin, 0);
  EXPECT_TRUE(std::isinf(c.tmax));
  EXPECT_NEAR(vertical_fov_deg(c), 40, 1e-3);  // the file's field of view stays without a vfov
}

TEST(CameraPose, BadPosesAreRefusedByName) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::nanf("");
  auto why = [](CameraPose p) { return pose_error(p); };
  EXPECT_EQ(why(pose_of(Vec3(0, 0, 5), Vec3(0, 0, 0), 45)), "");
  EXPECT_EQ(why(pose_of(Vec3(nan, 0, 5), Vec3(0, 0, 0))).rfind("position:", 0), 0u);
  EXPECT_EQ(why(pose_of(Vec3(0, 0, 2e7f), Vec3(0, 0, 0))).rfind("position:", 0), 0u);
  EXPECT_EQ(why(pose_of(Vec3(0, 0, 5), Vec3(inf, 0, 0))).rfind("target:", 0), 0u);
  EXPECT_EQ(why(pose_of(Vec3(1, 2, 3), Vec3(1, 2, 3))), "target: must differ from the position");
  CameraPose p = pose_of(Vec3(0, 0, 5), Vec3(0, 0, 0));
  p.up = Vec3(0, 0, 0);
  EXPECT_EQ(why(p), "up: must not be zero");
  p.up = Vec3(0, 0, -2);
  EXPECT_EQ(why(p), "up: must not be parallel to the view direction");
  for (float bad : {0.05f, 179.5f, -1.0f, nan}) {
    SCOPED_TRACE(bad);
    EXPECT_EQ(why(pose_of(Vec3(0, 0, 5), Vec3(0, 0, 0), bad)).rfind("vfov:", 0), 0u);
  }
  RenderParams params;
  params.camera = pose_of(Vec3(0, 0, 5), Vec3(0, 0, 5));
  try {
    params.validate();
    ADD_FAILURE() << "a pose looking at itself passed";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("camera.target (--camera):", 0), 0u) << e.what();
  }
}

TEST(CameraPose, TwoPosesAreTwoFilms) {
  // A checkpoint of one view must not resume another, even a float's last digit away.
  RenderParams a, b;
  a.camera = b.camera = pose_of(Vec3(0.1234567f, 0, 5), Vec3(0, 0, 0), 30);
  EXPECT_EQ(render_fingerprint("scene", a), render_fingerprint("scene", b));
  b.camera.position.x = std::nextafter(a.camera.position.x, 1.0f);
  EXPECT_NE(render_fingerprint("scene", a), render_fingerprint("scene", b));
  RenderParams none;
  EXPECT_NE(render_fingerprint("scene", a), render_fingerprint("scene", none));
}
