// stability_report: renders every stiff and extreme case of the stability issue and checks each
// (no NaN/Inf, no energy gain, continuity with its limit case within noise). As a GoogleTest
// binary every case is its own ctest test (label "stress"); with --report it prints the Markdown
// table of docs/stability.md instead and exits 1 if any case fails. This file holds the harness
// and the helpers the cases are written with; the cases are in stability_cases.cpp.
//   stability_report [gtest flags] | stability_report --report [--only SUBSTRING]
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "collada.h"
#include "stability.h"

using namespace pt;

namespace stability {

// ---- rendering and comparing ----

Render render(const SceneDesc& desc, const RenderParams& p) {
  auto scene = make_render_scene(desc, p);
  RenderSession s(*scene, p);
  s.render_all();
  return {s.image(), s.stats()};
}

double mean_lum(const ImageRGB& a, int x0, int y0, int x1, int y1) {
  if (x1 < 0) x1 = a.width;
  if (y1 < 0) y1 = a.height;
  double s = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) s += luminance(a.at(x, y));
  return s / (double(x1 - x0) * (y1 - y0));
}

namespace {

// The mean and standard error of the per-pixel luminance difference of two images over a window.
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

}  // namespace

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

void expect_same(Result& res, const ImageRGB& a, const ImageRGB& b, const std::string& what, double rel_tol) {
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

RenderParams small_params(int w, int h, int spp, int depth) {
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

SceneDesc furnace_sphere(const Material& m, float radius, float camera_z) {
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

std::string env_file(const std::string& name, std::function<Vec3(int, int)> texel, int w, int h) {
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

Result furnace(const Material& m, double expected, int spp) {
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

}  // namespace stability

namespace {

using namespace stability;

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
  std::system(("mkdir -p '" + stability::g_tmp + "'").c_str());
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
