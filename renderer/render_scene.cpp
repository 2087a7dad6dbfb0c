// Render scene construction: the parameters' checks, the scene base built once per scene file
// (materials, lights, Embree's BVH, feature bits, object bounds for the background mask) and the
// per-render views of it (camera framing, environment map, caustic lights).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <stdexcept>

#include "materials.h"
#include "options.h"
#include "render_scene.h"

namespace pt {

namespace {

// What a textured material reads that the mesh lacks, or nullptr.
const char* unreadable_textures(const PbrParams& p, const MeshDesc& mesh, size_t textures) {
  const size_t nv = mesh.positions.size();
  for (const TextureRef* r : p.texture_refs()) {
    if (!r->used()) continue;
    if (size_t(r->texture) >= textures) return "its texture";
    if ((r->set == 0 ? mesh.uvs : mesh.uvs1).size() != nv) return "texture coordinates";
  }
  if (p.tangent_space_tex() && mesh.tangents.size() != nv) return "tangents";
  if (p.vertex_color && mesh.colors.size() != nv) return "vertex colours";
  return nullptr;
}

}  // namespace

void RenderParams::validate() const {
  auto bad = [](const std::string& field, const std::string& why) { throw std::invalid_argument(field + ": " + why); };
  // Every option's range from the one table (options.h); RunLimits are the driver's to check.
  for (const RenderOption& o : render_options()) {
    if (o.type == OptionType::boolean || std::string(o.name) == "time_limit" || std::string(o.name) == "target_error")
      continue;
    double v = o.get(*this, RunLimits());
    if (!std::isfinite(v) || v < o.min || v > o.max)
      bad(std::string(o.name) + " (" + o.flag + ")",
          "must be " + std::string(o.type == OptionType::integer ? "between " : "finite and between ") +
              option_text(o, o.min) + " and " + option_text(o, o.max));
  }
  if (threads < 1 || threads > 1024) bad("threads (-t)", "must be between 1 and 1024");
  if (keep_fov && frame_scene) bad("frame_scene (--frame-scene)", "and keep_fov (--keep-fov) are two framings: choose one");
  if (cell_w != 0 || cell_h != 0) {
    if (cell_w < 1 || cell_h < 1 || cell_x < 0 || cell_y < 0 || cell_x + cell_w > width || cell_y + cell_h > height)
      bad("cell (-p)", "x y dx dy must lie inside the " + std::to_string(width) + "x" + std::to_string(height) + " frame");
  }
  if (camera.set) {
    const std::string why = pose_error(camera);
    if (!why.empty()) bad("camera." + why.substr(0, why.find(':')) + " (--camera)", why.substr(why.find(':') + 2));
  }
}

CameraParams camera_params(const RenderParams& params) {
  CameraParams cp;
  cp.width = params.width;
  cp.height = params.height;
  cp.lens_radius = params.lens_radius;
  cp.focal_distance = params.focal_distance;
  cp.file_camera = params.file_camera;
  cp.keep_fov = params.keep_fov;
  cp.frame_scene = params.frame_scene;
  cp.settings_file = params.camera_file;
  cp.pose = params.camera;
  return cp;
}

SceneBase make_scene_base(const SceneDesc& desc) {
  SceneBase base;
  base.materials = desc.materials;
  std::vector<EmitterPanel> panels;
  std::set<std::string> light_kinds;

  for (const LightDesc& ld : desc.lights) {
    Light l;
    l.name = ld.name;
    l.color = ld.color;
    if (is_black(ld.color)) {
      std::fprintf(stderr, "warning: %s: light '%s' has zero colour and is left out\n", desc.source.c_str(), ld.name.c_str());
      continue;
    }
    switch (ld.type) {
      case LightType::area: {
        l.kind = LightKind::rect;
        l.position = ld.position;
        l.direction = ld.direction;
        l.dim_x = ld.dim_x;
        l.dim_y = ld.dim_y;
        l.area = length(cross(ld.dim_x, ld.dim_y));
        if (!(l.area > 0) || !std::isfinite(l.area)) {
          std::fprintf(stderr, "warning: %s: area light '%s' has zero area and is left out\n", desc.source.c_str(), ld.name.c_str());
          continue;
        }
        // The panel is visible to rays and emits on the side it faces.
        EmitterPanel p;
        area_light_corners(ld, p.v);
        Material em;
        em.name = ld.name + " (panel)";
        em.type = MaterialType::emission;
        em.radiance = ld.color;
        p.material = int(base.materials.size());
        base.materials.push_back(em);
        p.light = int(base.lights.size());
        panels.push_back(p);
        break;
      }
      case LightType::point: l.kind = LightKind::point; l.position = ld.position; break;
      case LightType::spot:
        l.kind = LightKind::spot;
        l.position = ld.position;
        l.direction = ld.direction;
        l.cos_cutoff = std::cos(std::min(ld.spot_angle_deg, 360.0f) * 0.5f * kPi / 180);
        l.exponent = ld.spot_exponent;
        // Blender's importer: spot_blend = 1 - inner / outer, and Cycles' band (1 - cos outer) x blend.
        if (ld.spot_inner_deg >= 0 && ld.spot_angle_deg > 0)
          l.spot_smooth = (1 - l.cos_cutoff) * clampf(1 - ld.spot_inner_deg / ld.spot_angle_deg, 0, 1);
        break;
      case LightType::directional: l.kind = LightKind::directional; l.direction = ld.direction; break;
      case LightType::ambient: l.kind = LightKind::ambient; break;
    }
    light_kinds.insert(light_kind_name(l.kind));
    base.lights.push_back(std::move(l));
  }

  // Emissive mesh triangles become one mesh light per (mesh, material), sampled by area.
  std::vector<std::vector<int>> mesh_light(desc.meshes.size());
  bool emitters = false;  // an emitter lights the scene even where it is no light (a textured one)
  for (size_t mi = 0; mi < desc.meshes.size(); ++mi) {
    const MeshDesc& mesh = desc.meshes[mi];
    std::map<int, int> light_of_material;
    for (size_t t = 0; t < mesh.tri_material.size(); ++t) {
      int mat = mesh.tri_material[t];
      if (!is_emissive(base.materials[mat])) continue;
      emitters = true;
      // A textured emitter is no light: hits find its radiance, light sampling could not.
      // So is one with alpha (rays may pass what light sampling finds) and an unlit one.
      if (base.materials[mat].type == MaterialType::pbr && base.materials[mat].pbr.emission_found_by_hits()) continue;
      const uint32_t* vi = &mesh.indices[3 * t];
      if (!(length(cross(mesh.positions[vi[1]] - mesh.positions[vi[0]], mesh.positions[vi[2]] - mesh.positions[vi[0]])) > 0))
        continue;  // a zero-area triangle cannot emit
      auto it = light_of_material.find(mat);
      if (it == light_of_material.end()) {
        Light l;
        l.kind = LightKind::mesh;
        l.name = mesh.name;
        l.color = emitted_radiance(base.materials[mat], Vec3(0, 0, 1));  // what the front sends
        l.two_sided = base.materials[mat].type == MaterialType::pbr && base.materials[mat].pbr.double_sided;
        it = light_of_material.emplace(mat, int(base.lights.size())).first;
        base.lights.push_back(std::move(l));
      }
      Light& l = base.lights[it->second];
      for (int k = 0; k < 3; ++k) l.triangles.push_back(mesh.positions[mesh.indices[3 * t + k]]);
      if (mesh_light[mi].empty()) mesh_light[mi].assign(mesh.tri_material.size(), -1);
      mesh_light[mi][t] = it->second;
    }
  }
  for (Light& l : base.lights) {
    if (l.kind != LightKind::mesh) continue;
    std::vector<float> areas(l.triangles.size() / 3);
    double total = 0;
    for (size_t t = 0; t < areas.size(); ++t) {
      const Vec3* v = &l.triangles[3 * t];
      const Vec3 c = cross(v[1] - v[0], v[2] - v[0]);
      areas[t] = 0.5f * length(c);
      l.triangle_normals.push_back(normalize(c));
      total += areas[t];
    }
    l.area = float(total);
    l.triangle_distribution = Distribution1D(areas);
    light_kinds.insert("mesh");
  }

  SceneFeatures& f = base.features;
  std::set<std::string> mats;
  for (const MeshDesc& m : desc.meshes)
    for (int t : m.tri_material) mats.insert(material_type_name(base.materials[t].type));
  for (const SphereDesc& s : desc.spheres) mats.insert(material_type_name(base.materials[s.material].type));
  if (!panels.empty()) mats.insert("emission");
  f.materials.assign(mats.begin(), mats.end());
  f.lights.assign(light_kinds.begin(), light_kinds.end());
  f.spheres = !desc.spheres.empty();
  f.meshes = !desc.meshes.empty();
  for (const MeshDesc& m : desc.meshes) f.shading_normals |= !m.normals.empty();
  f.bits = 0;
  bool pbr = false;
  for (const Material& m : base.materials) {
    if (is_delta(m)) f.bits |= kFeatDelta;
    if (m.type == MaterialType::microfacet) f.bits |= kFeatMicrofacet;
    pbr |= m.type == MaterialType::pbr;
  }
  for (const Light& l : base.lights)
    if (l.kind == LightKind::ambient) f.bits |= kFeatInfinite;
  // Textured materials, on meshes that carry what they read (the loaders guarantee it).
  for (size_t mi = 0; mi < desc.meshes.size(); ++mi) {
    const MeshDesc& mesh = desc.meshes[mi];
    int last = -1;  // a mesh's triangles share few materials: each is checked once per run
    for (int t : mesh.tri_material) {
      if (t == last) continue;
      last = t;
      const Material& m = base.materials[size_t(t)];
      if (!m.textured()) continue;
      if (const char* why = unreadable_textures(m.pbr, mesh, desc.textures.size()))
        throw std::runtime_error(desc.source + ": material '" + m.name + "' is textured but mesh '" + mesh.name +
                                 "' cannot give it " + why);
      f.textured = true;
    }
  }
  for (const SphereDesc& s : desc.spheres)
    if (base.materials[size_t(s.material)].textured())
      throw std::runtime_error(desc.source + ": sphere '" + s.name + "' has a textured material");
  if (f.textured) {
    base.textures = std::make_shared<const std::vector<TextureDesc>>(desc.textures);
    f.textures = desc.textures.size();
  }
  CoverageTest coverage;  // alpha-tested glTF materials: their textures and factors decide each hit
  if (base.textures)
    coverage = [textures = base.textures, materials = base.materials](int m, const HitAttributes& at, float u) {
      return alpha_covers(*textures, materials[size_t(m)].pbr, at, u);
    };
  base.accel = std::make_shared<const Accel>(desc, panels, mesh_light, std::move(coverage));
  if (pbr || f.textured) f.bits = kFeatAll;  // glTF materials take the generic loop (path_tracer_for)
  base.default_light = desc.default_light && !emitters;
  base.triangle_count = desc.triangle_count();
  base.sphere_count = desc.spheres.size();
  base.camera = desc.camera;
  base.bounds = desc.geometry_bounds();
  base.caustic_targets = find_caustic_targets(desc, base.materials);
  // Only light paths read it, and they need something to aim at: other scenes skip the scan.
  base.emitters_share_a_plane = !base.caustic_targets.empty() && emitters_share_a_plane(desc, base.materials);
  // Each object's box, padded as Accel pads the scene's (relative to the largest coordinate).
  for (const MeshDesc& m : desc.meshes) {
    Bounds3 b;
    for (Vec3 p : m.positions) b.expand(p);
    if (!b.empty()) base.object_bounds.push_back(b);
  }
  for (const SphereDesc& s : desc.spheres) {
    Vec3 r(s.radius, s.radius, s.radius);
    base.object_bounds.push_back({s.center - r, s.center + r});
  }
  for (const EmitterPanel& p : panels) {
    Bounds3 b;
    for (Vec3 v : p.v) b.expand(v);
    base.object_bounds.push_back(b);
  }
  float size = 0;
  for (const Bounds3& b : base.object_bounds)
    size = std::max({size, max_component(abs(b.lo)), max_component(abs(b.hi)), max_component(b.hi - b.lo)});
  const float pad = 1e-3f * size + 1e-6f;
  for (Bounds3& b : base.object_bounds) b.lo = b.lo - Vec3(pad, pad, pad), b.hi = b.hi + Vec3(pad, pad, pad);
  base.source = desc.source;
  return base;
}

size_t SceneBase::memory_bytes() const {
  size_t bytes = accel ? accel->memory_bytes() : 0;
  bytes += materials.capacity() * sizeof(Material) + lights.capacity() * sizeof(Light);
  bytes += object_bounds.capacity() * sizeof(Bounds3) + caustic_targets.capacity() * sizeof(CausticTarget);
  if (textures)
    for (const TextureDesc& t : *textures) bytes += t.texels.capacity();
  for (const Light& l : lights)  // mesh lights: corners, normals, and the area distribution (float + double cdf)
    bytes += (l.triangles.capacity() + l.triangle_normals.capacity()) * sizeof(Vec3) + l.triangle_distribution.size() * (sizeof(float) + sizeof(double));
  return bytes;
}

namespace {

// A view from a base taken by value: make_render_scene moves its fresh base in, make_view copies.
std::unique_ptr<RenderScene> view_of(SceneBase base, const RenderParams& params,
                                     std::shared_ptr<const EnvironmentMap> environment) {
  auto rs = std::make_unique<RenderScene>();
  rs->materials = std::move(base.materials);
  rs->lights = std::move(base.lights);
  rs->accel = std::move(base.accel);
  rs->textures = std::move(base.textures);
  rs->triangle_count = base.triangle_count;
  rs->sphere_count = base.sphere_count;
  SceneFeatures& f = rs->features;
  f = std::move(base.features);
  if (!params.env_map.empty()) {
    std::shared_ptr<const EnvironmentMap> map = std::move(environment);
    if (!map) {
      ImageRGB env = read_image(params.env_map);
      map = std::make_shared<const EnvironmentMap>(env.width, env.height, std::move(env.pixels));
    }
    Light l;
    l.kind = LightKind::environment;
    l.name = params.env_map;
    l.env = map.get();
    rs->environment = std::move(map);
    rs->environment_light = int(rs->lights.size());
    rs->lights.push_back(std::move(l));
    std::set<std::string> kinds(f.lights.begin(), f.lights.end());
    kinds.insert("environment");
    f.lights.assign(kinds.begin(), kinds.end());
  }
  if (base.default_light && params.default_light && rs->lights.empty()) {
    // As a glTF viewer lights an unlit scene: white from every direction (unseen by camera rays)
    // and a sun from above, so that shapes shade (render_scene.h, kDefault*).
    std::fprintf(stderr, "warning: %s: no lights and no emissive surfaces: lit by a white environment and a sun "
                 "(--no-default-light: none)\n", base.source.c_str());
    Light env;
    env.kind = LightKind::ambient;
    rs->default_light = true;
    env.name = "default environment";
    env.color = Vec3(kDefaultEnvironment);
    env.sphere = true;
    rs->lights.push_back(std::move(env));
    Light sun;
    sun.kind = LightKind::directional;
    sun.name = "default sun";
    sun.color = Vec3(kDefaultSunIrradiance);
    sun.direction = -kDefaultSunDirection;
    rs->lights.push_back(std::move(sun));
    std::set<std::string> kinds(f.lights.begin(), f.lights.end());
    kinds.insert("ambient");
    kinds.insert("directional");
    f.lights.assign(kinds.begin(), kinds.end());
  }
  for (size_t i = 0; i < rs->lights.size(); ++i)
    if (rs->lights[i].kind == LightKind::ambient || rs->lights[i].kind == LightKind::environment)
      rs->infinite_lights.push_back(int(i));
  rs->camera = make_camera(base.camera, base.bounds, camera_params(params));
  rs->caustic_targets = std::move(base.caustic_targets);
  rs->emitters_share_a_plane = base.emitters_share_a_plane;
  rs->object_bounds = std::move(base.object_bounds);
  std::vector<float> power;
  for (size_t i = 0; i < rs->lights.size(); ++i) {
    const Light& l = rs->lights[i];
    if (l.kind != LightKind::rect && l.kind != LightKind::mesh) continue;
    rs->caustic_lights.push_back(int(i));
    power.push_back(luminance(l.color) * l.area);
  }
  if (!power.empty()) rs->caustic_light_distribution = Distribution1D(power);

  f.environment = rs->environment != nullptr;
  f.thin_lens = params.lens_radius > 0;
  f.adaptive = params.adaptive && params.spp > params.adaptive_batch;
  f.caustic_tracing = caustic_tracing_applies(*rs, params);
  if (!rs->infinite_lights.empty()) f.bits |= kFeatInfinite;
  return rs;
}

}  // namespace

std::unique_ptr<RenderScene> make_view(const SceneBase& base, const RenderParams& params,
                                       std::shared_ptr<const EnvironmentMap> environment) {
  params.validate();
  return view_of(base, params, std::move(environment));
}

std::unique_ptr<RenderScene> make_render_scene(const SceneDesc& desc, const RenderParams& params) {
  params.validate();  // before the build: a bad option fails fast
  return view_of(make_scene_base(desc), params, nullptr);
}

float autofocus_distance(const RenderScene& scene, float sx, float sy) {
  Ray r = scene.camera.pinhole_ray(sx, sy);
  SurfaceHit hit;
  if (!scene.accel->intersect(r, hit, true)) return kInf;  // what the camera sees, unlit surfaces too
  // The thin lens focuses on a plane at a depth along the view axis, not at a distance along the
  // ray: an off-centre hit's distance would put the plane behind it by 1 / cos of the ray's angle.
  const float depth = dot(hit.p - r.o, -scene.camera.back);
  return depth > 0 ? depth : kInf;
}

}  // namespace pt
