// Ray queries against a brute-force reference: Accel skips Embree for rays that miss the scene's
// bounds, and that shortcut must never drop a hit (rays grazing the bounds' faces, edges and
// corners included) nor keep a miss from being one.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "accel.h"
#include "collada.h"
#include "loop_forms.h"
#include "session.h"
#include "test_util.h"

using namespace pt;

namespace {

// The ray parameter of a hit: its distance along the ray in units of the direction's length.
double hit_t(const Ray& r, const SurfaceHit& h) {
  return double(dot(h.p - r.o, r.d)) / double(dot(r.d, r.d));
}

}  // namespace

namespace {

// A tilted quad (two triangles) and a sphere, far from the origin so that the bounds' padding is
// tested at a large coordinate scale too.
SceneDesc two_shapes(Vec3 offset) {
  SceneDesc d;
  d.materials.resize(1);
  MeshDesc m;
  m.positions = {offset + Vec3(-1, -1, 0.2f), offset + Vec3(1, -1, -0.2f), offset + Vec3(1, 1, 0.3f),
                 offset + Vec3(-1, 1, -0.1f)};
  m.indices = {0, 1, 2, 0, 2, 3};
  m.tri_material = {0, 0};
  d.meshes.push_back(m);
  SphereDesc s;
  s.center = offset + Vec3(0.5f, 0.2f, 1.0f);
  s.radius = 0.4f;
  d.spheres.push_back(s);
  return d;
}

// Double-precision reference: the nearest hit distance, or infinity; `clear` is false when the
// ray passes within `margin` of a triangle edge or grazes the sphere (where float results may
// legitimately differ).
double reference_hit(const SceneDesc& d, const Ray& r, double margin, bool& clear) {
  clear = true;
  double best = INFINITY;
  const MeshDesc& m = d.meshes[0];
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    Vec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]], c = m.positions[m.indices[t + 2]];
    double e1[3] = {b.x - a.x, b.y - a.y, b.z - a.z}, e2[3] = {c.x - a.x, c.y - a.y, c.z - a.z};
    double dir[3] = {r.d.x, r.d.y, r.d.z}, s[3] = {r.o.x - a.x, r.o.y - a.y, r.o.z - a.z};
    auto cross = [](const double* u, const double* v, double* o) {
      o[0] = u[1] * v[2] - u[2] * v[1];
      o[1] = u[2] * v[0] - u[0] * v[2];
      o[2] = u[0] * v[1] - u[1] * v[0];
    };
    auto dot = [](const double* u, const double* v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
    double p[3], q[3];
    cross(dir, e2, p);
    double det = dot(e1, p);
    if (std::fabs(det) < 1e-12) continue;
    double u = dot(s, p) / det;
    cross(s, e1, q);
    double v = dot(dir, q) / det, tt = dot(e2, q) / det;
    double w = 1 - u - v;
    double edge = std::min({u, v, w});
    if (std::fabs(edge) < margin) clear = false;
    if (std::fabs(tt - r.tmax) < margin * (1 + tt)) clear = false;  // ends on the surface
    if (edge >= 0 && tt > r.tmin && tt < r.tmax) best = std::min(best, tt);
  }
  const SphereDesc& sp = d.spheres[0];
  double oc[3] = {r.o.x - sp.center.x, r.o.y - sp.center.y, r.o.z - sp.center.z};
  double dd = double(r.d.x) * r.d.x + double(r.d.y) * r.d.y + double(r.d.z) * r.d.z;
  double bb = oc[0] * r.d.x + oc[1] * r.d.y + oc[2] * r.d.z;
  double cc = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - double(sp.radius) * sp.radius;
  double disc = bb * bb - dd * cc;
  if (std::fabs(disc) < margin * dd * sp.radius) clear = false;
  if (disc >= 0) {
    // Both roots: a ray starting inside the sphere hits its far side.
    for (double root : {(-bb - std::sqrt(disc)) / dd, (-bb + std::sqrt(disc)) / dd}) {
      if (std::fabs(root - r.tmin) < margin || std::fabs(root - r.tmax) < margin * (1 + root)) clear = false;
      if (root > r.tmin && root < r.tmax) {
        best = std::min(best, root);
        break;
      }
    }
  }
  return best;
}

void check_against_reference(Vec3 offset) {
  SceneDesc d = two_shapes(offset);
  Accel accel(d, {}, {});
  Bounds3 b = d.geometry_bounds();
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  int hits = 0, misses = 0, compared = 0;
  for (int i = 0; i < 200000; ++i) {
    // Targets on and just around the bounds (faces, edges, corners), origins all around.
    Vec3 target;
    for (int k = 0; k < 3; ++k) {
      float lo = b.lo[k], hi = b.hi[k], x = u(rng);
      float pick = x < 0.3f ? lo : x < 0.6f ? hi : lo + (hi - lo) * u(rng);
      target[k] = pick + (u(rng) - 0.5f) * 0.02f;
    }
    Vec3 dir = normalize(Vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f));
    Ray r;
    r.o = target - dir * (2 + 6 * u(rng));
    r.d = dir * (0.5f + u(rng));  // unnormalised directions too
    r.tmin = 0;
    r.tmax = u(rng) < 0.5f ? kInf : 4 + 8 * u(rng);
    bool clear;
    double ref = reference_hit(d, r, 1e-4, clear);
    if (!clear) continue;
    ++compared;
    SurfaceHit hit;
    bool got = accel.intersect(r, hit);
    ASSERT_EQ(got, std::isfinite(ref)) << "ray " << i << " from " << r.o.x << "," << r.o.y << "," << r.o.z;
    if (got) {
      EXPECT_NEAR(hit_t(r, hit), ref, 1e-3 * (1 + ref));
      ++hits;
    } else {
      ++misses;
    }
  }
  // Both outcomes well represented, or the comparison says little.
  EXPECT_GT(hits, 20000);
  EXPECT_GT(misses, 20000);
  EXPECT_GT(compared, 150000);
}

}  // namespace

TEST(Accel, AgreesWithBruteForceAroundTheSceneBoundsNearTheOrigin) { check_against_reference(Vec3(0, 0, 0)); }

TEST(Accel, AgreesWithBruteForceAroundTheSceneBoundsFarFromTheOrigin) {
  check_against_reference(Vec3(3000, -2000, 1000));
}

// intersect_many / occluded_many in packets of either width answer as intersect / occluded do, ray
// by ray: the same hits, the same surface, t within the packet kernels' rounding, and the same
// again with the rays read at a stride. 2003 rays: a partial last packet at both widths; rays that
// miss the scene's box skip Embree between the others.
TEST(Accel, ManyAtOnceAgreesWithOneAtATimeAtEitherPacketWidth) {
  SceneDesc d = two_shapes(Vec3(0, 0, 0));
  Accel accel(d, {}, {});
  EXPECT_TRUE(accel.packet_width() == 8 || accel.packet_width() == 16);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  std::vector<Ray> rays;
  for (int i = 0; i < 2003; ++i) {
    Ray r;
    r.o = Vec3(3 * u(rng), 3 * u(rng), 3 * u(rng));
    r.d = i % 7 == 0 ? r.o : Vec3(0.3f * u(rng), 0.3f * u(rng), 0.6f) - r.o * 0.3f;  // some leave the centre
    r.tmin = 0;
    r.tmax = i % 3 == 0 ? 3.0f : kInf;
    rays.push_back(r);
  }
  for (int width : {8, 16}) {
    SCOPED_TRACE("packets of " + std::to_string(width));
    forms::Scoped forms;
    forms->packet_width = width;
    ASSERT_EQ(accel.packet_width(), width);
    std::vector<SurfaceHit> hits(rays.size());
    std::vector<uint8_t> found(rays.size(), 7), blocked(rays.size(), 7);
    accel.intersect_many(rays.data(), rays.size(), hits.data(), found.data());
    accel.occluded_many(rays.data(), rays.size(), blocked.data());
    int n_found = 0, n_blocked = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      SurfaceHit h;
      const bool want = accel.intersect(rays[i], h);
      ASSERT_EQ(found[i], want ? 1 : 0) << "ray " << i;
      ASSERT_EQ(blocked[i], accel.occluded(rays[i]) ? 1 : 0) << "ray " << i;
      n_found += want;
      n_blocked += blocked[i];
      if (!want) continue;
      EXPECT_NEAR(hit_t(rays[i], hits[i]), hit_t(rays[i], h), 1e-5f * (1 + hit_t(rays[i], h))) << "ray " << i;
      EXPECT_EQ(hits[i].material, h.material) << "ray " << i;
      EXPECT_NEAR(dot(hits[i].ng, h.ng), 1.0f, 1e-4f) << "ray " << i;
    }
    EXPECT_GT(n_found, 300);
    EXPECT_LT(n_found, int(rays.size()) - 300);
    EXPECT_GT(n_blocked, 300);

    // Rays read in place from larger records (as the path pool passes them) give the same answers.
    struct Record {
      uint32_t tag;
      Ray ray;
      float other[5];
    };
    std::vector<Record> records(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) records[i] = {uint32_t(i), rays[i], {}};
    std::vector<SurfaceHit> strided_hits(rays.size());
    std::vector<uint8_t> strided_found(rays.size(), 7);
    accel.intersect_many(&records[0].ray, sizeof(Record), rays.size(), strided_hits.data(), strided_found.data());
    for (size_t i = 0; i < rays.size(); ++i) {
      ASSERT_EQ(strided_found[i], found[i]) << "ray " << i;
      if (found[i]) EXPECT_EQ(hit_t(rays[i], strided_hits[i]), hit_t(rays[i], hits[i])) << "ray " << i;
    }
  }
}

// Embree answers only rays whose origin and direction components lie within +-1.844e18 and whose
// fields are numbers. Accel refuses the rest (no hit, no occlusion) in every call, and traces the
// others, however large within the limit or with an unbounded segment.
TEST(Accel, RaysOutsideEmbreesRangeAreRefusedTheRestTraced) {
  SceneDesc d = two_shapes(Vec3(0, 0, 0));
  Accel accel(d, {}, {});
  Ray aimed;  // from in front of the quad, straight at it: a hit when traced
  aimed.o = Vec3(0.1f, 0.1f, 3);
  aimed.d = Vec3(0, 0, -1);
  aimed.tmin = 0;
  aimed.tmax = kInf;
  std::vector<Ray> refused;
  for (int field = 0; field < 8; ++field) {  // a NaN in any field
    Ray r = aimed;
    float* f[8] = {&r.o.x, &r.o.y, &r.o.z, &r.d.x, &r.d.y, &r.d.z, &r.tmin, &r.tmax};
    *f[field] = NAN;
    refused.push_back(r);
  }
  // Still aimed at the quad, past the limit: a direction of 2e18, an origin 2e18 away.
  Ray long_dir = aimed, far_origin = aimed;
  long_dir.d = Vec3(0, 0, -2e18f);
  far_origin.o = Vec3(0.1f, 0.1f, 2e18f);
  refused.push_back(long_dir);
  refused.push_back(far_origin);
  Ray big = aimed;  // the largest direction Embree takes: still a hit
  big.d = Vec3(0, 0, -1.8e18f);
  std::vector<Ray> traced = {aimed, big};
  for (int width : {8, 16}) {
    forms::Scoped forms;
    forms->packet_width = width;
    std::vector<Ray> all = refused;
    all.insert(all.end(), traced.begin(), traced.end());
    std::vector<SurfaceHit> hits(all.size());
    std::vector<uint8_t> found(all.size(), 7), blocked(all.size(), 7);
    accel.intersect_many(all.data(), all.size(), hits.data(), found.data());
    accel.occluded_many(all.data(), all.size(), blocked.data());
    for (size_t i = 0; i < all.size(); ++i) {
      SurfaceHit h;
      const bool want = i >= refused.size();
      EXPECT_EQ(accel.intersect(all[i], h), want) << "ray " << i;
      EXPECT_EQ(accel.occluded(all[i]), want) << "ray " << i;
      EXPECT_EQ(found[i], want ? 1 : 0) << "ray " << i << ", packets of " << width;
      EXPECT_EQ(blocked[i], want ? 1 : 0) << "ray " << i << ", packets of " << width;
    }
  }
}

namespace {

// A ray against a box, in double precision (independent of Accel's float slab test).
bool ray_meets_box(const Ray& r, Vec3 lo, Vec3 hi) {
  double t0 = 0, t1 = INFINITY;
  for (int k = 0; k < 3; ++k) {
    double o = r.o[k], d = r.d[k];
    if (d == 0) {
      if (o < lo[k] || o > hi[k]) return false;
      continue;
    }
    double a = (lo[k] - o) / d, b = (hi[k] - o) / d;
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  return t0 <= t1;
}

// Every pixel the session skips as background: no jittered camera ray through it reaches the box
// of any object (nor the scene's box, outside the scene's rectangle), and none hits anything.
// Returns how many pixels were skipped.
int check_background_pixels(const RenderScene& scene, const RenderParams& p) {
  RenderSession session(scene, p);
  Vec3 lo, hi;
  EXPECT_TRUE(scene.accel->hit_bounds(lo, hi));
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  int skipped = 0;
  for (int fy = 0; fy < p.height; ++fy)
    for (int fx = 0; fx < p.width; ++fx) {
      if (!session.sees_only_background(fx, fy)) continue;
      ++skipped;
      // The pixel's corners and random points inside it; for a thin lens, through the lens rim
      // (concentric map: u on the square's edge midpoints) and random lens points.
      const Vec2 rim[4] = {{0.f, 0.5f}, {1.f, 0.5f}, {0.5f, 0.f}, {0.5f, 1.f}};
      for (int k = 0; k < 16; ++k) {
        float jx = k < 4 ? float(k & 1) : u(rng), jy = k < 4 ? float(k >> 1) : u(rng);
        Vec2 lens = k < 8 ? rim[k & 3] : Vec2{u(rng), u(rng)};
        Ray r = scene.camera.generate_ray((fx + jx) / p.width, (fy + jy) / p.height, lens);
        bool meets = false;
        for (const Bounds3& b : scene.object_bounds) meets |= ray_meets_box(r, b.lo, b.hi);
        if (scene.object_bounds.empty()) meets = ray_meets_box(r, lo, hi);
        SurfaceHit h;
        if (meets || scene.accel->intersect(r, h)) {
          ADD_FAILURE() << "pixel (" << fx << ", " << fy << ") is skipped as background but a ray through it meets the scene";
          return skipped;
        }
      }
    }
  return skipped;
}

}  // namespace

TEST(Background, SkippedPixelsSeeNoGeometry) {
  for (Vec3 offset : {Vec3(0, 0, 0), Vec3(3000, -2000, 1000)}) {
    SceneDesc d = two_shapes(offset);
    for (auto [w, h] : {std::pair<int, int>{480, 360}, {64, 48}, {200, 300}}) {
      RenderParams p;
      p.width = w;
      p.height = h;
      p.keep_fov = true;
      auto scene = make_render_scene(d, p);
      int skipped = check_background_pixels(*scene, p);
      EXPECT_LT(skipped, w * h) << "the shapes are in view";
      // Near the origin the course framing leaves a border of background the shortcut must find.
      // Far from it the bounds' padding (relative to the coordinates) puts the camera inside the
      // padded box: no shortcut, which is conservative, not wrong.
      if (offset.x == 0) EXPECT_GT(skipped, w * h / 10) << w << "x" << h;
    }
  }
  SceneDesc cornell = load_collada(std::string(PT_OWN_SCENES) + "/cornell.dae");
  RenderParams p;
  p.width = 160;
  p.height = 120;
  p.keep_fov = true;
  check_background_pixels(*make_render_scene(cornell, p), p);
}

// Two small spheres far apart: the scene's rectangle holds both and the empty space between them;
// the objects' own rectangles leave that space to the background shortcut.
TEST(Background, ObjectRectanglesSkipTheEmptySpaceBetweenObjects) {
  SceneDesc d = test::two_small_spheres();
  for (float lens : {0.0f, 0.05f}) {
    RenderParams p;
    p.width = 120;
    p.height = 90;
    p.keep_fov = true;
    p.lens_radius = lens;
    auto scene = make_render_scene(d, p);
    ASSERT_EQ(scene->object_bounds.size(), 2u);
    int skipped = check_background_pixels(*scene, p);
    RenderSession session(*scene, p);
    EXPECT_TRUE(session.sees_only_background(p.width / 2, p.height / 2)) << "the centre, between the spheres";
    EXPECT_GT(skipped, p.width * p.height * 8 / 10) << "lens " << lens;
  }
}

TEST(Background, ThinLensSkipsOnlyPixelsNoLensPointSeesGeometryThrough) {
  SceneDesc d = two_shapes(Vec3(0, 0, 0));
  RenderParams p;
  p.width = 96;
  p.height = 72;
  p.keep_fov = true;
  const int pinhole = check_background_pixels(*make_render_scene(d, p), p);
  for (float radius : {0.05f, 0.3f})
    for (float focus : {1.0f, 4.7f, 50.0f}) {
      p.lens_radius = radius;  // rays leave from anywhere on the lens: the rectangle grows with the blur
      p.focal_distance = focus;
      int skipped = check_background_pixels(*make_render_scene(d, p), p);
      EXPECT_LE(skipped, pinhole) << radius << " " << focus;
      if (radius > 0.1f && focus != 4.7f) EXPECT_LT(skipped, pinhole) << "a large blur must grow the rectangle";
      if (radius < 0.1f) EXPECT_GT(skipped, pinhole / 2) << "a small lens keeps most of the shortcut, focus " << focus;
    }
}

// A cell (-p) builds its own background mask for its window of the frame: every frame pixel in the
// window must be background in the cell exactly when it is in the full frame (the mask's row and
// column offsets and its y flip), for the scene rectangle alone and with objects' rectangles.
TEST(Background, CellMasksAgreeWithTheFullFrame) {
  for (const SceneDesc& d : {two_shapes(Vec3(0, 0, 0)), test::two_small_spheres()}) {
    RenderParams p;
    p.width = 120;
    p.height = 90;
    p.keep_fov = true;
    auto scene = make_render_scene(d, p);
    RenderSession full(*scene, p);
    int background = 0;
    for (int fy = 0; fy < p.height; ++fy)
      for (int fx = 0; fx < p.width; ++fx) background += full.sees_only_background(fx, fy);
    EXPECT_GT(background, p.width * p.height / 10);
    EXPECT_LT(background, p.width * p.height);
    for (auto [cx, cy, cw, ch] : {std::array<int, 4>{0, 0, 40, 30}, {37, 11, 53, 61}, {100, 70, 20, 20}, {0, 45, 120, 45}}) {
      RenderParams c = p;
      c.cell_x = cx, c.cell_y = cy, c.cell_w = cw, c.cell_h = ch;
      RenderSession cell(*make_render_scene(d, c), c);
      for (int fy = cy; fy < cy + ch; ++fy)
        for (int fx = cx; fx < cx + cw; ++fx)
          ASSERT_EQ(cell.sees_only_background(fx, fy), full.sees_only_background(fx, fy))
              << "frame pixel " << fx << " " << fy << " in cell " << cx << " " << cy << " " << cw << " " << ch;
    }
  }
}
