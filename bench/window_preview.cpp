// bench_window_preview: the window's preview rate while the camera moves (docs/performance.md):
// each frame of a drag is a new session at 1/4 of the window's size rendering its first pass (one
// sample a pixel), as viewer.cpp's moved_view asks, for a camera orbiting the scene's target.
// Prints frames a second for the preview and, for scale, for the full-size first pass.
//   bench_window_preview [frames=60] [scene=scenes/cornell.dae] [W H = 640 480] [threads=2]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "camera.h"
#include "scene_file.h"
#include "session.h"

using namespace pt;

namespace {

// Seconds for `frames` sessions of one first pass each, the camera turning 2 degrees a frame.
double drag_seconds(const SceneBase& base, RenderParams p, int frames) {
  auto scene = make_view(base, p);
  const Camera start = scene->camera;
  const Vec3 arm = start.position - start.target;
  const auto t0 = std::chrono::steady_clock::now();
  for (int f = 0; f < frames; ++f) {
    const float a = float(f) * 2 * kPi / 180, c = std::cos(a), s = std::sin(a);
    const Vec3 turned(arm.x * c + arm.z * s, arm.y, -arm.x * s + arm.z * c);  // about +Y through the target
    scene->camera = camera_looking(start, start.target + turned, start.target);
    RenderSession session(*scene, p);
    session.render_all();
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  const int frames = argc > 1 ? std::atoi(argv[1]) : 60;
  const std::string path = argc > 2 ? argv[2] : std::string(PT_SOURCE_DIR) + "/scenes/cornell.dae";
  const int w = argc > 4 ? std::atoi(argv[3]) : 640, h = argc > 4 ? std::atoi(argv[4]) : 480;
  const int threads = argc > 5 ? std::atoi(argv[5]) : 2;
  const SceneBase base = make_scene_base(load_scene(path));
  RenderParams p;
  p.spp = 1;
  p.adaptive = false;
  p.threads = threads;
  p.keep_fov = true;  // the window's framing at any size
  std::printf("window_preview: %s, window %dx%d, %d threads, %d frames, 1 spp a frame\n", path.c_str(), w, h, threads, frames);
  for (int scale : {4, 1}) {
    p.width = std::max(1, w / scale), p.height = std::max(1, h / scale);
    drag_seconds(base, p, 3);  // warm-up
    const double s = drag_seconds(base, p, frames);
    std::printf("  %s %4dx%-4d %6.1f frames/s (%.1f ms a frame)\n", scale == 1 ? "full   " : "preview", p.width,
                p.height, frames / s, 1000 * s / frames);
  }
  return 0;
}
