// Helpers shared by the tests: scene paths (skipping cleanly without ../shared), temp dirs,
// and noise-aware image statistics.
#pragma once

#include <gtest/gtest.h>
#include <filesystem>

#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <sstream>
#include <string>

#include "collada.h"
#include "image.h"
#include "simd.h"

namespace pt::test {

// A diffuse sphere (albedo rho, radius 1, at the origin), a camera at (0, 0, camera_z) looking
// down -z with horizontal field of view `fov`, and one light at the origin given as its
// technique_common element ("" for no light).
inline std::string diffuse_sphere_scene(float rho, float camera_z, float fov, const std::string& light) {
  std::ostringstream s;
  s << R"(<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><up_axis>Y_UP</up_axis></asset>
  <library_cameras><camera id="C"><optics><technique_common><perspective>
    <xfov>)" << fov << R"(</xfov><aspect_ratio>1</aspect_ratio><znear>0.001</znear><zfar>1000</zfar>
  </perspective></technique_common></optics></camera></library_cameras>
  )" << (light.empty() ? "" : "<library_lights><light id=\"L\"><technique_common>" + light +
                                 "</technique_common></light></library_lights>") << R"(
  <library_effects><effect id="E"><profile_COMMON><technique sid="common"><phong>
    <diffuse><color>)" << rho << " " << rho << " " << rho << R"( 1</color></diffuse>
  </phong></technique></profile_COMMON></effect></library_effects>
  <library_materials><material id="M"><instance_effect url="#E"/></material></library_materials>
  <library_geometries>
    <geometry id="S"><extra><technique profile="CGL"><sphere><radius>1</radius></sphere></technique></extra></geometry>
  </library_geometries>
  <library_visual_scenes><visual_scene id="VS">
    <node id="cam"><translate>0 0 )" << camera_z << R"(</translate><instance_camera url="#C"/></node>
    )" << (light.empty() ? "" : R"(<node id="l"><instance_light url="#L"/></node>)") << R"(
    <node id="s"><instance_geometry url="#S"><bind_material><technique_common>
      <instance_material symbol="M" target="#M"/></technique_common></bind_material></instance_geometry></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#VS"/></scene>
</COLLADA>
)";
  return s.str();
}

// A command's exit status (-1 when it did not exit) and its stdout and stderr together.
struct RunResult {
  int status;
  std::string output;
};
inline RunResult run_command(const std::string& cmd) {
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return {-1, ""};
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

inline bool file_exists(const std::string& p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0;
}

// Whether the tests run under CI (CI=true), where a test that cannot run is a failure.
inline bool under_ci() {
  const char* ci = std::getenv("CI");
  return ci && std::string(ci) == "true";
}

// Path of a course scene in ../shared/scenes-cs184, or "" when it is absent.
inline std::string shared_scene(const std::string& name) {
  std::string p = std::string(PT_SHARED_SCENES) + "/" + name;
  return file_exists(p) ? p : "";
}

// For a test that cannot run here (no course scenes, no Xvfb): skipped on a user's machine, a
// failure under CI=true, where it must never pass or skip quietly.
#define PT_CANNOT_RUN(why)                                                       \
  do {                                                                           \
    if (::pt::test::under_ci()) FAIL() << "CI=true, yet this test cannot run: " << why; \
    GTEST_SKIP() << why;                                                         \
  } while (0)

// A course scene a test covers when it is there: "" when absent, and then, under CI=true, a
// failure (the test would pass on less than it claims).
inline std::string optional_shared_scene(const std::string& name) {
  std::string p = shared_scene(name);
  if (p.empty() && under_ci()) ADD_FAILURE() << "CI=true, yet ../shared/scenes-cs184/" << name << " is absent";
  return p;
}

#define PT_REQUIRE_SHARED_SCENE(var, name)                                      \
  std::string var = ::pt::test::shared_scene(name);                             \
  if (var.empty()) PT_CANNOT_RUN("../shared/scenes-cs184/" << name << " is absent")

// A scene with one box from (-1,0,-1) to (1,1.5,1) and the course's Cornell-box camera node.
inline SceneDesc camera_box_scene() {
  SceneDesc s;
  MeshDesc m;
  m.positions = {{-1, 0, -1}, {1, 0, -1}, {1, 1.5f, 1}};
  m.indices = {0, 1, 2};
  m.tri_material = {0};
  s.meshes.push_back(m);
  s.materials.push_back(Material());
  s.camera.present = true;
  s.camera.xfov_deg = 49.13434f;
  s.camera.aspect = 1.333333f;
  s.camera.znear = 0.1f;
  s.camera.zfar = 100;
  // Course camera matrix (Z-up file) with the Z_UP conversion applied on top.
  Mat4 file = Mat4::zero();
  double v[16] = {-1, 0, 0, 0, 0, 0, 1, 3, 0, 1, 0, 0, 0, 0, 0, 1};
  for (int i = 0; i < 16; ++i) file.m[i / 4][i % 4] = v[i];
  Mat4 up = Mat4::zero();
  up.m[0][0] = -1; up.m[1][2] = 1; up.m[2][1] = 1; up.m[3][3] = 1;
  s.camera.world = up * file;
  return s;
}

// Two small spheres far apart on a diagonal, no light: most of the course framing is background,
// including the space between them (the background mask and tile order tests).
inline SceneDesc two_small_spheres() {
  SceneDesc d;
  d.materials.resize(1);
  d.spheres.push_back({"a", Vec3(-2, -1.5f, 0), 0.3f, 0});
  d.spheres.push_back({"b", Vec3(2, 1.5f, 0), 0.3f, 0});
  return d;
}

// CPU seconds this process has used (all threads). A bound on it holds whatever else the machine
// runs, unlike a wall-clock bound: for "fails fast" checks, where hanging is the failure.
inline double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

inline std::string own_scene(const std::string& name) { return std::string(PT_OWN_SCENES) + "/" + name; }

// Made with its parents, so that a test binary run outside ctest (another checkout, another
// machine) still has somewhere to write.
inline std::string temp_dir() {
  std::string d = PT_TEST_TMP;
  std::error_code ec;
  std::filesystem::create_directories(d, ec);
  return d;
}

// Mean and standard error of the luminance over a pixel rectangle [x0,x1) x [y0,y1).
struct RegionStats {
  double mean = 0, stderr_ = 0;
  int n = 0;
};
inline RegionStats region_stats(const ImageRGB& img, int x0, int y0, int x1, int y1, int channel = -1) {
  double s = 0, s2 = 0;
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const Vec3& c = img.at(x, y);
      double v = channel < 0 ? luminance(c) : c[channel];
      s += v;
      s2 += v * v;
      ++n;
    }
  RegionStats r;
  r.n = n;
  r.mean = n ? s / n : 0;
  double var = n > 1 ? std::max(0.0, (s2 - s * s / n) / (n - 1)) : 0;
  r.stderr_ = n ? std::sqrt(var / n) : 0;
  return r;
}

// Writes a 16x8 environment map of one colour into the test temp dir and returns its path.
inline std::string uniform_sky(const std::string& name, Vec3 colour) {
  ImageRGB env;
  env.width = 16;
  env.height = 8;
  env.pixels.assign(size_t(env.width) * env.height, colour);
  std::string path = temp_dir() + "/" + name;
  write_image(env, path);
  return path;
}

// Turns the scene's area lights into emissive quads (mesh lights: sampled by triangle), wound to
// emit towards the light's direction.
inline void area_lights_as_meshes(SceneDesc& desc) {
  std::vector<LightDesc> kept;
  for (const LightDesc& l : desc.lights) {
    if (l.type != LightType::area) {
      kept.push_back(l);
      continue;
    }
    Material em;
    em.name = l.name + " (mesh)";
    em.type = MaterialType::emission;
    em.radiance = l.color;
    desc.materials.push_back(em);
    MeshDesc m;
    m.name = l.name;
    Vec3 corners[4];
    area_light_corners(l, corners);
    m.positions.assign(corners, corners + 4);
    m.indices = {0, 1, 2, 0, 2, 3};
    m.tri_material = {int(desc.materials.size()) - 1, int(desc.materials.size()) - 1};
    desc.meshes.push_back(m);
  }
  desc.lights = kept;
}

}  // namespace pt::test
