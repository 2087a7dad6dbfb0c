// Diffuse vertices in SSE2 lanes (see diffuse_lanes.h). Every expression keeps the scalar code's
// operation order (a dot product is (x x' + y y') + z z', a / s is a * (1 / s)), and SSE's add,
// multiply, divide and square root round as the scalar instructions do, so each lane computes the
// scalar path_step's bits. No FMA: the portable build has none, and contraction would change them.
#include "diffuse_lanes.h"

#include "simd.h"

namespace pt::lanes {

namespace {

using namespace simd;

// offset_ray_origin (accel.h), one coordinate.
inline vf offset_coordinate(vf p, vf n) {
  constexpr float origin = 1.0f / 32.0f, float_scale = 1.0f / 65536.0f, int_scale = 256.0f;
  vi of = vi(_mm_cvttps_epi32(__m128(splat(int_scale) * n)));
  vi bits = vi(p) + ((p < 0) ? -of : of);
  return sel(fabs(p) < origin, p + splat(float_scale) * n, vf(bits));
}
inline V3 offset_origin(V3 p, V3 n) {
  return {offset_coordinate(p.x, n.x), offset_coordinate(p.y, n.y), offset_coordinate(p.z, n.z)};
}

// The shading frame of path_step: normals turned to the viewer (face_viewer, opaque), then
// Frame(ns) (Duff et al. 2017), and the outgoing direction in it.
struct Shading {
  V3 ng, s, t, n, wo;  // wo local
};
__attribute__((always_inline)) inline Shading shading(const DiffuseVertices& v, int i) {
  Shading sh;
  V3 wo_world = neg(load3(v.dx, v.dy, v.dz, i));
  V3 ng = load3(v.gx, v.gy, v.gz, i), ns = load3(v.nx, v.ny, v.nz, i);
  vi flip = dot(wo_world, ng) < 0;
  ng = sel(flip, neg(ng), ng);
  ns = sel(flip, neg(ns), ns);
  ns = sel(dot(wo_world, ns) <= 0, ng, ns);
  vf sign = vf((vi(ns.z) & int32_t(0x80000000)) | vi(splat(1.0f)));  // copysign(1, n.z)
  vf a = splat(-1.0f) / (sign + ns.z);
  vf b = ns.x * ns.y * a;
  sh.s = {splat(1.0f) + sign * ns.x * ns.x * a, sign * b, -sign * ns.x};
  sh.t = {b, sign + ns.y * ns.y * a, -ns.y};
  sh.n = ns;
  sh.ng = ng;
  sh.wo = {dot(wo_world, sh.s), dot(wo_world, sh.t), dot(wo_world, sh.n)};
  return sh;
}

}  // namespace

void light_pass(DiffuseVertices& v, int n, const Light& light, int samples) {
  const V3 position = broadcast(light.position), dim_x = broadcast(light.dim_x), dim_y = broadcast(light.dim_y);
  const V3 rect_normal = broadcast(light.direction), color = broadcast(light.color);
  const bool rect = light.kind == LightKind::rect;
  const vf area = splat(light.area), half = splat(0.5f), inv_pi = splat(kInvPi), count = splat(float(samples));
  for (int i = 0; i < n; i += 4) {
    const Shading sh = shading(v, i);
    const V3 p = load3(v.px, v.py, v.pz, i);
    // sample_light for a rectangle or a given point of a mesh light
    V3 q = rect ? add(add(position, mul(dim_x, load(v.ulx + i) - half)), mul(dim_y, load(v.uly + i) - half))
                : load3(v.qx, v.qy, v.qz, i);
    V3 normal = rect ? rect_normal : load3(v.lx, v.ly, v.lz, i);
    V3 d = sub(q, p);
    vf dist2 = dot(d, d);
    V3 wi = mul(d, splat(1.0f) / sqrt(dist2));
    vf cos_l = -dot(wi, normal);
    vf pdf = dist2 / (area * cos_l);
    vi ok = (dist2 > 0) & (cos_l > 0) & is_finite(pdf) & (pdf > 0);
    ok &= ~(dot(wi, sh.ng) <= 0);  // below the surface (the scalar test's form, NaN included)
    V3 wl = {dot(wi, sh.s), dot(wi, sh.t), dot(wi, sh.n)};
    vi lobe = (sh.wo.z > 0) & (wl.z > 0);  // diffuse_eval
    V3 albedo = load3(v.ax, v.ay, v.az, i);
    V3 f = mul(albedo, inv_pi);
    f = sel(lobe, f, V3{vf{}, vf{}, vf{}});
    ok &= ~is_black(f);
    // power_heuristic(samples x pdf, diffuse_pdf)
    vf pdf_a = count * pdf;
    vf pdf_b = sel(sh.wo.z > 0, sel(wl.z > 0, wl.z * inv_pi, vf{}), vf{});
    vf r = pdf_b / pdf_a;
    vf w = sel(pdf_a == splat(kInf), splat(1.0f), sel(pdf_a > 0, splat(1.0f) / (splat(1.0f) + r * r), vf{}));
    V3 c = mul(mul(f, color), fabs(wl.z) * w / (pdf * count));
    // spawn_ray_to: from the hit, pushed to the target's side of Embree's normal
    V3 g = load3(v.gx, v.gy, v.gz, i);
    V3 nn = sel(dot(sub(q, p), g) >= 0, g, neg(g));
    V3 o = offset_origin(add(p, mul(nn, load(v.offset + i))), nn);
    storei(v.shadow + i, ok);
    store3(v.sox, v.soy, v.soz, i, o);
    store3(v.sdx, v.sdy, v.sdz, i, sub(q, o));
    store3(v.cx, v.cy, v.cz, i, c);
  }
}

void bounce_pass(DiffuseVertices& v, int n) {
  const vf one = splat(1.0f), inv_pi = splat(kInvPi);
  for (int i = 0; i < n; i += 4) {
    const Shading sh = shading(v, i);
    vf x, y;  // sample_cosine_hemisphere (sampling.h)
    concentric_disk(load(v.ubx + i), load(v.uby + i), x, y);
    vf z = sqrt(max0(one - x * x - y * y));
    vf pdf = sel(z > 0, z * inv_pi, vf{});
    vi ok = ~(sh.wo.z <= 0) & ~(pdf <= 0);  // diffuse_sample's tests, in their form (NaN passes them)
    V3 wi = add(add(mul(sh.s, x), mul(sh.t, y)), mul(sh.n, z));  // Frame::to_world
    ok &= ~(dot(wi, sh.ng) <= 0);  // reflection leaves on the viewer's side
    V3 beta = mul(load3(v.bx, v.by, v.bz, i), load3(v.ax, v.ay, v.az, i));
    ok &= ~is_black(beta) & all_finite(beta);
    // Russian roulette (urr is 2 where it is not played: it never ends those paths)
    vf m = sel(beta.x < sel(beta.y < beta.z, beta.z, beta.y), sel(beta.y < beta.z, beta.z, beta.y), beta.x);
    vf q = sel(m < splat(0.95f), m, splat(0.95f));
    vf urr = load(v.urr + i);
    vi played = urr < splat(1.5f);
    ok &= ~(played & (urr >= q));
    beta = sel(played, mul(beta, one / q), beta);
    // spawn_ray
    const V3 p = load3(v.px, v.py, v.pz, i), g = load3(v.gx, v.gy, v.gz, i);
    V3 nn = sel(dot(wi, g) >= 0, g, neg(g));
    V3 o = offset_origin(add(p, mul(nn, load(v.offset + i))), nn);
    storei(v.alive + i, ok);
    store3(v.bx, v.by, v.bz, i, beta);
    store3(v.ox, v.oy, v.oz, i, o);
    store3(v.wx, v.wy, v.wz, i, wi);
    store(v.pdf + i, pdf);
  }
}

}  // namespace pt::lanes
