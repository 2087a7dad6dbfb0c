// The CS184 COLLADA dialect (.dae with CGL extensions) -> SceneDesc.
#pragma once

#include <stdexcept>
#include <string>

#include "scene.h"

namespace pt {

// A load or build failure that names the file, element and (where known) line.
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct LoadLimits {
  size_t max_file_bytes = size_t(1) << 30;  // 1 GiB
  size_t max_triangles = 50'000'000;
  int max_node_depth = 128;
  size_t max_nodes = 1'000'000;
};

// Loads a scene file; throws SceneError naming the file, element and line on any problem.
SceneDesc load_collada(const std::string& path, const LoadLimits& limits = {});
// Parses scene text held in memory; `name` is used in messages.
SceneDesc parse_collada(const std::string& text, const std::string& name, const LoadLimits& limits = {});

}  // namespace pt
