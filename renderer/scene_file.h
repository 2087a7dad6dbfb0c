// Scene files: the one entry point that reads a COLLADA (.dae) or glTF 2.0 (.gltf, .glb) scene
// into a SceneDesc, the limits every loader enforces, and the error they throw.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

#include "scene.h"

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

enum class SceneFormat { collada, gltf, glb };
const char* scene_format_name(SceneFormat format);

// The loader for a file: binary glTF by its magic "glTF"; else by the extension of `name` (.dae,
// .gltf, .glb); else by content ('{' starts JSON, anything else is read as COLLADA).
SceneFormat detect_scene_format(const std::string& bytes, const std::string& name);

// `name` with the extension of the format `bytes` are in (".dae", ".gltf", ".glb"): the file name
// messages give where a scene is known by name only (the job service).
std::string scene_file_name(const std::string& name, const std::string& bytes);
// The scene file extensions, in the order a name is looked up: ".dae", ".gltf", ".glb".
extern const char* const kSceneExtensions[3];

// Loads a scene file of any supported format. A .gltf may reference buffers and images in files
// of its own folder (never outside it).
SceneDesc load_scene(const std::string& path, const LoadLimits& limits = {});
// Parses a scene held in memory; `name` picks the format (with the content) and names the file in
// messages. `base_dir` is the folder external glTF files are read from; empty refuses them (a
// self-contained .glb or data: URIs only, as the job service needs).
SceneDesc parse_scene(const std::string& bytes, const std::string& name, const LoadLimits& limits = {},
                      const std::string& base_dir = "");
// A file's bytes, refusing one over limits.max_file_bytes before reading it.
std::string read_scene_bytes(const std::string& path, const LoadLimits& limits = {});

}  // namespace pt
