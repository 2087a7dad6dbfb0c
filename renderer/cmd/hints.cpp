// Hints for disappointing settings (hints.h).
#include "hints.h"

#include <algorithm>
#include <cmath>

#include "camera.h"
#include "render_scene.h"

namespace pt {

std::string loaded_counts(const RenderScene& scene) {
  auto count = [](size_t n, const char* what) { return std::to_string(n) + " " + what + (n == 1 ? "" : "s"); };
  size_t own = 0;
  bool environment_map = false;
  for (const Light& l : scene.lights) {
    if (l.kind == LightKind::environment) environment_map = true;
    else ++own;
  }
  std::string lights = scene.default_light ? "no lights of its own (the default white environment and sun)"
                                           : count(own, "light") + (environment_map ? " and the environment map" : "");
  return count(scene.triangle_count, "triangle") + ", " + count(scene.sphere_count, "sphere") + ", " + lights;
}

std::string depth_hint(int max_depth, const SceneFeatures& f) {
  auto has = [&](const char* m) { return std::find(f.materials.begin(), f.materials.end(), m) != f.materials.end(); };
  // Depth 1 is direct light only and depth 2 one bounce: a mirror shows the lit room from 2, glass
  // (in, out, then the room) from 3 (cs184-spec: each specular event takes one level).
  if (max_depth >= 3 || !(has("mirror") || has("glass") || has("refraction"))) return "";
  return "-m " + std::to_string(max_depth) + " leaves mirror and glass " + (max_depth < 2 ? "black" : "dark") +
         ": what they reflect and refract needs -m 3 or more (-m 5 for glass seen through glass)";
}

std::vector<std::string> render_hints(const CliOptions& o, const SceneFeatures& f, const Camera& camera,
                                      const Bounds3& bounds, bool course_framing) {
  std::vector<std::string> hints;
  const RenderParams& p = o.params;
  if (std::string h = depth_hint(p.max_depth, f); !h.empty()) hints.push_back(h);
  if (p.spp == 1 && !(o.limits.target_error > 0))
    hints.push_back("-s 1 takes one sample a pixel, through its centre: expect jagged edges and heavy noise "
                    "(-s 64 or more, or --target-error 0.01)");
  if (course_framing && !p.keep_fov && !p.frame_scene) {
    const float shown = visible_bounds_fraction(camera, bounds);
    if (shown < 0.5f) {
      char pct[16];
      std::snprintf(pct, sizeof pct, "%.0f%%", 100 * shown);
      hints.push_back("-r " + std::to_string(p.width) + " " + std::to_string(p.height) + " shows " + pct +
                      " of the scene: as in the course, a size below 800x600 crops the centre of its view; "
                      "--keep-fov scales the whole view, --frame-scene fits the scene to the image");
    }
  }
  return hints;
}

}  // namespace pt
