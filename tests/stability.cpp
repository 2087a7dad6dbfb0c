// stability_report: renders every stiff and extreme case of the stability issue and checks each
// (no NaN/Inf, no energy gain, continuity with its limit case within noise). As a GoogleTest
// binary every case is its own ctest test (label "stress"); with --report it prints the Markdown
// table of docs/stability.md instead and exits 1 if any case fails.
//   stability_report [gtest flags] | stability_report --report [--only SUBSTRING]
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "bsdf_util.h"
#include "cli.h"
#include "collada.h"
#include "session.h"

using namespace pt;

namespace {

std::string g_tmp = PT_TEST_TMP;

struct Result {
  uint64_t nonfinite = 0;
  double max_pixel = 0, mean = 0;
  std::string expectation;  // what it was compared with
  bool pass = true;
  std::string detail;
};

struct Render {
  ImageRGB img;
  SessionStats stats;
};

Render render(const SceneDesc& desc, const RenderParams& p) {
  auto scene = make_render_scene(desc, p);
  RenderSession s(*scene, p);
  s.render_all();
  return {s.image(), s.stats()};
}

// Luminance mean over a window and the standard error of the per-pixel difference of two images.
double mean_lum(const ImageRGB& a, int x0 = 0, int y0 = 0, int x1 = -1, int y1 = -1) {
  if (x1 < 0) x1 = a.width;
  if (y1 < 0) y1 = a.height;
  double s = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) s += luminance(a.at(x, y));
  return s / (double(x1 - x0) * (y1 - y0));
}
void diff_stats(const ImageRGB& a, const ImageRGB& b, double* mean, double* stderr_, int x0 = 0, int y0 = 0,
                int x1 = -1, int y1 = -1) {
  if (x1 < 0) x1 = a.width;
  if (y1 < 0) y1 = a.height;
  double s = 0, s2 = 0;
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      double d = luminance(a.at(x, y)) - luminance(b.at(x, y));
      s += d;
      s2 += d * d;
      ++n;
    }
  *mean = s / n;
  *stderr_ = std::sqrt(std::max(0.0, (s2 - s * s / n) / (n - 1)) / n);
}

Result summarize(const Render& r) {
  Result out;
  out.nonfinite = r.stats.nonfinite;
  for (const Vec3& c : r.img.pixels) {
    if (!is_finite(c)) ++out.nonfinite;
    else out.max_pixel = std::max<double>(out.max_pixel, max_component(c));
  }
  out.mean = mean_lum(r.img);
  out.pass = out.nonfinite == 0;
  return out;
}

// `a` must equal `b` within 4.5 standard errors of their per-pixel difference (plus rel_tol).
void expect_same(Result& res, const ImageRGB& a, const ImageRGB& b, const std::string& what, double rel_tol = 0.01) {
  double d, se;
  diff_stats(a, b, &d, &se);
  double tol = 4.5 * se + rel_tol * std::max(1e-12, mean_lum(b));
  res.expectation = what;
  char buf[160];
  std::snprintf(buf, sizeof buf, "diff %.3g (tol %.3g)", d, tol);
  res.detail = buf;
  if (!(std::fabs(d) <= tol)) res.pass = false;
}

// ---- scenes ----

SceneDesc cornell() { return load_collada(std::string(PT_OWN_SCENES) + "/cornell.dae"); }

int find_sphere(const SceneDesc& d, MaterialType t) {
  for (size_t i = 0; i < d.spheres.size(); ++i)
    if (d.materials[d.spheres[i].material].type == t) return int(i);
  return -1;
}

RenderParams small_params(int w = 48, int h = 36, int spp = 32, int depth = 6) {
  RenderParams p;
  p.file_camera = true;
  p.width = w;
  p.height = h;
  p.spp = spp;
  p.max_depth = depth;
  p.adaptive = false;
  p.threads = 2;
  return p;
}

void scale_scene(SceneDesc& d, float s) {
  for (MeshDesc& m : d.meshes)
    for (Vec3& v : m.positions) v *= s;
  for (SphereDesc& sp : d.spheres) {
    sp.center *= s;
    sp.radius *= s;
  }
  for (LightDesc& l : d.lights) {
    l.position *= s;
    l.dim_x *= s;
    l.dim_y *= s;
  }
  for (int i = 0; i < 3; ++i) d.camera.world.m[i][3] *= s;
  d.camera.znear *= s;  // a scaled scene file scales its clip planes too
  d.camera.zfar *= s;
}

// A single sphere of `m` at the origin, camera at distance 6 looking at it, no lights: lit only by
// an environment map, so with a uniform map of radiance 1 no passive material may exceed 1.
SceneDesc furnace_sphere(const Material& m, float radius = 1, float camera_z = 6) {
  SceneDesc d;
  d.source = "furnace";
  d.materials.push_back(m);
  d.spheres.push_back({"s", Vec3(0.0f), radius, 0});
  d.camera.present = true;
  d.camera.xfov_deg = 2 * std::atan(1.2f * radius / camera_z) * 180 / kPi;
  d.camera.aspect = 1;
  d.camera.world.m[2][3] = camera_z;
  d.camera.znear = 1e-3f * radius;
  return d;
}

std::string env_file(const std::string& name, std::function<Vec3(int, int)> texel, int w = 64, int h = 32) {
  ImageRGB env;
  env.width = w;
  env.height = h;
  env.pixels.resize(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) env.at(x, y) = texel(x, y);
  std::string path = g_tmp + "/" + name + ".exr";
  write_image(env, path);
  return path;
}

using bsdf_test::conductor;
Material glass(float ior, Vec3 r = Vec3(1.0f), Vec3 t = Vec3(1.0f)) {
  return bsdf_test::dielectric(MaterialType::glass, ior, r, t);
}

// The sphere's pixels under a uniform white environment: mean and whether it stays <= 1 (no
// energy gain), optionally == expected.
Result furnace(const Material& m, double expected = -1, int spp = 64) {
  static std::string white = env_file("white", [](int, int) { return Vec3(1.0f); });
  SceneDesc d = furnace_sphere(m);
  RenderParams p = small_params(24, 24, spp, 200);
  p.env_map = white;
  Render r = render(d, p);
  Result res = summarize(r);
  // The central 12x12 pixels all see the sphere.
  double s = 0, s2 = 0;
  int n = 0;
  for (int y = 6; y < 18; ++y)
    for (int x = 6; x < 18; ++x) {
      double v = luminance(r.img.at(x, y));
      s += v;
      s2 += v * v;
      ++n;
    }
  double mean = s / n, se = std::sqrt(std::max(0.0, (s2 - s * s / n) / (n - 1)) / n);
  res.mean = mean;
  char buf[160];
  if (expected >= 0) {
    res.expectation = "white furnace: sphere = " + std::to_string(expected).substr(0, 5);
    std::snprintf(buf, sizeof buf, "sphere %.4f +- %.4f", mean, se);
    if (std::fabs(mean - expected) > 4.5 * se + 0.005) res.pass = false;
  } else {
    res.expectation = "white furnace: sphere <= 1";
    std::snprintf(buf, sizeof buf, "sphere %.4f +- %.4f", mean, se);
    if (mean > 1 + 4.5 * se + 0.005) res.pass = false;
  }
  res.detail = buf;
  return res;
}

struct Case {
  std::string group, name;
  std::function<Result()> run;
};

std::vector<Case> cases() {
  std::vector<Case> c;
  // ---- materials ----
  for (float ior : {1.0f, 1.0001f, 0.5f, 1.5f, 2.4f, 10.0f, 1000.0f})
    c.push_back({"material", "glass ior " + std::to_string(ior).substr(0, 6), [ior] { return furnace(glass(ior), 1.0); }});
  c.push_back({"material", "glass ior 1.0 vanishes in the Cornell box", [] {
                 SceneDesc with = cornell(), without = cornell();
                 int gi = find_sphere(with, MaterialType::glass);
                 with.materials[with.spheres[gi].material] = glass(1.0f);
                 without.spheres.erase(without.spheres.begin() + gi);
                 RenderParams p = small_params(48, 36, 256, 8);
                 Render a = render(with, p), b = render(without, p);
                 Result res = summarize(a);
                 expect_same(res, a.img, b.img, "the box without the sphere", 0.02);
                 return res;
               }});
  c.push_back({"material", "refraction-only ior 1.5 (TIR absorbs)", [] {
                 Material m = glass(1.5f);
                 m.type = MaterialType::refraction;
                 return furnace(m);
               }});
  c.push_back({"material", "glass R = T = 0 is black", [] { return furnace(glass(1.5f, Vec3(0.0f), Vec3(0.0f)), 0.0); }});
  c.push_back({"material", "mirror reflectance 1", [] {
                 Material m;
                 m.type = MaterialType::mirror;
                 m.albedo = Vec3(1.0f);
                 return furnace(m, 1.0);
               }});
  c.push_back({"material", "mirror reflectance 0", [] {
                 Material m;
                 m.type = MaterialType::mirror;
                 m.albedo = Vec3(0.0f);
                 return furnace(m, 0.0);
               }});
  c.push_back({"material", "diffuse albedo 1", [] {
                 Material m;
                 m.albedo = Vec3(1.0f);
                 return furnace(m, 1.0);
               }});
  for (float a : {1e-4f, 1e-2f, 0.25f, 1.0f})
    c.push_back({"material", "microfacet alpha " + std::to_string(a).substr(0, 6) + ", eta = k = 0 (F = 1)",
                 [a] { return furnace(conductor(a, Vec3(0.0f), Vec3(0.0f))); }});
  c.push_back({"material", "microfacet eta 1e30 k 1e30", [] { return furnace(conductor(0.2f, Vec3(1e30f), Vec3(1e30f))); }});
  c.push_back({"material", "microfacet alpha 1e-4 vs mirror", [] {
                 // A nearly delta conductor with F = 1 must approach the perfect mirror.
                 static std::string sky = env_file("sky", [](int x, int y) {
                   return Vec3(0.2f + 0.8f * float(y < 8), 0.3f + 0.02f * float(x % 8), 0.5f);
                 });
                 Material mirror;
                 mirror.type = MaterialType::mirror;
                 mirror.albedo = Vec3(1.0f);
                 RenderParams p = small_params(24, 24, 64, 4);
                 p.env_map = sky;
                 Render a = render(furnace_sphere(conductor(1e-4f, Vec3(0.0f), Vec3(0.0f))), p);
                 Render b = render(furnace_sphere(mirror), p);
                 Result res = summarize(a);
                 expect_same(res, a.img, b.img, "a perfect mirror", 0.02);
                 return res;
               }});
  // ---- camera ----
  auto cornell_pair = [](std::function<void(RenderParams&)> a_mod, std::function<void(RenderParams&)> b_mod,
                         std::string what, int spp = 64) {
    SceneDesc d = cornell();
    RenderParams pa = small_params(48, 36, spp, 5), pb = pa;
    a_mod(pa);
    b_mod(pb);
    Render a = render(d, pa), b = render(d, pb);
    Result res = summarize(a);
    expect_same(res, a.img, b.img, what, 0.02);
    return res;
  };
  c.push_back({"camera", "lens radius 1e-7 equals the pinhole", [=] {
                 return cornell_pair([](RenderParams& p) { p.lens_radius = 1e-7f; }, [](RenderParams&) {}, "pinhole");
               }});
  c.push_back({"camera", "focal distance 1e9 equals 1e7 (infinity)", [=] {
                 return cornell_pair([](RenderParams& p) { p.lens_radius = 0.05f; p.focal_distance = 1e9f; },
                                     [](RenderParams& p) { p.lens_radius = 0.05f; p.focal_distance = 1e7f; }, "focus at 1e7");
               }});
  for (float fd : {0.0f, 1e-6f})
    c.push_back({"camera", "focal distance " + std::to_string(fd).substr(0, 8) + ", lens 0.1", [fd] {
                   RenderParams p = small_params(32, 24, 16, 4);
                   p.lens_radius = 0.1f;
                   p.focal_distance = fd;
                   Result r = summarize(render(cornell(), p));
                   r.expectation = "finite";
                   return r;
                 }});
  c.push_back({"camera", "lens radius 1e3", [] {
                 RenderParams p = small_params(32, 24, 16, 4);
                 p.lens_radius = 1e3f;
                 Result r = summarize(render(cornell(), p));
                 r.expectation = "finite";
                 return r;
               }});
  c.push_back({"camera", "field of view 179.9 degrees", [] {
                 SceneDesc d = cornell();
                 d.camera.xfov_deg = 179.9f;
                 d.camera.yfov_deg = 0;
                 Result r = summarize(render(d, small_params(32, 24, 16, 4)));
                 r.expectation = "finite";
                 return r;
               }});
  c.push_back({"camera", "inside a glass sphere sees n^2 L", [] {
                 // L/n^2 is invariant along rays: inside glass of index 1.5 under a uniform sky of
                 // radiance 1 every direction carries 2.25 (Veach 1997, section 5.2).
                 static std::string white = env_file("white", [](int, int) { return Vec3(1.0f); });
                 SceneDesc d = furnace_sphere(glass(1.5f), 1, 0);
                 d.camera.xfov_deg = 60;
                 RenderParams p = small_params(16, 16, 256, 400);
                 p.env_map = white;
                 Render r = render(d, p);
                 Result res = summarize(r);
                 double m = mean_lum(r.img);
                 res.expectation = "2.25";
                 char buf[64];
                 std::snprintf(buf, sizeof buf, "mean %.4f", m);
                 res.detail = buf;
                 if (std::fabs(m - 2.25) > 0.05) res.pass = false;
                 return res;
               }});
  c.push_back({"camera", "inside a diffuse sphere with a point light", [] {
                 // Closed sphere, albedo 0.5, radius 1, point light of intensity 1 at the centre:
                 // L = rho E0 / (pi (1 - rho)) = 1/pi at infinite depth.
                 Material m;
                 m.albedo = Vec3(0.5f);
                 SceneDesc d = furnace_sphere(m, 1, 0);
                 d.camera.xfov_deg = 60;
                 d.lights.push_back({"bulb", LightType::point, Vec3(1.0f), Vec3(0.0f)});
                 Render r = render(d, small_params(16, 16, 256, 1000));
                 Result res = summarize(r);
                 double mean = mean_lum(r.img);
                 res.expectation = "1/pi = 0.3183";
                 char buf[64];
                 std::snprintf(buf, sizeof buf, "mean %.4f", mean);
                 res.detail = buf;
                 if (std::fabs(mean - 1 / kPi) > 0.01) res.pass = false;
                 return res;
               }});
  // ---- depth and sampling ----
  for (int m : {0, 1, 2, 1000, 100000})
    c.push_back({"depth", "-m " + std::to_string(m), [m] {
                   RenderParams p = small_params(32, 24, 16, m);
                   Render r = render(cornell(), p);
                   Result res = summarize(r);
                   double rays_per_sample = double(r.stats.rays) / double(r.stats.samples);
                   char buf[96];
                   std::snprintf(buf, sizeof buf, "%.2f rays/sample", rays_per_sample);
                   res.detail = buf;
                   res.expectation = "finite, bounded path length";
                   if (rays_per_sample > 60) res.pass = false;  // roulette must end paths
                   return res;
                 }});
  c.push_back({"sampling", "65536 spp on 4x3 equals 1024 spp", [] {
                 SceneDesc d = cornell();
                 RenderParams p = small_params(48, 36, 65536, 5), q = small_params(48, 36, 1024, 5);
                 p.cell_x = q.cell_x = 22;
                 p.cell_y = q.cell_y = 16;
                 p.cell_w = q.cell_w = 4;
                 p.cell_h = q.cell_h = 3;
                 Render a = render(d, p), b = render(d, q);
                 Result res = summarize(a);
                 double ma = mean_lum(a.img), mb = mean_lum(b.img);
                 res.expectation = "1024 spp";
                 char buf[96];
                 std::snprintf(buf, sizeof buf, "%.4f vs %.4f", ma, mb);
                 res.detail = buf;
                 if (std::fabs(ma - mb) > 0.1 * mb) res.pass = false;
                 return res;
               }});
  c.push_back({"sampling", "1 spp (pixel centre)", [] {
                 Result r = summarize(render(cornell(), small_params(32, 24, 1, 5)));
                 r.expectation = "finite";
                 return r;
               }});
  for (float tol : {0.0f, 1.0f})
    c.push_back({"sampling", "adaptive tolerance " + std::to_string(tol).substr(0, 3), [=] {
                   return cornell_pair([tol](RenderParams& p) { p.adaptive = true; p.adaptive_batch = 16; p.adaptive_tolerance = tol; },
                                       [](RenderParams&) {}, "non-adaptive", 128);
                 }});
  // ---- geometry and scale ----
  for (float s : {1e-4f, 1e4f})
    c.push_back({"scale", "scene scaled by " + std::to_string(s).substr(0, 6), [s] {
                   SceneDesc a = cornell(), b = cornell();
                   scale_scene(a, s);
                   RenderParams p = small_params(48, 36, 64, 5);
                   Render ra = render(a, p), rb = render(b, p);
                   Result res = summarize(ra);
                   expect_same(res, ra.img, rb.img, "unscaled scene", 0.02);
                   return res;
                 }});
  c.push_back({"geometry", "degenerate, zero-area and coincident triangles", [] {
                 SceneDesc d = cornell();
                 MeshDesc junk;
                 junk.name = "junk";
                 junk.positions = {{0, 0.5f, 0}, {0, 0.5f, 0}, {0.3f, 0.5f, 0}, {0.6f, 0.5f, 0}};  // repeated + collinear
                 junk.indices = {0, 1, 2, 0, 2, 3};
                 junk.tri_material = {0, 0};
                 d.meshes.push_back(junk);
                 MeshDesc dup = d.meshes[0];  // a coincident copy of the first wall
                 d.meshes.push_back(dup);
                 Result r = summarize(render(d, small_params(32, 24, 16, 5)));
                 r.expectation = "finite";
                 return r;
               }});
  c.push_back({"geometry", "sphere of radius 1e6 as a ground plane", [] {
                 // Far-away rays hitting a huge sphere must match a triangle plane (stable quadratic).
                 auto base = [] {
                   SceneDesc d;
                   d.source = "ground";
                   Material grey;
                   grey.albedo = Vec3(0.5f);
                   d.materials.push_back(grey);
                   d.lights.push_back({"sun", LightType::directional, Vec3(2.0f), Vec3(0.0f), normalize(Vec3(0.3f, -1, 0.2f))});
                   d.camera.present = true;
                   d.camera.xfov_deg = 40;
                   d.camera.aspect = 4.0f / 3;
                   // Looking down at the ground from height 3, 30 degrees below horizontal.
                   float a = 30 * kPi / 180;
                   Mat4 m;
                   m.m[1][1] = std::cos(a); m.m[1][2] = std::sin(a);
                   m.m[2][1] = -std::sin(a); m.m[2][2] = std::cos(a);
                   m.m[1][3] = 3;
                   m.m[2][3] = 5;
                   d.camera.world = m;
                   return d;
                 };
                 SceneDesc sph = base(), plane = base();
                 sph.spheres.push_back({"ground", Vec3(0, -1e6f, 0), 1e6f, 0});
                 MeshDesc g;
                 g.positions = {{-1e3f, 0, -1e3f}, {1e3f, 0, -1e3f}, {1e3f, 0, 1e3f}, {-1e3f, 0, 1e3f}};
                 g.indices = {0, 2, 1, 0, 3, 2};
                 g.tri_material = {0, 0};
                 plane.meshes.push_back(g);
                 RenderParams p = small_params(32, 24, 16, 2);
                 Render a = render(sph, p), b = render(plane, p);
                 Result res = summarize(a);
                 expect_same(res, a.img, b.img, "a triangle ground plane", 0.01);
                 return res;
               }});
  c.push_back({"geometry", "sphere of radius 1e-6 seen from 1e-5", [] {
                 static std::string white = env_file("white", [](int, int) { return Vec3(1.0f); });
                 Material m;
                 m.albedo = Vec3(0.8f);
                 SceneDesc d = furnace_sphere(m, 1e-6f, 1e-5f);
                 RenderParams p = small_params(24, 24, 64, 4);
                 p.env_map = white;
                 Render r = render(d, p);
                 Result res = summarize(r);
                 double centre = mean_lum(r.img, 8, 8, 16, 16);
                 res.expectation = "centre = 0.8";
                 char buf[64];
                 std::snprintf(buf, sizeof buf, "centre %.4f", centre);
                 res.detail = buf;
                 if (std::fabs(centre - 0.8) > 0.03) res.pass = false;
                 return res;
               }});
  c.push_back({"lights", "zero-area area light is left out", [] {
                 SceneDesc d = cornell();
                 d.lights[0].dim_x = Vec3(0.0f);
                 Render r = render(d, small_params(32, 24, 8, 4));
                 Result res = summarize(r);
                 res.expectation = "black";
                 if (res.max_pixel != 0) res.pass = false;
                 return res;
               }});
  c.push_back({"lights", "back-facing area light lights nothing", [] {
                 SceneDesc d = cornell();
                 d.lights[0].direction = -d.lights[0].direction;
                 d.lights[0].position.y += 0.001f;  // face the ceiling from just below it
                 Render r = render(d, small_params(32, 24, 8, 1));
                 Result res = summarize(r);
                 res.expectation = "walls black at m = 1";
                 double walls = mean_lum(r.img, 0, 12, 32, 24);
                 if (walls > 1e-6) res.pass = false;
                 return res;
               }});
  // ---- radiance ----
  for (float scale : {1e-8f, 1e8f})
    c.push_back({"radiance", "light radiance x " + std::to_string(scale).substr(0, 6), [scale] {
                   SceneDesc a = cornell(), b = cornell();
                   a.lights[0].color *= scale;
                   RenderParams p = small_params(32, 24, 16, 5);
                   Render ra = render(a, p), rb = render(b, p);
                   Result res = summarize(ra);
                   double ma = mean_lum(ra.img) / scale, mb = mean_lum(rb.img);
                   res.expectation = "linear in radiance";
                   char buf[96];
                   std::snprintf(buf, sizeof buf, "mean/scale %.5g vs %.5g", ma, mb);
                   res.detail = buf;
                   if (std::fabs(ma - mb) > 1e-3 * mb) res.pass = false;
                   std::string png = g_tmp + "/radiance.png", exr = g_tmp + "/radiance.exr";
                   write_image(ra.img, png);
                   write_image(ra.img, exr);
                   ImageRGB back = read_image(exr);
                   for (const Vec3& v : back.pixels)
                     if (!is_finite(v)) res.pass = false;
                   return res;
                 }});
  c.push_back({"radiance", "environment with 1e6 dynamic range", [] {
                 std::string hdr = env_file("hdr", [](int x, int y) { return (x == 10 && y == 5) ? Vec3(1e5f) : Vec3(0.1f); });
                 Material m;
                 m.albedo = Vec3(0.7f);
                 RenderParams p = small_params(24, 24, 64, 4);
                 p.env_map = hdr;
                 Result r = summarize(render(furnace_sphere(m), p));
                 r.expectation = "finite";
                 return r;
               }});
  c.push_back({"radiance", "environment with NaN and Inf texels", [] {
                 std::string bad = env_file("nan", [](int x, int y) {
                   if (x == 3) return Vec3(NAN, 1, 1);
                   if (y == 4) return Vec3(INFINITY, 0, 0);
                   if (x == 7) return Vec3(-5.0f);
                   return Vec3(0.5f);
                 });
                 Material m;
                 m.albedo = Vec3(0.7f);
                 RenderParams p = small_params(24, 24, 32, 4);
                 p.env_map = bad;
                 Result r = summarize(render(furnace_sphere(m), p));
                 r.expectation = "finite (bad texels read as black)";
                 return r;
               }});
  // ---- input ----
  c.push_back({"input", "NaN / Inf / negative numbers in a scene file", [] {
                 Result r;
                 r.expectation = "SceneError naming the element";
                 for (const char* bad : {"nan", "inf", "-1e999"}) {
                   std::string text = std::string(R"(<COLLADA><library_geometries><geometry id="g"><extra><technique profile="CGL"><sphere><radius>)") +
                                      bad + R"(</radius></sphere></technique></extra></geometry></library_geometries>
<library_visual_scenes><visual_scene id="v"><node><instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>
<scene><instance_visual_scene url="#v"/></scene></COLLADA>)";
                   try {
                     parse_collada(text, "bad.dae");
                     r.pass = false;
                   } catch (const SceneError& e) {
                     if (std::string(e.what()).find("<radius>") == std::string::npos) r.pass = false;
                   }
                 }
                 return r;
               }});
  c.push_back({"input", "NaN / Inf / negative / absurd flags", [] {
                 Result r;
                 r.expectation = "UsageError naming the flag";
                 for (std::vector<std::string> args : std::vector<std::vector<std::string>>{
                          {"-b", "nan", "s.dae"}, {"-d", "inf", "s.dae"}, {"-b", "-1", "s.dae"}, {"-s", "-5", "s.dae"},
                          {"-m", "99999999999", "s.dae"}, {"-r", "0", "10", "s.dae"}, {"-a", "32", "nan", "s.dae"}}) {
                   try {
                     parse_cli(args);
                     r.pass = false;
                   } catch (const UsageError& e) {
                     if (std::string(e.what()).find(args[0]) == std::string::npos) r.pass = false;
                   }
                 }
                 return r;
               }});
  return c;
}

const std::vector<Case>& all_cases() {
  static const std::vector<Case> c = cases();
  return c;
}

class Stability : public ::testing::TestWithParam<int> {};

TEST_P(Stability, Case) {
  const Case& c = all_cases()[GetParam()];
  Result r = c.run();
  EXPECT_EQ(r.nonfinite, 0u) << c.name;
  EXPECT_TRUE(r.pass) << c.group << ": " << c.name << ": expected " << r.expectation << "; measured " << r.detail;
}

std::string case_name(const ::testing::TestParamInfo<int>& info) {
  const Case& c = all_cases()[info.param];
  std::string n = c.group + "_" + c.name;
  std::string out;
  for (char ch : n) out += std::isalnum((unsigned char)ch) ? ch : '_';
  return out + "_" + std::to_string(info.param);
}

INSTANTIATE_TEST_SUITE_P(Cases, Stability, ::testing::Range(0, int(all_cases().size())), case_name);

int report(const std::string& only) {
  std::ostringstream table;
  table << "| group | case | non-finite samples | max pixel | mean | compared with | measured | result |\n"
        << "|---|---|---|---|---|---|---|---|\n";
  int failed = 0, passed = 0;
  for (const Case& c : all_cases()) {
    if (!only.empty() && (c.group + " " + c.name).find(only) == std::string::npos) continue;
    auto t0 = std::chrono::steady_clock::now();
    Result r;
    try {
      r = c.run();
    } catch (const std::exception& e) {
      r.pass = false;
      r.detail = std::string("exception: ") + e.what();
    }
    double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    (r.pass ? passed : failed)++;
    char row[1024];
    std::snprintf(row, sizeof row, "| %s | %s | %llu | %.4g | %.4g | %s | %s | %s |\n", c.group.c_str(), c.name.c_str(),
                  (unsigned long long)r.nonfinite, r.max_pixel, r.mean, r.expectation.c_str(), r.detail.c_str(),
                  r.pass ? "pass" : "**FAIL**");
    table << row;
    std::fprintf(stderr, "%-9s %-55s %s (%.2fs) %s\n", c.group.c_str(), c.name.c_str(), r.pass ? "pass" : "FAIL", secs,
                 r.detail.c_str());
  }
  std::printf("%s", table.str().c_str());
  std::printf("\nstability: %d passed, %d failed\n", passed, failed);
  return failed ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::system(("mkdir -p '" + g_tmp + "'").c_str());
  std::string only;
  bool as_report = false;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--report") as_report = true;
    else if (a == "--only" && i + 1 < argc) only = argv[++i];
  }
  if (as_report) return report(only);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
