#pragma once
/// @file
/// @brief The render-study matrix's judgement and reports (docs/render.md §6e): cost per sample,
/// the equal-error speed-up, the headline per cloth, and the CSV, JSON and Markdown of a run.

#include <string>
#include <vector>

#include "weft/study/render_matrix.h"

namespace weft::study {

/// The error the equal-error speed-up is taken at: 5 % of the reference's mean cloth pixel.
constexpr double kMatrixErrorFraction = 0.05;

/// CPU seconds per sample of a candidate's image A: its CPU time over spp × pixels.
[[nodiscard]] double cost_per_sample(const StudyCandidate& c, int pixels);

/// @brief How much sooner `c` reaches an RMSE of E over the cloth's values than the fine grid
/// `fine`, both rendered in one case. With per-sample variance v = noise² · spp and cost per
/// sample t, the fine grid (no bias: the reference's model) needs t_f v_f / E² of time; a
/// candidate with bias b < E needs t_c v_c / (E² − b²), and never reaches E when b ≥ E (0 is
/// returned); the fine grid itself gives 1. Cloth statistics (cloth_bias, cloth_noise), E = kMatrixErrorFraction ×
/// cloth mean.
[[nodiscard]] double equal_error_speedup(const StudyCandidate& c, const StudyCandidate& fine, double cloth_mean);

/// The speed-up the goal asks for at RMSE 5 % (docs/render.md §6e, "What accuracy costs in time").
constexpr double kMatrixSpeedupGoal = 3.0;

/// @brief The equal-error speed-up's ceiling r = t_f v_f / (t_c v_c): what `c` gains over the
/// fine grid at an error so large that its bias no longer counts, or were it unbiased. At an
/// error E the speed-up is r (1 − b²/E²) (equal_error_speedup), so no E gives more than r: a
/// representation whose samples are r < 3 times cheaper at equal noise cannot reach a 3×
/// speed-up at any accuracy, however small its bias. The fine grid gives 1.
[[nodiscard]] double speedup_ceiling(const StudyCandidate& c, const StudyCandidate& fine);

/// @brief The least RMSE over the cloth's values, as a fraction of the cloth's mean, at which `c`
/// is `target` times faster than the fine grid: r (1 − b²/E²) = target gives
/// E = b / √(1 − target/r). Infinite when r ≤ target (never that much faster: speedup_ceiling),
/// and for the fine grid itself unless target ≤ 1 (then 0).
[[nodiscard]] double error_for_speedup(const StudyCandidate& c, const StudyCandidate& fine, double cloth_mean,
                                       double target);

/// One representation of one cloth judged over the light × view set-ups (a representation fitted
/// to images, over those it was not fitted on).
struct MatrixVerdict {
  std::string name;
  std::string model;
  int factor = 0;
  double worst_relative_bias = 0.0;  ///< max over the judged cases of cloth_bias / cloth_mean
  std::string worst_case;
  double mean_relative_bias = 0.0;
  double memory_ratio = 0.0;     ///< fine grid's bytes / its bytes (MatrixMemory::values)
  double cost_ratio = 0.0;       ///< its cost per sample / the fine grid's, mean over the judged cases
  double speedup = 0.0;          ///< equal_error_speedup, the smallest over the judged cases
  double speedup_ceiling = 0.0;  ///< speedup_ceiling, the smallest over the judged cases
  /// error_for_speedup at kMatrixSpeedupGoal, the largest over the judged cases (relative).
  double error_for_goal = 0.0;
  /// The worst cloth bias at each block size of kBiasBlocks (bias_scales.h), relative, and the
  /// level (mean difference) of largest magnitude, relative and signed.
  std::vector<double> worst_relative_bias_by_block;
  double worst_relative_level = 0.0;
};

struct MatrixHeadline {
  std::string cloth;
  int judged_cases = 0;
  std::vector<MatrixVerdict> verdicts;  ///< every coarse representation, in candidate order
  /// Per factor of the study, the representation with the smallest worst-case bias.
  std::vector<MatrixVerdict> best;
  /// Per factor, the resolution floor (resolution_floor.h) judged like a representation over
  /// every set-up: named "resolution-floor-Nx", no memory, cost or speed-up.
  std::vector<MatrixVerdict> floors;
  std::string text;
};

/// The headline of each cloth, in the spec's order (a candidate fitted to images is not judged on its fitted_on case).
[[nodiscard]] std::vector<MatrixHeadline> matrix_headlines(const MatrixSpec& spec,
                                                           const std::vector<MatrixCaseResult>& results);

/// One row per case and candidate, only what does not depend on timing (the same bytes for any
/// rank or thread count): the cloth statistics, the frame bias and the memory.
[[nodiscard]] std::string matrix_csv(const std::vector<MatrixCaseResult>& results);
/// One row per case and candidate: spp, seconds, CPU seconds, cost per sample and its ratio to the
/// fine grid's, the equal-error speed-up, its ceiling and the error at which it reaches the goal.
[[nodiscard]] std::string matrix_cost_csv(const std::vector<MatrixCaseResult>& results);
/// Everything: the run's key, every case and candidate, the headlines (timing keys end in
/// "_seconds"; cost_ratio and speedup are timing-derived).
[[nodiscard]] std::string matrix_json(const MatrixSpec& spec, const std::vector<MatrixCaseResult>& results,
                                      const std::vector<MatrixHeadline>& headlines);
/// The headline table per cloth and representation, the goals of docs/render.md §6e, the worst
/// bias against image scale per representation and, for the candidates split into components,
/// each case's transmission, single and multiple scattering bias and level, as Markdown (what
/// the docs quote).
[[nodiscard]] std::string matrix_markdown(const std::vector<MatrixHeadline>& headlines,
                                          const std::vector<MatrixCaseResult>& results);

}  // namespace weft::study
