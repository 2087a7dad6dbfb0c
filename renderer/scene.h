// SceneDesc: what a scene file says, as plain validated data (world space, Y up).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "math.h"

namespace pt {

// Materials are a closed set; every switch over this enum lives in materials.cpp.
enum class MaterialType { diffuse, mirror, glass, refraction, microfacet, emission, pbr };
const char* material_type_name(MaterialType type);

// A texture a glTF material reads at a hit: which one, from which TEXCOORD set, through
// KHR_texture_transform's matrix.
struct TextureRef {
  int texture = -1;  // index into SceneDesc::textures; -1: none
  int set = 0;       // TEXCOORD_0 or TEXCOORD_1
  bool transformed = false;
  float m[6] = {1, 0, 0, 0, 1, 0};  // uv' = (m0 u + m1 v + m2, m3 u + m4 v + m5)
  bool used() const { return texture >= 0; }
};

// glTF alphaMode: opaque, cut out below a cutoff, or blended (rendered as stochastic
// pass-through: a ray passes a surface of alpha a with probability 1 - a).
enum class AlphaMode { opaque, mask, blend };

// glTF 2.0's metal-rough material with the extensions read (docs/gltf.md): the factors, and the
// textures that multiply them at each hit (material_at). Plain data: a hit's copy is cheap.
struct PbrParams {
  Vec3 base{1, 1, 1};  // base colour (linear), x COLOR_0 where vertex_color
  float metallic = 1, roughness = 1;
  float ior = 1.5f;                        // KHR_materials_ior
  float specular = 1;                      // KHR_materials_specular: F0 and F90 scale
  Vec3 specular_color{1, 1, 1};            // KHR_materials_specular: F0 tint
  float transmission = 0;                  // KHR_materials_transmission
  Vec3 emissive{0, 0, 0};                  // emissiveFactor x KHR_materials_emissive_strength
  float normal_scale = 1;
  float clearcoat = 0, clearcoat_roughness = 0;  // KHR_materials_clearcoat
  float clearcoat_normal_scale = 1;
  // The coat's normal in the shading frame of the hit (path_vertex.h sets it from the coat's normal
  // map, or from the unbent normal under a base normal map); zero: the shading normal.
  Vec3 coat_normal{0, 0, 0};
  Vec3 sheen_color{0, 0, 0};                     // KHR_materials_sheen
  float sheen_roughness = 0;
  Vec3 attenuation{0, 0, 0};  // KHR_materials_volume: absorption per unit length inside the mesh
  bool unlit = false;         // KHR_materials_unlit: `emissive` holds the base colour, seen by camera rays
  bool vertex_color = false;               // the mesh's COLOR_0 multiplies the base colour
  bool double_sided = false;               // doubleSided: emission leaves both faces
  AlphaMode alpha_mode = AlphaMode::opaque;
  float alpha = 1;                         // baseColorFactor's alpha (x the texture's x COLOR_0's)
  float alpha_cutoff = 0.5f;               // MASK: alpha below it is cut out
  TextureRef base_tex, metal_rough_tex, emissive_tex, normal_tex, transmission_tex;
  TextureRef specular_tex, specular_color_tex, clearcoat_tex, clearcoat_roughness_tex, clearcoat_normal_tex,
      sheen_color_tex, sheen_roughness_tex;
  // Every texture slot, for what looks at them all (the loader's uv sets, the mesh checks).
  std::array<const TextureRef*, 12> texture_refs() const {
    return {&base_tex,     &metal_rough_tex,    &emissive_tex,  &normal_tex,
            &transmission_tex, &specular_tex,   &specular_color_tex, &clearcoat_tex,
            &clearcoat_roughness_tex, &clearcoat_normal_tex, &sheen_color_tex, &sheen_roughness_tex};
  }
  std::array<TextureRef*, 12> texture_refs() {
    const auto c = const_cast<const PbrParams*>(this)->texture_refs();
    std::array<TextureRef*, 12> out;
    for (size_t i = 0; i < c.size(); ++i) out[i] = const_cast<TextureRef*>(c[i]);
    return out;
  }
  // Emission that light sampling cannot know: textured, cut out by alpha, or seen by camera rays
  // only (unlit). Such emitters are found by the rays that hit them, never registered as lights.
  bool emission_found_by_hits() const { return emissive_tex.used() || alpha_tested() || unlit; }
  // The texture whose tangent frame the mesh must carry (a normal map's), or nullptr.
  const TextureRef* tangent_space_tex() const {
    return normal_tex.used() ? &normal_tex : clearcoat_normal_tex.used() ? &clearcoat_normal_tex : nullptr;
  }
  bool alpha_tested() const { return alpha_mode != AlphaMode::opaque; }
  bool textured() const {
    bool any = vertex_color || alpha_tested();
    for (const TextureRef* r : texture_refs()) any |= r->used();
    return any;
  }
};

struct Material {
  std::string name;
  MaterialType type = MaterialType::diffuse;
  Vec3 albedo{0.5f, 0.5f, 0.5f};  // diffuse colour, or mirror/glass reflectance
  bool schlick = false;           // mirror: albedo is F0 of Schlick's Fresnel (glTF's smooth metals)
  Vec3 transmittance{1, 1, 1};    // glass / refraction
  float ior = 1.5f;               // glass / refraction
  float alpha = 0.5f;             // microfacet Beckmann roughness
  Vec3 eta{1, 1, 1}, k{0, 0, 0};  // microfacet conductor, per RGB channel
  Vec3 radiance{0, 0, 0};         // emission
  PbrParams pbr;                  // pbr (glTF)
  // Read per hit (material_at): the pbr material's textures and vertex colours.
  bool textured() const { return type == MaterialType::pbr && pbr.textured(); }
};

// How texture coordinates outside [0, 1] wrap (glTF sampler wrapS / wrapT).
enum class TextureWrap { repeat, clamp, mirror };

// A texture as the file stores it: 8-bit RGB, the top row first; uv (0, 0) is the top-left corner
// of the image (glTF 2.0, section 3.8.4.2). Filtered bilinearly, or nearest. Colours are
// sRGB-encoded; data (metal / roughness, normals) is linear.
struct TextureDesc {
  std::string name;
  int width = 0, height = 0;
  std::vector<uint8_t> texels;  // 3 bytes a texel
  std::vector<uint8_t> alpha;   // 1 byte a texel (linear), or empty: opaque
  bool srgb = true;
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
  // glTF: the full angle of the inner cone; the edge softens over a band that grows as it narrows
  // (Blender's spot_blend = 1 - inner / outer, render_scene.cpp). < 0: no such cone.
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
  std::vector<Vec2> uvs;           // per-vertex texture coordinates (TEXCOORD_0), or empty
  std::vector<Vec2> uvs1;          // TEXCOORD_1, or empty
  std::vector<Vec3> colors;        // per-vertex linear RGB colours, or empty
  std::vector<float> color_alpha;  // COLOR_0's alpha per vertex, or empty (opaque; read for alpha-tested materials)
  // Per-vertex tangents for normal maps (xyz, w = the bitangent's sign), world space, or empty.
  std::vector<std::array<float, 4>> tangents;
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
  // glTF without a camera: a three-quarter view that fits the bounds (make_camera), not the
  // course's framing down -Z.
  bool overview = false;
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
  // glTF: without lights and emitters the render adds a white environment and a sun (as glTF
  // viewers light such a scene; the course renders it black); RenderParams::default_light turns
  // it off.
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

// Per-vertex tangents from texture coordinate set `set` (0: uvs, 1: uvs1), for normal maps: each
// vertex's dP/du made orthogonal to its normal, and the handedness glTF's bitangent takes
// (MikkTSpace's per-vertex result for smooth meshes; vertices shared by faces of unrelated uv
// directions get their average). A vertex without uv area keeps a zero tangent (no bend).
void compute_tangents(MeshDesc& mesh, int set);

}  // namespace pt
