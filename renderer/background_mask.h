// Which pixels see only background: where every camera ray misses the scene, a sample is black
// without a ray query (the path loop would stop at its first, missed one) and counts one ray.
// Off where the camera sees an environment (its background is not black).
#pragma once

#include <cstdint>
#include <vector>

#include "render_scene.h"

namespace pt {

class BackgroundMask {
 public:
  BackgroundMask() = default;
  // For the camera of `scene` over a frame of params.width x params.height pixels, of which the
  // film is the w x h window whose top-left lies at (frame_x0, frame_y0).
  BackgroundMask(const RenderScene& scene, const RenderParams& params, int frame_x0, int frame_y0, int w, int h);

  // True when every camera ray of frame pixel (fx, fy_up) (y up, as the course counts rows) misses
  // the scene.
  bool sees_only_background(int fx, int fy_up) const {
    if (!m_rect) return false;
    const int x = fx - m_frame_x0, y = (m_frame_h - 1 - fy_up) - m_frame_y0;
    if (!m_mask.empty() && x >= 0 && y >= 0 && x < m_w && y < m_h) return m_mask[size_t(y) * m_w + x];
    return outside_rectangle(fx, fy_up);
  }
  // The same for film pixel i = y w + x, from the mask where there is one (the tile loops ask once
  // per pixel and pass).
  bool film_pixel(size_t i, int x, int y) const {
    if (!m_mask.empty()) return m_mask[i] != 0;
    return sees_only_background(m_frame_x0 + x, m_frame_h - 1 - (m_frame_y0 + y));
  }
  // The area (pixels) where the scene's bounds project, clipped to the frame; -1 when unknown.
  double scene_pixels() const { return m_scene_pixels; }

  // Objects whose own projected rectangles refine the scene's.
  static constexpr size_t kMaxMaskedObjects = 256;

 private:
  bool outside_rectangle(int fx, int fy_up) const { return outside_columns(fx) || outside_rows(fy_up); }
  bool outside_columns(int fx) const { return fx + 1 < m_u0 || fx > m_u1; }
  bool outside_rows(int fy_up) const { return fy_up + 1 < m_v0 || fy_up > m_v1; }

  int m_frame_x0 = 0, m_frame_y0 = 0, m_frame_h = 0, m_w = 0, m_h = 0;
  // Outside this rectangle of frame pixels (y up) every camera ray misses.
  bool m_rect = false;
  float m_u0 = 0, m_u1 = 0, m_v0 = 0, m_v1 = 0;
  double m_scene_pixels = -1;
  // Film pixels that see only background: outside the rectangle, or inside it where no object's
  // own rectangle reaches. Empty without a rectangle, or for films over 2^24 pixels (the
  // rectangle alone decides there).
  std::vector<uint8_t> m_mask;
};

}  // namespace pt
