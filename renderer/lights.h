// Lights as the integrator sees them: sampling from a shading point, pdfs for MIS, and the
// importance-sampled environment map.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "math.h"
#include "sampling.h"

namespace pt {

// Lat-long environment map with the course's mapping: theta = acos(y) (0 = +Y, top row),
// phi = atan2(-z, x) + pi. Sampled in proportion to luminance x sin(theta).
class EnvironmentMap {
 public:
  EnvironmentMap(int width, int height, std::vector<Vec3> texels);
  Vec3 lookup(Vec3 dir) const;  // bilinear, wraps in phi, clamps in theta
  Vec3 sample(Vec2 u, float* pdf) const;
  float pdf(Vec3 dir) const;
  int width() const { return m_w; }
  int height() const { return m_h; }

 private:
  int m_w, m_h;
  std::vector<Vec3> m_texels;
  Distribution1D m_marginal;                 // over rows
  std::vector<Distribution1D> m_conditional;  // within each row
};

enum class LightKind { rect, mesh, point, spot, directional, ambient, environment };
const char* light_kind_name(LightKind kind);

struct Light {
  LightKind kind = LightKind::point;
  std::string name;
  Vec3 color;            // radiance / intensity / irradiance, by kind
  Vec3 position;         // rect centre, point and spot position
  Vec3 direction;        // rect facing normal, spot axis, directional: direction light travels
  Vec3 dim_x, dim_y;     // rect edges
  float area = 0;        // rect and mesh
  float cos_cutoff = -1; // spot: cosine of the half angle
  float exponent = 0;    // spot fall-off exponent
  // glTF spot: the width, in cos(theta), of the edge band where the intensity rises as a smoothstep
  // from the cone's edge (Blender's spot_blend, as its glTF importer sets it); 0: a hard edge.
  float spot_smooth = 0;
  bool sphere = false;   // ambient: every direction, not only the +Y hemisphere (the default light)
  bool two_sided = false;  // mesh: both faces emit (a double-sided glTF emitter)
  std::vector<Vec3> triangles;  // mesh: three corners per triangle, world space
  std::vector<Vec3> triangle_normals;  // mesh: each triangle's unit normal, kept off the sampling path
  Distribution1D triangle_distribution;
  const EnvironmentMap* env = nullptr;

  bool is_delta() const { return kind == LightKind::point || kind == LightKind::spot || kind == LightKind::directional; }
  bool is_infinite() const {
    return kind == LightKind::directional || kind == LightKind::ambient || kind == LightKind::environment;
  }
};

// An area light's normal at a sampled point, turned towards `to` (from the point) when both of the
// light's faces emit.
inline Vec3 facing_normal(const Light& l, Vec3 n, Vec3 to) { return l.two_sided && dot(to, n) < 0 ? -n : n; }

struct LightSample {
  Vec3 wi;         // unit direction from the shading point towards the light
  Vec3 radiance;   // arriving radiance (or intensity / d^2 for point and spot)
  float pdf = 0;   // solid angle; 1 for delta lights
  Vec3 point;      // point on the light (finite lights), for the shadow ray
  bool infinite = false;
};

// A point on an area emitter (rect or mesh), uniform by area, and the unit normal of the side it
// emits to. Shared by light sampling and the caustic light paths that leave it.
void sample_area_light_point(const Light& light, Vec2 u, Vec3& point, Vec3& normal);
// Samples a direction towards the light from p. Returns false when the light cannot contribute.
bool sample_light(const Light& light, Vec3 p, Vec2 u, LightSample& s);
// Solid-angle pdf that sample_light would pick the direction from p to a point on an area
// emitter (rect / mesh) with unit normal n_light at distance d.
float area_light_pdf(const Light& light, Vec3 p, Vec3 light_point, Vec3 n_light);
// Radiance of an infinite light (ambient / environment) seen along dir, and its sampling pdf.
Vec3 infinite_light_radiance(const Light& light, Vec3 dir);
float infinite_light_pdf(const Light& light, Vec3 dir);

}  // namespace pt
