// SceneDesc: what a scene file says, as plain validated data (world space, Y up).
#pragma once

#include <cstdint>
#include <string>
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
};

struct MeshDesc {
  std::string name;
  std::vector<Vec3> positions;     // world space
  std::vector<uint32_t> indices;   // three per triangle
  std::vector<int> tri_material;   // one material index per triangle
  std::vector<Vec3> normals;       // per-vertex shading normals; empty means flat shading
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
};

struct SceneDesc {
  std::string source;  // file the scene came from (for messages)
  std::vector<Material> materials;
  std::vector<MeshDesc> meshes;
  std::vector<SphereDesc> spheres;
  std::vector<LightDesc> lights;
  CameraDesc camera;

  size_t triangle_count() const;
  // Bounds of all meshes and spheres (lights excluded), as the course's camera framing uses.
  Bounds3 geometry_bounds() const;
};

// Computes area-weighted vertex normals (the course recomputes them this way); leaves
// `normals` empty when every vertex normal equals its faces' normal (flat shading suffices).
void compute_vertex_normals(MeshDesc& mesh);

}  // namespace pt
