// The GLFW debug window: a render thread (viewer_loop.h) runs RenderSession passes of doubling
// sample targets and hands finished tiles (tone-mapped exactly like the PNG) to the window thread,
// which uploads them into one texture drawn as a full-window quad (viewer_gl.h). Keys change
// RenderParams, cancel the running pass through its cancel flag and start a new session; the
// window thread never waits on rendering. The render size follows the window's framebuffer (course
// behaviour); until the new session's first tiles arrive the previous image is stretched to it.
// The status panel and the rate legend are drawn over the image (overlay.h). What input does to
// the settings and the camera is viewer_input.cpp's; this file is the display and the window.
#include "viewer.h"

#include <GLFW/glfw3.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <thread>

#include "denoiser.h"
#include "hints.h"
#include "overlay.h"
#include "scene_file.h"
#include "session.h"
#include "viewer_gl.h"
#include "viewer_input.h"
#include "viewer_keys.h"
#include "viewer_loop.h"

namespace pt {

namespace {

using namespace viewer;

// ---- the window thread ----

constexpr int kMinWindowW = 160, kMinWindowH = 120;

class Viewer : public ScriptHost {
 public:
  Viewer(const CliOptions& o, const SceneDesc& desc, const SceneFeatures& features, GLFWwindow* win,
         WindowScript* script)
      : m_options(o), m_desc(desc), m_win(win), m_input(o, desc, features, m_sh), m_script(script) {
    glfwSetWindowUserPointer(win, this);
    glfwSetKeyCallback(win, [](GLFWwindow* w, int key, int, int action, int) {
      if (action != GLFW_RELEASE) self(w)->on_key(key, action == GLFW_REPEAT);
    });
    glfwSetMouseButtonCallback(win, [](GLFWwindow* w, int button, int action, int) {
      if (button != GLFW_MOUSE_BUTTON_LEFT && button != GLFW_MOUSE_BUTTON_RIGHT) return;
      double x, y;
      glfwGetCursorPos(w, &x, &y);
      self(w)->button(button == GLFW_MOUSE_BUTTON_LEFT, action == GLFW_PRESS, x, y);
    });
    glfwSetCursorPosCallback(win, [](GLFWwindow* w, double x, double y) { self(w)->cursor(x, y); });
    glfwSetScrollCallback(win, [](GLFWwindow* w, double, double dy) { self(w)->m_input.wheel(dy); });
    glfwSetFramebufferSizeCallback(win, [](GLFWwindow* w, int width, int height) {
      Viewer* v = self(w);
      v->m_input.framebuffer_resized(width, height);
      v->m_dirty = true;
    });
    glfwSetWindowRefreshCallback(win, [](GLFWwindow* w) { self(w)->m_dirty = true; });
  }

  int run(const SceneBase& base) {
    int fw, fh;
    glfwGetFramebufferSize(m_win, &fw, &fh);
    m_input.start(fw, fh);
    if (m_options.params.cell_w > 0) say("window: -p is ignored; the window renders the whole frame");
    const RenderParams want = m_input.want();
    say("window: %dx%d, %s", want.width, want.height, ViewerInput::settings_text(want).c_str());

    glGenTextures(1, &m_tex);
    m_sh.wake_window = [] { glfwPostEmptyEvent(); };
    RenderLoop loop(m_options, m_desc, base, m_sh);
    std::thread render([&] { loop.run(); });
    while (!glfwWindowShouldClose(m_win)) {
      glfwWaitEventsTimeout(0.02);
      {
        std::lock_guard<std::mutex> lk(m_sh.mutex);
        m_status = m_sh.status;
        if (!m_sh.fatal.empty()) {
          std::fprintf(stderr, "pathtracer: %s\n", m_sh.fatal.c_str());
          m_exit = 1;
          break;
        }
      }
      upload_tiles(m_status);  // after the status snapshot: a completed pass's tiles are all queued by then
      m_input.tick();
      if (m_script && !m_script->done()) m_script->step(*this);
      m_dirty |= m_input.take_redraw();
      if (m_dirty || panel_changed()) {
        draw();
        glfwSwapBuffers(m_win);
        m_dirty = false;
      }
      update_title(m_status);
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

  // ScriptHost: the handlers real input runs.
  void key(int glfw_key) override { on_key(glfw_key, false); }
  void click(double x, double y) override {
    int ww, wh;
    glfwGetWindowSize(m_win, &ww, &wh);
    m_input.click(x, y, ww, wh);
  }
  void button(bool left, bool down, double x, double y) override {
    int ww, wh;
    glfwGetWindowSize(m_win, &ww, &wh);
    m_input.button(left ? CameraNav::left : CameraNav::right, down, x, y, ww, wh);
  }
  void cursor(double x, double y) override {
    int ww, wh;
    glfwGetWindowSize(m_win, &ww, &wh);
    m_input.cursor(x, y, ww, wh);
  }
  void wheel(double steps) override {
    m_input.wheel(steps);
    m_input.settle_now();
  }
  void request_size(int w, int h) override { glfwSetWindowSize(m_win, w, h); }
  bool rendering_at(int w, int h) override {
    const RenderParams want = m_input.want();
    return want.width == w && want.height == h && !m_input.resize_pending();
  }
  bool reached(double spp) override {
    std::lock_guard<std::mutex> lk(m_sh.mutex);
    const Status& st = m_status;
    return st.gen == m_sh.want_gen && m_sh.handled == m_sh.issued && st.gen == m_tex_gen &&
           (st.reached_spp >= spp || st.finished);
  }
  bool synced() override {
    std::lock_guard<std::mutex> lk(m_sh.mutex);
    return m_sh.handled == m_sh.issued && m_status.gen == m_sh.want_gen;
  }
  std::string title() override {
    update_title(m_status);
    return m_title;
  }
  void report_overlay() override {
    int fw, fh;
    glfwGetFramebufferSize(m_win, &fw, &fh);
    say("%s", overlay_report(layout_overlay(overlay_inputs(), fw, fh), fw, fh).c_str());
  }
  // Draws the current image and reads the framebuffer back (what the window shows).
  bool screenshot(const std::string& path) override {
    draw();
    m_dirty = true;
    int fw, fh;
    glfwGetFramebufferSize(m_win, &fw, &fh);
    try {
      write_png8(gl_read_frame(fw, fh), fw, fh, path);
      say("screenshot: %s %dx%d", path.c_str(), fw, fh);
      return true;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "pathtracer: screenshot: %s\n", e.what());
      m_exit = 1;
      return false;
    }
  }
  void close(int status) override {
    m_exit = std::max(m_exit, status);
    glfwSetWindowShouldClose(m_win, GLFW_TRUE);
  }

 private:
  static Viewer* self(GLFWwindow* w) { return static_cast<Viewer*>(glfwGetWindowUserPointer(w)); }

  // The display's own keys (views, panels, closing); the rest change what renders (viewer_input.h).
  void on_key(int key, bool repeat) {
    if (key != GLFW_KEY_SLASH) set_show_keys(false);
    m_input.key(key, repeat);
    if (key == GLFW_KEY_ESCAPE || key == GLFW_KEY_Q) glfwSetWindowShouldClose(m_win, GLFW_TRUE);
    if (repeat) return;  // the keys below act once per press
    switch (key) {
      case GLFW_KEY_T:
        m_show_rate = !m_show_rate;
        upload_all();
        say("view: %s", m_show_rate ? "sample rate" : m_show_denoised ? "denoised" : "radiance");
        break;
      case GLFW_KEY_N: toggle_denoised(); break;
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

  // The denoised view: the film denoised at pass ends (viewer_loop.h). A render without the
  // denoiser's features restarts with them.
  void toggle_denoised() {
    if (!Denoiser::shared().available()) {
      say("denoiser: %s", Denoiser::shared().description().c_str());
      return;
    }
    m_show_denoised = !m_show_denoised;
    bool restart = false;
    {
      std::lock_guard<std::mutex> lk(m_sh.mutex);
      if (m_show_denoised && !m_sh.want.features) {
        m_sh.want.features = true;
        ++m_sh.want_gen;
        restart = true;
      }
    }
    m_sh.wake.notify_all();
    if (restart) m_sh.cancel = true;
    upload_all();
    say("view: %s%s", m_show_denoised ? "denoised" : "radiance",
        restart ? " (the render restarts with the denoiser's albedo and normal features)" : "");
  }

  void set_show_keys(bool on) {
    m_dirty |= on != m_show_keys;
    m_show_keys = on;
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
    bool new_denoised = false;
    {
      std::lock_guard<std::mutex> lk(m_sh.tile_mutex);
      tiles.swap(m_sh.tiles);
      const Shared::Denoised& d = m_sh.denoised;
      if (d.gen == m_tex_gen && d.number != m_denoised_number && !m_rgb.empty()) {
        // Over the raw picture at the session's cell offset, as its tiles are.
        m_denoised_number = d.number;
        m_denoised_gen = d.gen;
        m_denoised = m_rgb;
        for (int y = 0; y < d.height && y + m_cell_y0 < m_tex_h; ++y)
          std::copy(d.rgb.begin() + size_t(y) * d.width * 3, d.rgb.begin() + size_t(y + 1) * d.width * 3,
                    m_denoised.begin() + (size_t(y + m_cell_y0) * m_tex_w + m_cell_x0) * 3);
        new_denoised = true;
      }
    }
    if (new_denoised && m_show_denoised && !m_show_rate) upload_all();
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
    const bool denoised = m_show_denoised && m_denoised.size() == m_rgb.size() && m_denoised_gen_ok();
    const std::vector<uint8_t>& src = m_show_rate ? m_rate : denoised ? m_denoised : m_rgb;
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
    if (m_input.band().active()) {
      double x0, y0, x1, y1;
      m_input.band().corners(x0, y0, x1, y1);
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
    in.show_denoised = m_show_denoised;
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

  const CliOptions& m_options;
  const SceneDesc& m_desc;
  GLFWwindow* m_win;
  Shared m_sh;
  ViewerInput m_input;
  WindowScript* m_script;
  Status m_status;  // the render thread's, as of this frame
  GLuint m_tex = 0;
  int m_tex_w = 0, m_tex_h = 0;
  uint64_t m_tex_gen = 0;
  int m_cell_x0 = 0, m_cell_y0 = 0;    // where the session's image lies in the texture (a cell's offset)
  std::vector<uint8_t> m_rgb, m_rate;  // what the texture holds, for each view
  std::vector<uint32_t> m_count;       // samples in each pixel, for the rate legend
  bool m_show_rate = false, m_show_keys = false, m_show_panel = true, m_dirty = true;
  bool m_show_denoised = m_options.denoise;  // N; --denoise starts with it
  std::vector<uint8_t> m_denoised;  // the last denoised picture of the texture's session, texture-sized
  uint64_t m_denoised_number = 0, m_denoised_gen = 0;
  bool m_denoised_gen_ok() const { return m_denoised_gen == m_tex_gen; }
  std::vector<std::string> m_panel_lines;  // as last drawn: the ETA counts down between passes
  std::string m_title;
  int m_exit = 0;
};

std::string g_glfw_error;

}  // namespace

int run_viewer(const CliOptions& o, WindowScript* script) {
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
    const SceneBase base = make_scene_base(desc);  // each of the window's sessions is a view of it (make_view)
    const auto first = make_view(base, p);
    if (!o.quiet) std::fprintf(stderr, "Loaded %s: %s\n", o.scene_path.c_str(), loaded_counts(*first).c_str());
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
      Viewer viewer(o, desc, first->features, win, script);
      rc = viewer.run(base);
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
