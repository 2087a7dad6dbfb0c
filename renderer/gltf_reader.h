// The glTF reader's internals, shared by its stages: gltf_json.cpp (the container and the JSON
// checked against the schema and our limits, before tinygltf sees it), gltf_tinygltf.cpp
// (tinygltf confined to the scene's folder, images decoded by OpenImageIO), gltf_scene.cpp (nodes,
// meshes, cameras, lights -> SceneDesc) and gltf_materials.cpp. Not part of the renderer's API.
#pragma once

// tinygltf without its stb image codecs (images go through OpenImageIO) and without its file
// system functions (ours read only inside the scene's folder): the same in every file that
// includes it, since these change its declarations.
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_FS
#include <tiny_gltf.h>

#include <cstdint>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "gltf.h"

namespace pt::gltf_detail {

// User text quoted in a message, cut short without splitting a UTF-8 character.
inline std::string clip(const std::string& s, size_t n = 60) {
  if (s.size() <= n) return s;
  while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xc0) == 0x80) --n;
  return s.substr(0, n) + "...";
}

// The file being read: its name for messages, the limits, where external files may come from,
// and the warnings printed so far (one line per kind of problem).
struct Context {
  std::string name;
  LoadLimits limits;
  std::string base_dir;  // empty: no external files
  bool binary = false;
  mutable std::set<std::string> warned;
  mutable int warnings = 0;
  mutable std::vector<std::string> lines;

  [[noreturn]] void fail(const std::string& path, const std::string& msg) const {
    throw SceneError(name + ": " + (path.empty() ? "/" : path) + ": " + msg);
  }
  // One line per `kind` (a mode, an extension, a feature): the first place it occurs is named.
  void warn(const std::string& kind, const std::string& path, const std::string& msg) const {
    if (!warned.insert(kind).second) return;
    if (++warnings > limits.max_warnings) return;
    lines.push_back(name + ": " + (path.empty() ? "/" : path) + ": " + msg);
    std::fprintf(stderr, "warning: %s\n", lines.back().c_str());
  }
  // The warnings, and a line counting those over the cap.
  std::vector<std::string> take_warnings() const {
    std::vector<std::string> out = std::move(lines);
    if (warnings > limits.max_warnings) {
      out.push_back(name + ": " + std::to_string(warnings - limits.max_warnings) + " more warnings not shown");
      std::fprintf(stderr, "warning: %s\n", out.back().c_str());
    }
    return out;
  }
};

// The parts of a file: the JSON text and, for a .glb, its BIN chunk (a view into the bytes).
struct Parts {
  std::string json;
  const uint8_t* bin = nullptr;
  size_t bin_size = 0;
};

// What the checks found that the later stages need.
struct Checked {
  std::vector<bool> decode_image;  // images a material reads (every texture but occlusion's)
};

// Splits a .glb into its JSON and BIN chunks (glTF 2.0, section 4.4), or takes the text as JSON.
Parts split_file(const Context& ctx, const std::string& bytes);
// Parses the JSON within the limits (values, nesting) and checks what tinygltf and the scene
// builder rely on: types, required properties, indices, byte ranges, data URIs, external file
// names, extensions, the node hierarchy (trees, no cycles). Throws SceneError with the JSON path.
Checked check_json(const Context& ctx, const Parts& parts);
// A percent-decoded relative URI naming a file inside the scene's folder, or "" when it is not one.
std::string local_file_name(const std::string& uri);

// Decoded textures, in image order; an image nobody reads stays empty.
struct Images {
  std::vector<TextureDesc> images;
  std::vector<bool> ok;
};
// tinygltf's model of the checked file, external files read only inside ctx.base_dir (their
// resolved paths added to `files_read`), the images materials read decoded (Images) within the
// texture limits.
tinygltf::Model run_tinygltf(const Context& ctx, const std::string& bytes, const Parts& parts, const Checked& checked,
                             Images& images, std::vector<std::string>& files_read);

// The scene's nodes, meshes, cameras and lights (gltf_scene.cpp), with materials made on demand.
SceneDesc build_scene(const Context& ctx, const tinygltf::Model& model, Images& images);

// Materials (gltf_materials.cpp): our material for glTF material `index` (-1: the default
// material), with per-hit vertex colours where the primitive has COLOR_0; textures it reads per
// hit are added to desc.textures (the material's TextureRefs say which TEXCOORD sets it reads).
class MaterialMaker {
 public:
  MaterialMaker(const Context& ctx, const tinygltf::Model& model, Images& images, SceneDesc& desc)
      : m_ctx(ctx), m_model(model), m_images(images), m_desc(desc) {}
  // Index into desc.materials; `path` is where the primitive names the material.
  int material(int index, bool vertex_color, const std::string& path);

 private:
  Material make(int index, bool vertex_color, const std::string& path);
  TextureRef texture_ref(const tinygltf::TextureInfo& info, bool srgb, const std::string& path);
  TextureRef texture_ref(int texture, int tex_coord, const tinygltf::ExtensionMap& ext, bool srgb, const std::string& path);
  // The texture info `key` of a material extension's object `ext` at `path`, or none.
  TextureRef extension_texture(const tinygltf::Value& ext, const char* key, bool srgb, const std::string& path);
  int texture_for(int texture, bool srgb, const std::string& path);
  const TextureDesc* image_of(int texture, const std::string& path);

  const Context& m_ctx;
  const tinygltf::Model& m_model;
  Images& m_images;
  SceneDesc& m_desc;
  std::vector<int> m_made[2];        // by glTF index + 1, with and without vertex colours
  std::vector<int> m_texture_of[2];  // desc texture by glTF texture index (data, colour), or -1
};

}  // namespace pt::gltf_detail
