// The minimal path loop of minimal_loop.h with its own work in AVX2 lanes, eight paths at a time:
// a measure of how much of that loop's time a ray wide lanes take away, with its rays going
// through Accel's array interface (Ray and SurfaceHit records, packed into Embree's packets there:
// pass) or kept in Embree's own packet layout (pass_in_place). The same paths as the scalar loop:
// a pool of 256, camera rays through the scene's camera, one shadow ray a hit to a point on the
// first light, a cosine-weighted bounce with a constant albedo, at most five hits. Its random numbers are a
// counter-based hash in lanes (PCG's output permutation of a per-sample key plus a draw index;
// M. Jarzynski and M. Olano, "Hash Functions for GPU Rendering", JCGT 9(3), 2020) instead of
// the scalar loop's PCG32 streams, since a 64-bit multiply has no AVX2 lane form.
#pragma once

#include <chrono>
#include <cstdint>
#include <vector>

#include "minimal_loop.h"
#include "lane_math.h"

namespace bench {

PT_BEGIN_AVX2
namespace lanes8 {
using namespace pt::lane8;
typedef uint32_t vu __attribute__((vector_size(32)));
constexpr int kW = 8;
// The names this loop was written with, on lane_math.h's eight-wide vocabulary.
using vf = F;
using vi = I;
inline vf sel(vi m, vf a, vf b) { return select(m, a, b); }
inline V3 sel(vi m, V3 a, V3 b) { return select(m, a, b); }
inline V3 add(V3 a, V3 b) { return a + b; }
inline V3 sub(V3 a, V3 b) { return a - b; }
inline V3 mul(V3 a, vf s) { return a * s; }
inline V3 neg(V3 a) { return -a; }
inline V3 broadcast(pt::Vec3 a) { return splat(a); }
inline void storei(int* p, vi a) { store_mask(p, a); }
inline V3 offset_origin(V3 p, V3 n) { return offset_ray_origin(p, n); }
inline void concentric_disk(vf ux, vf uy, vf& x, vf& y) {
  const V2 d = sample_concentric_disk(V2{ux, uy});
  x = d.x, y = d.y;
}

inline vu hash(vu x) {
  const vu state = x * 747796405u + 2891336453u;
  const vu word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}
inline vf unit(vu h) { return __builtin_convertvector(vi(h >> 8u), vf) * splat(0x1p-24f); }
inline vu loadu32(const uint32_t* p) { return *reinterpret_cast<const vu*>(p); }

// A cosine-weighted direction about unit normal n.
inline V3 cosine_direction(V3 n, vf u1, vf u2) { return Frame(n).to_world(sample_cosine_hemisphere(V2{u1, u2})); }

constexpr size_t kPool = 256, kPad = kPool + kW;

// The hits of one step, gathered from SurfaceHit records into lanes.
struct HitLanes {
  alignas(32) float px[kPad], py[kPad], pz[kPad], gx[kPad], gy[kPad], gz[kPad], nx[kPad], ny[kPad], nz[kPad];
  alignas(32) float off[kPad], dx[kPad], dy[kPad], dz[kPad];
  alignas(32) uint32_t key[kPad], draw[kPad];
  // Out: the bounce ray's origin and direction.
  alignas(32) float ox[kPad], oy[kPad], oz[kPad], wx[kPad], wy[kPad], wz[kPad];
};

inline MinimalLoopResult pass(const pt::RenderScene& scene, const std::vector<int>& pixels, int w, int h, int spp) {
  using namespace pt;
  constexpr int kHits = 5;
  constexpr float kAlbedo = 0.6f;
  const Accel& accel = *scene.accel;
  std::vector<Ray> rays(kPad), shadow(kPad);
  std::vector<SurfaceHit> hits(kPool);
  std::vector<uint8_t> found(kPool), blocked(kPool);
  std::vector<float> beta(kPool), film(size_t(w) * size_t(h), 0.0f);
  std::vector<int> depth(kPool), pixel(kPool);
  std::vector<uint32_t> key(kPool), draws(kPool), slot(kPad);
  static thread_local HitLanes v;
  alignas(32) float sx[kPad], sy[kPad];
  alignas(32) uint32_t new_key[kPad];
  Vec2 lens[kPad];
  const Light* light = scene.lights.empty() ? nullptr : &scene.lights[0];
  const bool aimed = light && !light->is_infinite();
  const V3 l_pos = broadcast(aimed ? light->position : Vec3(0.0f)), l_dx = broadcast(aimed ? light->dim_x : Vec3(0.0f)),
           l_dy = broadcast(aimed ? light->dim_y : Vec3(0.0f));
  const vf half = splat(0.5f), one = splat(1.0f);

  const uint64_t n_pixels = pixels.size(), total = n_pixels * uint64_t(spp);
  uint64_t next = 0;
  MinimalLoopResult r;
  size_t live = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (;;) {
    // Refill: keys, sensor points and lens draws in lanes, then the camera's own lanes.
    const size_t first_new = live;
    size_t fresh = 0;
    for (; live < kPool && next < total; ++next, ++live, ++fresh) {
      pixel[live] = pixels[size_t(next % n_pixels)];
      new_key[fresh] = uint32_t(pixel[live]) * 0x9E3779B9u ^ uint32_t(next / n_pixels) * 0x85EBCA6Bu;
    }
    for (size_t i = 0; i < fresh; i += kW) {
      const vu k = hash(loadu32(new_key + i));
      const vu base = k * 4u;  // draws 0-3 of the sample: the jitter, then the lens
      vf px, py;
      for (int j = 0; j < kW; ++j) {
        const int p = pixel[std::min(first_new + i + j, kPool - 1)];
        px[j] = float(p % w);
        py[j] = float(p / w);
      }
      store(sx + i, (px + unit(hash(base))) / splat(float(w)));
      store(sy + i, one - (py + unit(hash(base + 1u))) / splat(float(h)));
      const vf lx = unit(hash(base + 2u)), ly = unit(hash(base + 3u));
      for (int j = 0; j < kW; ++j) lens[i + j] = Vec2{lx[j], ly[j]};
      for (int j = 0; j < kW && i + j < fresh; ++j) {
        key[first_new + i + j] = k[j];
        draws[first_new + i + j] = 4;
      }
    }
    if (fresh) scene.camera.generate_rays(sx, sy, lens, fresh, &rays[first_new]);
    for (size_t i = first_new; i < live; ++i) beta[i] = 1, depth[i] = 0;
    if (live == 0) break;

    accel.intersect_many(rays.data(), live, hits.data(), found.data());
    size_t n = 0;  // the hits, gathered into lanes
    for (size_t i = 0; i < live; ++i) {
      if (!found[i]) continue;
      const SurfaceHit& s = hits[i];
      v.px[n] = s.p.x, v.py[n] = s.p.y, v.pz[n] = s.p.z;
      v.gx[n] = s.ng.x, v.gy[n] = s.ng.y, v.gz[n] = s.ng.z;
      v.nx[n] = s.ns.x, v.ny[n] = s.ns.y, v.nz[n] = s.ns.z;
      v.off[n] = s.offset;
      v.dx[n] = rays[i].d.x, v.dy[n] = rays[i].d.y, v.dz[n] = rays[i].d.z;
      v.key[n] = key[i];
      v.draw[n] = draws[i];
      slot[n++] = uint32_t(i);
    }
    for (size_t i = n; i < (n + kW - 1) / kW * kW; ++i) {  // the last group's spare lanes: finite values
      v.px[i] = v.py[i] = v.pz[i] = v.gx[i] = v.gy[i] = v.nx[i] = v.ny[i] = v.off[i] = v.dx[i] = v.dy[i] = 0;
      v.gz[i] = v.nz[i] = v.dz[i] = 1;
      v.key[i] = v.draw[i] = 0;
    }
    for (size_t i = 0; i < n; i += kW) {
      const vu base = loadu32(v.key + i) * 4u + loadu32(v.draw + i);
      const V3 p = load3(v.px, v.py, v.pz, int(i)), g = load3(v.gx, v.gy, v.gz, int(i));
      const V3 ns = load3(v.nx, v.ny, v.nz, int(i)), d = load3(v.dx, v.dy, v.dz, int(i));
      const vf off = load(v.off + i);
      // The shadow ray: spawn_ray_to a point on the light, or along the facing normal.
      const vf ux = unit(hash(base)), uy = unit(hash(base + 1u));
      const vi facing = dot(d, ns) < 0;
      const V3 n_face = sel(facing, ns, neg(ns));
      V3 so, sd;
      vf stmax;
      if (aimed) {
        const V3 q = add(add(l_pos, mul(l_dx, ux - half)), mul(l_dy, uy - half));
        const V3 side = sel(dot(sub(q, p), g) >= 0, g, neg(g));
        so = offset_origin(add(p, mul(side, off)), side);
        sd = sub(q, so);
        stmax = splat(kShadowRayEnd);
      } else {
        const V3 side = sel(dot(n_face, g) >= 0, g, neg(g));
        so = offset_origin(add(p, mul(side, off)), side);
        sd = n_face;
        stmax = splat(kInf);
      }
      for (int j = 0; j < kW; ++j) {
        Ray& s = shadow[i + j];
        s.o = Vec3(so.x[j], so.y[j], so.z[j]);
        s.d = Vec3(sd.x[j], sd.y[j], sd.z[j]);
        s.tmin = 0;
        s.tmax = stmax[j];
      }
      // The bounce: a cosine-weighted direction, then spawn_ray.
      const V3 wi = cosine_direction(n_face, unit(hash(base + 2u)), unit(hash(base + 3u)));
      const V3 side = sel(dot(wi, g) >= 0, g, neg(g));
      store3(v.ox, v.oy, v.oz, int(i), offset_origin(add(p, mul(side, off)), side));
      store3(v.wx, v.wy, v.wz, int(i), wi);
    }
    accel.occluded_many(shadow.data(), n, blocked.data());
    r.rays += live + n;
    size_t kept = 0;  // the paths that go on, packed to the front of the pool
    for (size_t k = 0; k < n; ++k) {
      const size_t i = slot[k];
      if (!blocked[k]) film[size_t(pixel[i])] += beta[i];
      if (++depth[i] >= kHits) continue;
      if (hits[i].light >= 0) film[size_t(pixel[i])] += beta[i];
      Ray& next_ray = rays[kept];
      next_ray.o = Vec3(v.ox[k], v.oy[k], v.oz[k]);
      next_ray.d = Vec3(v.wx[k], v.wy[k], v.wz[k]);
      next_ray.tmin = 0;
      next_ray.tmax = kInf;
      beta[kept] = beta[i] * kAlbedo;
      depth[kept] = depth[i];
      pixel[kept] = pixel[i];
      key[kept] = key[i];
      draws[kept] = draws[i] + 4;
      ++kept;
    }
    live = kept;
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (float f : film) r.radiance += double(f);
  return r;
}

// The same loop with its rays where Embree reads them (Accel::RayPacket16: no packing) and its hits
// read in lanes (the point from t, the unit normal from Embree's; no shading normal, no material):
// each slot takes a new camera sample where its path ends, so packets stay full without moving
// paths between slots. The frame is the geometric normal's: on curved meshes its paths differ from
// the scalar loop's, which turns its shading normals.
inline MinimalLoopResult pass_in_place(const pt::RenderScene& scene, const std::vector<int>& pixels, int w, int h,
                                       int spp) {
  using namespace pt;
  using Packet = Accel::RayPacket16;
  constexpr int kHits = 5;
  constexpr size_t kPackets = kPool / 16;
  const Accel& accel = *scene.accel;
  const Camera& cam = scene.camera;
  std::vector<Packet> rays(kPackets), shadow(kPackets);
  struct alignas(64) Slots {  // Embree reads valid masks 64-byte aligned
    float beta[kPool];
    int depth[kPool], pixel[kPool], valid[kPool], svalid[kPool], fresh[kPool];
    uint32_t key[kPool], draw[kPool];
    float px[kPool], py[kPool];
  };
  static thread_local Slots sl;
  std::vector<float> film(size_t(w) * size_t(h), 0.0f);
  const Light* light = scene.lights.empty() ? nullptr : &scene.lights[0];
  const bool aimed = light && !light->is_infinite();
  const V3 l_pos = broadcast(aimed ? light->position : Vec3(0.0f)), l_dx = broadcast(aimed ? light->dim_x : Vec3(0.0f)),
           l_dy = broadcast(aimed ? light->dim_y : Vec3(0.0f));
  const vf half = splat(0.5f), one = splat(1.0f), albedo = splat(0.6f), inf = splat(kInf);
  const V3 c_pos = broadcast(cam.position), c_right = broadcast(cam.right), c_up = broadcast(cam.up),
           c_back = broadcast(cam.back);
  for (Packet& pk : rays)
    for (int k = 0; k < 16; ++k) pk.mask[k] = ~0u, pk.id[k] = 0, pk.flags[k] = 0, pk.time[k] = 0;
  shadow = rays;
  for (size_t i = 0; i < kPool; ++i) sl.valid[i] = 0, sl.depth[i] = kHits;

  const uint64_t n_pixels = pixels.size(), total = n_pixels * uint64_t(spp);
  uint64_t next = 0;
  MinimalLoopResult r;
  const auto t0 = std::chrono::steady_clock::now();
  for (;;) {
    // Slots whose path ended take the next sample.
    size_t live = 0;
    for (size_t i = 0; i < kPool; ++i) {
      sl.fresh[i] = 0;
      if (sl.depth[i] >= kHits || !sl.valid[i]) {
        if (next < total) {
          const int pix = pixels[size_t(next % n_pixels)];
          sl.pixel[i] = pix;
          sl.key[i] = uint32_t(pix) * 0x9E3779B9u ^ uint32_t(next / n_pixels) * 0x85EBCA6Bu;
          sl.px[i] = float(pix % w);
          sl.py[i] = float(pix / w);
          sl.fresh[i] = -1;
          sl.valid[i] = -1;
          ++next;
        } else {
          sl.valid[i] = 0;
        }
      }
      live += sl.valid[i] != 0;
    }
    if (live == 0) break;
    // Camera rays for the fresh slots, in lanes, blended into the packets.
    for (size_t c = 0; c < kPool; c += kW) {
      const vi fresh = *reinterpret_cast<const vi*>(sl.fresh + c);
      if (!_mm256_movemask_ps(_mm256_castsi256_ps(__m256i(fresh)))) continue;
      Packet& pk = rays[c / 16];
      const size_t o = c % 16;
      const vu k = hash(loadu32(sl.key + c)), base = k * 4u;
      const vf sx = (load(sl.px + c) + unit(hash(base))) / splat(float(w));
      const vf sy = one - (load(sl.py + c) + unit(hash(base + 1u))) / splat(float(h));
      V3 dc{(splat(2.0f) * sx - one) * splat(cam.tan_half_w), (splat(2.0f) * sy - one) * splat(cam.tan_half_h), splat(-1.0f)};
      V3 org = c_pos;
      if (cam.lens_radius > 0) {
        vf lx, ly;
        concentric_disk(unit(hash(base + 2u)), unit(hash(base + 3u)), lx, ly);
        lx = lx * splat(cam.lens_radius);
        ly = ly * splat(cam.lens_radius);
        const vf f = splat(cam.focal_distance);
        V3 dir{dc.x * f - lx, dc.y * f - ly, dc.z * f};
        dc = sel(dot(dir, dir) > 0, dir, dc);
        org = add(add(c_pos, mul(c_right, lx)), mul(c_up, ly));
      }
      const V3 d = normalize(add(add(mul(c_right, dc.x), mul(c_up, dc.y)), mul(c_back, dc.z)));
      store(pk.ox + o, sel(fresh, org.x, load(pk.ox + o)));
      store(pk.oy + o, sel(fresh, org.y, load(pk.oy + o)));
      store(pk.oz + o, sel(fresh, org.z, load(pk.oz + o)));
      store(pk.dx + o, sel(fresh, d.x, load(pk.dx + o)));
      store(pk.dy + o, sel(fresh, d.y, load(pk.dy + o)));
      store(pk.dz + o, sel(fresh, d.z, load(pk.dz + o)));
      store(sl.beta + c, sel(fresh, one, load(sl.beta + c)));
      storei(sl.depth + c, fresh ? vi{} : *reinterpret_cast<const vi*>(sl.depth + c));
      *reinterpret_cast<vu*>(sl.key + c) = vu(fresh ? vi(k) : vi(loadu32(sl.key + c)));
      *reinterpret_cast<vu*>(sl.draw + c) = vu(fresh ? vi{} + 4 : vi(loadu32(sl.draw + c)));
    }
    for (size_t b = 0; b < kPackets; ++b) {
      Packet& pk = rays[b];
      for (int k = 0; k < 16; ++k) pk.tnear[k] = 0, pk.tfar[k] = kInf, pk.geom[k] = ~0u, pk.inst[k] = ~0u;
      accel.intersect16(sl.valid + 16 * b, pk);
    }
    // Every hit: the shadow ray and the bounce, in lanes, straight into the packets.
    size_t n_shadow = 0;
    for (size_t c = 0; c < kPool; c += kW) {
      Packet& pk = rays[c / 16];
      Packet& sp = shadow[c / 16];
      const size_t o = c % 16;
      const vi hit = *reinterpret_cast<const vi*>(sl.valid + c) & (vi(loadu32(pk.geom + o)) != vi{} - 1);
      storei(sl.svalid + c, hit);
      const vf t = sel(hit, load(pk.tfar + o), vf{});  // lanes without a hit keep finite rays
      const V3 d = load3(pk.dx, pk.dy, pk.dz, int(o));
      const V3 p = add(load3(pk.ox, pk.oy, pk.oz, int(o)), mul(d, t));
      const V3 g = normalize(load3(pk.ngx, pk.ngy, pk.ngz, int(o)));
      const vu base = loadu32(sl.key + c) * 4u + loadu32(sl.draw + c);
      const V3 n_face = sel(dot(d, g) < 0, g, neg(g));
      V3 so, sd;
      vf stmax;
      if (aimed) {
        const V3 q = add(add(l_pos, mul(l_dx, unit(hash(base)) - half)), mul(l_dy, unit(hash(base + 1u)) - half));
        const V3 side = sel(dot(sub(q, p), g) >= 0, g, neg(g));
        so = offset_origin(p, side);
        sd = sub(q, so);
        stmax = splat(kShadowRayEnd);
      } else {
        so = offset_origin(p, n_face);
        sd = n_face;
        stmax = inf;
      }
      store3(sp.ox + o, sp.oy + o, sp.oz + o, 0, so);
      store3(sp.dx + o, sp.dy + o, sp.dz + o, 0, sd);
      store(sp.tnear + o, vf{});
      store(sp.tfar + o, stmax);
      const V3 wi = cosine_direction(n_face, unit(hash(base + 2u)), unit(hash(base + 3u)));
      const V3 no = offset_origin(p, n_face);
      // Rays of lanes without a hit keep their (finite) old values: their slot restarts.
      store3(pk.ox + o, pk.oy + o, pk.oz + o, 0, sel(hit, no, load3(pk.ox, pk.oy, pk.oz, int(o))));
      store3(pk.dx + o, pk.dy + o, pk.dz + o, 0, sel(hit, wi, d));
      const vi depth = *reinterpret_cast<const vi*>(sl.depth + c) + 1;
      storei(sl.depth + c, hit ? depth : vi{} + kHits);
      // Paths that go on gather an emitter's light where they hit one (as the scalar loop does).
      for (int m = _mm256_movemask_ps(_mm256_castsi256_ps(__m256i(hit & (depth < kHits)))); m; m &= m - 1) {
        const size_t i = c + size_t(__builtin_ctz(unsigned(m)));
        if (accel.light_at(pk.geom[i % 16], pk.prim[i % 16]) >= 0) film[size_t(sl.pixel[i])] += sl.beta[i];
      }
      *reinterpret_cast<vu*>(sl.draw + c) = loadu32(sl.draw + c) + 4u;
      n_shadow += size_t(__builtin_popcount(_mm256_movemask_ps(_mm256_castsi256_ps(__m256i(hit)))));
    }
    for (size_t b = 0; b < kPackets; ++b) accel.occluded16(sl.svalid + 16 * b, shadow[b]);
    r.rays += live + n_shadow;
    for (size_t c = 0; c < kPool; c += kW) {  // unblocked shadow rays bring light; throughput falls
      const Packet& sp = shadow[c / 16];
      const size_t o = c % 16;
      const vf beta = load(sl.beta + c);
      const int lit = _mm256_movemask_ps(_mm256_castsi256_ps(
          __m256i(*reinterpret_cast<const vi*>(sl.svalid + c) & (load(sp.tfar + o) >= 0))));
      for (int m = lit; m; m &= m - 1) film[size_t(sl.pixel[c + size_t(__builtin_ctz(unsigned(m)))])] += beta[__builtin_ctz(unsigned(m))];
      store(sl.beta + c, beta * albedo);
    }
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (float f : film) r.radiance += double(f);
  return r;
}

}  // namespace lanes8
PT_END_AVX2

// The lanes loop where the CPU has AVX2 (it has no SSE2 form); false elsewhere. `in_place`: its rays
// in Embree's packet layout (pass_in_place) instead of Accel's records.
inline bool minimal_loop_lanes_pass(const pt::RenderScene& scene, const std::vector<int>& pixels, int w, int h, int spp,
                                    MinimalLoopResult& out, bool in_place = false) {
  if (!pt::simd::use_avx2()) return false;
  out = in_place ? lanes8::pass_in_place(scene, pixels, w, h, spp) : lanes8::pass(scene, pixels, w, h, spp);
  return true;
}

}  // namespace bench
