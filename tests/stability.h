// The stability harness's shared parts: what a case measures (Result), the case table
// (stability_cases.cpp) and the render, comparison and scene helpers the cases are written with
// (stability.cpp).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "image.h"
#include "options.h"
#include "scene.h"
#include "session.h"

namespace stability {

// Scratch files (environment maps, written images); PT_TEST_TMP comes from tests/CMakeLists.txt.
inline const std::string g_tmp = PT_TEST_TMP;

struct Result {
  uint64_t nonfinite = 0;
  double max_pixel = 0, mean = 0;
  std::string expectation;  // what it was compared with
  bool pass = true;
  std::string detail;
};

struct Render {
  pt::ImageRGB img;
  pt::SessionStats stats;
};

struct Case {
  std::string group, name;
  std::function<Result()> run;
};

// Every case, in a fixed order: a case's index is part of its ctest name.
const std::vector<Case>& all_cases();

// ---- rendering and comparing (stability.cpp) ----

Render render(const pt::SceneDesc& desc, const pt::RenderParams& p);
// Luminance mean over a window (the whole image by default).
double mean_lum(const pt::ImageRGB& a, int x0 = 0, int y0 = 0, int x1 = -1, int y1 = -1);
// Non-finite samples and pixels, brightest pixel, mean; passes when all are finite.
Result summarize(const Render& r);
// `a` must equal `b` within 4.5 standard errors of their per-pixel difference (plus rel_tol).
void expect_same(Result& res, const pt::ImageRGB& a, const pt::ImageRGB& b, const std::string& what,
                 double rel_tol = 0.01);

// ---- scenes ----

pt::SceneDesc cornell();
// The first sphere of material type `t`, or -1.
int find_sphere(const pt::SceneDesc& d, pt::MaterialType t);
pt::RenderParams small_params(int w = 48, int h = 36, int spp = 32, int depth = 6);
// Scales every position and size, the camera's position and clip planes with them.
void scale_scene(pt::SceneDesc& d, float s);
// A single sphere of `m` at the origin, camera at distance 6 looking at it, no lights: lit only by
// an environment map, so with a uniform map of radiance 1 no passive material may exceed 1.
pt::SceneDesc furnace_sphere(const pt::Material& m, float radius = 1, float camera_z = 6);
// Writes a w x h environment map to g_tmp/name.exr; returns its path.
std::string env_file(const std::string& name, std::function<pt::Vec3(int, int)> texel, int w = 64, int h = 32);
// The sphere's pixels under a uniform white environment: mean and whether it stays <= 1 (no
// energy gain), optionally == expected.
Result furnace(const pt::Material& m, double expected = -1, int spp = 64);

}  // namespace stability
