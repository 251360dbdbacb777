#pragma once
/// @file
/// @brief Albedo-corrected downsampling (docs/render.md §6d (b)): one albedo multiplier k_N per
/// coarsening level N, fitted so that the exponential-N× grid renders as bright as the fine grid
/// on ONE scene, then reported on the others (the protocol of the downsampling literature).
/// Everything fitted here is fitted to images of the fine grid: the study labels its candidates
/// `fitted_to_images` and `uses_ground_truth`.

#include <utility>
#include <vector>

#include "weft/core/progress.h"
#include "weft/render/scene.h"
#include "weft/study/render_study.h"

namespace weft::study {

/// The albedo an albedo-corrected candidate renders with: albedo × k, each channel clamped to
/// [0, 1] (an albedo above 1 would create energy).
[[nodiscard]] render::Rgb corrected_albedo(const render::Rgb& albedo, double k);

/// The largest albedo factor that still changes the image: 1/min Λ_c over the channels Λ_c > 0 (1
/// when all are 0). Up to it channels reach 1 one by one (the brightest first: the correction
/// saturates channel by channel, by design); beyond it every channel is clamped at 1 and k
/// changes nothing. The fit's range (fit_albedo) and the largest k a study takes
/// (check_study_scene).
[[nodiscard]] double albedo_k_max(const render::Rgb& albedo);

/// One coarsening level's fit.
struct AlbedoFit {
  int factor = 0;
  double k = 1.0;          ///< the multiplier found
  double target = 0.0;     ///< the fine reference's mean pixel
  double fitted = 0.0;     ///< the coarse image's mean pixel at k
  double tolerance = 0.0;  ///< the stopping tolerance on |fitted − target|
  int renders = 0;         ///< coarse renders spent
  /// |fitted − target| ≤ tolerance; false when the budget ran out or the target lies outside
  /// what k ∈ [0, k_max] can reach (k is then the end nearer to it).
  bool converged = false;
};

/// @brief Fits k_N for every factor of spec.factors on `scene` (a study scene: check_study_scene).
///
/// Target: the mean pixel (all pixels and channels) of the fine grid rendered at
/// spec.reference_spp, against the exponential-N× grid (volume::downsample) with albedo
/// corrected_albedo(Λ, k), rendered at spec.spp (16 when spec.spp is 0) with spec.seed for every
/// k (common random numbers: the mean is a smooth, monotone function of k). The pixels the
/// cloth does not affect are the same in both images in expectation, so matching the whole
/// image's mean matches the mean over the cloth's pixels without a mask. Stopping rule:
/// |mean − target| ≤ max(2 standard errors of the difference, 0.1 % of the target), or 10
/// renders per factor; steps are secant steps kept inside the bracket found so far (bisection
/// when a secant step leaves it), over k ∈ [0, 1/min Λ_c] (beyond it every channel is clamped).
/// Every MPI rank must call it (renders are collective; rank 0 writes the coarse grids under
/// spec.work_dir and decides each step for all ranks).
[[nodiscard]] std::vector<AlbedoFit> fit_albedo(const render::SceneDesc& scene, const StudySpec& spec,
                                                ProgressSink& progress = null_progress());

/// fit_albedo's (factor, k_N) pairs, what StudySpec::albedo_factors takes for the other scenes.
[[nodiscard]] std::vector<std::pair<int, double>> fit_albedo_factors(const render::SceneDesc& scene,
                                                                     const StudySpec& spec, ProgressSink& progress);

}  // namespace weft::study
