// The window's input turned into render settings, without GLFW or OpenGL: the course's settings
// keys, the camera moves (viewer_nav.h) with their quarter-size previews, the cell mode's rubber
// band, click-to-focus, the S and D files, and the render size that follows the window. Each change
// goes to the render thread through Shared (viewer_loop.h), which cancels the running pass and
// starts the session the new settings ask for. The display (viewer.cpp) owns the window and feeds
// this its events in window coordinates, with the window's size.
#pragma once

#include <set>
#include <string>

#include "viewer_loop.h"
#include "viewer_nav.h"

namespace pt {
namespace viewer {

class ViewerInput {
 public:
  ViewerInput(const CliOptions& o, const SceneDesc& desc, const SceneFeatures& features, Shared& sh);
  // The first settings: the options at the window's framebuffer size, the whole frame.
  void start(int width, int height);

  // The keys that change what renders (settings, R, S, D, C, Space); the display keeps its own
  // (views, panels, closing). `repeat`: a held key's repeats, which only the settings keys take.
  void key(int key, bool repeat);
  // Window coordinates, y down, in a ww x wh window.
  void click(double x, double y, int ww, int wh);
  void button(CameraNav::Button b, bool down, double x, double y, int ww, int wh);
  void cursor(double x, double y, int ww, int wh);
  void wheel(double steps);
  // The framebuffer's new size: the render follows once the window has stopped changing.
  void framebuffer_resized(int width, int height);
  // Between frames: a settled resize, a camera at rest after a move.
  void tick() {
    apply_resize();
    settle_view(false);
  }
  // The full-size render of the moved camera now, not after the rest time (the wheel in scripts).
  void settle_now() { settle_view(true); }

  RenderParams want();
  bool resize_pending() const { return m_resize_w > 0; }
  const CellBand& band() const { return m_band; }
  // Something the display draws changed (the band); reading it clears it.
  bool take_redraw() {
    const bool r = m_redraw;
    m_redraw = false;
    return r;
  }
  static std::string settings_text(const RenderParams& p);

 private:
  // Applies a settings change and restarts the render: the running pass is cancelled at once.
  template <class F>
  void change(F&& edit);
  void push_command(const Command& c);
  void cell_button(bool down, double x, double y, int ww, int wh);
  void clear_cell();
  Camera shown_camera();
  void moved_view();
  void settle_view(bool now);
  void write_camera();
  void apply_resize();

  const CliOptions& m_options;
  const SceneDesc& m_desc;
  SceneFeatures m_features;
  Shared& m_sh;
  CameraNav m_nav;
  bool m_cell_mode = false;  // C: a left drag picks a cell instead of orbiting
  CellBand m_band;
  std::set<std::string> m_hinted;
  bool m_previewing = false;  // rendering at 1/kPreviewScale while the camera moves
  int m_full_w = 0, m_full_h = 0;
  Clock::time_point m_moved_at;
  int m_resize_w = 0, m_resize_h = 0;
  Clock::time_point m_resize_at;
  bool m_redraw = false;
};

}  // namespace viewer
}  // namespace pt
