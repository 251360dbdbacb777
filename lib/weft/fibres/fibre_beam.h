#pragma once
/// @file
/// @brief The fibre ground truth T_fibre(t): a beam of parallel rays (the voxel beam's lattice,
/// weft/volume/lattice.h) intersected exactly with the fibres' capsules (capsule_index.h)
/// (docs/validate.md §Fibre ground truth).
///
/// Each ray's path inside the fibres is the union of its capsule intervals (overlapping fibres
/// counted once: a point of space is fibre or not). Opaque fibres: τ_i(t) = 0 before the ray's
/// first entry, ∞ after. Fibres of internal extinction κ: τ_i(t) = κ·|union ∩ [0, t]|.
/// T_fibre(t) = mean over rays of exp(−τ_i(t)), with the standard error of that mean.

#include <limits>

#include "weft/core/progress.h"
#include "weft/fibres/capsule_index.h"
#include "weft/volume/beam.h"
#include "weft/volume/lattice.h"

namespace weft::fibres {

/// Extinction inside the fibres [1/length]; infinity = opaque fibres.
inline constexpr double kOpaque = std::numeric_limits<double>::infinity();

/// T_fibre(t) of the beam `spec` (direction, rays_per_column, jitter, seed, depth_step,
/// column_stride; scale and method are ignored) over `box` with lattice cells of width `cell`.
/// Unlike a voxel column, the rays of one cell meet different fibres, so every ray is a
/// sample (distinct_rays = rays). Depths where no ray got through have log T = −∞ and a
/// standard error of 0. Same seed ⇒ same bytes for any thread count. Throws weft::Error for a
/// bad spec, a negative or NaN extinction, or a beam no ray of which enters the box.
[[nodiscard]] volume::TransmittanceCurve measure_fibre_beam(const CapsuleIndex& fibres, const volume::WorldBox& box,
                                                            double cell, const volume::BeamSpec& spec,
                                                            double extinction = kOpaque,
                                                            ProgressSink& progress = null_progress());

/// The same beam over a grid's active box with its voxel size as the cell width: the rays of
/// the grid's voxel beam (measure_beam) with the same spec.
[[nodiscard]] volume::TransmittanceCurve measure_fibre_beam(const CapsuleIndex& fibres, const volume::Grid& grid,
                                                            const volume::BeamSpec& spec, double extinction = kOpaque,
                                                            ProgressSink& progress = null_progress());

/// Throws weft::Error when the fibre beam would be over the budget of every pass
/// (volume/pass_budget.h: its steps or its memory): what measure_fibre_beam checks first, for a
/// caller that checks every beam before tracing any.
void check_fibre_beam(const volume::WorldBox& box, double cell, const volume::BeamSpec& spec);
void check_fibre_beam(const volume::Grid& grid, const volume::BeamSpec& spec);

/// The box holding every capsule of the index (for beams through fibres without a grid).
[[nodiscard]] volume::WorldBox fibre_box(const CapsuleIndex& fibres);

}  // namespace weft::fibres

namespace weft::fibres {

/// How far a voxel beam's T is from the fibre beam's on the same depths (the voxelization
/// error, docs/validate.md §Voxelization error).
struct CurveDifference {
  double rms = 0.0;           ///< √(mean over depths of (T_a − T_b)²)
  double max_abs = 0.0;       ///< max over depths of |T_a − T_b|
  double rms_stderr_a = 0.0;  ///< √(mean over depths of se_a²)
  double rms_stderr_b = 0.0;  ///< √(mean over depths of se_b²): the noise of a jittered fibre beam
  double end_a = 0.0;         ///< T_a at the last depth
  double end_b = 0.0;         ///< T_b at the last depth
};
/// Throws weft::Error when the depth grids differ.
[[nodiscard]] CurveDifference curve_difference(const volume::TransmittanceCurve& a,
                                               const volume::TransmittanceCurve& b);

}  // namespace weft::fibres
