// Which pixels see only background (background_mask.h).
#include "background_mask.h"

#include <algorithm>
#include <cmath>

#include "accel.h"

namespace pt {

// Where the scene's (padded) bounding box projects on the sensor of a camera in front of it. The
// box is convex and wholly in front, so every pinhole ray that can hit it passes inside the box
// spanned by its eight projected corners; a pixel wholly outside (with a pixel of margin) sees only
// background. Without an environment seen by the camera, background is exactly black and the
// path loop would stop at its first, missed query: the sample is black and counts one ray.
// A thin lens sees a point at depth z from lens point l at sensor position p/z - l (1/z - 1/f)
// (camera.cpp's ray through the focus point p f / z): the rectangle grows by the lens radius times
// the largest |1/z - 1/f| over the box, which a corner (the nearest or farthest) attains.
namespace {

// The frame-pixel rectangle (y up, unclipped, without margin) holding box [lo, hi] as the camera
// sees it, or false when a corner lies beside or behind the camera (no rectangle holds it).
bool project_box(const Camera& cam, int width, int height, Vec3 lo, Vec3 hi, float r[4]) {
  const bool lens = cam.lens_radius > 0;
  float u0 = kInf, u1 = -kInf, v0 = kInf, v1 = -kInf, blur = 0;
  for (int c = 0; c < 8; ++c) {
    Vec3 corner(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z);
    Vec3 v = corner - cam.position;
    float z = -dot(v, cam.back);
    if (!(z > 1e-3f * length(v))) return false;
    float u = (dot(v, cam.right) / (z * cam.tan_half_w) + 1) * 0.5f * float(width);
    float w = (dot(v, cam.up) / (z * cam.tan_half_h) + 1) * 0.5f * float(height);
    if (!std::isfinite(u) || !std::isfinite(w)) return false;
    u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, w), v1 = std::max(v1, w);
    if (lens) blur = std::max(blur, cam.lens_radius * std::fabs(1 / z - 1 / cam.focal_distance));
  }
  if (lens) {  // blur is in sensor units (tan); pixels per unit differ along x and y
    float bu = blur * 0.5f * float(width) / cam.tan_half_w, bv = blur * 0.5f * float(height) / cam.tan_half_h;
    if (!std::isfinite(bu) || !std::isfinite(bv)) return false;
    u0 -= bu, u1 += bu, v0 -= bv, v1 += bv;
  }
  r[0] = u0, r[1] = u1, r[2] = v0, r[3] = v1;
  return true;
}

}  // namespace

BackgroundMask::BackgroundMask(const RenderScene& scene, const RenderParams& params, int frame_x0, int frame_y0, int w,
                               int h)
    : m_frame_x0(frame_x0), m_frame_y0(frame_y0), m_frame_h(params.height), m_w(w), m_h(h) {
  const Camera& cam = scene.camera;
  Vec3 lo, hi;
  if (!scene.accel || !scene.accel->hit_bounds(lo, hi)) return;
  if (!(cam.tan_half_w > 0) || !(cam.tan_half_h > 0)) return;
  if (cam.lens_radius > 0 && !(cam.focal_distance > 0 && std::isfinite(cam.focal_distance))) return;
  float r[4];
  if (!project_box(cam, params.width, params.height, lo, hi, r)) return;
  m_u0 = r[0] - 1, m_u1 = r[1] + 1, m_v0 = r[2] - 1, m_v1 = r[3] + 1;
  // The caustic light paths are counted on this area, clipped to the full frame (not to a crop or
  // cell window, so that windows trace the frame's paths): a box around a close camera projects far
  // past the frame, and light paths only splat inside it.
  auto clipped = [](float a, float b, float size) {
    return std::max(0.0, double(std::min(b, size)) - double(std::max(a, 0.0f)));
  };
  m_scene_pixels = clipped(m_u0, m_u1, float(params.width)) * clipped(m_v0, m_v1, float(params.height));
  m_rect = scene.environment_light < 0;
  if (!m_rect || size_t(w) * h > (size_t(1) << 24)) return;

  // Within the rectangle, the pixels no object's own rectangle reaches (the sky above an open
  // floor), for a bounded number of objects: the mask starts as "no object" and each object's
  // rectangle clears its rows' spans. Without that (no objects, too many, or one that does not
  // project), the rectangle alone decides.
  const auto& objects = scene.object_bounds;
  bool by_objects = !objects.empty() && objects.size() <= kMaxMaskedObjects;
  m_mask.assign(size_t(w) * h, by_objects ? 1 : 0);
  for (size_t k = 0; k < objects.size() && by_objects; ++k) {
    const Bounds3& b = objects[k];
    if (!project_box(cam, params.width, params.height, b.lo, b.hi, r)) {
      by_objects = false;
      std::fill(m_mask.begin(), m_mask.end(), uint8_t(0));
      break;
    }
    // Film pixels whose frame pixel [fx, fx + 1] x [fy, fy + 1] meets the rectangle grown by a pixel.
    auto px = [](float v, int size) { return int(std::clamp(v, -4.0f, float(size) + 4)); };
    int fx0 = px(std::floor(r[0] - 2), params.width), fx1 = px(std::ceil(r[1] + 1), params.width);
    int fy0 = px(std::floor(r[2] - 2), params.height), fy1 = px(std::ceil(r[3] + 1), params.height);
    int x0 = std::max(fx0 - m_frame_x0, 0), x1 = std::min(fx1 - m_frame_x0, w - 1);
    if (x0 > x1) continue;
    for (int fy_up = std::max(fy0, 0); fy_up <= std::min(fy1, params.height - 1); ++fy_up) {
      int y = (params.height - 1 - fy_up) - m_frame_y0;
      if (y < 0 || y >= h) continue;
      uint8_t* row = m_mask.data() + size_t(y) * w;
      std::fill(row + x0, row + x1 + 1, uint8_t(0));
    }
  }
  // Then the rectangle, which is a product of a column range and a row range.
  std::vector<uint8_t> column_outside(static_cast<size_t>(w));
  for (int x = 0; x < w; ++x) column_outside[size_t(x)] = outside_columns(m_frame_x0 + x);
  for (int y = 0; y < h; ++y) {
    uint8_t* row = m_mask.data() + size_t(y) * w;
    if (outside_rows(params.height - 1 - (m_frame_y0 + y))) std::fill(row, row + w, uint8_t(1));
    else
      for (int x = 0; x < w; ++x) row[x] |= column_outside[size_t(x)];
  }
}

}  // namespace pt
