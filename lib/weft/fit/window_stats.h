#pragma once
/// @file
/// @brief Window-mean concentration statistics of a grid along an axis, and the one window → voxels
/// conversion (Jarabo et al. 2018, Eq. 19–20; docs/architecture.md §6 "Predictions").
///
/// What a "window" is. A beam along axis a sees, ray by ray, the concentration averaged over the
/// depth it has crossed; the gamma model replaces that per-ray mean C_ray by a Gamma(α, β)
/// variable, so T(t) = E[exp(−σ C_ray t)] = (1 + σt/β)^−α (the Laplace transform of Eq. 19).
/// A window of length L is a segment of L along a column; its sample is the mean of C over it.
/// All window positions along every column of the face are samples (stride one voxel), so the
/// statistics describe the medium at scale L, not one curve: the model is predicted from the
/// voxels, never fitted to T_gt (that is what the separate Levenberg–Marquardt fit does, to show
/// the best any gamma law can do). Taking L = t for each depth t would reproduce T_gt by
/// construction and predict nothing. The default L is the grid's extent along the beam (the
/// depth the beam crosses); L larger than the extent is clamped to it (reported as used).

#include <cstdint>

#include "weft/core/progress.h"
#include "weft/volume/grid.h"

namespace weft::fit {

/// Mean and variance of window-mean concentration.
struct ConcentrationStats {
  double mean = 0.0;
  double variance = 0.0;  ///< population variance over the samples
  std::uint64_t samples = 0;
  int window_voxels = 0;  ///< window length used, in voxels
  double window = 0.0;    ///< window length used, world units
};

/// The window (or block) of length `window` in voxels of edge h along an extent of n voxels:
/// round(window / h) clamped to 1..n; a window ≤ 0 is the whole extent. The one conversion every
/// statistic and model uses, so they agree on L.
[[nodiscard]] int window_voxels(double window, double h, int n);

/// Window statistics along `axis` (0, 1, 2; direction sense does not matter) for window length
/// `window` (world units; 0 = the grid's extent along the axis). Values are concentrations (or
/// extinctions, then use σ = 1). Throws weft::Error for an empty grid or a negative window.
[[nodiscard]] ConcentrationStats window_stats(const volume::Grid& grid, int axis, double window = 0.0,
                                              ProgressSink& progress = null_progress());

}  // namespace weft::fit
