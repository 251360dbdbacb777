#pragma once
/// @file
/// @brief The corpus study of `weft validate --corpus` (docs/validate.md): every woven pattern and the
/// knit × yarn presets × voxel sizes, each case an independent unit (a cloth generated from the
/// run seed, voxelized, validated at the default σ and scale), so cases can be spread over
/// threads or processes and reduced in case order.

#include <cstdint>
#include <string>
#include <vector>

#include "weft/core/progress.h"
#include "weft/fit/report.h"

namespace weft::dist {
class UnitStore;
}

namespace weft::study {

struct CorpusCase {
  std::string pattern;
  std::string preset;
  double voxel_size = 0.01;  ///< mm
  [[nodiscard]] std::string name() const;
};

/// Every woven pattern and stockinette × cotton, polyester, wool × 10 and 20 µm (42 cases);
/// quick: plain and stockinette, cotton, 20 µm.
[[nodiscard]] std::vector<CorpusCase> corpus_cases(bool quick);

/// @brief The cases whose name contains one of `parts` (e.g. "20um", "plain-cotton-10um"), in
/// their order; all cases when `parts` is empty. Fails naming a part that matches no case.
[[nodiscard]] std::vector<CorpusCase> select_corpus_cases(const std::vector<CorpusCase>& cases,
                                                          const std::vector<std::string>& parts);

struct CorpusAxis {
  std::string axis;
  double scale = 0.0;
  std::vector<fit::ModelRatio> models;
  fit::ModelRatio predicted;  ///< fit::predicted: the one model fixed before measuring
  fit::ModelRatio best;       ///< fit::best_by_ground_truth: a diagnostic chosen with T_gt
  /// The voxel ground truth against the fibres' (T_fibre, opaque fibres, the same rays and
  /// depths): the voxelization error of the case (docs/validate.md "Voxelization error").
  double voxel_minus_fibre_rms = 0.0;  ///< RMS over depths of T_gt − T_fibre
  double voxel_minus_fibre_max = 0.0;  ///< max over depths of |T_gt − T_fibre|
  double fibre_stderr_rms = 0.0;       ///< T_fibre's RMS standard error: the noise of that difference
};

struct CorpusResult {
  CorpusCase c;
  double sigma = 0.0;
  std::uint64_t active_voxels = 0;
  std::vector<CorpusAxis> axes;
  double seconds = 0.0;
};

/// Generates, voxelizes and validates one case (beams x, y, z; `window` as `weft validate
/// --window`), and measures each beam through the case's fibres (T_fibre on the same rays). The
/// cloth's seed is `seed` for every case (the same yarns at both voxel sizes).
[[nodiscard]] CorpusResult run_corpus_case(const CorpusCase& c, std::uint64_t seed, const std::string& window,
                                           ProgressSink& progress = null_progress());

/// @brief The corpus study: run_corpus_case for every case, each case a work unit spread over
/// threads and, under mpirun, over ranks (dist::run_units; case i is unit i). Every case uses the
/// same `seed` (as run_corpus_case), so a case's bytes depend only on (seed, window, the case),
/// never on where it ran. Returns the results in case order on rank 0, an empty vector elsewhere.
/// `store` records each finished case (--resume); `progress` counts cases over all ranks.
[[nodiscard]] std::vector<CorpusResult> run_corpus(const std::vector<CorpusCase>& cases, std::uint64_t seed,
                                                   const std::string& window, ProgressSink& progress = null_progress(),
                                                   dist::UnitStore* store = nullptr);

}  // namespace weft::study
