// The COLLADA reader on the course scenes in ../shared/scenes-cs184 (skipped cleanly when absent).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "collada.h"
#include "test_util.h"
#include "collada_docs.h"

namespace pt {
namespace {

using namespace collada_docs;

// ============================================================================================
// The course scenes in ../shared/scenes-cs184

const MeshDesc* find_mesh(const SceneDesc& s, const std::string& name) {
  for (const MeshDesc& m : s.meshes)
    if (m.name == name) return &m;
  return nullptr;
}
const Material& mesh_material(const SceneDesc& s, const std::string& name) {
  const MeshDesc* m = find_mesh(s, name);
  static const Material none;
  EXPECT_NE(m, nullptr) << "no mesh " << name;
  if (!m || m->tri_material.empty()) return none;
  return s.materials.at(m->tri_material[0]);
}

// The Cornell box that every CB scene shares: 5 walls x 2 triangles, x,z in [-1,1], y in [0,1.5].
void expect_cornell_box(const SceneDesc& s) {
  for (const char* wall : {"ceiling-mesh", "floor-mesh", "leftWall-mesh", "rightWall-mesh", "backWall-mesh"}) {
    const MeshDesc* m = find_mesh(s, wall);
    ASSERT_NE(m, nullptr) << wall;
    EXPECT_EQ(m->indices.size(), 6u) << wall;
    EXPECT_TRUE(m->normals.empty()) << wall << " is flat";
    for (const Vec3& p : m->positions) {
      EXPECT_LE(std::fabs(p.x), 1.0f + 1e-4f) << wall;
      EXPECT_LE(std::fabs(p.z), 1.0f + 5e-3f) << wall;
      EXPECT_GE(p.y, -1e-4f) << wall;
      EXPECT_LE(p.y, 1.5f + 1e-4f) << wall;
    }
  }
  EXPECT_TRUE(vec_near(mesh_material(s, "floor-mesh").albedo, {0.6f, 0.6f, 0.6f}));
  EXPECT_TRUE(vec_near(mesh_material(s, "ceiling-mesh").albedo, {0.6f, 0.6f, 0.6f}));
  EXPECT_TRUE(vec_near(mesh_material(s, "backWall-mesh").albedo, {0.6f, 0.6f, 0.6f}));
  EXPECT_TRUE(vec_near(mesh_material(s, "leftWall-mesh").albedo, {0.6f, 0.2f, 0.2f}));
  EXPECT_TRUE(vec_near(mesh_material(s, "rightWall-mesh").albedo, {0.2f, 0.2f, 0.6f}));
}

// The 0.6 x 0.8 area light at y = 1.49 facing down, radiance 10.
void expect_cornell_area_light(const SceneDesc& s) {
  ASSERT_EQ(s.lights.size(), 1u);
  const LightDesc& l = s.lights[0];
  EXPECT_EQ(l.type, LightType::area);
  EXPECT_TRUE(vec_near(l.color, {10, 10, 10}));
  EXPECT_NEAR(l.position.y, 1.49f, 1e-5f);
  EXPECT_NEAR(l.position.x, 0.0f, 1e-5f);
  EXPECT_NEAR(l.position.z, 0.0f, 5e-3f);
  EXPECT_TRUE(vec_near(l.direction, {0, -1, 0}, 1e-5f));
  EXPECT_NEAR(std::fabs(l.dim_x.x), 0.6f, 1e-5f);
  EXPECT_NEAR(std::fabs(l.dim_y.z), 0.8f, 1e-5f);
  EXPECT_NEAR(length(l.dim_x) * length(l.dim_y), 0.48f, 1e-5f);
  EXPECT_NEAR(dot(l.dim_x, l.direction), 0.0f, 1e-5f);
  EXPECT_NEAR(dot(l.dim_y, l.direction), 0.0f, 1e-5f);
}

void expect_course_camera(const SceneDesc& s, float aspect, float z) {
  ASSERT_TRUE(s.camera.present);
  EXPECT_FLOAT_EQ(s.camera.xfov_deg, 49.13434f);
  EXPECT_NEAR(s.camera.aspect, aspect, 1e-5f);
  EXPECT_FLOAT_EQ(s.camera.znear, 0.1f);
  EXPECT_FLOAT_EQ(s.camera.zfar, 100);
  EXPECT_TRUE(vec_near(s.camera.world.point({0, 0, 0}), {0, 0, z}));
}

TEST(ColladaCourseScene, CBempty) {
  PT_REQUIRE_SHARED_SCENE(path, "CBempty.dae");
  SceneDesc s = load_collada(path);
  EXPECT_EQ(s.source, path);
  EXPECT_EQ(s.triangle_count(), 10u);
  EXPECT_EQ(s.meshes.size(), 5u);
  EXPECT_TRUE(s.spheres.empty());
  expect_cornell_box(s);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].type, LightType::point);
  EXPECT_TRUE(vec_near(s.lights[0].color, {5, 5, 5}));
  EXPECT_TRUE(vec_near(s.lights[0].position, {0, 1.49f, 0.004315853f}, 1e-5f));
  expect_course_camera(s, 1.777778f, 3);
}

TEST(ColladaCourseScene, CBspheres) {
  PT_REQUIRE_SHARED_SCENE(path, "CBspheres.dae");
  SceneDesc s = load_collada(path);
  EXPECT_EQ(s.triangle_count(), 10u);
  expect_cornell_box(s);
  expect_cornell_area_light(s);
  expect_course_camera(s, 1.333333f, 3);
  ASSERT_EQ(s.spheres.size(), 2u);
  // Sphere1 (glass) at (-0.4, 0.3, 0.3) Z-up -> (0.4, 0.3, 0.3); Sphere2 (mirror) -> (-0.4, 0.3, -0.3).
  EXPECT_TRUE(vec_near(s.spheres[0].center, {0.4f, 0.3f, 0.3f}));
  EXPECT_TRUE(vec_near(s.spheres[1].center, {-0.4f, 0.3f, -0.3f}));
  for (const SphereDesc& sp : s.spheres) EXPECT_NEAR(sp.radius, 0.3f, 1e-6f);
  const Material& glass = s.materials.at(s.spheres[0].material);
  EXPECT_EQ(glass.type, MaterialType::glass);
  EXPECT_FLOAT_EQ(glass.ior, 1.45f);
  EXPECT_TRUE(vec_near(glass.albedo, {1, 1, 1}));
  EXPECT_TRUE(vec_near(glass.transmittance, {1, 1, 1}));
  const Material& mirror = s.materials.at(s.spheres[1].material);
  EXPECT_EQ(mirror.type, MaterialType::mirror);
  EXPECT_TRUE(vec_near(mirror.albedo, {1, 1, 1}));
  // The light mesh's node is commented out: no emissive geometry.
  EXPECT_EQ(find_mesh(s, "light-mesh"), nullptr);
}

TEST(ColladaCourseScene, CBspheresLambertian) {
  PT_REQUIRE_SHARED_SCENE(path, "CBspheres_lambertian.dae");
  SceneDesc s = load_collada(path);
  EXPECT_EQ(s.triangle_count(), 10u);
  expect_cornell_box(s);
  expect_cornell_area_light(s);
  ASSERT_EQ(s.spheres.size(), 2u);
  for (const SphereDesc& sp : s.spheres) {
    EXPECT_NEAR(sp.radius, 0.3f, 1e-6f);
    const Material& m = s.materials.at(sp.material);
    EXPECT_EQ(m.type, MaterialType::diffuse);
    EXPECT_TRUE(vec_near(m.albedo, {0.8f, 0.8f, 0.8f}));
  }
}

TEST(ColladaCourseScene, CBspheresMicrofacetAlAg) {
  PT_REQUIRE_SHARED_SCENE(path, "CBspheres_microfacet_al_ag.dae");
  SceneDesc s = load_collada(path);
  EXPECT_EQ(s.triangle_count(), 10u);
  expect_cornell_box(s);
  expect_cornell_area_light(s);
  ASSERT_EQ(s.spheres.size(), 2u);
  const Material* silver = nullptr;
  const Material* aluminium = nullptr;
  for (const SphereDesc& sp : s.spheres) {
    EXPECT_NEAR(sp.radius, 0.3f, 1e-6f);
    const Material& m = s.materials.at(sp.material);
    EXPECT_EQ(m.type, MaterialType::microfacet);
    if (m.alpha == 0.25f) silver = &m;
    if (m.alpha == 0.025f) aluminium = &m;
  }
  ASSERT_NE(silver, nullptr) << "no sphere with alpha 0.25";
  ASSERT_NE(aluminium, nullptr) << "no sphere with alpha 0.025";
  EXPECT_TRUE(vec_near(silver->eta, {0.059193f, 0.059881f, 0.047366f}));
  EXPECT_TRUE(vec_near(silver->k, {4.1283f, 3.5892f, 2.8132f}));
  EXPECT_TRUE(vec_near(aluminium->eta, {1.3352f, 1.0109f, 0.68955f}));
  EXPECT_TRUE(vec_near(aluminium->k, {7.3398f, 6.6157f, 5.6471f}));
}

TEST(ColladaCourseScene, CBbunny) {
  PT_REQUIRE_SHARED_SCENE(path, "CBbunny.dae");
  SceneDesc s = load_collada(path);
  EXPECT_EQ(s.triangle_count(), 10u + 28576u);
  expect_cornell_box(s);
  expect_cornell_area_light(s);
  expect_course_camera(s, 1.777778f, -3);  // the camera is on the -z side
  const MeshDesc* bunny = find_mesh(s, "Mesh-mesh");
  ASSERT_NE(bunny, nullptr);
  EXPECT_EQ(bunny->indices.size(), 3u * 28576u);
  const Material& m = mesh_material(s, "Mesh-mesh");
  EXPECT_EQ(m.type, MaterialType::diffuse);
  EXPECT_TRUE(vec_near(m.albedo, {0.5f, 0.5f, 0.5f}));
  // Curved: smooth unit normals, one per vertex.
  ASSERT_EQ(bunny->normals.size(), bunny->positions.size());
  for (size_t i = 0; i < bunny->normals.size(); i += 97) EXPECT_NEAR(length(bunny->normals[i]), 1.0f, 1e-4f) << i;
  // The bunny sits inside the box.
  Bounds3 b;
  for (const Vec3& p : bunny->positions) b.expand(p);
  EXPECT_GT(b.lo.y, -1e-3f);
  EXPECT_LT(b.hi.y, 1.5f);
  EXPECT_GT(b.lo.x, -1.0f);
  EXPECT_LT(b.hi.x, 1.0f);
}

TEST(ColladaCourseScene, CBdragon) {
  PT_REQUIRE_SHARED_SCENE(path, "CBdragon.dae");
  SceneDesc s = load_collada(path);
  const MeshDesc* dragon = find_mesh(s, "dragon-mesh");
  const MeshDesc* quad = find_mesh(s, "light-mesh");
  ASSERT_NE(dragon, nullptr);
  ASSERT_NE(quad, nullptr);
  EXPECT_EQ(dragon->indices.size(), 3u * 100000u);
  EXPECT_EQ(dragon->positions.size(), 50000u);
  EXPECT_EQ(quad->indices.size(), 6u);
  EXPECT_EQ(s.triangle_count(), 100000u + 10u + 2u);
  expect_cornell_box(s);
  expect_cornell_area_light(s);
  // Mirror dragon (its common diffuse 0.28 is ignored).
  const Material& dm = mesh_material(s, "dragon-mesh");
  EXPECT_EQ(dm.type, MaterialType::mirror);
  EXPECT_TRUE(vec_near(dm.albedo, {1.0f, 0.8f, 0.4f}));
  // The active emissive quad: 0.8 x 0.6 at y = 1.49, coplanar with the area light.
  const Material& qm = mesh_material(s, "light-mesh");
  EXPECT_EQ(qm.type, MaterialType::emission);
  EXPECT_TRUE(vec_near(qm.radiance, {10, 10, 10}));
  EXPECT_NEAR(mesh_area(*quad), 0.48, 1e-5);
  for (const Vec3& p : quad->positions) EXPECT_NEAR(p.y, 1.49f, 1e-5f);
  // Its winding faces down into the box, as its file normals say.
  for (size_t t = 0; t < quad->indices.size(); t += 3) {
    const Vec3* v = quad->positions.data();
    EXPECT_LT(cross(v[quad->indices[t + 1]] - v[quad->indices[t]], v[quad->indices[t + 2]] - v[quad->indices[t]]).y, 0);
  }
  // Curved dragon: unit vertex normals.
  ASSERT_EQ(dragon->normals.size(), dragon->positions.size());
  for (size_t i = 0; i < dragon->normals.size(); i += 101) EXPECT_NEAR(length(dragon->normals[i]), 1.0f, 1e-4f) << i;
}

}  // namespace
}  // namespace pt
