// Camera placement (course framing, authored, or a settings file) and ray generation.
#include "camera.h"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "lane_math.h"
#include "loop_forms.h"
#include "sampling.h"

// Camera rays at every width (camera_rays.inc): one at a time, four in SSE2, eight in AVX2.
namespace pt::lane1 {
#include "camera_rays.inc"
}  // namespace pt::lane1
namespace pt::lane4 {
#include "camera_rays.inc"
}  // namespace pt::lane4
PT_BEGIN_AVX2
namespace pt::lane8 {
#include "camera_rays.inc"
}  // namespace pt::lane8
PT_END_AVX2

namespace pt {

namespace {

constexpr float kDeg = kPi / 180;

void set_basis(Camera& c, Vec3 back, Vec3 up_hint) {
  c.back = normalize(back);
  Vec3 right = cross(up_hint, c.back);
  if (length(right) < 1e-6f) right = cross(Vec3(0, 0, 1), c.back);  // looking straight up or down
  c.right = normalize(right);
  c.up = cross(c.back, c.right);
}

// The authored field of view, horizontal and vertical, in radians.
void file_fov(const CameraDesc& cd, float* h_fov, float* v_fov) {
  float xf = cd.xfov_deg * kDeg, yf = cd.yfov_deg * kDeg;
  if (!cd.present) {
    xf = 50 * kDeg;
    yf = 0;
  }
  float aspect = cd.aspect > 0 ? cd.aspect : 4.0f / 3.0f;
  if (yf <= 0) yf = 2 * std::atan(std::tan(xf / 2) / aspect);
  if (xf <= 0) xf = 2 * std::atan(std::tan(yf / 2) * aspect);
  *h_fov = xf;
  *v_fov = yf;
}

void read_settings_file(Camera& c, const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open camera settings file");
  float v[32];
  const char* fields[] = {"hFov", "vFov", "aspect", "nearClip", "farClip", "position.x", "position.y",
                          "position.z", "target.x", "target.y", "target.z", "phi", "theta", "distance",
                          "minDistance", "maxDistance", "c2w[0][0]", "c2w[0][1]", "c2w[0][2]", "c2w[1][0]",
                          "c2w[1][1]", "c2w[1][2]", "c2w[2][0]", "c2w[2][1]", "c2w[2][2]", "screenWidth",
                          "screenHeight", "screenDistance", "focalDistance", "lensRadius"};
  for (int i = 0; i < 30; ++i) {
    if (!(in >> v[i]) || !std::isfinite(v[i]))
      throw std::runtime_error(path + ": camera settings field " + fields[i] + " is missing or not a number");
  }
  c.position = Vec3(v[5], v[6], v[7]);
  c.target = Vec3(v[8], v[9], v[10]);
  // Rows of the camera-to-world rotation; its columns are right, up, back.
  c.right = normalize(Vec3(v[16], v[19], v[22]));
  c.up = normalize(Vec3(v[17], v[20], v[23]));
  c.back = normalize(Vec3(v[18], v[21], v[24]));
  if (is_black(c.right) || is_black(c.up) || is_black(c.back))
    throw std::runtime_error(path + ": camera settings rotation is degenerate");
  if (!(v[27] > 0)) throw std::runtime_error(path + ": screenDistance must be positive");
  c.screen_distance = v[27];
  if (v[3] >= 0 && v[4] > v[3]) {
    c.tmin = v[3];
    c.tmax = v[4];
  }
}

// The projected bounding box on the image plane at unit depth: x and y extents in tangent units
// (x along right, y along up), from the corners in front of the camera. False when none is.
bool projected_bounds(const Camera& c, const Bounds3& b, float& x0, float& x1, float& y0, float& y1) {
  if (b.empty()) return false;
  x0 = y0 = kInf, x1 = y1 = -kInf;
  for (int i = 0; i < 8; ++i) {
    const Vec3 corner((i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z);
    const Vec3 d = corner - c.position;
    const float z = -dot(d, c.back);
    if (!(z > 1e-6f * length(d))) return false;  // a corner at or behind the camera: no finite fit
    const float x = dot(d, c.right) / z, y = dot(d, c.up) / z;
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  }
  return std::isfinite(x0 + x1 + y0 + y1);
}

}  // namespace

float visible_bounds_fraction(const Camera& c, const Bounds3& b) {
  float x0, x1, y0, y1;
  if (!projected_bounds(c, b, x0, x1, y0, y1)) return 0;
  const float area = (x1 - x0) * (y1 - y0);
  if (!(area > 0)) return 1;
  const float w = std::max(0.0f, std::min(x1, c.tan_half_w) - std::max(x0, -c.tan_half_w));
  const float h = std::max(0.0f, std::min(y1, c.tan_half_h) - std::max(y0, -c.tan_half_h));
  return std::min(1.0f, w * h / area);
}

Camera make_camera(const SceneDesc& scene, const CameraParams& p) {
  return make_camera(scene.camera, scene.geometry_bounds(), p);
}

Camera make_camera(const CameraDesc& authored, const Bounds3& b, const CameraParams& p) {
  Camera c;
  c.width = p.width;
  c.height = p.height;
  c.lens_radius = p.lens_radius;
  c.focal_distance = p.focal_distance;

  if (!p.settings_file.empty()) {
    read_settings_file(c, p.settings_file);
  } else if ((p.file_camera || authored.as_authored) && authored.present) {
    const Mat4& m = authored.world;
    c.position = m.point(Vec3(0, 0, 0));
    Vec3 r = m.vector(Vec3(1, 0, 0)), u = m.vector(Vec3(0, 1, 0));
    set_basis(c, m.vector(Vec3(0, 0, 1)), u);
    if (dot(cross(u, m.vector(Vec3(0, 0, 1))), r) < 0) c.right = -c.right;  // keep handedness as authored
    float h_fov, v_fov;
    file_fov(authored, &h_fov, &v_fov);
    // Authored horizontal FOV spans the output width; the vertical follows the output aspect. A
    // glTF camera keeps its vertical FOV instead (its aspect ratio is the viewport's: glTF 2.0, 5.12).
    if (authored.as_authored && authored.yfov_deg > 0) c.screen_distance = float(p.height) / (2 * std::tan(v_fov / 2));
    else c.screen_distance = float(p.width) / (2 * std::tan(h_fov / 2));
    c.tmin = authored.znear;
    c.tmax = authored.zfar;
    c.target = c.position - c.back;
  } else if (authored.overview && !authored.present) {
    // A glTF scene without a camera: from above and to the side (azimuth 45 degrees from +Z
    // towards +X, elevation 30), far enough that the bounding sphere fits the 45-degree vertical
    // field of view (wider images see more around it). Every face of a box shows.
    const float v_fov = 45 * kDeg;
    const Vec3 dir = normalize(Vec3(std::sin(45 * kDeg) * std::cos(30 * kDeg), std::sin(30 * kDeg),
                                    std::cos(45 * kDeg) * std::cos(30 * kDeg)));
    const float radius = b.empty() ? 1.0f : 0.5f * length(b.diagonal());
    // A tall image's horizontal field is the narrower one: the sphere fits that.
    const float tan_fit = std::tan(v_fov / 2) * std::min(1.0f, float(p.width) / float(std::max(1, p.height)));
    float dist = 1.05f * radius / std::sin(std::atan(tan_fit));
    if (!(dist > 0) || !std::isfinite(dist)) dist = 1;
    c.target = b.empty() ? Vec3(0.0f) : b.center();
    c.position = c.target + dir * dist;
    set_basis(c, dir, Vec3(0, 1, 0));
    c.screen_distance = float(p.height) / (2 * std::tan(v_fov / 2));
    c.tmin = std::max(1e-4f, 1e-4f * dist);
  } else {
    // Course framing: orbit the bounding-box centre at 1.5x its diagonal, looking from the
    // direction of the camera node's matrix applied to the point (0, 0, -1); world up is +Y.
    float h_fov, v_fov;
    file_fov(authored, &h_fov, &v_fov);
    const float aspect = 800.0f / 600.0f;  // the course fits the FOV to its 800x600 screen
    if (std::tan(h_fov / 2) / std::tan(v_fov / 2) < aspect)
      h_fov = 2 * std::atan(std::tan(v_fov / 2) * aspect);
    else
      v_fov = 2 * std::atan(std::tan(h_fov / 2) / aspect);
    c.screen_distance = 600.0f / (2 * std::tan(v_fov / 2));
    Vec3 target = b.empty() ? Vec3(0.0f) : b.center();
    float dist = b.empty() ? 1.0f : 1.5f * length(b.diagonal());
    if (!(dist > 0)) dist = 1;
    Vec3 dir(0, 0, 1);
    if (authored.present) {
      Vec3 d = normalize(authored.world.point(Vec3(0, 0, -1)));
      if (!is_black(d) && is_finite(d)) dir = d;
    }
    c.target = target;
    c.position = target + dir * dist;
    set_basis(c, dir, Vec3(0, 1, 0));
  }
  // Resizing keeps the angle of a pixel: the FOV follows the output size (course behaviour).
  // keep_fov instead scales the course's 800-pixel-wide view to the output width; frame_scene
  // keeps the course's view direction and fits the field of view to the projected bounds (the
  // view looks at their centre, so a symmetric fit wastes little), with a 2% margin.
  const bool course_framing = p.settings_file.empty() && !p.file_camera && !(authored.as_authored && authored.present) &&
                              !(authored.overview && !authored.present);
  float x0, x1, y0, y1;
  if (course_framing && p.frame_scene && projected_bounds(c, b, x0, x1, y0, y1)) {
    const float need_x = 1.02f * std::max(-x0, x1), need_y = 1.02f * std::max(-y0, y1);
    const float fit = std::min(need_x > 0 ? 0.5f * p.width / need_x : kInf, need_y > 0 ? 0.5f * p.height / need_y : kInf);
    if (std::isfinite(fit) && fit > 0) c.screen_distance = fit;
  } else if (course_framing && p.keep_fov) {
    c.screen_distance *= float(p.width) / 800.0f;
  }
  if (p.pose.set) {
    // A pose places the camera wherever the framing put it: the file's clip range no longer
    // applies, and the framing's field of view stays unless the pose gives one.
    c = camera_looking(c, p.pose.position, p.pose.target, p.pose.up);
    if (p.pose.vfov_deg > 0) c.screen_distance = float(p.height) / (2 * std::tan(0.5f * p.pose.vfov_deg * kDeg));
    c.tmin = 0;
    c.tmax = kInf;
  }
  c.tan_half_w = (0.5f * p.width) / c.screen_distance;
  c.tan_half_h = (0.5f * p.height) / c.screen_distance;
  return c;
}

void Camera::pinhole_ray(float sx, float sy, Ray& r) const {
  r.o = position;
  r.d = lane1::pinhole_direction(*this, sx, sy);
  r.tmin = tmin;
  r.tmax = tmax;
}

namespace {

// Rays for sensor points i < n: eight at a time in AVX2 where forms::use_avx2(), then four in
// SSE2, the tail one by one. A null lens_u makes pinhole rays.
void camera_rays(const Camera& c, const float* sx, const float* sy, const Vec2* lens_u, size_t n, Ray* out) {
  size_t i = forms::use_avx2() ? lane8::camera_rays(c, sx, sy, lens_u, n, out) : 0;
  i += lane4::camera_rays(c, sx + i, sy + i, lens_u ? lens_u + i : nullptr, n - i, out + i);
  lane1::camera_rays(c, sx + i, sy + i, lens_u ? lens_u + i : nullptr, n - i, out + i);
}

}  // namespace

void Camera::pinhole_rays(const float* sx, const float* sy, size_t n, Ray* out) const {
  camera_rays(*this, sx, sy, nullptr, n, out);
}

void Camera::generate_rays(const float* sx, const float* sy, const Vec2* lens_u, size_t n, Ray* out) const {
  camera_rays(*this, sx, sy, lens_u, n, out);
}

Ray Camera::pinhole_ray(float sx, float sy) const {
  Ray r;
  pinhole_ray(sx, sy, r);
  return r;
}

void Camera::generate_ray(float sx, float sy, Vec2 lens_u, Ray& r) const {
  lane1::camera_ray(*this, sx, sy, lens_u, r.o, r.d);
  r.tmin = tmin;
  r.tmax = tmax;
}

Ray Camera::generate_ray(float sx, float sy, Vec2 lens_u) const {
  Ray r;
  generate_ray(sx, sy, lens_u, r);
  return r;
}

bool Camera::sensor_point(Vec3 p, Vec2 lens_u, float& sx, float& sy, Vec3& origin) const {
  // A thin lens maps a point at depth z, seen from lens point l, to the sensor point p/z + l (1/f
  // - 1/z) (camera space, sensor at depth 1): generate_ray aims from l at the focus point f x dc.
  float lx = 0, ly = 0;
  origin = position;
  if (lens_radius > 0) {
    if (!(focal_distance > 0)) return false;
    Vec2 d = sample_concentric_disk(lens_u);
    lx = lens_radius * d.x, ly = lens_radius * d.y;
    origin = position + right * lx + up * ly;
  }
  Vec3 v = p - origin;
  float z = -dot(v, back);
  if (!(z > 0)) return false;
  float cx = dot(v, right) / z, cy = dot(v, up) / z;
  if (lens_radius > 0) cx += lx / focal_distance, cy += ly / focal_distance;
  sx = (cx / tan_half_w + 1) * 0.5f;
  sy = (cy / tan_half_h + 1) * 0.5f;
  return std::isfinite(sx) && std::isfinite(sy);
}

Camera camera_looking(Camera c, Vec3 position, Vec3 target, Vec3 up) {
  const Vec3 back = position - target;
  if (!(length(back) > 0) || !is_finite(back)) return c;
  c.position = position;
  c.target = target;
  set_basis(c, back, up);
  return c;
}

float vertical_fov_deg(const Camera& c) { return 2 * std::atan(c.tan_half_h) / kDeg; }

std::string pose_error(const CameraPose& p) {
  // Past 1e7 a float keeps under a unit of precision: positions that far are typos, not scenes.
  constexpr float kFar = 1e7f;
  auto bad = [&](Vec3 v) { return !is_finite(v) || std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}) > kFar; };
  if (bad(p.position)) return "position: each coordinate must be finite and within 1e7";
  if (bad(p.target)) return "target: each coordinate must be finite and within 1e7";
  if (bad(p.up)) return "up: each coordinate must be finite and within 1e7";
  const float scale = std::max({1.0f, length(p.position), length(p.target)});
  const Vec3 view = p.position - p.target;
  if (!(length(view) > 1e-5f * scale)) return "target: must differ from the position";
  if (!(length(p.up) > 0)) return "up: must not be zero";
  if (!(length(cross(normalize(p.up), normalize(view))) > 1e-3f)) return "up: must not be parallel to the view direction";
  if (p.vfov_deg != 0 && !(p.vfov_deg >= kMinPoseFov && p.vfov_deg <= kMaxPoseFov))
    return "vfov: must be between 0.1 and 179 degrees";
  return "";
}

void write_camera_settings(const Camera& c, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write camera settings");
  float h_fov = 2 * std::atan(c.tan_half_w) / kDeg, v_fov = 2 * std::atan(c.tan_half_h) / kDeg;
  Vec3 d = c.position - c.target;
  float dist = length(d);
  Vec3 dn = dist > 0 ? d / dist : Vec3(0, 0, 1);
  out << h_fov << " " << v_fov << " " << float(c.width) / c.height << " " << c.tmin << " "
      << (std::isfinite(c.tmax) ? c.tmax : 1e30f) << "\n";
  out << c.position.x << " " << c.position.y << " " << c.position.z << " " << c.target.x << " " << c.target.y << " "
      << c.target.z << "\n";
  out << std::acos(clampf(dn.y, -1, 1)) << " " << std::atan2(dn.x, dn.z) << " " << dist << " " << dist / 20 << " "
      << dist * 10 << "\n";
  out << c.right.x << " " << c.up.x << " " << c.back.x << " " << c.right.y << " " << c.up.y << " " << c.back.y << " "
      << c.right.z << " " << c.up.z << " " << c.back.z << "\n";
  out << c.width << " " << c.height << " " << c.screen_distance << "\n";
  out << c.focal_distance << " " << c.lens_radius << "\n";
}

}  // namespace pt
