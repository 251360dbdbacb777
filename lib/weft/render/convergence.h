#pragma once
/// @file
/// @brief Convergence studies of a render (supplement Figs. S.6–S.8; docs/render.md §6):
/// error against a reference and the log–log rate of that error (the contact sheet of its images:
/// contact_sheet.h).

#include <string>
#include <vector>

#include "weft/render/image.h"

namespace weft::render {

/// @brief Least-squares line through (log x, log y): y ≈ e^intercept · x^slope.
struct LogLogFit {
  double slope = 0.0;
  double intercept = 0.0;
  double slope_stderr = 0.0;  ///< from the residuals (0 for 2 points); a fit diagnostic, not a CI
  int points = 0;             ///< pairs used (both x and y finite and > 0)
};

/// Fits the points with x > 0 and y > 0 (others are skipped). Throws weft::Error for fewer than
/// two usable points, or when all usable x are equal.
[[nodiscard]] LogLogFit fit_log_log(const std::vector<double>& x, const std::vector<double>& y);

/// Throws weft::Error naming `source` and the first offending pixel when `reference` is not a
/// radiance image: a negative or non-finite value (an EXR may hold either, e.g. a difference image),
/// against which an RMSE would measure nothing a render converges to.
void check_reference(const Image& reference, const std::string& source);

/// Mean over pixels and channels of the variance of the pixel estimates (0 if the image carries none).
[[nodiscard]] double mean_variance(const Image& image);

/// RMSE of `image` against `reference`, with the reference's own noise removed:
/// sqrt(max(0, rmse² − mean_variance(reference))). E[rmse²] = true error² + the reference's
/// mean variance when the two are rendered with independent samples, so this is the estimate
/// of the error against the exact image (equal to rmse() for a reference without variances).
[[nodiscard]] double rmse_against_noisy_reference(const Image& image, const Image& reference);

}  // namespace weft::render
