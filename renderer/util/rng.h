// Deterministic random numbers: a value-type PCG32 seeded from (job seed, pixel, sample index).
#pragma once

#include <cstdint>

#include "math.h"

namespace pt {

// SplitMix64 finaliser (Steele et al., "Fast splittable pseudorandom number generators", 2014),
// used to decorrelate seeds built from small integers.
inline uint64_t mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// PCG32 (O'Neill, "PCG: A Family of Simple Fast Space-Efficient Statistically Good Algorithms
// for Random Number Generation", 2014): 64-bit LCG state, XSH-RR output.
class Pcg32 {
 public:
  Pcg32() { seed(0, 0); }
  Pcg32(uint64_t init_state, uint64_t stream) { seed(init_state, stream); }
  void seed(uint64_t init_state, uint64_t stream) {
    m_state = 0;
    m_inc = (stream << 1u) | 1u;
    next_u32();
    m_state += init_state;
    next_u32();
  }
  uint32_t next_u32() {
    uint64_t old = m_state;
    m_state = old * 6364136223846793005ull + m_inc;
    uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32 - rot) & 31));
  }
  // Uniform float in [0, 1): 24 random mantissa bits, so 1 is never returned.
  float next_float() { return float(next_u32() >> 8) * 0x1p-24f; }
  Vec2 next_2d() {
    float a = next_float();
    return {a, next_float()};
  }

 private:
  uint64_t m_state = 0, m_inc = 1;
};

// The generator for one camera sample: the same (seed, pixel, sample) always gives the same
// stream, whatever the thread count or tile order.
inline Pcg32 make_sample_rng(uint64_t seed, uint64_t pixel_index, uint64_t sample_index) {
  return Pcg32(mix64(seed ^ mix64(sample_index)), mix64(pixel_index + 0x632be59bd9b4e019ull * seed));
}

}  // namespace pt
