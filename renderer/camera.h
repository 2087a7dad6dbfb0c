// Pinhole and thin-lens cameras, placed as the course does (orbiting the scene's bounding box)
// or as authored in the file, plus the course's camera settings file (-c).
#pragma once

#include <string>

#include "math.h"
#include "scene.h"

namespace pt {

// The course's focal distance (-d): every default of it (CameraParams, RenderParams, the option
// table, Camera) is this one.
constexpr double kCourseFocalDistance = 4.7;

// An explicit pose (the job service's camera field): it replaces the framing's position and
// orientation, and a vertical field of view > 0 replaces its field of view.
struct CameraPose {
  bool set = false;
  Vec3 position, target, up{0, 1, 0};
  float vfov_deg = 0;  // 0: the framing's
};
// Why `pose` cannot place a camera, naming the part ("position: ..."), or "" when it can.
std::string pose_error(const CameraPose& pose);
// The vertical field of view a pose may ask for, in degrees.
constexpr float kMinPoseFov = 0.1f, kMaxPoseFov = 179;

struct CameraParams {
  int width = 800, height = 600;   // full frame in pixels (-r)
  float lens_radius = 0;           // -b; 0 is a pinhole
  float focal_distance = float(kCourseFocalDistance);  // -d: plane of focus, world units along the view axis
  bool file_camera = false;        // use the scene file's camera pose and FOV as authored
  bool keep_fov = false;           // -r scales the course's 800x600 view instead of cropping it
  bool frame_scene = false;        // the course's view direction, the field of view fitted to the bounds
  std::string settings_file;       // -c: course camera settings file
  CameraPose pose;                 // applied after the framing when set
};

struct Camera {
  Vec3 position;
  Vec3 right, up, back;            // camera-to-world axes (the camera looks along -back)
  float tan_half_w = 0, tan_half_h = 0;
  int width = 800, height = 600;
  float lens_radius = 0, focal_distance = float(kCourseFocalDistance);
  float tmin = 0, tmax = kInf;
  float screen_distance = 0;       // pixels, as in the course's settings file
  Vec3 target;                     // what the course camera orbits (for the settings file)

  // (sx, sy) in [0,1]^2 on the sensor, y up, (0,0) = bottom-left; lens_u picks the lens point.
  Ray generate_ray(float sx, float sy, Vec2 lens_u) const;
  // The same, written into r (for rays that go into an array: see spawn_ray in accel.h).
  void generate_ray(float sx, float sy, Vec2 lens_u, Ray& r) const;
  // The pinhole ray through the same sensor point (what autofocus casts).
  Ray pinhole_ray(float sx, float sy) const;
  void pinhole_ray(float sx, float sy, Ray& r) const;
  // pinhole_ray for sensor points (sx[i], sy[i]), i < n, in lanes (the same bits): eight at a
  // time in AVX2 where forms::use_avx2(), then four in SSE2, the tail one by one.
  void pinhole_rays(const float* sx, const float* sy, size_t n, Ray* out) const;
  // generate_ray for sensor points (sx[i], sy[i]) and lens samples lens_u[i], i < n, in lanes as
  // pinhole_rays (the same bits). Any camera: a pinhole's rays ignore lens_u.
  void generate_rays(const float* sx, const float* sy, const Vec2* lens_u, size_t n, Ray* out) const;
  // The inverse of generate_ray: the sensor point (sx, sy) whose ray from lens sample lens_u passes
  // through world point p, and that ray's origin. False for a point not in front of the lens or a
  // lens focused at zero. (sx, sy) may lie outside [0,1]^2.
  bool sensor_point(Vec3 p, Vec2 lens_u, float& sx, float& sy, Vec3& origin) const;
};

// `c` moved to look from `position` at `target` with `up` (world +Y by default), its field of view,
// size and lens kept: what the window's orbit, pan and dolly show. A pose with position == target
// keeps c.
Camera camera_looking(Camera c, Vec3 position, Vec3 target, Vec3 up = Vec3(0, 1, 0));
// The camera's vertical field of view in degrees.
float vertical_fov_deg(const Camera& camera);

// Builds the camera; throws std::runtime_error naming the settings file on a bad -c file.
Camera make_camera(const SceneDesc& scene, const CameraParams& params);
// The same from what the camera reads of a scene: the file's camera and the geometry bounds (the
// course framing orbits them), so a view can be made without the scene's vertices.
Camera make_camera(const CameraDesc& authored, const Bounds3& bounds, const CameraParams& params);
// The fraction of the scene's bounding box, as the camera projects it, that the image shows
// (1: all of it; 0 for empty bounds or bounds behind the camera). The CLI's crop hint reads it.
float visible_bounds_fraction(const Camera& camera, const Bounds3& bounds);
// Writes the course's six-line camera settings file (the window's D key).
void write_camera_settings(const Camera& camera, const std::string& path);

}  // namespace pt
