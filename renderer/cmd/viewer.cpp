// The GLFW debug window: a render thread (viewer_loop.h) runs RenderSession passes of doubling
// sample targets and hands finished tiles (tone-mapped exactly like the PNG) to the window thread,
// which uploads them into one texture drawn as a full-window quad (viewer_gl.h). Keys change
// RenderParams, cancel the running pass through its cancel flag and start a new session; the
// window thread never waits on rendering. The render size follows the window's framebuffer (course
// behaviour); until the new session's first tiles arrive the previous image is stretched to it.
// The status panel and the rate legend are drawn over the image (overlay.h). S and D write into
// --output-dir (default: the current directory). --script replays input (viewer_script.h).
#include "viewer.h"

#include <GLFW/glfw3.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <set>
#include <thread>

#include "hints.h"
#include "overlay.h"
#include "scene_file.h"
#include "session.h"
#include "viewer_gl.h"
#include "viewer_keys.h"
#include "viewer_loop.h"
#include "viewer_script.h"

namespace pt {

namespace {

using namespace viewer;

// ---- the window thread ----

constexpr double kScriptTimeoutMs = 120000;
constexpr double kResizeSettleMs = 150;
// While the camera moves the render runs at 1/kPreviewScale of the window's size (a coarse preview,
// the same renderer); kRestMs after the last wheel step, or when a drag ends, it renders in full.
constexpr int kPreviewScale = 4;
constexpr double kRestMs = 150;
constexpr int kMinWindowW = 160, kMinWindowH = 120;

class Viewer {
 public:
  Viewer(const CliOptions& o, const SceneDesc& desc, GLFWwindow* win, std::vector<ScriptLine> script)
      : m_options(o), m_desc(desc), m_win(win), m_script(std::move(script)) {
    glfwSetWindowUserPointer(win, this);
    glfwSetKeyCallback(win, [](GLFWwindow* w, int key, int, int action, int) {
      if (action != GLFW_RELEASE) self(w)->on_key(key, action == GLFW_REPEAT);
    });
    glfwSetMouseButtonCallback(win, [](GLFWwindow* w, int button, int action, int) {
      if (button != GLFW_MOUSE_BUTTON_LEFT && button != GLFW_MOUSE_BUTTON_RIGHT) return;
      double x, y;
      glfwGetCursorPos(w, &x, &y);
      self(w)->on_button(button == GLFW_MOUSE_BUTTON_LEFT ? CameraNav::left : CameraNav::right, action == GLFW_PRESS, x, y);
    });
    glfwSetCursorPosCallback(win, [](GLFWwindow* w, double x, double y) { self(w)->on_cursor(x, y); });
    glfwSetScrollCallback(win, [](GLFWwindow* w, double, double dy) { self(w)->on_wheel(dy); });
    glfwSetFramebufferSizeCallback(win, [](GLFWwindow* w, int width, int height) {
      Viewer* v = self(w);
      v->m_resize_w = width;
      v->m_resize_h = height;
      v->m_resize_at = Clock::now();
      v->m_dirty = true;
    });
    glfwSetWindowRefreshCallback(win, [](GLFWwindow* w) { self(w)->m_dirty = true; });
  }

  int run(std::unique_ptr<RenderScene> scene) {
    int fw, fh;
    glfwGetFramebufferSize(m_win, &fw, &fh);
    m_sh.want = m_options.params;
    m_sh.want.cell_x = m_sh.want.cell_y = m_sh.want.cell_w = m_sh.want.cell_h = 0;
    m_sh.want.width = std::min(std::max(1, fw), 16384);
    m_sh.want.height = std::min(std::max(1, fh), 16384);
    m_nav.reset(make_camera(m_desc, camera_params(m_sh.want)));
    m_features = scene->features;
    if (m_options.params.cell_w > 0) say("window: -p is ignored; the window renders the whole frame");
    say("window: %dx%d, %s", m_sh.want.width, m_sh.want.height, settings_text(m_sh.want).c_str());

    glGenTextures(1, &m_tex);
    m_sh.wake_window = [] { glfwPostEmptyEvent(); };
    RenderLoop loop(m_options, m_desc, *scene, m_sh);
    std::thread render([&] { loop.run(); });
    while (!glfwWindowShouldClose(m_win)) {
      glfwWaitEventsTimeout(0.02);
      Status st;
      {
        std::lock_guard<std::mutex> lk(m_sh.mutex);
        st = m_sh.status;
        if (!m_sh.fatal.empty()) {
          std::fprintf(stderr, "pathtracer: %s\n", m_sh.fatal.c_str());
          m_exit = 1;
          break;
        }
      }
      upload_tiles(st);  // after the status snapshot: a completed pass's tiles are all queued by then
      apply_resize();
      settle_view(false);
      if (m_script_pos < m_script.size()) step_script(st);
      if (m_dirty || panel_changed()) {
        draw();
        glfwSwapBuffers(m_win);
        m_dirty = false;
      }
      update_title(st);
    }
    {
      std::lock_guard<std::mutex> lk(m_sh.mutex);
      m_sh.quit = true;
      m_sh.cancel = true;
    }
    m_sh.wake.notify_all();
    render.join();  // the running pass stops within a few samples
    glDeleteTextures(1, &m_tex);
    return m_exit;
  }

 private:
  static Viewer* self(GLFWwindow* w) { return static_cast<Viewer*>(glfwGetWindowUserPointer(w)); }

  static std::string settings_text(const RenderParams& p) {
    return "spp " + std::to_string(p.spp) + ", light samples " + std::to_string(p.light_samples) + ", max depth " +
           std::to_string(p.max_depth) + ", lens radius " + fmt_g(p.lens_radius) + ", focal distance " +
           fmt_g(p.focal_distance);
  }

  // Applies a settings change and restarts the render: the running pass is cancelled at once.
  template <class F>
  void change(F&& edit) {
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

  RenderParams want() {
    std::lock_guard<std::mutex> lk(m_sh.mutex);
    return m_sh.want;
  }

  void push_command(const Command& c) {
    {
      std::lock_guard<std::mutex> lk(m_sh.mutex);
      m_sh.commands.push_back(c);
      ++m_sh.issued;
      m_sh.cancel = true;  // pause the pass; the render thread resumes it after the command
    }
    m_sh.wake.notify_all();
  }

  void on_key(int key, bool repeat) {
    if (key != GLFW_KEY_SLASH) set_show_keys(false);
    if (is_setting_key(key)) {
      change([key](RenderParams& p) { return apply_setting_key(key, p); });
      const std::string hint = depth_hint(want().max_depth, m_features);  // said once, as the CLI's hints
      if (!hint.empty() && m_hinted.insert(hint).second) say("hint: %s", hint.c_str());
    }
    if (key == GLFW_KEY_ESCAPE || key == GLFW_KEY_Q) glfwSetWindowShouldClose(m_win, GLFW_TRUE);
    if (key == GLFW_KEY_R) change([](RenderParams&) { return std::string("restart"); });
    if (repeat) return;  // the keys below act once per press
    switch (key) {
      case GLFW_KEY_T:
        m_show_rate = !m_show_rate;
        upload_all();
        say("view: %s", m_show_rate ? "sample rate" : "radiance");
        break;
      case GLFW_KEY_S: push_command({CommandKind::save}); break;
      case GLFW_KEY_D: write_camera(); break;
      case GLFW_KEY_C:
        m_cell_mode = !m_cell_mode;
        m_band.cancel();
        say("cell mode: %s", m_cell_mode ? "on (drag a rectangle to render only it)" : "off");
        if (!m_cell_mode) clear_cell();
        m_dirty = true;
        break;
      case GLFW_KEY_SPACE:
        m_nav.home();
        moved_view();
        settle_view(true);
        break;
      case GLFW_KEY_SLASH:  // '?' on most layouts
        set_show_keys(!m_show_keys);
        if (m_show_keys) {
          std::printf("Window keys:\n%s", window_keys_text().c_str());
          std::fflush(stdout);
        }
        break;
      case GLFW_KEY_H:             // the course's H toggles hemisphere sampling: that is the -H flag here
      case GLFW_KEY_GRAVE_ACCENT:  // the course's key for its on-screen info text
        m_show_panel = !m_show_panel;
        m_dirty = true;
        say("panel: %s", m_show_panel ? "shown" : "hidden");
        break;
      default: break;
    }
  }

  void set_show_keys(bool on) {
    m_dirty |= on != m_show_keys;
    m_show_keys = on;
  }

  void on_click(double x, double y) {
    int ww, wh;
    glfwGetWindowSize(m_win, &ww, &wh);
    if (ww <= 0 || wh <= 0 || x < 0 || y < 0 || x > ww || y > wh) return;
    // Course autofocus: the pinhole ray through the cursor position (window coordinates).
    push_command({CommandKind::focus, float(x / ww), float(1 - y / wh)});
  }

  // ---- camera navigation (viewer_nav.h) ----

  void on_button(CameraNav::Button b, bool down, double x, double y) {
    if (m_cell_mode && b == CameraNav::left) return cell_button(down, x, y);
    if (down) return m_nav.press(b, x, y);
    const bool dragged = m_nav.dragging();
    if (m_nav.release(x, y)) on_click(x, y);  // a click focuses, as before
    if (dragged) settle_view(true);
  }

  void on_cursor(double x, double y) {
    if (m_band.active()) {
      m_band.move(x, y);
      m_dirty = true;
      return;
    }
    int ww, wh;
    glfwGetWindowSize(m_win, &ww, &wh);
    if (m_nav.move(x, y, ww, wh, shown_camera())) moved_view();
  }

  void on_wheel(double steps) {
    if (m_nav.scroll(steps)) moved_view();
  }

  // ---- the course's cell mode: a rubber band picks the cell (-p) the render redoes ----

  void cell_button(bool down, double x, double y) {
    if (down) return m_band.press(x, y);
    m_band.move(x, y);
    m_dirty = true;
    int ww, wh, cx, cy, cw, ch;
    glfwGetWindowSize(m_win, &ww, &wh);
    const RenderParams now = want();
    if (!m_band.release(ww, wh, now.width, now.height, cx, cy, cw, ch)) return on_click(x, y);  // a click focuses
    change([=](RenderParams& p) {
      p.cell_x = cx, p.cell_y = cy, p.cell_w = cw, p.cell_h = ch;
      return "cell: " + std::to_string(cx) + " " + std::to_string(cy) + " " + std::to_string(cw) + " " + std::to_string(ch);
    });
  }

  // Back to the whole frame (leaving cell mode, moving the camera, resizing).
  void clear_cell() {
    if (want().cell_w == 0) return;
    change([](RenderParams& p) {
      p.cell_x = p.cell_y = p.cell_w = p.cell_h = 0;
      return std::string("cell: whole frame");
    });
  }

  // The camera the window shows now, at the full window size.
  Camera shown_camera() {
    std::lock_guard<std::mutex> lk(m_sh.mutex);
    RenderParams p = m_sh.want;
    if (m_previewing) p.width = m_full_w, p.height = m_full_h;
    return view_camera(m_desc, p, m_sh.view);
  }

  // A new pose: a coarse preview renders at once (the previous one is cancelled).
  void moved_view() {
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
  void settle_view(bool now) {
    if (!m_previewing || (!now && (m_nav.dragging() || ms_since(m_moved_at) < kRestMs))) return;
    m_previewing = false;
    change([this](RenderParams& p) {
      p.width = m_full_w, p.height = m_full_h;
      return "camera: " + pose_text(m_sh.view);
    });
  }

  void write_camera() {
    std::string path = output_path(m_options, "_cam_settings.txt");
    try {
      write_camera_settings(shown_camera(), path);
      say("wrote %s", path.c_str());
    } catch (const std::exception& e) {
      say("camera settings: %s", e.what());
    }
  }

  // Debounced: the render restarts at the new size once the window has stopped changing.
  void apply_resize() {
    if (m_resize_w <= 0 || m_resize_h <= 0 || ms_since(m_resize_at) < kResizeSettleMs) return;
    int w = std::min(m_resize_w, 16384), h = std::min(m_resize_h, 16384);
    m_resize_w = m_resize_h = 0;
    const RenderParams now = want();
    if (now.width != w || now.height != h)
      change([w, h](RenderParams& p) {
        p.width = w, p.height = h;
        p.cell_x = p.cell_y = p.cell_w = p.cell_h = 0;  // a cell of the old frame
        return "size " + std::to_string(w) + "x" + std::to_string(h);
      });
  }

  // Tiles go into the frame-sized image at the session's cell offset: a cell render paints over
  // the image the window shows, as the course's does.
  void upload_tiles(const Status& st) {
    if (st.gen != 0 && st.gen != m_tex_gen) {
      m_tex_gen = st.gen;
      m_cell_x0 = st.cell_x0, m_cell_y0 = st.cell_y0;
      if (st.frame_w != m_tex_w || st.frame_h != m_tex_h) {
        m_tex_w = st.frame_w;
        m_tex_h = st.frame_h;
        m_rgb.assign(size_t(m_tex_w) * m_tex_h * 3, 0);
        m_rate.assign(m_rgb.size(), 0);
        m_count.assign(size_t(m_tex_w) * m_tex_h, 0);
        gl_texture_init(m_tex, m_tex_w, m_tex_h, m_rgb.data());
        m_dirty = true;
      }
    }
    std::vector<TileUpdate> tiles;
    {
      std::lock_guard<std::mutex> lk(m_sh.tile_mutex);
      tiles.swap(m_sh.tiles);
    }
    for (const TileUpdate& u : tiles) {
      if (u.gen != m_tex_gen) continue;  // from a session that was replaced
      const Tile& t = u.tile;
      const int tw = t.x1 - t.x0, x0 = t.x0 + m_cell_x0, y0 = t.y0 + m_cell_y0;
      if (x0 < 0 || y0 < 0 || x0 + tw > m_tex_w || y0 + (t.y1 - t.y0) > m_tex_h) continue;
      for (int y = t.y0; y < t.y1; ++y) {
        size_t dst = (size_t(y + m_cell_y0) * m_tex_w + x0) * 3, src = size_t(y - t.y0) * tw * 3;
        std::copy(u.rgb.begin() + src, u.rgb.begin() + src + tw * 3, m_rgb.begin() + dst);
        std::copy(u.rate.begin() + src, u.rate.begin() + src + tw * 3, m_rate.begin() + dst);
        std::copy(u.count.begin() + src / 3, u.count.begin() + src / 3 + tw, m_count.begin() + dst / 3);
      }
      upload_rect(x0, y0, tw, t.y1 - t.y0);
    }
  }

  void upload_rect(int x, int y, int w, int h) {
    const std::vector<uint8_t>& src = m_show_rate ? m_rate : m_rgb;
    if (src.empty()) return;
    gl_texture_update(m_tex, src.data(), m_tex_w, x, y, w, h);
    m_dirty = true;
  }

  void upload_all() { upload_rect(0, 0, m_tex_w, m_tex_h); }

  // The image, the cell mode's band, then the overlay.
  void draw() {
    int fw, fh, ww, wh;
    glfwGetFramebufferSize(m_win, &fw, &fh);
    gl_draw_texture(m_tex_w > 0 ? m_tex : 0, fw, fh);
    if (m_band.active()) {
      double x0, y0, x1, y1;
      m_band.corners(x0, y0, x1, y1);
      glfwGetWindowSize(m_win, &ww, &wh);
      gl_draw_band(x0, y0, x1, y1, ww, wh);
    }
    Overlay o = layout_overlay(overlay_inputs(), fw, fh);
    draw_overlay(o, fw, fh);
    m_panel_lines = o.panel_layout.lines;
  }

  // What the overlay is drawn over and which of its parts are on.
  OverlayInputs overlay_inputs() {
    OverlayInputs in;
    {
      std::lock_guard<std::mutex> lk(m_sh.mutex);
      in.status = m_sh.status;
      in.params = m_sh.want;
      in.current = in.status.gen == m_sh.want_gen;
    }
    in.show_panel = m_show_panel, in.show_keys = m_show_keys, in.show_rate = m_show_rate;
    in.have_image = m_tex_w > 0;
    if (m_show_rate && !m_count.empty()) {
      auto [lo, hi] = std::minmax_element(m_count.begin(), m_count.end());
      in.min_count = *lo;
      in.max_count = *hi;
    }
    return in;
  }

  // The panel's text changes without new tiles: the ETA counts down, a key changes a setting.
  bool panel_changed() {
    int fw, fh;
    glfwGetFramebufferSize(m_win, &fw, &fh);
    return layout_overlay(overlay_inputs(), fw, fh).panel_layout.lines != m_panel_lines;
  }

  void update_title(const Status& st) {
    bool current;
    {
      std::lock_guard<std::mutex> lk(m_sh.mutex);
      current = st.gen == m_sh.want_gen;
    }
    std::string name = m_options.scene_path.substr(m_options.scene_path.find_last_of('/') + 1);
    std::string title = "pathtracer: " + name + " | " + progress_text(st, current);
    if (m_title != title) {
      m_title = title;
      glfwSetWindowTitle(m_win, title.c_str());
    }
  }

  void report_overlay() {
    int fw, fh;
    glfwGetFramebufferSize(m_win, &fw, &fh);
    say("%s", overlay_report(layout_overlay(overlay_inputs(), fw, fh), fw, fh).c_str());
  }

  // Runs script commands until one has to wait; a failure closes the window with status 1.
  void step_script(const Status& st) {
    while (m_script_pos < m_script.size()) {
      const ScriptLine& l = m_script[m_script_pos];
      const std::string& c = l.words[0];
      auto arg = [&](int i) { return std::strtod(l.words[i].c_str(), nullptr); };
      if (!m_step_started) {
        m_step_started = true;
        m_step_at = Clock::now();
        if (c == "resize") glfwSetWindowSize(m_win, int(arg(1)), int(arg(2)));
      }
      bool done = true;
      if (c == "wait_spp") {
        std::lock_guard<std::mutex> lk(m_sh.mutex);
        done = st.gen == m_sh.want_gen && m_sh.handled == m_sh.issued && st.gen == m_tex_gen &&
               (st.reached_spp >= arg(1) || st.finished);
      } else if (c == "wait_ms") {
        done = ms_since(m_step_at) >= arg(1);
      } else if (c == "sync") {
        std::lock_guard<std::mutex> lk(m_sh.mutex);
        done = m_sh.handled == m_sh.issued && st.gen == m_sh.want_gen;
        if (done) say("sync: %.0f ms", ms_since(m_step_at));
      } else if (c == "resize") {
        std::lock_guard<std::mutex> lk(m_sh.mutex);
        done = m_sh.want.width == int(arg(1)) && m_sh.want.height == int(arg(2)) && m_resize_w == 0;
      } else if (c == "key") {
        on_key(key_code(l.words[1]), false);
      } else if (c == "click") {
        on_click(arg(1), arg(2));
      } else if (c == "drag") {  // press, STEPS moves along the line, release: as a hand would
        const int steps = std::max(1, int(arg(6)));
        on_button(l.words[1] == "left" ? CameraNav::left : CameraNav::right, true, arg(2), arg(3));
        for (int k = 1; k <= steps; ++k)
          on_cursor(arg(2) + (arg(4) - arg(2)) * k / steps, arg(3) + (arg(5) - arg(3)) * k / steps);
        on_button(l.words[1] == "left" ? CameraNav::left : CameraNav::right, false, arg(4), arg(5));
      } else if (c == "wheel") {
        on_wheel(arg(1));
        settle_view(true);
      } else if (c == "title") {
        update_title(st);
        say("title: %s", m_title.c_str());
      } else if (c == "overlay") {
        report_overlay();
      } else if (c == "screenshot") {
        screenshot(l.words[1]);
      } else if (c == "close" || c == "quit") {
        glfwSetWindowShouldClose(m_win, GLFW_TRUE);
      }
      if (!done) {
        if (ms_since(m_step_at) > kScriptTimeoutMs) {
          std::fprintf(stderr, "pathtracer: %s:%d: '%s' timed out\n", m_options.script.c_str(), l.line, c.c_str());
          m_exit = 1;
          glfwSetWindowShouldClose(m_win, GLFW_TRUE);
        }
        return;
      }
      ++m_script_pos;
      m_step_started = false;
      if (c == "close" || c == "quit") return;
    }
  }

  // Draws the current image and reads the framebuffer back (what the window shows).
  void screenshot(const std::string& path) {
    draw();
    int fw, fh;
    glfwGetFramebufferSize(m_win, &fw, &fh);
    try {
      write_png8(gl_read_frame(fw, fh), fw, fh, path);
      say("screenshot: %s %dx%d", path.c_str(), fw, fh);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "pathtracer: screenshot: %s\n", e.what());
      m_exit = 1;
    }
    m_dirty = true;
  }

  const CliOptions& m_options;
  const SceneDesc& m_desc;
  GLFWwindow* m_win;
  Shared m_sh;
  GLuint m_tex = 0;
  int m_tex_w = 0, m_tex_h = 0;
  uint64_t m_tex_gen = 0;
  int m_cell_x0 = 0, m_cell_y0 = 0;    // where the session's image lies in the texture (a cell's offset)
  std::vector<uint8_t> m_rgb, m_rate;  // what the texture holds, for each view
  std::vector<uint32_t> m_count;       // samples in each pixel, for the rate legend
  bool m_show_rate = false, m_show_keys = false, m_show_panel = true, m_dirty = true;
  std::vector<std::string> m_panel_lines;  // as last drawn: the ETA counts down between passes
  int m_resize_w = 0, m_resize_h = 0;
  Clock::time_point m_resize_at;
  CameraNav m_nav;
  bool m_cell_mode = false;  // C: a left drag picks a cell instead of orbiting
  CellBand m_band;
  SceneFeatures m_features;
  std::set<std::string> m_hinted;
  bool m_previewing = false;  // rendering at 1/kPreviewScale while the camera moves
  int m_full_w = 0, m_full_h = 0;
  Clock::time_point m_moved_at;
  std::string m_title;
  std::vector<ScriptLine> m_script;
  size_t m_script_pos = 0;
  bool m_step_started = false;
  Clock::time_point m_step_at;
  int m_exit = 0;
};

std::string g_glfw_error;

}  // namespace

int run_viewer(const CliOptions& o) {
  std::vector<ScriptLine> script;
  try {
    if (!o.script.empty()) script = load_script(o.script);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pathtracer: %s\n", e.what());
    return 1;
  }
  struct stat dir;
  if (!o.output_dir.empty() && (stat(o.output_dir.c_str(), &dir) != 0 || !S_ISDIR(dir.st_mode))) {
    std::fprintf(stderr, "pathtracer: --output-dir %s: not a directory\n", o.output_dir.c_str());
    return 1;
  }
  glfwSetErrorCallback([](int, const char* text) { g_glfw_error = text; });
  if (!glfwInit()) {
    std::fprintf(stderr, "pathtracer: cannot open the debug window (%s); give -f FILE to render to a file\n",
                 g_glfw_error.c_str());
    return 2;
  }
  int rc;
  try {
    SceneDesc desc = load_scene(o.scene_path);
    RenderParams p = o.params;
    p.cell_w = p.cell_h = 0;
    auto scene = make_render_scene(desc, p);
    if (!o.quiet)
      std::fprintf(stderr, "Loaded %s: %s\n", o.scene_path.c_str(), loaded_counts(*scene).c_str());
    glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
    GLFWwindow* win = glfwCreateWindow(o.params.width, o.params.height, "pathtracer", nullptr, nullptr);
    if (!win) {
      std::fprintf(stderr, "pathtracer: cannot open the debug window (%s); give -f FILE to render to a file\n",
                   g_glfw_error.c_str());
      glfwTerminate();
      return 2;
    }
    // The smallest window the status panel fits at its smallest text (or the -r size, if smaller).
    glfwSetWindowSizeLimits(win, std::min(kMinWindowW, o.params.width), std::min(kMinWindowH, o.params.height),
                            GLFW_DONT_CARE, GLFW_DONT_CARE);
    glfwMakeContextCurrent(win);
    glfwSwapInterval(0);
    {
      Viewer viewer(o, desc, win, std::move(script));
      rc = viewer.run(std::move(scene));
    }
    glfwDestroyWindow(win);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pathtracer: %s\n", e.what());
    rc = 1;
  }
  glfwTerminate();
  return rc;
}

}  // namespace pt
