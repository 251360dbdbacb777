#pragma once
/// @file
/// @brief The volumetric path tracer: radiance along a camera ray through surfaces and media
/// (docs/render.md §1–§3), specialised at compile time on what the scene needs.

#include <cstdint>
#include <memory>
#include <vector>

#include "weft/core/rng.h"
#include "weft/render/lights.h"
#include "weft/render/medium.h"
#include "weft/render/world.h"

namespace weft::render {

/// Per-thread state: ray counts and each medium's scratch (trackers, accessors).
struct PathCounters {
  std::uint64_t rays = 0;
  std::vector<std::unique_ptr<MediumScratch>> scratch;

  explicit PathCounters(const std::vector<std::shared_ptr<const Medium>>& media) {
    for (const auto& m : media) scratch.push_back(m->make_scratch());
  }
};

/// `kMedia`: the scene has media; `kNonExp`: some medium is not a homogeneous exponential one, so
/// flights and shadows go through the Medium interface (otherwise they are the final
/// ExponentialMedium's, called without virtual dispatch). Instantiated for the three
/// specialisations render() chooses from: <false, false>, <true, false> and <true, true>.
template <bool kMedia, bool kNonExp>
class Integrator {
 public:
  explicit Integrator(const World& w) : w_(w) {}

  /// Radiance along a camera ray (docs/render.md §1–§3).
  [[nodiscard]] Rgb li(Vec3 o, Vec3 d, Pcg32& rng, PathCounters& counters) const;

 private:
  [[nodiscard]] Vec3 offset(const SurfaceHit& hit, const Vec3& dir) const;
  bool roulette(Rgb& beta, int depth, Pcg32& rng) const;
  [[nodiscard]] double shadow(Vec3 x, const LightSample& ls, int medium, transmittance::Origin origin, Pcg32& rng,
                              PathCounters& counters) const;

  const World& w_;
};

extern template class Integrator<false, false>;
extern template class Integrator<true, false>;
extern template class Integrator<true, true>;

}  // namespace weft::render
