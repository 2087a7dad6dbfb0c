// The GLFW debug window (`pathtracer scene.dae` without -f): the progressive render as it
// converges, a status panel and rate legend over it, the course's render-mode keys,
// click-to-focus, camera moves and cell mode. viewer.cpp (the display), viewer_input.cpp (key
// codes only), viewer_gl.cpp and overlay.cpp are the only files that include GLFW / OpenGL; they
// are linked into the pathtracer executable only, never into the renderer library.
#pragma once

#include <string>
#include <vector>

#include "cli.h"

namespace pt {
namespace viewer {

// What a window script drives: the window's own input handlers, as a hand would, and what it
// shows. The test build's --script player (viewer_script.h) is the one script.
class ScriptHost {
 public:
  virtual ~ScriptHost() = default;
  virtual void key(int glfw_key) = 0;
  virtual void click(double x, double y) = 0;  // window coordinates, y down
  virtual void button(bool left, bool down, double x, double y) = 0;
  virtual void cursor(double x, double y) = 0;
  virtual void wheel(double steps) = 0;          // the view settles at once after it
  virtual void request_size(int w, int h) = 0;   // asks the window system for this size
  virtual bool rendering_at(int w, int h) = 0;   // the render has taken that size
  virtual bool reached(double spp) = 0;          // the settings' image has spp (or finished) and is shown
  virtual bool synced() = 0;                     // every command handled, the session current
  virtual std::string title() = 0;
  virtual void report_overlay() = 0;             // the panel's layout, on the log
  virtual bool screenshot(const std::string& path) = 0;  // false when it failed (said on stderr)
  virtual void close(int status) = 0;
};

// Input that drives the window between frames.
class WindowScript {
 public:
  virtual ~WindowScript() = default;
  // Runs commands until one has to wait or the script ends.
  virtual void step(ScriptHost& host) = 0;
  virtual bool done() const = 0;
};

}  // namespace viewer

// Opens the window and renders until it is closed (or `script` closes it). Returns the exit
// status: 0 when closed, 1 on a scene, render or script error, 2 when no window can be opened (no
// display).
int run_viewer(const CliOptions& options, viewer::WindowScript* script = nullptr);

// The pathtracer command (main.cpp) on its arguments (without argv[0]), with the window driven by
// `script` where one is given (the test build).
int pathtracer_main(const std::vector<std::string>& args, const char* argv0, viewer::WindowScript* script);

}  // namespace pt
