// SceneDesc: what a scene file says, as plain validated data (world space, Y up).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "math.h"

namespace pt {

// Materials are a closed set; every switch over this enum lives in materials.cpp.
enum class MaterialType { diffuse, mirror, glass, refraction, microfacet, emission };
const char* material_type_name(MaterialType type);

struct Material {
  std::string name;
  MaterialType type = MaterialType::diffuse;
  Vec3 albedo{0.5f, 0.5f, 0.5f};  // diffuse colour, or mirror/glass reflectance
  Vec3 transmittance{1, 1, 1};    // glass / refraction
  float ior = 1.5f;               // glass / refraction
  float alpha = 0.5f;             // microfacet Beckmann roughness
  Vec3 eta{1, 1, 1}, k{0, 0, 0};  // microfacet conductor, per RGB channel
  Vec3 radiance{0, 0, 0};         // emission
  // Diffuse only: the albedo is multiplied at each hit by this texture at the hit's uv and, with
  // vertex_color, by the mesh's interpolated vertex colour (the meshes carry uvs / colors then).
  int texture = -1;
  bool vertex_color = false;
  bool textured() const { return texture >= 0 || vertex_color; }
};

// How texture coordinates outside [0, 1] wrap (glTF sampler wrapS / wrapT).
enum class TextureWrap { repeat, clamp, mirror };

// A colour texture as the file stores it: sRGB-encoded 8-bit RGB, the top row first; uv (0, 0) is
// the top-left corner of the image (glTF 2.0, section 3.8.4.2). Filtered bilinearly, or nearest.
struct TextureDesc {
  std::string name;
  int width = 0, height = 0;
  std::vector<uint8_t> texels;  // 3 bytes a texel
  TextureWrap wrap_s = TextureWrap::repeat, wrap_t = TextureWrap::repeat;
  bool nearest = false;
};

// Light kinds that come from <light> elements (emissive meshes are found from their material).
enum class LightType { area, point, directional, spot, ambient };
const char* light_type_name(LightType type);

struct LightDesc {
  std::string name;
  LightType type = LightType::point;
  Vec3 color{1, 1, 1};     // radiance (area, ambient), intensity (point, spot), irradiance (directional)
  Vec3 position{0, 0, 0};  // area centre, point and spot position
  Vec3 direction{0, 0, -1};  // area facing, spot axis; for directional: the direction light travels
  Vec3 dim_x{1, 0, 0}, dim_y{0, 1, 0};  // area rectangle edges (full lengths)
  float spot_angle_deg = 45;    // full cone angle (COLLADA falloff_angle)
  float spot_exponent = 0;      // COLLADA falloff_exponent: cos^e fall-off inside the cone
  // glTF: the full angle of the cone of full intensity; from it to spot_angle_deg the intensity
  // falls as KHR_lights_punctual recommends (squared, linear in the cosine). < 0: no such cone.
  float spot_inner_deg = -1;
};

// An area light's rectangle: its four corners in order around its edges, wound counter-clockwise
// seen from the side it faces (cross(v[1] - v[0], v[2] - v[0]) along `direction`). The visible
// panel, the light-plane scan (caustics.cpp) and the tests' meshed lights all take these.
inline void area_light_corners(const LightDesc& l, Vec3 v[4]) {
  const Vec3 c = l.position, hx = l.dim_x * 0.5f, hy = l.dim_y * 0.5f;
  v[0] = c - hx - hy, v[1] = c + hx - hy, v[2] = c + hx + hy, v[3] = c - hx + hy;
  if (dot(cross(l.dim_x, l.dim_y), l.direction) < 0) std::swap(v[1], v[3]);
}

struct MeshDesc {
  std::string name;
  std::vector<Vec3> positions;     // world space
  std::vector<uint32_t> indices;   // three per triangle
  std::vector<int> tri_material;   // one material index per triangle
  std::vector<Vec3> normals;       // per-vertex shading normals; empty means flat shading
  std::vector<Vec2> uvs;           // per-vertex texture coordinates, or empty
  std::vector<Vec3> colors;        // per-vertex linear RGB colours, or empty
};

struct SphereDesc {
  std::string name;
  Vec3 center;
  float radius = 1;
  int material = 0;
};

struct CameraDesc {
  bool present = false;
  float xfov_deg = 50, yfov_deg = 0;  // 0 means derived from the other one and the aspect ratio
  float aspect = 0;
  float znear = 0.001f, zfar = 1000;
  Mat4 world;  // camera-to-world, after the up-axis conversion
  // glTF: placed as authored whatever --file-camera says, keeping the vertical field of view (the
  // course's bounding-box framing is for COLLADA scenes).
  bool as_authored = false;
};

struct SceneDesc {
  std::string source;  // file the scene came from (for messages)
  // Other files the loader read (a .gltf's buffers and images), resolved: a checkpoint's
  // fingerprint covers them (checkpoint.h).
  std::vector<std::string> input_files;
  std::vector<Material> materials;
  std::vector<MeshDesc> meshes;
  std::vector<SphereDesc> spheres;
  std::vector<LightDesc> lights;
  std::vector<TextureDesc> textures;
  CameraDesc camera;
  // glTF: without lights and emitters the render adds a uniform white environment (as glTF viewers
  // light such a scene; the course renders it black); RenderParams::default_light turns it off.
  bool default_light = false;
  // What the loader ignored or defaulted, one line each ("file: where: what"), capped by
  // LoadLimits::max_warnings with a last line counting the rest. The loaders also print them to
  // stderr ("warning: ..."); the job service shows them with the scene and its jobs.
  std::vector<std::string> warnings;

  size_t triangle_count() const;
  // Bounds of all meshes and spheres (lights excluded), as the course's camera framing uses.
  Bounds3 geometry_bounds() const;
};

// Computes area-weighted vertex normals (the course recomputes them this way); leaves
// `normals` empty when every vertex normal equals its faces' normal (flat shading suffices).
void compute_vertex_normals(MeshDesc& mesh);

}  // namespace pt
