// What the scene fuzz targets (fuzz_collada, fuzz_gltf) share: load limits small enough that each
// input stays fast, and the steps after a successful load (the render scene with tiny render
// parameters, one autofocus ray and the central ray's hit shaded; never a render).
#pragma once

#include <cmath>
#include <memory>
#include <stdexcept>

#include "materials.h"
#include "scene_file.h"
#include "session.h"

namespace fuzz {

// Smaller than the defaults so each input stays fast; the limit checks themselves are exercised.
inline const pt::LoadLimits& scene_limits() {
  static const pt::LoadLimits limits = [] {
    pt::LoadLimits l;
    l.max_file_bytes = size_t(4) << 20;
    l.max_triangles = 200'000;
    l.max_nodes = 20'000;
    l.max_markup = 200'000;
    l.max_values = 2'000'000;
    l.max_json_values = 200'000;
    l.max_texture_pixels = 1 << 20;
    l.max_texture_bytes = size_t(16) << 20;
    return l;
  }();
  return limits;
}

// Builds the loaded scene and casts one autofocus ray. `variant` picks the camera placement and
// the default light, so both sides of each are covered.
inline int build_and_probe(const pt::SceneDesc& desc, size_t variant) {
  pt::RenderParams params;
  params.width = 8;
  params.height = 6;
  params.spp = 1;
  params.threads = 1;
  params.file_camera = variant % 2 == 1;
  params.default_light = variant % 4 < 2;
  std::unique_ptr<pt::RenderScene> scene;
  try {
    scene = pt::make_render_scene(desc, params);
  } catch (const std::runtime_error&) {
    return 0;  // a build failure (Embree) is reported, not a crash
  }
  pt::autofocus_distance(*scene, 0.5f, 0.5f);
  // The central camera ray's hit shaded as a path would: textures, normal map, the BSDF.
  const pt::Ray r = scene->camera.pinhole_ray(0.5f, 0.5f);
  pt::SurfaceHit hit;
  if (scene->accel->intersect(r, hit)) {
    pt::Vec3 ns = hit.ns;
    const pt::Material& m = pt::material_at(*scene, scene->materials[size_t(hit.material)], hit, ns);
    const pt::Frame frame(ns);
    const pt::Vec3 wo = frame.to_local(-r.d);
    pt::BsdfSample s;
    if (pt::sample_bsdf(m, wo, 0.3f, pt::Vec2{0.4f, 0.6f}, s)) {
      const pt::Vec3 f = pt::eval_bsdf(m, wo, s.wi);
      if (!pt::is_finite(f) || !std::isfinite(pt::bsdf_pdf(m, wo, s.wi)) || !pt::is_finite(s.weight))
        throw std::logic_error("a non-finite BSDF value");
    }
  }
  return 0;
}

}  // namespace fuzz
