#pragma once
/// @file
/// @brief The length scale of the local concentration statistics (docs/validate.md): a property of the
/// cloth, not of the voxel.
///
/// The autocorrelation of C along an axis has a fibre-scale part (falling within a fibre
/// diameter or a voxel, whichever is larger: the old default window, 4–5 voxels at every voxel
/// size) and a yarn-scale part (yarns, plies and gaps). Rays "see one concentration" over the
/// yarn scale, so that is the window of Eq. 19–20 and the block of the local fields:
///   yarn           the yarn diameter from the grid's provenance (weft gen records it); the
///                  default; a grid without provenance is refused with what to pass instead;
///   yarn-measured  the yarn scale estimated from the voxels alone (below). It is NOT resolution
///                  independent (0.19 / 0.25 / 0.33 mm for the same cloth at 5 / 10 / 20 µm, against
///                  its provenance diameter 0.30 mm), which is why it is not a default;
///   corr           each axis's fibre-scale correlation length (1/e lag; voxel dependent, kept
///                  for comparison with earlier versions);
///   extent         the whole depth along each beam;
///   a length       in the grid's world units.
/// Measured yarn scale: the autocorrelation R(l) along each axis is smoothed with a triangle of
/// half-width ℓ_f (its own 1/e lag, the fibre scale; smoothing R by a triangle is the same as
/// computing the autocorrelation of C box-averaged over ℓ_f along the axis), which removes the
/// fibre-scale part; the 1/e lag of the smoothed R is the yarn-scale correlation length ℓ_y; the
/// yarn scale is 3 ℓ_y (a yarn's cross-section decorrelates over about a third of its diameter:
/// checked against the provenance diameter of weft's own cloths, docs/validate.md), the median
/// over the axes longer than one voxel. It cannot be measured, and is refused naming why and
/// suggesting a length, when C is uniform over the box (R is 0: no structure) or when the
/// median axis's smoothed R stays above 1/e up to half the box (the structure is larger than the
/// grid: only a lower bound).

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/front_end.h"
#include "weft/core/progress.h"
#include "weft/volume/grid.h"
#include "weft/volume/provenance.h"

namespace weft::fit {

/// The window option as `weft validate`, `weft fit` and Python's validate/fit spell it, with its
/// separator; the study's is kStudyWindowOption. The advice in every error names the asker's own.
inline const Spelling kWindowOption{"--window ", "window="};
inline const Spelling kStudyWindowOption{"--study-window ", "window="};

struct StatisticsScale {
  std::string rule;                ///< "yarn", "yarn-measured", "corr", "extent" or "length"
  std::array<double, 3> length{};  ///< per axis, world units (0 = the extent along that axis)
  std::string source;              ///< human-readable: where the length came from
};

/// What a scale becomes on a grid: per axis the length the statistics and the local models use
/// (fit::window_voxels: round(L/h) voxels clamped to 1..n, n the active box's extent along the
/// axis; the extent for 0), and a warning line for every clamp, so a window of 1e-9 or 1e9 is
/// never changed in silence (report.json records both lengths: `window.length`,
/// `window.length_used`).
struct ScaleUse {
  std::array<double, 3> length{};  ///< per axis, world units
  std::vector<std::string> notes;  ///< one line per clamp (and per one-voxel window, see scale_use)
};

/// The ScaleUse of `scale` on `grid`. With `local_models` (validate's predictions), a window of
/// one voxel along an axis also gets a note: the local models' blocks then hold each voxel's own
/// value, so along that axis they reproduce the ground truth instead of predicting it (measured:
/// RMS error 2e-16 on T).
/// `option` is the window's option with its separator as each front end writes it (the study's
/// is `--study-window `).
[[nodiscard]] ScaleUse scale_use(const StatisticsScale& scale, const volume::Grid& grid, bool local_models,
                                 FrontEnd asker = FrontEnd::cli, const Spelling& option = kWindowOption);

/// Parses `text` (one of the names above or a positive length) and resolves it for `grid`.
/// Throws weft::Error for an unknown name or a non-positive length (naming the option as `asker`
/// writes it).
[[nodiscard]] StatisticsScale resolve_scale(const std::string& text, const volume::Grid& grid,
                                            const volume::Provenance& provenance,
                                            ProgressSink& progress = null_progress(), FrontEnd asker = FrontEnd::cli,
                                            const Spelling& option = kWindowOption);

/// Checks `text` as resolve_scale would (a known name or a positive length) without a grid, so
/// a bad --window is refused before anything is loaded; `option` names it in the errors (the
/// asker's spelling: "--window", "--study-window", "window").
void check_scale_text(const std::string& text, const std::string& option = "window");

/// Correlation length of C along `axis`: the lag at which the autocorrelation of C along the
/// columns of the active box (about the box mean) first falls to 1/e, linearly interpolated, in
/// world units. The scale over which a ray sees one concentration: the natural window of
/// Eq. 19–20 ("local" statistics), measured from the voxels alone. Lags are searched up to
/// min(extent − 1, 128) voxels; if the autocorrelation stays above 1/e (or C is uniform) the
/// result is the extent itself.
[[nodiscard]] double correlation_length(const volume::Grid& grid, int axis, ProgressSink& progress = null_progress());

/// Autocorrelation of C along `axis` about the box mean, lags 0..max_lag (R(0) = 1; all zeros
/// for a uniform grid), summed per column and merged in a fixed order.
[[nodiscard]] std::vector<double> autocorrelation(const volume::Grid& grid, int axis, int max_lag,
                                                  ProgressSink& progress = null_progress());

/// The measured yarn scale (world units), from the voxels alone (see the file comment); throws
/// weft::Error when it cannot be measured, naming the alternative as `asker` writes it.
[[nodiscard]] double measured_yarn_scale(const volume::Grid& grid, ProgressSink& progress = null_progress(),
                                         FrontEnd asker = FrontEnd::cli, const Spelling& option = kWindowOption);

/// The first lag (interpolated linearly, in lags) at which `r` falls to 1/e (0 when r(0) is
/// already there, as for a uniform grid's all-zero R); nullopt when it never does.
[[nodiscard]] std::optional<double> lag_falling_to_inverse_e(const std::vector<double>& r);
/// lag_falling_to_inverse_e, or r.size() − 1 when r never falls to 1/e.
[[nodiscard]] double lag_at_inverse_e(const std::vector<double>& r);

}  // namespace weft::fit
