// Light sampling (uniform area sampling for rectangles and emissive meshes, delta lights with
// inverse-square fall-off) and the importance-sampled environment map.
#include "lights.h"

#include "scene.h"

namespace pt {

const char* light_kind_name(LightKind kind) {
  switch (kind) {
    case LightKind::rect: return "area";
    case LightKind::mesh: return "mesh";
    case LightKind::point: return "point";
    case LightKind::spot: return "spot";
    case LightKind::directional: return "directional";
    case LightKind::ambient: return "ambient";
    case LightKind::environment: return "environment";
  }
  return "?";
}

const char* light_type_name(LightType type) {
  switch (type) {
    case LightType::area: return "area";
    case LightType::point: return "point";
    case LightType::directional: return "directional";
    case LightType::spot: return "spot";
    case LightType::ambient: return "ambient";
  }
  return "?";
}

// ---- environment map ----

namespace {
inline Vec3 env_direction(float u, float v) {
  float phi = 2 * kPi * u, theta = kPi * v;
  float st = std::sin(theta);
  return {-st * std::cos(phi), std::cos(theta), st * std::sin(phi)};
}
inline Vec2 env_uv(Vec3 d) {
  float theta = std::acos(clampf(d.y, -1, 1));
  float phi = std::atan2(-d.z, d.x) + kPi;
  return {phi / (2 * kPi), theta / kPi};
}
}  // namespace

EnvironmentMap::EnvironmentMap(int width, int height, std::vector<Vec3> texels)
    : m_w(width), m_h(height), m_texels(std::move(texels)) {
  // Non-finite or negative texels would poison sums; they are read as black.
  for (Vec3& t : m_texels)
    if (!is_finite(t) || t.x < 0 || t.y < 0 || t.z < 0) t = Vec3(0.0f);
  std::vector<float> row_weight(m_h);
  m_conditional.reserve(m_h);
  for (int y = 0; y < m_h; ++y) {
    float sin_theta = std::sin(kPi * (y + 0.5f) / m_h);
    std::vector<float> w(m_w);
    double sum = 0;
    for (int x = 0; x < m_w; ++x) {
      w[x] = luminance(m_texels[size_t(y) * m_w + x]) * sin_theta;
      sum += w[x];
    }
    m_conditional.emplace_back(w);
    row_weight[y] = float(sum);
  }
  m_marginal = Distribution1D(row_weight);
}

Vec3 EnvironmentMap::lookup(Vec3 dir) const {
  Vec2 uv = env_uv(dir);
  float fx = uv.x * m_w - 0.5f, fy = uv.y * m_h - 0.5f;
  int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  float tx = fx - x0, ty = fy - y0;
  auto at = [&](int x, int y) {
    x = ((x % m_w) + m_w) % m_w;
    y = std::min(std::max(y, 0), m_h - 1);
    return m_texels[size_t(y) * m_w + x];
  };
  return (at(x0, y0) * (1 - tx) + at(x0 + 1, y0) * tx) * (1 - ty) +
         (at(x0, y0 + 1) * (1 - tx) + at(x0 + 1, y0 + 1) * tx) * ty;
}

Vec3 EnvironmentMap::sample(Vec2 u, float* pdf) const {
  if (m_marginal.total() <= 0) {
    *pdf = 0;
    return Vec3(0, 1, 0);
  }
  float p_row, p_col, uy, ux;
  size_t y = m_marginal.sample_discrete(u.y, &p_row, &uy);
  size_t x = m_conditional[y].sample_discrete(u.x, &p_col, &ux);
  float fu = (x + ux) / m_w, fv = (y + uy) / m_h;
  Vec3 d = env_direction(fu, fv);
  float sin_theta = std::sin(kPi * fv);
  // p(u, v) = p_row p_col w h; p(omega) = p(u, v) / (2 pi^2 sin theta).
  *pdf = sin_theta > 0 ? p_row * p_col * m_w * m_h / (2 * kPi * kPi * sin_theta) : 0;
  return d;
}

float EnvironmentMap::pdf(Vec3 dir) const {
  if (m_marginal.total() <= 0) return 0;
  Vec2 uv = env_uv(dir);
  int x = std::min(int(uv.x * m_w), m_w - 1), y = std::min(int(uv.y * m_h), m_h - 1);
  float sin_theta = std::sin(kPi * uv.y);
  if (sin_theta <= 0) return 0;
  return m_marginal.discrete_pdf(y) * m_conditional[y].discrete_pdf(x) * m_w * m_h / (2 * kPi * kPi * sin_theta);
}

// ---- light sampling ----

void sample_area_light_point(const Light& light, Vec2 u, Vec3& point, Vec3& normal) {
  if (light.kind == LightKind::rect) {
    point = lane1::rect_light_point(light.position, light.dim_x, light.dim_y, u);
    normal = light.direction;
    return;
  }
  float prob, ux;
  size_t t = light.triangle_distribution.sample_discrete(u.x, &prob, &ux);
  Vec2 b = sample_uniform_triangle({ux, u.y});
  const Vec3* v = &light.triangles[3 * t];
  point = v[0] * b.x + v[1] * b.y + v[2] * (1 - b.x - b.y);
  normal = light.triangle_normals[t];
}

bool sample_light(const Light& light, Vec3 p, Vec2 u, LightSample& s) {
  s.infinite = false;
  switch (light.kind) {
    case LightKind::rect:
    case LightKind::mesh: {
      Vec3 q, n;
      sample_area_light_point(light, u, q, n);
      n = facing_normal(light, n, p - q);
      s.radiance = light.color;
      s.point = q;
      return lane1::sample_area_light(p, q, n, light.area, s.wi, s.pdf);
    }
    case LightKind::point:
    case LightKind::spot: {
      Vec3 d = light.position - p;
      float dist2 = length_squared(d);
      if (!(dist2 > 0)) return false;
      s.wi = d / std::sqrt(dist2);
      float falloff = 1;
      if (light.kind == LightKind::spot) {
        float c = dot(-s.wi, light.direction);
        if (c < light.cos_cutoff) return false;
        falloff = light.exponent > 0 ? std::pow(std::max(c, 0.0f), light.exponent) : 1.0f;
        const float t = c - light.cos_cutoff;
        if (t < light.spot_smooth) {  // glTF: Cycles' smoothstep edge (docs/gltf.md)
          const float x = t / light.spot_smooth;
          falloff *= x * x * (3 - 2 * x);
        }
      }
      s.radiance = light.color * (falloff / dist2);
      s.pdf = 1;
      s.point = light.position;
      return is_finite(s.radiance);
    }
    case LightKind::directional:
      s.wi = -light.direction;
      s.radiance = light.color;
      s.pdf = 1;
      s.infinite = true;
      return true;
    case LightKind::ambient: {
      if (light.sphere) {
        s.wi = sample_uniform_sphere(u);
        s.pdf = uniform_sphere_pdf();
      } else {
        Vec3 h = sample_uniform_hemisphere(u);  // around +Y
        s.wi = Vec3(h.x, h.z, h.y);
        s.pdf = uniform_hemisphere_pdf();
      }
      s.radiance = light.color;
      s.infinite = true;
      return true;
    }
    case LightKind::environment: {
      float pdf;
      s.wi = light.env->sample(u, &pdf);
      if (!(pdf > 0)) return false;
      s.pdf = pdf;
      s.radiance = light.env->lookup(s.wi);
      s.infinite = true;
      return true;
    }
  }
  return false;
}

float area_light_pdf(const Light& light, Vec3 p, Vec3 light_point, Vec3 n_light) {
  return lane1::area_light_pdf(p, light_point, n_light, light.area);
}

Vec3 infinite_light_radiance(const Light& light, Vec3 dir) {
  if (light.kind == LightKind::ambient) return dir.y > 0 || light.sphere ? light.color : Vec3(0.0f);
  if (light.kind == LightKind::environment) return light.env->lookup(dir);
  return Vec3(0.0f);
}

float infinite_light_pdf(const Light& light, Vec3 dir) {
  if (light.kind == LightKind::ambient) return light.sphere ? uniform_sphere_pdf() : dir.y > 0 ? uniform_hemisphere_pdf() : 0;
  if (light.kind == LightKind::environment) return light.env->pdf(dir);
  return 0;
}

}  // namespace pt
