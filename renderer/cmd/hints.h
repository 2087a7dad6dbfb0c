// One-line hints for settings that will visibly disappoint (the course's defaults among them): the
// pathtracer command prints them before it renders, so a black mirror or a crop says why.
#pragma once

#include <string>
#include <vector>

#include "cli.h"

namespace pt {

struct Camera;
struct RenderScene;
struct SceneFeatures;

// "7972 triangles, 0 spheres, 1 light": what the "Loaded" line counts. The default light of a
// glTF scene without any is named as such, not counted as the scene's.
std::string loaded_counts(const RenderScene& scene);

// `course_framing`: the camera is the course's (no -c, no --file-camera, no glTF camera);
// `bounds`: the geometry bounds the course frames. Each hint names the flag that helps.
std::vector<std::string> render_hints(const CliOptions& options, const SceneFeatures& features, const Camera& camera,
                                      const Bounds3& bounds, bool course_framing);
// The hint for a max depth that leaves the scene's mirrors and glass black or dark, or "".
std::string depth_hint(int max_depth, const SceneFeatures& features);

}  // namespace pt
