// Sampler::next_2d_many: the Owen-scrambled Sobol draws of many samplers, eight at a time in AVX2
// lanes: sobol.inc's draw compiled in lane_math.h's lane8. A draw is about a hundred integer
// instructions (four hashes of four multiplies, three bit reversals, the second dimension's
// transform); in AVX2 each is one instruction for eight lanes. Without AVX2 the draws stay scalar
// (see sobol.inc). Integer arithmetic only: the lanes give next_2d's bits.
#include <algorithm>
#include <cstdlib>
#include <new>
#include <vector>

#include "lane_math.h"
#include "loop_forms.h"
#include "sampler.h"

PT_BEGIN_AVX2
namespace pt::lane8 {

#include "sobol.inc"

namespace {

// Draws of samplers with states (base, index, dim) into (u, v) for whole blocks of sixteen, as
// two groups of eight side by side, so that the core overlaps their chains (one is fourteen
// dependent multiplies of ten cycles each).
constexpr size_t kGroups = 2, kBlock = 8 * kGroups;

void sobol_lanes(const uint32_t* base, const uint32_t* index, const uint32_t* dim, size_t n, float* u, float* v) {
  for (size_t i = 0; i < n; i += kBlock) {
    F x[kGroups], y[kGroups];
    for (size_t g = 0; g < kGroups; ++g)
      sobol_2d(load(base + i + 8 * g), load(index + i + 8 * g), load(dim + i + 8 * g), x[g], y[g]);
    for (size_t g = 0; g < kGroups; ++g) store(u + i + 8 * g, x[g]), store(v + i + 8 * g, y[g]);
  }
}

// Draw `draw` of fresh samplers from their bases and sample indices, for whole blocks of sixteen.
void sobol_lanes_fresh(const uint32_t* base, const uint32_t* sample, uint32_t draw, size_t n, Vec2* out) {
  const U dim = U{} + draw;
  for (size_t i = 0; i < n; i += kBlock) {
    F x[kGroups], y[kGroups];
    for (size_t g = 0; g < kGroups; ++g)
      sobol_2d(loadu(base + i + 8 * g), reverse_bits(loadu(sample + i + 8 * g)), dim, x[g], y[g]);
    for (size_t g = 0; g < kGroups; ++g)
      for (size_t k = 0; k < 8; ++k) out[i + 8 * g + k] = {x[g][k], y[g][k]};
  }
}

}  // namespace

}  // namespace pt::lane8
PT_END_AVX2

namespace pt {

namespace {

using lane8::kBlock;

// 32-byte aligned storage for the lanes' loads and stores.
template <class T>
struct AlignedAllocator {
  using value_type = T;
  AlignedAllocator() = default;
  template <class U>
  AlignedAllocator(const AlignedAllocator<U>&) {}
  T* allocate(size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(32))); }
  void deallocate(T* p, size_t) { ::operator delete(p, std::align_val_t(32)); }
  bool operator==(const AlignedAllocator&) const { return true; }
  bool operator!=(const AlignedAllocator&) const { return false; }
};

}  // namespace

// Reads and writes the samplers' state for the lanes; a friend of Sampler.
struct SamplerLanes {
  template <class At>
  static void draw(At s, size_t n, Vec2* out) {
    if (!forms::lanes() || !Sampler::lanes_available()) {
      for (size_t i = 0; i < n; ++i) out[i] = s(i).next_2d();
      return;
    }
    // The Sobol samplers' states, packed; the others draw alone, in place.
    struct Scratch {
      std::vector<uint32_t, AlignedAllocator<uint32_t>> base, index, dim, which;
      std::vector<float, AlignedAllocator<float>> u, v;
    };
    static thread_local Scratch t;
    const size_t padded = (n + kBlock - 1) / kBlock * kBlock;
    for (auto* a : {&t.base, &t.index, &t.dim, &t.which}) a->resize(padded);
    t.u.resize(padded);
    t.v.resize(padded);
    size_t m = 0;
    for (size_t i = 0; i < n; ++i) {
      Sampler& r = s(i);
      if (r.m_dim >= Sampler::kSobolDimensions) {  // next_2d's own branch, inlined: deep paths draw here
        out[i] = r.rng().next_2d();
        continue;
      }
      t.base[m] = r.m_base, t.index[m] = r.m_index_reversed, t.dim[m] = ++r.m_dim, t.which[m] = uint32_t(i);
      ++m;
    }
    if (m == 0) return;
    for (size_t k = m; k < (m + kBlock - 1) / kBlock * kBlock; ++k) t.base[k] = t.index[k] = t.dim[k] = 0;  // padding
    lane8::sobol_lanes(t.base.data(), t.index.data(), t.dim.data(), m, t.u.data(), t.v.data());
    if (m == n) {  // the common case: every sampler in lanes
      for (size_t k = 0; k < m; ++k) out[k] = {t.u[k], t.v[k]};
    } else {
      for (size_t k = 0; k < m; ++k) out[t.which[k]] = {t.u[k], t.v[k]};
    }
  }
};

void Sampler::sobol_draws(const uint32_t* base, const uint32_t* sample, size_t n, uint32_t draw, Vec2* out) {
  const size_t whole = n / kBlock * kBlock;
  lane8::sobol_lanes_fresh(base, sample, draw, whole, out);
  if (whole == n) return;
  uint32_t b[kBlock] = {}, s[kBlock] = {};  // the last, partial block, padded
  Vec2 o[kBlock];
  std::copy(base + whole, base + n, b);
  std::copy(sample + whole, sample + n, s);
  lane8::sobol_lanes_fresh(b, s, draw, kBlock, o);
  std::copy(o, o + (n - whole), out + whole);
}

bool Sampler::lanes_available() { return simd::avx2_available(); }

void Sampler::next_2d_many(Sampler* s, size_t n, Vec2* out) {
  SamplerLanes::draw([s](size_t i) -> Sampler& { return s[i]; }, n, out);
}

void Sampler::next_2d_many(Sampler* const* s, size_t n, Vec2* out) {
  SamplerLanes::draw([s](size_t i) -> Sampler& { return *s[i]; }, n, out);
}

}  // namespace pt
