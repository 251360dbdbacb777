#pragma once
/// @file
/// @brief The render-study matrix (docs/render.md §6e): the image study of render_study.h run on
/// every cloth × light set-up × view, each case a work unit rendered on one rank, with the
/// statistics over the cloth's pixels, the memory of every representation in bytes and the cost
/// per sample, gathered on rank 0 in case order.
///
/// A case's bytes depend only on (the spec, the case): images at a fixed spp, seeds from the
/// spec, cloths from their generator spec and seed. So the matrix gives the same numbers for any
/// rank or thread count (timings aside), and a finished case stored by `--resume`
/// (dist::UnitStore, keyed by the spec) stands for a rerun of it.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "weft/core/front_end.h"
#include "weft/core/progress.h"
#include "weft/render/cloth_scene.h"
#include "weft/study/render_study.h"
#include "weft/study/representation_memory.h"

namespace weft::dist {
class UnitStore;
}

namespace weft::study {

/// A case's film side, pixels (`--study-film`, Python's film=).
constexpr int kMinMatrixFilm = 8;
constexpr int kMaxMatrixFilm = 4096;
/// Yarns per side of a matrix cloth (`--study-yarns`, Python's yarns=): 64 × 64 yarns at 10 µm
/// are already about 10⁹ voxels of box.
constexpr int kMaxMatrixYarns = 64;

struct MatrixSpec {
  /// Cloth patterns of `weft gen` (default: the plain weave, a twill, the stockinette knit), each
  /// generated with the default yarns at `yarns` × `yarns` and `voxel_size`.
  std::vector<std::string> cloths{"plain", "twill22", "stockinette"};
  int yarns = 4;
  double voxel_size = 0.01;      ///< mm
  std::uint64_t cloth_seed = 1;  ///< the generator's seed (the same yarns in every case)
  std::vector<render::ClothLighting> lightings{render::ClothLighting::back, render::ClothLighting::front,
                                               render::ClothLighting::grazing};
  std::vector<double> tilts{45.0, 8.0};  ///< views: degrees off the cloth's normal
  int width = 96;                        ///< film
  int height = 72;
  /// Every case's study: factors, memory rules, spp (> 0: the matrix renders at fixed spp, so a
  /// case's numbers do not depend on where or when it ran), reference spp, seed, scale. Its
  /// work_dir is the matrix's folder (cases, cloths and the unit stores go under it).
  StudySpec study;
};

/// The defaults of the study matrix (docs/render.md §6e), where every front end (the CLI's
/// `--study` with no scene, Python's weft.render_matrix) starts: the spec's cloths, set-ups, film
/// and yarns; factors 2, 4, 8; the default memory rule and `segment`; 64 spp per candidate image
/// and a 1024 spp reference. With `quick`: 2 × 2 yarns at 20 µm, a 32 × 24 film, 8 spp and a
/// 128 spp reference.
[[nodiscard]] MatrixSpec default_matrix_spec(bool quick);

/// Throws weft::Error naming the bad field (no cloths, lightings or views, a cloth, lighting or
/// view given twice (require_distinct: a cloth by its pattern, so "twill" and "twill22" are one),
/// a tilt outside [0, 80], a film under 8 px, yarns < 1, voxel size not > 0, study.spp == 0, or
/// what check_study_spec refuses, its options spelled for `front`).
void check_matrix_spec(const MatrixSpec& spec, FrontEnd front = FrontEnd::cli);

/// The cloths' patterns as every output names them: each of MatrixSpec::cloths with its alias
/// resolved (cloth::canonical_pattern: "twill" is "twill22", "knit" "stockinette"), as `weft gen
/// --pattern` resolves it.
[[nodiscard]] std::vector<std::string> matrix_patterns(const MatrixSpec& spec);

struct MatrixCase {
  std::size_t cloth = 0;  ///< index into MatrixSpec::cloths
  std::string pattern;    ///< that cloth's pattern (matrix_patterns: aliases resolved)
  render::ClothLighting lighting = render::ClothLighting::back;
  double tilt = 45.0;
  /// "plain-back-45deg": the tilt in the fewest digits that read back as the same number
  /// (matrix_tilt_name), so distinct views never share a case's folder.
  std::string name;
  /// The set-up the albedo factors were fitted on (its cloth's first lighting × first view):
  /// the albedo-corrected candidates are not judged on it in the headline (the others are).
  bool fitted_on = false;
};

/// A view's tilt as case names write it: weft::number_name, the shortest decimal that reads back as
/// the same double (45 → "45", 30.00000001 → "30.00000001"), −0 as "0". Distinct tilts give
/// distinct names; a rounded form (6 significant digits) gave 30 and 30.00000001 one folder, the
/// second case's files over the first's.
[[nodiscard]] std::string matrix_tilt_name(double tilt);

/// Every cloth × lighting × view, in that nesting order.
[[nodiscard]] std::vector<MatrixCase> matrix_cases(const MatrixSpec& spec);

/// The bytes a representation takes, every channel counted (representation_memory.h): the
/// study's own count of the candidate, carried per case.
using MatrixMemory = RepresentationMemory;

struct MatrixCandidate {
  StudyCandidate study;  ///< its numbers and curve (image and error map not kept)
  MatrixMemory memory;
};

struct MatrixCaseResult {
  MatrixCase c;
  int width = 0;
  int height = 0;
  int reference_spp = 0;
  double reference_mean = 0.0;
  int cloth_pixels = 0;
  double cloth_mean = 0.0;
  double reference_seconds = 0.0;
  std::vector<std::pair<int, double>> albedo_factors;  ///< what the case's study was given
  std::vector<MatrixCandidate> candidates;
  std::vector<ResolutionFloor> resolution_floors;  ///< the case's study's (resolution_floor.h)
  std::vector<std::string> notes;                  ///< the case's study's warnings (a clamped window)
};

/// @brief A case as JSON, written once: what a stored case holds and crosses ranks as (MessagePack,
/// doubles exact), and what matrix.json reports per case, whose reports add the judged figures
/// (render_matrix_report.h). Per candidate the study's own JSON (study_candidate_json,
/// render_study_report.h: the one writer of a candidate) less its scene path, with its memory
/// (MatrixMemory: memory_bytes = values, memory_tree_bytes, memory_channels).
[[nodiscard]] nlohmann::json matrix_case_json(const MatrixCaseResult& r);

/// The folder of case `c` under the matrix's work_dir (its study's files and images).
[[nodiscard]] std::filesystem::path matrix_case_dir(const MatrixSpec& spec, const MatrixCase& c);

/// The JSON that identifies a run (every field a case's bytes depend on): the key of the
/// --resume stores, so a changed spec is refused rather than mixed with old cases.
[[nodiscard]] std::string matrix_key(const MatrixSpec& spec);

/// The progress stage of the matrix's cases: kMatrixCaseUnits per case, moved by each case's
/// renders in proportion to their pixel samples (kStudyRendersStage) as they go, so a bar has
/// its rate and ETA within a case (docs/render.md §6e).
inline constexpr std::string_view kMatrixCasesStage = "study cases x1000";
inline constexpr std::uint64_t kMatrixCaseUnits = 1000;

/// @brief Runs every case (collective: every rank calls it). Cloths are generated first (one
/// unit per cloth, kept under work_dir/cloths/ by a hash of their generator spec), then each
/// case runs run_study rank-locally (dist::RankLocal) and writes its study's files into
/// matrix_case_dir. Returns the cases in order on rank 0, an empty vector elsewhere.
/// `progress` gets the cloths' and the albedo fits' stages, then kMatrixCasesStage over all
/// ranks; `store` (may be null) records each finished case. A Cancelled from `progress`
/// (Ctrl-C in Python) stops the case being rendered at its next report and reaches the caller:
/// the cases finished before stay in `store`, the one stopped is not stored.
[[nodiscard]] std::vector<MatrixCaseResult> run_matrix(const MatrixSpec& spec, ProgressSink& progress = null_progress(),
                                                       dist::UnitStore* store = nullptr);

}  // namespace weft::study
