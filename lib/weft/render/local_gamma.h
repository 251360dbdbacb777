#pragma once
/// @file
/// @brief The coarse local statistic fields of `weft fit --block B` as a heterogeneous gamma
/// medium (model and its limits: docs/render.md §"Local gamma").

#include <array>
#include <filesystem>
#include <memory>

#include "weft/core/rng.h"
#include "weft/transmittance/gamma_hazard.h"
#include "weft/transmittance/pair.h"
#include "weft/volume/dda.h"
#include "weft/volume/grid.h"

namespace weft::render {

/// @brief Per coarse voxel v a gamma-concentration law (α_v = C̄²/V, β_v = C̄/V from the block
/// mean C̄ and the column-mean variance V along the ray's dominant axis), applied along a ray
/// as the hazard Σ(s) = σα_v/(β_v + σs) of that law at memory s
/// (transmittance::GammaHazard); how s passes from voxel to voxel is the memory rule
/// (docs/render.md §5e; the default, `optical-depth`, converts the optical depth so far into
/// the cell's memory).
/// H(t) = ∫Σ and T = e^{−H}. A constant field is exactly the homogeneous gamma law
/// T = (1 + σt/β)^{−α} under every rule but renewal; V = 0 gives the exponential e^{−σC̄t}.
///
/// A segment that starts at a scattering event (Origin::scatterer) uses each voxel's reciprocal
/// partner T_S = (1 + σt/β)^{−(α+1)}, i.e. the hazard (σC̄ + κ)/(1 + κs) with κ = σV/C̄: the
/// size-biased concentration E[C²]/E[C] = C̄ + V/C̄ replaces C̄ (docs/render.md §5b; which rules
/// make the pair exactly reciprocal where the field varies: §5e).
///
/// Holds a volume::Tracer and voxel readers, so one instance per thread (clone() shares the grids).
class LocalGammaField {
 public:
  /// Reads "mean_concentration" and "var_concentration_{x,y,z}" from the .vdb `weft fit
  /// --block` writes. Throws weft::Error naming the file for a missing grid, an empty mean
  /// grid, a negative or NaN value in a grid, or σ not finite and positive.
  LocalGammaField(const std::filesystem::path& vdb, double sigma,
                  transmittance::MemoryRule memory = transmittance::kDefaultMemoryRule);

  /// A field on the same (shared, read-only) grids with its own DDA tracer, for another thread.
  [[nodiscard]] std::unique_ptr<LocalGammaField> clone() const;
  [[nodiscard]] transmittance::MemoryRule memory() const { return memory_; }

  /// log T = −H over [t0, t1] along the ray, the memory starting at t0 (world distances);
  /// T_Q for segments from a source or surface, T_S for segments from a scattering event.
  [[nodiscard]] double log_transmittance(const volume::Ray& ray, double t0, double t1,
                                         transmittance::Origin origin = transmittance::Origin::source);
  /// T = e^{−H} over [t0, t1] for a shadow ray, the walk ended early by volume::ShadowRoulette
  /// once T is small: an unbiased estimate, exact while T stays above ShadowRoulette::kBelow.
  [[nodiscard]] double transmittance(const volume::Ray& ray, double t0, double t1, transmittance::Origin origin,
                                     Pcg32& rng);
  /// The distance t in (t0, t1] where H reaches `h` (h = −log u samples the free flight),
  /// or +∞ when H(t1) < h.
  [[nodiscard]] double sample_distance(const volume::Ray& ray, double t0, double t1, double h,
                                       transmittance::Origin origin = transmittance::Origin::source);

 private:
  /// Walks the non-empty coarse cells, entering each into `hazard` and calling piece(a, b) with
  /// a, b distances from t0; stops when piece returns false.
  template <typename Piece>
  void walk(const volume::Ray& ray, double t0, double t1, transmittance::GammaHazard& hazard, Piece&& piece);
  LocalGammaField() = default;
  void make_accessors();

  std::shared_ptr<const volume::Grid> mean_;
  std::array<std::shared_ptr<const volume::Grid>, 3> var_;
  std::unique_ptr<volume::Tracer> tracer_;
  std::array<std::unique_ptr<volume::VoxelReader>, 3> var_readers_;
  double sigma_ = 1.0;
  transmittance::MemoryRule memory_ = transmittance::kDefaultMemoryRule;
};

}  // namespace weft::render
