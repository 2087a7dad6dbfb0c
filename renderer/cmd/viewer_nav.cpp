// The window's orbit, pan and dolly (viewer_nav.h). The pose is spherical about the target, as
// the course's camera keeps it: position = target + r (sin phi sin theta, cos phi, sin phi cos theta).
#include "viewer_nav.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pt {
namespace viewer {

namespace {

constexpr double kClickSlopPx = 3;                // a press that moves less is a click
constexpr float kMinPolar = 1e-3f;                // the poles: the basis needs a horizontal axis
constexpr float kDollyStep = 1.0f / 20, kMinDistance = 1.0f / 20, kMaxDistance = 10;

}  // namespace

std::string pose_text(const ViewPose& v) {
  if (!v.moved) return "initial";
  auto g = [](float x) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", double(x));
    return std::string(b);
  };
  return "position " + g(v.position.x) + " " + g(v.position.y) + " " + g(v.position.z) + ", target " + g(v.target.x) +
         " " + g(v.target.y) + " " + g(v.target.z);
}

void CameraNav::reset(const Camera& c) {
  Vec3 d = c.position - c.target;
  float r = length(d);
  if (!(r > 0) || !is_finite(d)) d = c.back, r = 1;
  m_target0 = m_target = c.position - d;
  m_r0 = m_r = r;
  const Vec3 n = d / r;
  m_phi0 = m_phi = std::acos(clampf(n.y, -1, 1));
  m_theta0 = m_theta = std::atan2(n.x, n.z);
  m_moved = false;
}

Vec3 CameraNav::position() const {
  const float s = std::sin(m_phi);
  return m_target + Vec3(s * std::sin(m_theta), std::cos(m_phi), s * std::cos(m_theta)) * m_r;
}

ViewPose CameraNav::pose() const { return {m_moved, position(), m_target}; }

void CameraNav::press(Button b, double x, double y) {
  m_pressed = true;
  m_dragged = false;
  m_button = b;
  m_press_x = m_last_x = x;
  m_press_y = m_last_y = y;
}

bool CameraNav::move(double x, double y, int w, int h, const Camera& view) {
  if (!m_pressed || w <= 0 || h <= 0) return false;
  if (!m_dragged && std::hypot(x - m_press_x, y - m_press_y) < kClickSlopPx) return false;
  m_dragged = true;
  const double dx = x - m_last_x, dy = y - m_last_y;
  m_last_x = x, m_last_y = y;
  if (dx == 0 && dy == 0) return false;
  if (m_button == left) {
    // Dragging down raises the camera over the target (the course: phi -= dy pi / height).
    m_phi = clampf(m_phi - float(dy * kPi / h), kMinPolar, kPi - kMinPolar);
    m_theta -= float(dx * kPi / w);
  } else {
    // The view plane at the target's depth follows the cursor: r / screen distance per pixel.
    const float px = view.screen_distance > 0 ? m_r / view.screen_distance * float(view.height) / float(h) : 0;
    const Vec3 shift = view.right * float(-dx * px) + view.up * float(dy * px);
    m_target = m_target + shift;
  }
  m_moved = true;
  return true;
}

bool CameraNav::release(double x, double y) {
  const bool click = m_pressed && !m_dragged && std::hypot(x - m_press_x, y - m_press_y) < kClickSlopPx;
  m_pressed = m_dragged = false;
  return click;
}

bool CameraNav::scroll(double steps) {
  if (steps == 0) return false;
  const float r = std::min(std::max(m_r - float(steps) * kDollyStep * m_r0, kMinDistance * m_r0), kMaxDistance * m_r0);
  if (r == m_r) return false;
  m_r = r;
  m_moved = true;
  return true;
}

void CameraNav::home() {
  m_target = m_target0;
  m_phi = m_phi0, m_theta = m_theta0, m_r = m_r0;
  m_moved = false;
}

bool CellBand::release(int ww, int wh, int fw, int fh, int& x, int& y, int& dx, int& dy) {
  m_active = false;
  if (ww <= 0 || wh <= 0 || fw <= 0 || fh <= 0) return false;
  // Window to frame pixels (a HiDPI framebuffer has more pixels than the window has points); the
  // band covers every pixel it touches.
  const double sx = double(fw) / ww, sy = double(fh) / wh;
  auto clampi = [](double v, int hi) { return std::min(std::max(int(v), 0), hi); };
  const int left = clampi(std::floor(std::min(m_x0, m_x1) * sx), fw), right = clampi(std::ceil(std::max(m_x0, m_x1) * sx), fw);
  const int top = clampi(std::floor(std::min(m_y0, m_y1) * sy), fh), bottom = clampi(std::ceil(std::max(m_y0, m_y1) * sy), fh);
  if (right - left < 2 || bottom - top < 2) return false;
  x = left, dx = right - left;
  y = fh - bottom, dy = bottom - top;  // bottom-left origin, as -p counts
  return true;
}

}  // namespace viewer
}  // namespace pt
