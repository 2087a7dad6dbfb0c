// The CS184 COLLADA dialect (.dae with CGL extensions) -> SceneDesc. Most callers want
// load_scene / parse_scene (scene_file.h), which pick this loader or the glTF one.
#pragma once

#include <string>

#include "scene.h"
#include "load_limits.h"

namespace pt {

// Loads a scene file; throws SceneError naming the file, element and line on any problem.
SceneDesc load_collada(const std::string& path, const LoadLimits& limits = {});
// Parses scene text held in memory; `name` is used in messages.
SceneDesc parse_collada(const std::string& text, const std::string& name, const LoadLimits& limits = {});

}  // namespace pt
