// The window's input turned into render settings (viewer_input.h).
#include "viewer_input.h"

#include <GLFW/glfw3.h>  // key codes only

#include <algorithm>
#include <cstdio>

#include "hints.h"
#include "viewer_keys.h"

namespace pt {
namespace viewer {

namespace {

constexpr double kResizeSettleMs = 150;
// While the camera moves the render runs at 1/kPreviewScale of the window's size (a coarse preview,
// the same renderer); kRestMs after the last wheel step, or when a drag ends, it renders in full.
constexpr int kPreviewScale = 4;
constexpr double kRestMs = 150;
constexpr int kMaxSide = 16384;

}  // namespace

ViewerInput::ViewerInput(const CliOptions& o, const SceneDesc& desc, const SceneFeatures& features, Shared& sh)
    : m_options(o), m_desc(desc), m_features(features), m_sh(sh) {}

void ViewerInput::start(int width, int height) {
  m_sh.want = m_options.params;
  m_sh.want.cell_x = m_sh.want.cell_y = m_sh.want.cell_w = m_sh.want.cell_h = 0;
  m_sh.want.width = std::min(std::max(1, width), kMaxSide);
  m_sh.want.height = std::min(std::max(1, height), kMaxSide);
  m_nav.reset(make_camera(m_desc, camera_params(m_sh.want)));
}

std::string ViewerInput::settings_text(const RenderParams& p) {
  return "spp " + std::to_string(p.spp) + ", light samples " + std::to_string(p.light_samples) + ", max depth " +
         std::to_string(p.max_depth) + ", lens radius " + fmt_g(p.lens_radius) + ", focal distance " +
         fmt_g(p.focal_distance);
}

template <class F>
void ViewerInput::change(F&& edit) {
  std::string text;
  {
    std::lock_guard<std::mutex> lk(m_sh.mutex);
    text = edit(m_sh.want);
    ++m_sh.want_gen;
    m_sh.cancel = true;
  }
  m_sh.wake.notify_all();
  if (!text.empty()) say("%s", text.c_str());
}

RenderParams ViewerInput::want() {
  std::lock_guard<std::mutex> lk(m_sh.mutex);
  return m_sh.want;
}

void ViewerInput::push_command(const Command& c) {
  {
    std::lock_guard<std::mutex> lk(m_sh.mutex);
    m_sh.commands.push_back(c);
    ++m_sh.issued;
    m_sh.cancel = true;  // pause the pass; the render thread resumes it after the command
  }
  m_sh.wake.notify_all();
}

void ViewerInput::key(int key, bool repeat) {
  if (is_setting_key(key)) {
    change([key](RenderParams& p) { return apply_setting_key(key, p); });
    const std::string hint = depth_hint(want().max_depth, m_features);  // said once, as the CLI's hints
    if (!hint.empty() && m_hinted.insert(hint).second) say("hint: %s", hint.c_str());
  }
  if (key == GLFW_KEY_R) change([](RenderParams&) { return std::string("restart"); });
  if (repeat) return;  // the keys below act once per press
  switch (key) {
    case GLFW_KEY_S: push_command({CommandKind::save}); break;
    case GLFW_KEY_D: write_camera(); break;
    case GLFW_KEY_C:
      m_cell_mode = !m_cell_mode;
      m_band.cancel();
      say("cell mode: %s", m_cell_mode ? "on (drag a rectangle to render only it)" : "off");
      if (!m_cell_mode) clear_cell();
      m_redraw = true;
      break;
    case GLFW_KEY_SPACE:
      m_nav.home();
      moved_view();
      settle_view(true);
      break;
    default: break;
  }
}

void ViewerInput::click(double x, double y, int ww, int wh) {
  if (ww <= 0 || wh <= 0 || x < 0 || y < 0 || x > ww || y > wh) return;
  // Course autofocus: the pinhole ray through the cursor position (window coordinates).
  push_command({CommandKind::focus, float(x / ww), float(1 - y / wh)});
}

void ViewerInput::button(CameraNav::Button b, bool down, double x, double y, int ww, int wh) {
  if (m_cell_mode && b == CameraNav::left) return cell_button(down, x, y, ww, wh);
  if (down) return m_nav.press(b, x, y);
  const bool dragged = m_nav.dragging();
  if (m_nav.release(x, y)) click(x, y, ww, wh);  // a click focuses, as before
  if (dragged) settle_view(true);
}

void ViewerInput::cursor(double x, double y, int ww, int wh) {
  if (m_band.active()) {
    m_band.move(x, y);
    m_redraw = true;
    return;
  }
  if (m_nav.move(x, y, ww, wh, shown_camera())) moved_view();
}

void ViewerInput::wheel(double steps) {
  if (m_nav.scroll(steps)) moved_view();
}

// The course's cell mode: a rubber band picks the cell (-p) the render redoes.
void ViewerInput::cell_button(bool down, double x, double y, int ww, int wh) {
  if (down) return m_band.press(x, y);
  m_band.move(x, y);
  m_redraw = true;
  int cx, cy, cw, ch;
  const RenderParams now = want();
  if (!m_band.release(ww, wh, now.width, now.height, cx, cy, cw, ch)) return click(x, y, ww, wh);  // a click focuses
  change([=](RenderParams& p) {
    p.cell_x = cx, p.cell_y = cy, p.cell_w = cw, p.cell_h = ch;
    return "cell: " + std::to_string(cx) + " " + std::to_string(cy) + " " + std::to_string(cw) + " " + std::to_string(ch);
  });
}

// Back to the whole frame (leaving cell mode, moving the camera, resizing).
void ViewerInput::clear_cell() {
  if (want().cell_w == 0) return;
  change([](RenderParams& p) {
    p.cell_x = p.cell_y = p.cell_w = p.cell_h = 0;
    return std::string("cell: whole frame");
  });
}

// The camera the window shows now, at the full window size.
Camera ViewerInput::shown_camera() {
  std::lock_guard<std::mutex> lk(m_sh.mutex);
  RenderParams p = m_sh.want;
  if (m_previewing) p.width = m_full_w, p.height = m_full_h;
  return view_camera(m_desc, p, m_sh.view);
}

// A new pose: a coarse preview renders at once (the previous one is cancelled).
void ViewerInput::moved_view() {
  m_moved_at = Clock::now();
  clear_cell();
  change([this](RenderParams& p) {
    m_sh.view = m_nav.pose();
    if (!m_previewing) m_full_w = p.width, m_full_h = p.height;
    m_previewing = true;
    p.width = std::max(1, m_full_w / kPreviewScale);
    p.height = std::max(1, m_full_h / kPreviewScale);
    return std::string();
  });
}

// Once the view rests (or at once with `now`), the full-size render of the new pose.
void ViewerInput::settle_view(bool now) {
  if (!m_previewing || (!now && (m_nav.dragging() || ms_since(m_moved_at) < kRestMs))) return;
  m_previewing = false;
  change([this](RenderParams& p) {
    p.width = m_full_w, p.height = m_full_h;
    return "camera: " + pose_text(m_sh.view);
  });
}

void ViewerInput::write_camera() {
  std::string path = output_path(m_options, "_cam_settings.txt");
  try {
    write_camera_settings(shown_camera(), path);
    say("wrote %s", path.c_str());
  } catch (const std::exception& e) {
    say("camera settings: %s", e.what());
  }
}

void ViewerInput::framebuffer_resized(int width, int height) {
  m_resize_w = width;
  m_resize_h = height;
  m_resize_at = Clock::now();
}

// Debounced: the render restarts at the new size once the window has stopped changing.
void ViewerInput::apply_resize() {
  if (m_resize_w <= 0 || m_resize_h <= 0 || ms_since(m_resize_at) < kResizeSettleMs) return;
  int w = std::min(m_resize_w, kMaxSide), h = std::min(m_resize_h, kMaxSide);
  m_resize_w = m_resize_h = 0;
  const RenderParams now = want();
  if (now.width != w || now.height != h)
    change([w, h](RenderParams& p) {
      p.width = w, p.height = h;
      p.cell_x = p.cell_y = p.cell_w = p.cell_h = 0;  // a cell of the old frame
      return "size " + std::to_string(w) + "x" + std::to_string(h);
    });
}

}  // namespace viewer
}  // namespace pt
