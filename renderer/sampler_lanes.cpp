// Sampler::next_2d_many: the Owen-scrambled Sobol draws of many samplers, eight at a time in AVX2
// lanes. A draw is about a hundred integer instructions (four hashes of four multiplies, three
// bit reversals, a table lookup per byte); in AVX2 each is one instruction for eight lanes, with
// the bit reversal as byte shuffles and the table lookups as a transform of a few shifts. SSE2 has neither a 32-bit
// multiply nor a byte shuffle (measured: 1.4x fewer instructions than scalar, not worth a path),
// so without AVX2 the draws stay scalar. Integer arithmetic only: the lanes give next_2d's bits.
#include <immintrin.h>

#include <algorithm>
#include <cstdlib>
#include <new>
#include <vector>

#include "sampler.h"
#include "simd.h"

namespace pt {

namespace {

#define PT_AVX2 __attribute__((target("avx2"), always_inline)) inline

typedef uint32_t vu __attribute__((vector_size(32)));
typedef int32_t vs __attribute__((vector_size(32)));
typedef float vf8 __attribute__((vector_size(32)));

PT_AVX2 vu splat(uint32_t x) { return vu{x, x, x, x, x, x, x, x}; }

PT_AVX2 vu hash(vu x) {  // hash_u32
  x ^= x >> 16;
  x *= splat(0x7feb352du);
  x ^= x >> 15;
  x *= splat(0x846ca68bu);
  x ^= x >> 16;
  return x;
}

PT_AVX2 vu laine_karras(vu x, vu seed) {  // laine_karras_permutation
  x += seed;
  x ^= x * splat(0x6c50b47cu);
  x ^= x * splat(0xb82f1e52u);
  x ^= x * splat(0xc7afe638u);
  x ^= x * splat(0x8d22f6e6u);
  return x;
}

PT_AVX2 vu reverse(vu x) {  // reverse_bits32: the bytes in reverse order, each byte's bits by nibble tables
  const __m256i swap = _mm256_setr_epi8(3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12,
                                        3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12);
  // A nibble's bits reversed: in the high nibble (for the low one) and in the low nibble.
  const __m256i to_high = _mm256_setr_epi8(0x00, -0x80, 0x40, -0x40, 0x20, -0x60, 0x60, -0x20, 0x10, -0x70, 0x50, -0x30,
                                           0x30, -0x50, 0x70, -0x10, 0x00, -0x80, 0x40, -0x40, 0x20, -0x60, 0x60, -0x20,
                                           0x10, -0x70, 0x50, -0x30, 0x30, -0x50, 0x70, -0x10);
  const __m256i to_low = _mm256_setr_epi8(0x0, 0x8, 0x4, 0xc, 0x2, 0xa, 0x6, 0xe, 0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf,
                                          0x0, 0x8, 0x4, 0xc, 0x2, 0xa, 0x6, 0xe, 0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf);
  const __m256i nibble = _mm256_set1_epi8(0x0f);
  __m256i b = _mm256_shuffle_epi8(__m256i(x), swap);
  __m256i lo = _mm256_and_si256(b, nibble), hi = _mm256_and_si256(_mm256_srli_epi16(b, 4), nibble);
  return vu(_mm256_or_si256(_mm256_shuffle_epi8(to_high, lo), _mm256_shuffle_epi8(to_low, hi)));
}

// sobol_dim1_reversed(j) from r = reverse_bits32(j), without its tables: the dimension's generator
// matrix is Pascal's triangle mod 2, so by Lucas' theorem bit a of the result is the XOR of the
// bits b of r whose index has every bit of a (b a superset of a). That sum over supersets takes
// one shift-mask-XOR per index bit (a "zeta transform" over GF(2)).
PT_AVX2 vu sobol_dim1_reversed_from_reversed(vu r) {
  r ^= (r >> 1) & splat(0x55555555u);
  r ^= (r >> 2) & splat(0x33333333u);
  r ^= (r >> 4) & splat(0x0f0f0f0fu);
  r ^= (r >> 8) & splat(0x00ff00ffu);
  r ^= (r >> 16) & splat(0x0000ffffu);
  return r;
}

PT_AVX2 vf8 unit(vu x) {  // u32_to_unit: exact, x >> 8 fits a float's mantissa
  vf8 f = __builtin_convertvector(vs(x >> 8), vf8);
  return f * vf8{0x1p-24f, 0x1p-24f, 0x1p-24f, 0x1p-24f, 0x1p-24f, 0x1p-24f, 0x1p-24f, 0x1p-24f};
}

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

// The lanes' arithmetic: draws of samplers with states (base, index, dim) into (u, v), sixteen
// at a time as two groups of eight, each step taken for both groups so that the core overlaps
// their chains (one is fourteen dependent multiplies of ten cycles each).
constexpr size_t kGroups = 2, kBlock = 8 * kGroups;

__attribute__((target("avx2"))) static void sobol_lanes(const uint32_t* base, const uint32_t* index,
                                                        const uint32_t* dim, size_t n, float* u, float* v) {
  auto at = [](const uint32_t* a, size_t i) { return reinterpret_cast<const vu*>(a + i); };
  for (size_t i = 0; i < n; i += kBlock) {
    vu seed[kGroups], j[kGroups], x[kGroups], y[kGroups];
    for (size_t g = 0; g < kGroups; ++g) seed[g] = hash(*at(base, i + 8 * g) + splat(0x9e3779b9u) * *at(dim, i + 8 * g));
    for (size_t g = 0; g < kGroups; ++g) j[g] = laine_karras(*at(index, i + 8 * g), seed[g]);
    for (size_t g = 0; g < kGroups; ++g) {
      const vu r = reverse(j[g]);
      x[g] = laine_karras(r, seed[g] ^ splat(0xa511e9b3u));
      y[g] = laine_karras(sobol_dim1_reversed_from_reversed(r), seed[g] ^ splat(0x63d83595u));
    }
    for (size_t g = 0; g < kGroups; ++g) {
      *reinterpret_cast<vf8*>(u + i + 8 * g) = unit(reverse(x[g]));
      *reinterpret_cast<vf8*>(v + i + 8 * g) = unit(reverse(y[g]));
    }
  }
}

static PT_AVX2 vu loadu(const uint32_t* a) {
  vu x;
  __builtin_memcpy(&x, a, sizeof x);
  return x;
}

// Draw `draw` of fresh samplers from their bases and sample indices, for whole blocks of sixteen.
__attribute__((target("avx2"))) static void sobol_lanes_fresh(const uint32_t* base, const uint32_t* sample,
                                                              uint32_t draw, size_t n, Vec2* out) {
  for (size_t i = 0; i < n; i += kBlock) {
    vu seed[kGroups], j[kGroups], x[kGroups], y[kGroups];
    for (size_t g = 0; g < kGroups; ++g) seed[g] = hash(loadu(base + i + 8 * g) + splat(0x9e3779b9u * draw));
    for (size_t g = 0; g < kGroups; ++g) j[g] = laine_karras(reverse(loadu(sample + i + 8 * g)), seed[g]);
    for (size_t g = 0; g < kGroups; ++g) {
      const vu r = reverse(j[g]);
      x[g] = laine_karras(r, seed[g] ^ splat(0xa511e9b3u));
      y[g] = laine_karras(sobol_dim1_reversed_from_reversed(r), seed[g] ^ splat(0x63d83595u));
    }
    for (size_t g = 0; g < kGroups; ++g) {
      const vf8 u = unit(reverse(x[g])), v = unit(reverse(y[g]));
      for (size_t k = 0; k < 8; ++k) out[i + 8 * g + k] = {u[k], v[k]};
    }
  }
}

// Reads and writes the samplers' state for the lanes; a friend of Sampler.
struct SamplerLanes {
  template <class At>
  static void draw(At s, size_t n, Vec2* out, bool lanes) {
    if (!lanes || !Sampler::lanes_available()) {
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
    sobol_lanes(t.base.data(), t.index.data(), t.dim.data(), m, t.u.data(), t.v.data());
    if (m == n) {  // the common case: every sampler in lanes
      for (size_t k = 0; k < m; ++k) out[k] = {t.u[k], t.v[k]};
    } else {
      for (size_t k = 0; k < m; ++k) out[t.which[k]] = {t.u[k], t.v[k]};
    }
  }
};

void Sampler::sobol_draws(const uint32_t* base, const uint32_t* sample, size_t n, uint32_t draw, Vec2* out) {
  const size_t whole = n / kBlock * kBlock;
  sobol_lanes_fresh(base, sample, draw, whole, out);
  if (whole == n) return;
  uint32_t b[kBlock] = {}, s[kBlock] = {};  // the last, partial block, padded
  Vec2 o[kBlock];
  std::copy(base + whole, base + n, b);
  std::copy(sample + whole, sample + n, s);
  sobol_lanes_fresh(b, s, draw, kBlock, o);
  std::copy(o, o + (n - whole), out + whole);
}

bool Sampler::lanes_available() { return simd::avx2_available(); }

void Sampler::next_2d_many(Sampler* s, size_t n, Vec2* out, bool lanes) {
  SamplerLanes::draw([s](size_t i) -> Sampler& { return s[i]; }, n, out, lanes);
}

void Sampler::next_2d_many(Sampler* const* s, size_t n, Vec2* out, bool lanes) {
  SamplerLanes::draw([s](size_t i) -> Sampler& { return *s[i]; }, n, out, lanes);
}

}  // namespace pt
