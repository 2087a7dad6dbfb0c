// The window's camera moves, with the course window's semantics (../shared/notes/cs184-spec.md,
// "GUI controls"): a left drag orbits the camera around its target (a full window height turns
// the polar angle by pi, clamped to [0, pi]; a full width turns the azimuth by pi), a right drag
// pans camera and target in the view plane (the point under the cursor at the target's depth
// stays under it), one wheel step dollies by 1/20 of the initial distance (kept between 1/20 and
// 10 times it), and home() returns to the initial camera. A press and release within a few pixels
// is a click (autofocus), not a drag. No GLFW here: viewer.cpp feeds it window coordinates.
#pragma once

#include <string>

#include "camera.h"

namespace pt {
namespace viewer {

// Where the window's navigation has put the camera: none until it moves.
struct ViewPose {
  bool moved = false;
  Vec3 position, target;
};

// "position x y z, target x y z" (shortest %g), or "initial" for an unmoved pose.
std::string pose_text(const ViewPose& pose);

class CameraNav {
 public:
  enum Button { left = 0, right = 1 };
  // Starts from `initial` (the camera the settings give): its target and distance are the orbit's.
  void reset(const Camera& initial);
  void press(Button b, double x, double y);
  // A cursor move; true when a drag moved the camera. `view` is the camera shown now (its basis
  // and screen distance give the pan's scale); w x h the window size.
  bool move(double x, double y, int w, int h, const Camera& view);
  // True when the press was a click: released without having dragged.
  bool release(double x, double y);
  bool scroll(double steps);
  void home();
  bool dragging() const { return m_pressed && m_dragged; }
  ViewPose pose() const;

 private:
  Vec3 position() const;

  Vec3 m_target0, m_target;
  float m_phi0 = 0, m_theta0 = 0, m_phi = 0, m_theta = 0;  // polar angle from +Y, azimuth about it
  float m_r0 = 1, m_r = 1;
  bool m_moved = false;
  bool m_pressed = false, m_dragged = false;
  Button m_button = left;
  double m_press_x = 0, m_press_y = 0, m_last_x = 0, m_last_y = 0;
};

// The course's cell mode (C): a left drag draws a rubber band, and its release picks the cell the
// render redoes (-p: x y dx dy, bottom-left origin, in frame pixels).
class CellBand {
 public:
  void press(double x, double y) { m_active = true, m_x0 = m_x1 = x, m_y0 = m_y1 = y; }
  void move(double x, double y) { m_x1 = x, m_y1 = y; }
  void cancel() { m_active = false; }
  bool active() const { return m_active; }
  // The band in window coordinates, as drawn.
  void corners(double& x0, double& y0, double& x1, double& y1) const { x0 = m_x0, y0 = m_y0, x1 = m_x1, y1 = m_y1; }
  // Ends the drag: the cell under the band in a fw x fh frame shown in a ww x wh window, clipped
  // to the frame. False for a band under two frame pixels wide or tall (a click).
  bool release(int ww, int wh, int fw, int fh, int& x, int& y, int& dx, int& dy);

 private:
  bool m_active = false;
  double m_x0 = 0, m_y0 = 0, m_x1 = 0, m_y1 = 0;
};

}  // namespace viewer
}  // namespace pt
