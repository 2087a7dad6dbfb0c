// What the caustic light tracer (caustics.h) needs to know of a scene, found once when its base
// is built: where the delta geometry is (what light paths aim at) and whether emitters share a
// plane with another surface. Scene analysis only; the light tracer is caustics.cpp.
#pragma once

#include <vector>

#include "math.h"

namespace pt {

struct Material;
struct SceneDesc;

// A sphere that bounds geometry with a delta material: what light paths are aimed at.
struct CausticTarget {
  Vec3 center;
  float radius = 0;
};

// One bounding sphere per sphere with a delta material and one per mesh for its delta triangles;
// past kMaxCausticTargets of them, one sphere around them all (a light path weighs every cone).
constexpr size_t kMaxCausticTargets = 64;
std::vector<CausticTarget> find_caustic_targets(const SceneDesc& desc, const std::vector<Material>& materials);

// Whether an emitter (area light or emissive triangle) has another surface in its plane over it, as
// the course's CBdragon has an area light and an emissive quad in one plane: where two surfaces
// overlap, a ray sees one of them, and light paths must check which (caustics.cpp,
// light_seen_from) or they would count both. Conservative: faces that only touch count too.
bool emitters_share_a_plane(const SceneDesc& desc, const std::vector<Material>& materials);

}  // namespace pt
