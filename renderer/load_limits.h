// What every scene loader shares: the limits it enforces on a file and the error it throws. The
// loaders (collada.h, gltf.h) and their entry point (scene_file.h) include this, not each other.
#pragma once

#include <cstddef>
#include <stdexcept>

namespace pt {

// A load or build failure that names the file and where in it: the element and line (COLLADA) or
// the JSON path (glTF, "scene.gltf: /meshes/3/primitives/0/indices: ...").
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Bounds on what a scene may make the loader do: hostile files (huge, deeply nested, millions of
// tiny elements, one mesh instanced millions of times) fail fast with a SceneError naming the limit.
struct LoadLimits {
  size_t max_file_bytes = size_t(1) << 30;  // 1 GiB (also for text given to parse_scene)
  size_t max_triangles = 50'000'000;
  int max_node_depth = 128;
  size_t max_nodes = 1'000'000;  // node instances visited (a glTF node reached twice counts twice)
  // XML elements and attributes, counted in the raw text before the DOM is built (the DOM costs
  // ~50 bytes each; real scenes keep their bulk in a few number arrays and have far fewer).
  size_t max_markup = 4'000'000;
  // Numbers and indices read, counted again each time instancing reads an array again.
  size_t max_values = 400'000'000;
  int max_warnings = 20;  // printed per file; further ones are counted and summarised
  // glTF: JSON values (objects, arrays, numbers, strings) and their nesting, counted while the
  // text parses (a parsed value costs ~16-80 bytes; real files keep their bulk in buffers).
  size_t max_json_values = 4'000'000;
  int max_json_depth = 64;
  // glTF textures: pixels of one image, and the bytes all decoded textures take (3 a pixel).
  size_t max_texture_pixels = size_t(1) << 26;  // 8192 x 8192
  size_t max_texture_bytes = size_t(1) << 30;
};

}  // namespace pt
