#pragma once
// Deterministic random numbers: a PCG32 stream per (seed, pixel, sample), so results do not
// depend on how work is split across threads.
#include <cstdint>

namespace femto {

/// SplitMix64 finaliser: decorrelates structured keys (seed, pixel, sample) into stream seeds.
constexpr uint64_t mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// PCG32 (O'Neill 2014), XSH-RR output; 2^64 period per stream, 2^63 streams.
class Rng {
 public:
  Rng() { seed(0, 0); }
  Rng(uint64_t state_seed, uint64_t stream) { seed(state_seed, stream); }

  /// Stream for one sample of one pixel of a render with the given user seed.
  static Rng for_sample(uint64_t seed, uint64_t pixel, uint64_t sample) {
    const uint64_t a = mix64(seed ^ mix64(pixel + 0x632be59bd9b4e019ULL));
    return Rng(mix64(a ^ mix64(sample)), a);
  }

  void seed(uint64_t state_seed, uint64_t stream) {
    state_ = 0;
    inc_ = (stream << 1u) | 1u;
    next_u32();
    state_ += state_seed;
    next_u32();
  }

  uint32_t next_u32() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    const auto xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    const auto rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31u));
  }

  /// Uniform double in [0, 1) with 53 random bits.
  double uniform() {
    const uint64_t hi = next_u32() >> 5;  // 27 bits
    const uint64_t lo = next_u32() >> 6;  // 26 bits
    return static_cast<double>((hi << 26) | lo) * (1.0 / 9007199254740992.0);
  }

  /// Uniform double in [0, 1) with 32 random bits, from one output (uniform() takes two): for
  /// angles, where steps of 2^-32 are far below any tally's resolution.
  double uniform32() { return static_cast<double>(next_u32()) * (1.0 / 4294967296.0); }

 private:
  uint64_t state_ = 0;
  uint64_t inc_ = 1;
};

}  // namespace femto
