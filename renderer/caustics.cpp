// Caustic light paths (see caustics.h for the split with the path tracer).
#include "caustics.h"

#include <algorithm>
#include <cmath>

#include "accel.h"
#include "lane_math.h"
#include "loop_forms.h"
#include "materials.h"
#include "path_settings.h"
#include "render_scene.h"
#include "sampler.h"

namespace pt {

namespace {

// Light paths use the sample streams of pixels no film has (the Sobol index is 32 bits; the
// high bits of the path index pick the pseudo-pixel).
constexpr uint64_t kLightPathPixel = 0xC0FFEE0000000000ull;

// Uniform sampling of the cone of directions from p that can reach a sphere (PBRT 3rd ed.,
// 13.6.4 "Sampling a cone"); a point inside the sphere sees the whole sphere of directions.
// Plain floats, no default values: a light path's start keeps an array of kMaxCausticTargets
// of them, and initialising all of it cost more than the rest of the start (callgrind, CBspheres).
struct Cone {
  float ax, ay, az;
  float cos_max;  // -1: every direction
  float solid_angle;
  Vec3 axis() const { return {ax, ay, az}; }
  void set_axis(Vec3 a) { ax = a.x, ay = a.y, az = a.z; }
};

Cone cone_towards(Vec3 p, const CausticTarget& t) {
  Cone c;
  Vec3 d = t.center - p;
  float dist2 = length_squared(d);
  if (!(dist2 > t.radius * t.radius)) {
    c.set_axis(Vec3(0, 0, 1));
    c.cos_max = -1;
    c.solid_angle = 4 * kPi;
    return c;
  }
  float dist = std::sqrt(dist2);
  c.set_axis(d / dist);
  float sin2 = t.radius * t.radius / dist2;
  c.cos_max = std::sqrt(std::max(0.0f, 1 - sin2));
  // 1 - cos_max without cancellation for far, small targets.
  float one_minus = sin2 / (1 + c.cos_max);
  c.solid_angle = 2 * kPi * one_minus;
  return c;
}

Vec3 sample_cone(const Cone& c, Vec2 u) {
  if (c.cos_max <= -1) return sample_uniform_sphere(u);
  float cos_t = 1 - u.x * (1 - c.cos_max);
  float sin_t = std::sqrt(std::max(0.0f, 1 - cos_t * cos_t));
  float phi = 2 * kPi * u.y;
  Frame f(c.axis());
  return f.to_world(Vec3(std::cos(phi) * sin_t, std::sin(phi) * sin_t, cos_t));
}

// Connects a non-delta vertex of the path to the camera (the pinhole, or the thin lens at the
// point u_lens picks) and splats what the camera sees there. Light arrives along `arriving`
// (pointing into the surface) with flux weight `beta`.
bool prepare_splat(const RenderScene& scene, const CausticFilm& film, const SurfaceHit& hit, const Material& m,
                   Vec3 arriving, Vec3 beta, Vec2 u_lens, Ray& shadow, CausticSplat& splat) {
  const Camera& cam = scene.camera;
  float sx, sy;
  Vec3 eye;
  if (!cam.sensor_point(hit.p, u_lens, sx, sy, eye)) return false;
  if (!(sx >= 0 && sx < 1 && sy >= 0 && sy < 1)) return false;
  Vec3 v = hit.p - eye;
  float dist2 = length_squared(v), dist = std::sqrt(dist2);
  float z = -dot(v, cam.back);
  if (!(dist > 0) || dist < cam.tmin || dist > cam.tmax) return false;
  int fx = std::min(int(sx * film.frame_w), film.frame_w - 1);
  int fy_up = std::min(int(sy * film.frame_h), film.frame_h - 1);
  int x = fx - film.x0, y = (film.frame_h - 1 - fy_up) - film.y0;
  if (x < 0 || y < 0 || x >= film.w || y >= film.h) return false;

  // The path tracer's shading frame at its first vertex: opaque, normals turned to the viewer.
  Vec3 wo_world = -v / dist, wi_world = -arriving;
  Vec3 ng = hit.ng, ns = hit.ns;
  face_viewer(wo_world, false, ng, ns);
  float cos_wi_g = dot(wi_world, ng), cos_wo_g = dot(wo_world, ng);
  if (cos_wi_g <= 0 || cos_wo_g <= 0) return false;  // the path tracer bounces on the viewer's side only
  Frame frame(ns);
  Vec3 wi = frame.to_local(wi_world);
  Vec3 f = eval_bsdf(m, frame.to_local(wo_world), wi);
  if (is_black(f)) return false;
  spawn_ray_to(hit, eye, shadow);  // the splat counts if nothing blocks it

  // Pixel value = W H / (4 tan_w tan_h) x the integral over visible area of L cos_x / (r^2 cos^3);
  // the flux estimate carries cos at the surface w.r.t. the true normal, the path tracer's
  // L_o uses the shading cosine |wi.z| (Veach 1997, 5.3, adjoint shading normals). A thin lens
  // has the same Jacobian from each lens point (the focus plane at f maps the sensor scaled by
  // f), and the lens point is drawn as the path tracer draws it, uniformly: no extra factor.
  float cos_cam = z / dist;
  float k = float(film.frame_w) * float(film.frame_h) / (4 * cam.tan_half_w * cam.tan_half_h);
  Vec3 value = beta * f * (std::fabs(wi.z) / cos_wi_g * cos_wo_g * k / (dist2 * cos_cam * cos_cam * cos_cam));
  if (!is_finite(value) || is_black(value)) return false;
  splat = {uint32_t(size_t(y) * film.w + x), value};
  return true;
}

}  // namespace

bool caustic_tracing_applies(const RenderScene& scene, const RenderParams& params) {
  const Camera& cam = scene.camera;
  const bool camera_ok = cam.lens_radius <= 0 || (cam.focal_distance > 0 && std::isfinite(cam.focal_distance));
  return params.caustic_tracing && !params.hemisphere && params.spp > 1 && params.max_depth >= 2 && camera_ok &&
         !scene.caustic_targets.empty() && !scene.caustic_lights.empty();
}

namespace {

// A light path between its vertices: its random numbers, next ray and weights.
struct LightPath {
  Sampler rng{SamplerKind::independent, 0, 0, 0};  // set by start_light_path
  Ray ray;
  Vec3 beta, throughput{1.0f};
  Vec3 origin;     // the point on the light it left
  int light = -1;  // that light (RenderScene::lights)
  int delta_bounces = 0, diffuse_vertices = 0, vertex = 1;  // the next vertex, as the path tracer counts
  uint32_t id = 0;                                          // its place among the call's paths
};

// Light path `index` up to its first ray: a point on a light chosen by power (uniform by area),
// then a direction into the cone of one target, chosen in proportion to the cones' solid angles
// (the pdf is the number of cones holding the direction over their total solid angle). False if
// the path carries nothing.
bool start_light_path(const RenderScene& scene, const RenderParams& params, uint64_t index, LightPath& lp) {
  Sampler& rng = lp.rng;
  rng = Sampler(params.sampler, params.seed, kLightPathPixel + (index >> 32), uint32_t(index));
  Vec2 u_light = rng.next_2d(), u_point = rng.next_2d();
  float p_light, u_reuse;
  size_t li = scene.caustic_light_distribution.sample_discrete(u_light.x, &p_light, &u_reuse);
  const Light& light = scene.lights[scene.caustic_lights[li]];
  Vec3 x0, n;
  sample_area_light_point(light, u_point, x0, n);

  Cone cones[kMaxCausticTargets];
  size_t nt = scene.caustic_targets.size();
  float total = 0;
  for (size_t k = 0; k < nt; ++k) total += (cones[k] = cone_towards(x0, scene.caustic_targets[k])).solid_angle;
  Vec2 u_dir = rng.next_2d();
  float pick = rng.next_float() * total;
  size_t chosen = 0;
  while (chosen + 1 < nt && pick >= cones[chosen].solid_angle) pick -= cones[chosen++].solid_angle;
  Vec3 wi = sample_cone(cones[chosen], u_dir);
  n = facing_normal(light, n, wi);
  float cos_l = dot(wi, n);
  if (!(cos_l > 0)) return false;  // one-sided emitters light their front only
  int holding = 0;
  for (size_t k = 0; k < nt; ++k) holding += (k == chosen || dot(wi, cones[k].axis()) >= cones[k].cos_max);
  float pdf_dir = float(holding) / total;
  lp.beta = light.color * (cos_l * light.area / (p_light * pdf_dir));
  if (!is_finite(lp.beta)) return false;
  lp.origin = x0;
  lp.light = scene.caustic_lights[li];
  lp.ray.o = offset_ray_origin(x0, n);
  lp.ray.d = wi;
  lp.ray.tmin = 0;
  lp.ray.tmax = kInf;
  lp.throughput = Vec3(1.0f);
  lp.delta_bounces = lp.diffuse_vertices = 0;
  lp.vertex = 1;
  return true;
}

// Whether the path tracer, arriving at the light path's first vertex `hit` from the other way,
// would see the light at the point the path left: the same closest-hit query, reversed. The
// forward ray leaves the light's plane, so it cannot see a surface that overlaps the light in that
// plane (emitters_share_a_plane), and light paths would count both emitters where the path tracer,
// whose share they replace, sees one.
bool light_seen_from(const RenderScene& scene, const SurfaceHit& hit, const LightPath& lp, uint64_t& rays) {
  Vec3 to_light = lp.origin - hit.p;
  float dist = length(to_light);
  if (!(dist > 0)) return false;
  Ray back;
  spawn_ray(hit, to_light / dist, back);
  SurfaceHit seen;
  ++rays;
  return scene.accel->intersect(back, seen) && seen.light == lp.light;
}

// What a light path does with its ray's hit: a connection to the camera from a non-delta vertex
// (its shadow ray and splat go to `connect`), then the BSDF bounce and roulette. False when the
// path ends; otherwise lp.ray is the next ray.
template <class Connect>
bool light_path_step(const RenderScene& scene, const RenderParams& params, const CausticFilm& film, LightPath& lp,
                     bool found, const SurfaceHit& hit, uint64_t& rays, Connect&& connect) {
  const int vertex = lp.vertex++;
  if (!found) return false;
  Vec3 ns_at = hit.ns;  // scenes with light tracing have no normal maps (no glTF delta materials)
  const Material& m = material_at(scene, scene.materials[hit.material], hit, ns_at);  // used within this call
  if (m.type == MaterialType::emission) return false;  // emitters reflect nothing
  const bool delta = is_delta(m);
  // Ours are L S+ D+ E: a first non-delta vertex ends a path with no delta bounce, and a delta
  // one after the diffuse part ends it too (the path tracer renders both).
  if (delta ? lp.diffuse_vertices > 0 : lp.delta_bounces == 0) return false;
  if (vertex == 1 && scene.emitters_share_a_plane && !light_seen_from(scene, hit, lp, rays)) return false;
  Sampler& rng = lp.rng;
  if (!delta) {
    Vec2 u_lens = scene.camera.lens_radius > 0 ? rng.next_2d() : Vec2{0.5f, 0.5f};
    Ray shadow;
    CausticSplat splat;
    if (prepare_splat(scene, film, hit, m, lp.ray.d, lp.beta, u_lens, shadow, splat)) connect(shadow, splat);
    ++lp.diffuse_vertices;
  } else {
    ++lp.delta_bounces;
  }
  if (vertex + 1 > params.max_depth) return false;  // no room for another vertex
  Vec3 wo_world = -lp.ray.d, ng = hit.ng, ns = hit.ns;
  bool transmissive = is_transmissive(m);
  face_viewer(wo_world, transmissive, ng, ns);
  Frame frame(ns);
  float u_lobe = 0;  // only glass and refraction choose a lobe; the others skip that draw
  if (transmissive) u_lobe = rng.next_float();
  else rng.skip_1d();
  Vec2 u;  // delta lobes need no direction sample: skipped, the draws after it stay the same
  if (delta) rng.skip_2d();
  else u = rng.next_2d();
  BsdfSample bs;
  if (!sample_bsdf(m, frame.to_local(wo_world), u_lobe, u, bs)) return false;
  Vec3 wi_world = frame.to_world(bs.wi);
  if (!transmissive && dot(wi_world, ng) <= 0) return false;
  // Importance transport through a shading normal (Veach 1997, eq. 5.19).
  float den = std::fabs(dot(wo_world, ng)) * std::fabs(dot(wi_world, ns));
  if (!(den > 0)) return false;
  float correction = std::fabs(dot(wo_world, ns)) * std::fabs(dot(wi_world, ng)) / den;
  lp.throughput *= bs.weight * correction;
  lp.beta *= bs.weight * correction;
  if (is_black(lp.beta) || !is_finite(lp.beta)) return false;
  if (vertex >= kRouletteStart) {  // the camera paths' roulette, on the path's relative throughput
    const float q = lane1::roulette_probability(lp.throughput);
    if (rng.next_float() >= q) return false;
    lp.beta /= q;
    lp.throughput /= q;
  }
  spawn_ray(hit, wi_world, lp.ray);
  return true;
}

}  // namespace

void trace_caustic_paths(const RenderScene& scene, const RenderParams& params, const CausticFilm& film,
                         uint64_t first, uint64_t count, std::vector<CausticSplat>& out, uint64_t& rays) {
  // A pool of paths advances a vertex at a time, their rays traced together (Embree packets
  // unless forms::packets is off), then their camera connections. Splats are kept in path order, as
  // one path after another would make them, so the image does not depend on the pool.
  constexpr size_t kSlots = 256;
  struct Pending {
    uint32_t id;
    CausticSplat splat;
  };
  // Kept on the thread from call to call (one call per chunk of paths).
  static thread_local std::vector<LightPath> paths;
  static thread_local std::vector<Ray> shadows;
  static thread_local std::vector<SurfaceHit> hits(kSlots);
  static thread_local std::vector<uint8_t> found(kSlots), blocked;
  static thread_local std::vector<Pending> pending, made;
  paths.clear();
  made.clear();
  uint64_t next = 0;
  for (;;) {
    while (paths.size() < kSlots && next < count) {
      LightPath& lp = paths.emplace_back();
      lp.id = uint32_t(next);
      if (!start_light_path(scene, params, first + next++, lp)) paths.pop_back();
    }
    const size_t m = paths.size();
    if (m == 0) break;
    rays += m;
    if (forms::packets()) {  // the rays where they lie in the paths, not copied out
      scene.accel->intersect_many(&paths[0].ray, sizeof(LightPath), m, hits.data(), found.data());
    } else {
      for (size_t i = 0; i < m; ++i) found[i] = scene.accel->intersect(paths[i].ray, hits[i]);
    }
    shadows.clear();
    pending.clear();
    size_t live = 0;
    for (size_t i = 0; i < m; ++i) {
      LightPath& lp = paths[i];
      auto connect = [&](const Ray& shadow, const CausticSplat& splat) {
        shadows.push_back(shadow);
        pending.push_back({lp.id, splat});
      };
      if (light_path_step(scene, params, film, lp, found[i] != 0, hits[i], rays, connect)) {
        if (live != i) paths[live] = std::move(lp);
        ++live;
      }
    }
    paths.erase(paths.begin() + ptrdiff_t(live), paths.end());
    blocked.resize(shadows.size());
    rays += shadows.size();
    if (forms::packets()) {
      scene.accel->occluded_many(shadows.data(), shadows.size(), blocked.data());
    } else {
      for (size_t k = 0; k < shadows.size(); ++k) blocked[k] = scene.accel->occluded(shadows[k]);
    }
    for (size_t k = 0; k < pending.size(); ++k)
      if (!blocked[k]) made.push_back(pending[k]);
  }
  // Path order; a path's own splats are already in vertex order.
  std::stable_sort(made.begin(), made.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  for (const auto& p : made) out.push_back(p.splat);
}

}  // namespace pt
