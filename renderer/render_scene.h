// What a render reads of a scene: the view-independent SceneBase (BVH, lights, materials, the
// feature analysis; shared by every view of one file) and the RenderScene one set of options sees
// (camera, environment map, the features the path loop is specialised on). Built by render_scene.cpp.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "accel.h"
#include "camera.h"
#include "caustics.h"
#include "image.h"
#include "lights.h"
#include "options.h"
#include "scene.h"
#include "texture.h"

namespace pt {

// Feature bits the path loop is specialised on: a scene pays only for what it has.
enum FeatureBits : uint32_t {
  kFeatDelta = 1,        // mirror, glass or refraction materials
  kFeatMicrofacet = 2,   // microfacet materials
  kFeatInfinite = 4,     // ambient or environment lights (escaping rays look them up)
  kFeatTexture = 8,      // glTF materials (textures, vertex colours, the pbr BSDF): such scenes take the generic loop
  kFeatAll = 15,
};

struct SceneFeatures {
  std::vector<std::string> materials, lights;
  bool spheres = false, meshes = false, environment = false, thin_lens = false;
  bool adaptive = false, shading_normals = false;
  bool caustic_tracing = false;  // caustics by light tracing (caustics.h)
  bool textured = false;         // textured glTF materials (textures or vertex colours)
  size_t textures = 0;           // textures the materials read per hit
  uint32_t bits = kFeatAll;  // which specialised path loop runs
};

// The view-independent part of a render scene: built once per scene file and shared read-only by
// every view of it (the server keeps one per file content). It keeps no vertex arrays of the file:
// only the BVH and what a view needs (the file's camera and the geometry bounds).
struct SceneBase {
  std::vector<Material> materials;  // the file's, then one emission material per area-light panel
  std::vector<Light> lights;        // without the environment map (that is a render option)
  std::shared_ptr<const std::vector<TextureDesc>> textures;  // what textured materials read
  bool default_light = false;       // SceneDesc::default_light: a view may add the default light
  std::shared_ptr<const Accel> accel;
  SceneFeatures features;           // what the file contains; a view adds the options' features
  size_t triangle_count = 0, sphere_count = 0;
  CameraDesc camera;                // what make_camera reads of the file
  Bounds3 bounds;
  std::vector<CausticTarget> caustic_targets;  // bounds of the delta-material geometry
  bool emitters_share_a_plane = false;         // caustics.h: light paths check what a ray sees
  std::vector<Bounds3> object_bounds;  // each mesh, sphere and light panel, padded as Accel pads its bounds
  std::string source;

  // Bytes held for rendering: BVH and geometry (Accel::memory_bytes), lights, materials.
  size_t memory_bytes() const;
};

// The default light of a glTF scene without lights or emitters (SceneDesc::default_light): a
// uniform environment of this radiance plus a sun of this irradiance (W/m^2) shining from this
// direction (towards the sun: above, in front, a little to the side of the default view).
constexpr float kDefaultEnvironment = 0.5f, kDefaultSunIrradiance = 2.0f;
inline const Vec3 kDefaultSunDirection = normalize(Vec3(0.25f, 0.85f, 0.45f));

struct RenderScene {
  std::vector<Material> materials;
  std::vector<Light> lights;
  std::vector<int> infinite_lights;  // ambient / environment, looked up when rays escape
  int environment_light = -1;        // visible to camera rays
  std::shared_ptr<const EnvironmentMap> environment;
  std::shared_ptr<const std::vector<TextureDesc>> textures;  // shared with the SceneBase
  std::shared_ptr<const Accel> accel;  // shared with the SceneBase and its other views
  Camera camera;
  SceneFeatures features;
  size_t triangle_count = 0, sphere_count = 0;
  bool default_light = false;  // lit by the default environment and sun (no lights of its own)
  // What the caustic light tracer samples: delta geometry to aim at, area and mesh lights by power.
  std::vector<CausticTarget> caustic_targets;
  std::vector<Bounds3> object_bounds;  // from SceneBase: what the background mask projects
  std::vector<int> caustic_lights;
  Distribution1D caustic_light_distribution;
  bool emitters_share_a_plane = false;  // from SceneBase (caustics.h)
};

// A glTF material at a hit (Material::textured): its factors times its textures at the hit's
// texture coordinates and its vertex colour, and the shading normal `ns` bent by its normal map.
// Held per thread until the thread's next call. Out of line, so that the loops that may meet one
// stay as small as without textures.
const Material& textured_material(const RenderScene& scene, const Material& m, const SurfaceHit& hit, Vec3& ns);

// Whether a ray stops at a hit on an alpha-tested material (PbrParams::alpha_tested): MASK keeps
// alpha at or above the cutoff, BLEND keeps the hit with probability alpha (u uniform in [0, 1)).
// Alpha is baseColorFactor's x the base colour texture's x COLOR_0's (glTF 2.0, 3.9.4).
bool alpha_covers(const std::vector<TextureDesc>& textures, const PbrParams& p, const HitAttributes& at, float u);

// After the path vertex has built its shading frame (and turned it to the viewer: `flipped`), puts
// the coat normal that textured_material found for `m` into that frame (PbrParams::coat_normal).
// Nothing for other materials.
void localize_coat(const Material& m, const Frame& frame, bool flipped);

// The material a path sees at a hit: `m`, or textured_material for a textured one.
inline const Material& material_at(const RenderScene& scene, const Material& m, const SurfaceHit& hit, Vec3& ns) {
  return __builtin_expect(m.textured(), 0) ? textured_material(scene, m, hit, ns) : m;
}

// Builds what the integrator needs from the file's description: lights (area lights also as
// visible panels, emissive meshes as mesh lights), the environment map, the camera, the BVH.
// The same as make_view(make_scene_base(desc), params).
std::unique_ptr<RenderScene> make_render_scene(const SceneDesc& desc, const RenderParams& params);
// The expensive, options-independent part: lights, materials, the BVH, the feature analysis.
SceneBase make_scene_base(const SceneDesc& desc);
// One view of a shared base for a set of options: the camera, the environment map, the options'
// features. Cheap (copies materials and lights); the view shares the base's BVH. `environment`:
// the map params.env_map names, already loaded by an earlier view (the window's sessions share it).
std::unique_ptr<RenderScene> make_view(const SceneBase& base, const RenderParams& params,
                                       std::shared_ptr<const EnvironmentMap> environment = nullptr);
// The camera part of the render options (what make_render_scene passes to make_camera).
CameraParams camera_params(const RenderParams& params);

// Depth along the view axis of the first surface the pinhole ray through sensor point (sx, sy)
// (y up) meets, or infinity: what autofocus sets the focal distance to (the course sets the distance
// along the ray, which focuses an off-centre click too far; docs/cs184-compat.md).
float autofocus_distance(const RenderScene& scene, float sx, float sy);

}  // namespace pt
