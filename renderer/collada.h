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

// Bounds on what a scene may make the loader do: hostile files (huge, deeply nested, millions of
// tiny elements, one mesh instanced millions of times) fail fast with a SceneError naming the limit.
struct LoadLimits {
  size_t max_file_bytes = size_t(1) << 30;  // 1 GiB (also for text given to parse_collada)
  size_t max_triangles = 50'000'000;
  int max_node_depth = 128;
  size_t max_nodes = 1'000'000;
  // XML elements and attributes, counted in the raw text before the DOM is built (the DOM costs
  // ~50 bytes each; real scenes keep their bulk in a few number arrays and have far fewer).
  size_t max_markup = 4'000'000;
  // Numbers and indices read, counted again each time instancing reads an array again.
  size_t max_values = 400'000'000;
  int max_warnings = 20;  // printed per file; further ones are counted and summarised
};

// Loads a scene file; throws SceneError naming the file, element and line on any problem.
SceneDesc load_collada(const std::string& path, const LoadLimits& limits = {});
// Parses scene text held in memory; `name` is used in messages.
SceneDesc parse_collada(const std::string& text, const std::string& name, const LoadLimits& limits = {});

}  // namespace pt
