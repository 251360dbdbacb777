#pragma once
/// @file
/// @brief The coarse local statistic fields of `weft fit --block B` as a heterogeneous gamma
/// medium (model and its limits: docs/render.md §"Local gamma").

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <vector>

#include "weft/core/rng.h"
#include "weft/transmittance/gamma_hazard.h"
#include "weft/transmittance/pair.h"
#include "weft/volume/dda.h"
#include "weft/volume/grid.h"
#include "weft/volume/voxel_walk.h"

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
/// A field whose active box fits in `max_dense_bytes` of records is held as one dense array of
/// per-voxel records {C̄, V_x, V_y, V_z} (16 bytes) and walked by volume::DenseWalk (the trees are
/// let go); a larger one keeps its four trees and walks them (volume::Tracer). Both walks give
/// the same pieces and the same numbers bit for bit (docs/render.md §5b "Dense walk").
///
/// Holds a walker (and voxel readers), so one instance per thread (clone() shares the data).
class LocalGammaField {
 public:
  /// Records of 16 bytes per voxel of the mean grid's active box up to this size are walked
  /// densely: 64 MiB, four million voxels, far above a coarse cloth field's box.
  static constexpr std::uint64_t kMaxDenseBytes = std::uint64_t{64} << 20;

  /// Reads "mean_concentration" and "var_concentration_{x,y,z}" from the .vdb `weft fit
  /// --block` writes. Throws weft::Error naming the file for a missing grid, an empty mean
  /// grid, a negative or NaN value in a grid, or σ not finite and positive. `max_dense_bytes`
  /// 0 keeps the trees (tests compare the walks).
  LocalGammaField(const std::filesystem::path& vdb, double sigma,
                  transmittance::MemoryRule memory = transmittance::kDefaultMemoryRule,
                  std::uint64_t max_dense_bytes = kMaxDenseBytes);

  /// A field on the same (shared, read-only) grids with its own DDA tracer, for another thread.
  [[nodiscard]] std::unique_ptr<LocalGammaField> clone() const;
  [[nodiscard]] transmittance::MemoryRule memory() const { return memory_; }
  /// True when the field is held as dense records (walked by volume::DenseWalk).
  [[nodiscard]] bool dense() const { return records_ != nullptr; }

  /// log T = −H over [t0, t1] along the ray, the memory starting at t0 (world distances);
  /// T_Q for segments from a source or surface, T_S for segments from a scattering event.
  [[nodiscard]] double log_transmittance(const volume::Ray& ray, double t0, double t1,
                                         transmittance::Origin origin = transmittance::Origin::source);
  /// log T over [t0, ends[k]] for every k, from one walk (a beam's depth profile): `ends` are
  /// ray parameters in increasing order; an end at or before t0 gives 0. Each is what
  /// log_transmittance(ray, t0, ends[k], origin) gives, up to the rounding of the sum's order.
  void log_transmittance_profile(const volume::Ray& ray, double t0, std::span<const double> ends, std::span<double> out,
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
  /// One voxel's four channels as the file holds them: the mean C̄ (0: vacuum) and the
  /// column-mean variance V per axis.
  struct Record {
    float mean = 0.0f;
    std::array<float, 3> var{0.0f, 0.0f, 0.0f};
  };

  /// Walks the non-empty coarse cells, entering each into `hazard` and calling piece(a, b) with
  /// a, b distances from t0; stops when piece returns false.
  template <typename Piece>
  void walk(const volume::Ray& ray, double t0, double t1, transmittance::GammaHazard& hazard, Piece&& piece);
  LocalGammaField() = default;
  void make_dense(std::uint64_t max_dense_bytes);
  void make_accessors();

  std::shared_ptr<const volume::Grid> mean_;
  std::array<std::shared_ptr<const volume::Grid>, 3> var_;
  std::unique_ptr<volume::Tracer> tracer_;
  std::array<std::unique_ptr<volume::VoxelReader>, 3> var_readers_;
  std::shared_ptr<const std::vector<Record>> records_;  ///< the dense box, x-major (null: the trees)
  volume::DenseWalk dense_walk_;
  volume::DenseWalk::State walk_state_;  ///< this thread's walk (kept out of registers across log1p)
  double sigma_ = 1.0;
  transmittance::MemoryRule memory_ = transmittance::kDefaultMemoryRule;
};

}  // namespace weft::render
