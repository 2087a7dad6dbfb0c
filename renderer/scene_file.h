// Scene files: the one entry point that reads a COLLADA (.dae) or glTF 2.0 (.gltf, .glb) scene
// into a SceneDesc (the limits every loader enforces and the error they throw: load_limits.h).
#pragma once

#include <string>

#include "load_limits.h"
#include "scene.h"

namespace pt {

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
