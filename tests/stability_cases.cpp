// The stability cases, by group (material, camera, depth, sampling, scale, geometry, lights,
// radiance, input), each a closure that renders and checks; stability.cpp runs them. Their order
// is fixed: a case's index is part of its ctest name.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bsdf_util.h"
#include "cli.h"
#include "collada.h"
#include "stability.h"

using namespace pt;

namespace stability {

namespace {

using bsdf_test::conductor;
// Glass of index `ior`, reflectance `r` and transmittance `t`.
Material glass(float ior, Vec3 r = Vec3(1.0f), Vec3 t = Vec3(1.0f)) {
  return bsdf_test::dielectric(MaterialType::glass, ior, r, t);
}

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

}  // namespace

const std::vector<Case>& all_cases() {
  static const std::vector<Case> c = cases();
  return c;
}

}  // namespace stability
