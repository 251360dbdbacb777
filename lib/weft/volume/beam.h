#pragma once
/// @file
/// @brief Ground-truth transmittance of a beam of parallel rays through a voxel grid.
///
/// A beam is a set of parallel rays covering the grid's active bounding box as seen from
/// `direction`: one ray per column (a lattice cell of one voxel's width on the plane
/// perpendicular to the beam), at the cell centre or at `rays_per_column` jittered points.
/// Depth t is measured from where each ray enters the box. T_gt(t) = mean over rays of
/// exp(−τ_i(t)) (docs/architecture.md §6), accumulated with log-sum-exp so that T far below 1e−300 is still
/// reported correctly as log T.

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "weft/core/progress.h"
#include "weft/volume/grid.h"

namespace weft::volume {

/// How the rays of a beam are traced.
enum class BeamMethod {
  automatic,    ///< streaming for axis beams, per_ray otherwise
  streaming,    ///< one pass over the active voxels (axis beams only)
  per_ray,      ///< weft's hierarchical Amanatides–Woo DDA per ray (dda.h)
  openvdb_dda,  ///< openvdb::math::DDA<Ray, 0> with a value accessor per ray (reference, slower)
};

[[nodiscard]] std::string to_string(BeamMethod method);
/// Parses "auto" | "streaming" | "per-ray" | "openvdb"; throws weft::Error otherwise.
[[nodiscard]] BeamMethod parse_beam_method(const std::string& text);

struct BeamSpec {
  /// World direction of travel (need not be unit). Exactly one non-zero component = axis beam.
  std::array<double, 3> direction{0.0, 0.0, 1.0};
  /// μ = scale × value: σ for concentration grids, 1 for extinction grids.
  double scale = 1.0;
  /// Rays per column; > 1 implies jitter. Axis-aligned rays of one column cross the same
  /// voxels, so for axis beams every ray of a column has the same τ (counted once).
  int rays_per_column = 1;
  /// Jittered origins within each column cell instead of the centre.
  bool jitter = false;
  std::uint64_t seed = 1;
  /// Depth spacing (world units); 0 means one voxel.
  double depth_step = 0.0;
  BeamMethod method = BeamMethod::automatic;
  /// Oblique beams: keep only the rays whose chord through the box is the whole depth grid (a
  /// slab's rays that enter one face and leave the opposite one), not the rays that enter or leave
  /// through a side and see a shorter chord. Those mix T ≈ 1 into the mean and dilute every
  /// comparison of two media along the beam (docs/validate.md "Fields along any direction"). Axis
  /// beams cross the whole box anyway.
  bool full_chords = false;
  /// Keeps one lattice cell (column) per stride × stride block of cells, at an offset drawn
  /// per block from `seed`: 1/stride² of the rays, a cheaper and noisier ground truth. 1 = all.
  int column_stride = 1;
};

/// T(t) on a depth grid, as log T with the relative standard error of T.
struct TransmittanceCurve {
  std::vector<double> depth;       ///< world distance from the entry face
  std::vector<double> log_t;       ///< log of the mean over rays of exp(−τ_i(t))
  std::vector<double> rel_stderr;  ///< standard error of that mean divided by the mean
  std::uint64_t rays = 0;          ///< rays traced that entered the box
  /// The samples behind the standard error: an axis beam's rays_per_column rays of one column
  /// cross the same voxels, so they count once; = rays otherwise. Columns count as independent
  /// samples of the cloth even where a fine lattice repeats an optical depth (docs/validate.md
  /// "What the standard error is").
  std::uint64_t distinct_rays = 0;
  std::array<double, 3> direction{0.0, 0.0, 1.0};  ///< unit direction
  std::string method;

  [[nodiscard]] std::size_t size() const { return depth.size(); }
  [[nodiscard]] double transmittance(std::size_t k) const;
  [[nodiscard]] double stderr_abs(std::size_t k) const { return transmittance(k) * rel_stderr[k]; }
};

/// Parses "x", "+y", "-z" or "dx,dy,dz" (non-zero, finite); throws weft::Error otherwise.
[[nodiscard]] std::array<double, 3> parse_direction(const std::string& text);
/// The axis (0, 1, 2) of a direction with exactly one non-zero component, else −1.
[[nodiscard]] int beam_axis(const std::array<double, 3>& direction);
/// "+x", "-z", or "(0.577, 0.577, 0.577)".
[[nodiscard]] std::string direction_label(const std::array<double, 3>& direction);

/// What measure_beam would spend on a beam, estimated from the grid's active box and the spec
/// before anything is allocated (docs/robustness.md "Work and memory budgets").
struct BeamCost {
  double rays = 0.0;   ///< rays traced (an axis beam streamed: its columns)
  double steps = 0.0;  ///< rays × (cells crossed + depths profiled), or columns × (box depth + depths)
  double bytes = 0.0;  ///< the accumulators, the depth grid and every thread's scratch
};
/// Throws weft::Error for the bad specs measure_beam refuses.
[[nodiscard]] BeamCost estimate_beam(const Grid& grid, const BeamSpec& spec);

/// Measures T_gt(t) of the beam. Throws weft::Error for an empty grid, a bad spec (σ ≤ 0,
/// rays_per_column < 1, zero direction), streaming asked for a non-axis direction, or a beam
/// whose estimate_beam is over the budgets of check_pass_cost (pass_budget.h), before any work.
/// Reports progress (and so can be stopped) after every ~10⁶ steps of work per thread.
[[nodiscard]] TransmittanceCurve measure_beam(const Grid& grid, const BeamSpec& spec,
                                              ProgressSink& progress = null_progress());

/// The depth grid (distances from the entry face) on which measure_beam reports T for this
/// beam: it depends on the grid's box and the spec only, so predictions can be made on it
/// without measuring anything.
[[nodiscard]] std::vector<double> beam_depths(const Grid& grid, const BeamSpec& spec);

/// The optical depth profiles τ_i(t_k) of every ray of the beam (rays in a fixed order that
/// does not depend on the method), with the depth grid; for tests and small grids.
struct BeamDepths {
  std::vector<double> depth;
  std::vector<std::vector<double>> tau;  ///< tau[ray][k]
};
[[nodiscard]] BeamDepths beam_optical_depths(const Grid& grid, const BeamSpec& spec);

}  // namespace weft::volume
