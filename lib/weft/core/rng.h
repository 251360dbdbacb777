#pragma once
/// @file
/// @brief PCG32 random streams keyed by (run seed, work-unit index).
///
/// Every work unit (a ray range, an image tile, a 2D realization) draws from its own stream, so
/// results do not depend on how units are scheduled over threads (docs/architecture.md §5).

#include <cstdint>
#include <limits>

namespace weft {

/// @brief O'Neill's PCG-XSH-RR 64/32 generator with a selectable stream.
class Pcg32 {
 public:
  using result_type = std::uint32_t;

  /// Stream `stream` of the generator seeded by `seed`; distinct streams are independent.
  explicit Pcg32(std::uint64_t seed = 0x853c49e6748fea9bULL, std::uint64_t stream = 0xda3e39cb94b95bdbULL) {
    inc_ = (stream << 1U) | 1U;
    state_ = 0;
    next_u32();
    state_ += seed;
    next_u32();
  }

  static constexpr result_type min() { return 0; }
  static constexpr result_type max() { return std::numeric_limits<std::uint32_t>::max(); }
  result_type operator()() { return next_u32(); }

  std::uint32_t next_u32() {
    const std::uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    const auto xorshifted = static_cast<std::uint32_t>(((old >> 18U) ^ old) >> 27U);
    const auto rot = static_cast<std::uint32_t>(old >> 59U);
    return (xorshifted >> rot) | (xorshifted << ((32U - rot) & 31U));
  }

  /// Uniform double in [0, 1) with 53 random bits.
  double uniform() {
    const std::uint64_t hi = next_u32();
    const std::uint64_t lo = next_u32();
    const std::uint64_t bits = ((hi << 32U) | lo) >> 11U;
    return static_cast<double>(bits) * 0x1.0p-53;
  }

  /// Uniform double in (0, 1): never 0, for samplers that take log(ξ).
  double uniform_open() {
    double u = 0.0;
    do {
      u = uniform();
    } while (u == 0.0);
    return u;
  }

  /// Uniform integer in [0, bound) without modulo bias.
  std::uint32_t uniform_below(std::uint32_t bound) {
    const std::uint32_t threshold = (0U - bound) % bound;
    for (;;) {
      const std::uint32_t r = next_u32();
      if (r >= threshold) return r % bound;
    }
  }

 private:
  std::uint64_t state_ = 0;
  std::uint64_t inc_ = 0;
};

/// @brief SplitMix64 finaliser: decorrelates neighbouring keys before they seed a stream.
constexpr std::uint64_t mix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30U)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27U)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31U);
}

/// @brief The stream of work unit `unit` in a run seeded by `seed`.
inline Pcg32 stream_for(std::uint64_t seed, std::uint64_t unit) {
  return Pcg32(mix64(seed), mix64(unit ^ 0x5851f42d4c957f2dULL));
}

}  // namespace weft
