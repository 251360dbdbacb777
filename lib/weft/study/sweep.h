#pragma once
/// @file
/// @brief What accuracy costs in time (`weft validate --sweep`): per axis beam, the full-resolution
/// ground truth (the reference), the same with fewer rays, and two models on grids downsampled
/// by f — the exponential (RTE) law per coarse voxel, and the gamma law per coarse voxel from the
/// fine grid's local statistics — each with its RMS error on T(t) against the reference and
/// its time. Writing tables and charts is the app's business.
///
/// Coarse models along a ray (docs/validate.md, "Accuracy and cost"). A coarse voxel v holds the
/// mean C̄_v of its f³ fine voxels and, per axis, the variance V_v of its f² fine column means
/// along that axis (the local fields of `weft fit --block f`). The ray's optical depth through v
/// over a segment of length s is σ·s·C_v with C_v the concentration the ray sees there:
///  - exponential: C_v = C̄_v, so T = exp(−σ Σ_v s_v C̄_v);
///  - gamma (independent voxels): C_v ~ Gamma(α_v = C̄_v²/V_v, β_v = C̄_v/V_v) (Eq. 19), constant
///    within v and independent between voxels, so the Laplace transforms multiply:
///    T = Π_v E[exp(−σ s_v C_v)] = Π_v (1 + σ s_v/β_v)^−α_v. Independence holds when the
///    correlation length of C along the ray is short against the coarse voxel; a constant field
///    of n voxels gives (1 + σs/β)^−nα, not the homogeneous law of one voxel of length ns;
///  - gamma (memory along the ray): the hazard of the law of v with the memory s measured from
///    the ray's entry, Σ(s) = σα_v/(β_v + σs) (render::LocalGammaField's composition), so
///    −log T = Σ_v α_v [log1p(σb_v/β_v) − log1p(σa_v/β_v)] over the segment [a_v, b_v]: a
///    constant field is exactly the homogeneous law (1 + σt/β)^−α (C fully correlated along the
///    whole ray).
/// V_v = 0 is the exponential law in v; C̄_v = 0 is vacuum. Every model is evaluated for the
/// reference's own rays (one per fine column of the face: a coarse column weighs as many fine
/// columns of the fine active face as it covers) at the reference's depths.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "weft/core/progress.h"
#include "weft/volume/grid.h"

namespace weft::dist {
class UnitStore;
}

namespace weft::study {

/// How a coarse voxel's concentration composes along a ray (see the file comment).
enum class CoarseLaw { exponential, gamma_independent, gamma_memory };

/// log T(t_k) of an axis beam through coarse fields, t_k = k·h (k = 0 … n, n the fine active
/// box's extent along the axis, h the fine voxel size), for one ray per fine column of the fine
/// active face. `mean` (and `variance`, ignored for the exponential law) have voxel size f·h, the
/// blocks anchored at the fine active box's lower corner, index 0 there (volume/block_lattice.h:
/// volume::downsample, local_fields).
/// `direction` is an axis direction (either sense). Throws weft::Error for a non-axis direction,
/// σ ≤ 0, an empty fine box, or coarse grids whose voxel size is not f·h.
[[nodiscard]] std::vector<double> coarse_beam_log_t(const volume::Grid& mean, const volume::Grid* variance,
                                                    const volume::IndexBox& fine_box, double fine_voxel, int factor,
                                                    const std::array<double, 3>& direction, double sigma,
                                                    CoarseLaw law);

struct SweepSpec {
  std::vector<std::array<double, 3>> directions{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  double sigma = 1.0;
  std::vector<int> factors{2, 4, 8, 16};
  /// Ground truth with fewer rays: one column per stride² (1, 1/4, 1/16 of the rays).
  std::vector<int> ray_strides{1, 2, 4};
  /// Every timing is the median of this many runs.
  int repetitions = 3;
  std::uint64_t seed = 1;
};

/// One point of the accuracy/time plane.
struct SweepRow {
  std::string axis;    ///< "+x"
  std::string method;  ///< "reference", "fewer-rays", "exponential", "gamma", "gamma-memory"
  int factor = 1;      ///< downsampling factor (1 at full resolution)
  double ray_fraction = 1.0;
  std::uint64_t rays = 0;
  double error_rms_t = 0.0;   ///< RMS |T − T_ref| over the reference's depths
  double error_max_t = 0.0;   ///< max |T − T_ref|
  double stderr_rms_t = 0.0;  ///< RMS standard error of T (ray estimates only; 0 for models)
  /// The accuracy a user gets: the RMS standard error for ray estimates (their error against
  /// the infinitely sampled truth), the RMS error against the reference for models.
  double accuracy_rms_t = 0.0;
  double prepare_seconds = 0.0;    ///< downsampling or local statistics (models), 0 for rays
  double transport_seconds = 0.0;  ///< the beam itself
  [[nodiscard]] double seconds() const { return prepare_seconds + transport_seconds; }
  bool pareto = false;  ///< on its axis's Pareto front of (seconds, accuracy_rms_t)
};

struct Sweep {
  double sigma = 1.0;
  double voxel_size = 1.0;
  std::uint64_t active_voxels = 0;
  int repetitions = 1;
  std::vector<SweepRow> rows;
};

/// Runs the sweep. Throws weft::Error for an empty grid, non-axis directions, σ ≤ 0, factors
/// outside 2..4096, strides < 1 or repetitions < 1.
///
/// The work is a set of units (one per downsampling factor, one per axis × ray stride) spread
/// over threads and, under mpirun, over ranks (dist::run_units); rank 0 reduces them in unit
/// order, so every number but the timings is the same for any ranks and threads. On other ranks
/// the result has no rows. With `store`, rank 0 records each finished unit there and a resumed
/// store's units are not run again (`weft validate --sweep --resume`).
[[nodiscard]] Sweep sweep(const volume::Grid& grid, const SweepSpec& spec, ProgressSink& progress = null_progress(),
                          dist::UnitStore* store = nullptr);

/// Marks the rows on the Pareto front of each axis: no other row of the axis is at least as
/// fast and at least as accurate, and strictly better in one.
void mark_pareto(std::vector<SweepRow>& rows);

}  // namespace weft::study
