#pragma once
/// @file
/// @brief The squared bias of a rendered image against a noisy reference, with its standard
/// error (docs/render.md §6c): what the image study reports as a candidate's bias.

#include <vector>

#include "weft/render/image.h"

namespace weft::study {

/// @brief The squared bias of a candidate from two images `a`, `b` (independent seeds, same
/// spp) and a `reference` (independent seed, with per-pixel variances): the mean over values i
/// of x_i = ((a+b)/2 − r)² − (a − b)²/4 − var r_i, whose expectation is the squared bias of
/// value i (E(X − r)² = bias² + var X + var r; E(a − b)²/4 = var of (a+b)/2). The standard
/// error is the spread of the x_i over √n (values independent: every pixel has its own streams).
struct BiasEstimate {
  double bias_sq = 0.0;    ///< may be < 0 by noise
  double stderr_sq = 0.0;  ///< standard error of bias_sq
  /// Over the same values: the mean of (a − r)² − var r, the squared error of `a` at its spp
  /// with the reference's noise removed (§6b), and the mean of (a − b)²/2, one image's variance.
  double error_sq = 0.0;
  double noise_sq = 0.0;
};
/// Only the pixels where `mask` (one flag per pixel, if given) is set count. Throws weft::Error
/// for images of different sizes.
[[nodiscard]] BiasEstimate estimate_bias(const render::Image& a, const render::Image& b, const render::Image& reference,
                                         const std::vector<bool>* mask = nullptr);

}  // namespace weft::study
