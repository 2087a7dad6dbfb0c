// The debug window's render thread (viewer.cpp runs the window): it steps the progressive driver
// (driver.h: pass sizes, --target-error, --time-limit) over a session for the settings the window
// asks for, hands finished tiles (tone-mapped as the PNG is) to the window thread, and runs its
// focus and save commands between passes. No GLFW here: it wakes the window through
// Shared::wake_window.
#pragma once

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "cli.h"
#include "session.h"
#include "viewer_nav.h"

namespace pt {
namespace viewer {

using Clock = std::chrono::steady_clock;
inline double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}
// A line on stdout, flushed: the window's log, which the tests read.
void say(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
// A number as the course prints it (shortest %g).
std::string fmt_g(double v);
// The scene path without ".dae" (or ".gltf", ".glb"): the course names screenshots and camera files after it.
std::string scene_base(const std::string& path);
// Where the window writes a file named after the scene: --output-dir (default: the current
// directory), the scene's file name without its extension, then `suffix`.
std::string output_path(const CliOptions& o, const std::string& suffix);

// ---- state shared by the window thread and the render thread ----

struct TileUpdate {
  uint64_t gen;
  Tile tile;
  std::vector<uint8_t> rgb, rate;  // tone-mapped radiance and the rate colouring, 3 bytes a pixel
  std::vector<uint32_t> count;     // samples taken in each pixel
};

// What the render thread reports about the session it runs.
struct Status {
  uint64_t gen = 0;  // 0: no session yet
  int width = 0, height = 0;  // the session's image: the frame, or its cell (-p, the C key)
  int frame_w = 0, frame_h = 0, cell_x0 = 0, cell_y0 = 0;  // the frame, and where the image's top-left lies in it
  int spp = 0;           // the session's target
  int reached_spp = 0;   // the last completed pass's target
  bool finished = false;
  double error = INFINITY, seconds = 0;
  // The render's ProgressEstimate after the last pass, and when it was read: the title counts
  // the ETA down from there.
  double progress = 0, eta = -1;
  Clock::time_point at{};
};

enum class CommandKind { focus, save };

struct Command {
  CommandKind kind;
  float sx = 0, sy = 0;  // focus: sensor point, y up
};

// The camera the window shows for settings p and the navigation's pose.
Camera view_camera(const SceneDesc& desc, const RenderParams& p, const ViewPose& view);

struct Shared {
  std::mutex mutex;
  std::condition_variable wake;
  RenderParams want;       // what the window asks for; a change bumps want_gen
  ViewPose view;           // where the navigation put the camera (changes with want_gen too)
  uint64_t want_gen = 1;
  std::deque<Command> commands;
  uint64_t issued = 0, handled = 0;  // commands
  bool quit = false;
  std::string fatal;       // a render-thread error that ends the window
  std::atomic<bool> cancel{false};
  Status status;

  std::mutex tile_mutex;
  std::vector<TileUpdate> tiles;
  // The last denoised picture of session `gen` (tone-mapped, the session's image size), under
  // tile_mutex; the window's N key shows it.
  struct Denoised {
    uint64_t gen = 0, number = 0;  // number: bumps with each picture
    int width = 0, height = 0;
    std::vector<uint8_t> rgb;
  } denoised;

  std::function<void()> wake_window;  // wakes the window thread's event wait (set before the loop runs)
};

// ---- the render thread ----

class RenderLoop {
 public:
  RenderLoop(const CliOptions& o, const SceneDesc& desc, const SceneBase& base, Shared& sh)
      : m_options(o), m_desc(desc), m_base(base), m_sh(sh) {}
  // Renders until Shared::quit; an exception ends it with Shared::fatal set.
  void run();

 private:
  void loop();
  void start_session(const RenderParams& p, const ViewPose& view, uint64_t gen);
  // The render scene for settings p and the pose: a view of the base (make_view, as a job's) with
  // view_camera's camera.
  std::unique_ptr<RenderScene> make_scene(const RenderParams& p, const ViewPose& view);
  // Runs on a worker thread right after the tile is finished for this pass.
  void send_tile(uint64_t gen, const RenderSession& s, const Tile& t);
  // After a pass of a session with the denoiser's features: denoises the film (fast quality; the
  // finished render's at full quality) while denoising costs at most a tenth of the render time.
  void denoise_after_pass(const PassReport& r, bool finished);
  // Runs between passes (the pass was cancelled to get here; it resumes where it stopped).
  // Returns the autofocus distance for a focus command.
  float handle(const Command& c, const RenderParams& want, const ViewPose& view);

  const CliOptions& m_options;
  const SceneDesc& m_desc;
  const SceneBase& m_base;
  Shared& m_sh;
  std::shared_ptr<const EnvironmentMap> m_environment;  // -e's map, read once for every session
  std::unique_ptr<RenderScene> m_scene;  // the session's view of the base
  std::unique_ptr<RenderSession> m_session;
  std::unique_ptr<ProgressiveDriver> m_driver;  // the session's passes and stop rules
  ProgressEstimate m_estimate;
  RenderParams m_params;
  uint64_t m_gen = 0;
  bool m_done = false;
  double m_denoise_spent = 0;  // this session's denoising time
  bool m_denoise_failed = false;
  Status m_status;
};

}  // namespace viewer
}  // namespace pt
