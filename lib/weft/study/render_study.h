#pragma once
/// @file
/// @brief Accuracy against time in images (docs/render.md §6c): a fine cloth
/// grid rendered to low noise is the reference, and coarse models of the same cloth are rendered
/// at (about) equal time and compared with it, with their bias and their noise apart.
///
/// Candidates, all of the one grid medium of a scene (the default cloth of `weft gen` when the
/// app is given none):
///   fine              the fine grid itself, exponential per voxel (the reference's model)
///   exponential-Nx    the grid downsampled N× (volume::downsample, volume-conserving), exponential
///                     per coarse voxel: what a coarse render grid without statistics carries
///   local-gamma-Nx    the local statistic fields of N³ blocks (fit::local_fields, what
///                     `weft fit --block N` writes) as a local-gamma medium (§5b) under its
///                     default memory rule; local-gamma-<rule>-Nx under another (§5e)
///   shadow-corrected-Nx  the grid downsampled N× with each coarse voxel's extinction corrected
///                     for self-shadowing in its block (volume::shadowed_downsample, isotropic;
///                     docs/render.md §6d), exponential per coarse voxel
///   shadow-directional-Nx  the same correction kept per axis: a direction-dependent extinction
///                     σ(ω) = Σ_a ω_a² σ'_a from three grids (render::DeltaTrackingGridMedium, §6d)
///   albedo-corrected-Nx  exponential-Nx with the albedo × k_N of StudySpec::albedo_factors
///                     (fitted to images of another scene; only when given)
///   slab-gamma        one homogeneous box of the grid's active box with the gamma law of the
///                     grid's pooled window statistics at the yarn scale (predicted from the
///                     voxels, never fitted to the rendered reference)
/// and the best predictive model of `weft validate` on the fine grid, rendered as local fields
/// when it has a local-field medium: local-gamma is (b) and local-exponential is (a), so it is
/// then named but not rendered twice; any other model has no local-field medium and is reported
/// as such.
///
/// Time. Each candidate's first image is rendered in passes of one sample per pixel until its
/// wall-time budget is spent (render's own time budget: rank 0's clock decides for every MPI
/// rank), or at a fixed spp (StudySpec::spp: deterministic, for tests and MPI comparisons). The
/// spp reached and the seconds used are recorded; the image is reproduced bit for bit by
/// rendering the candidate's scene at that spp and seed. The second image (for the noise) is
/// rendered at exactly the first one's spp with another seed.
///
/// Statistics, per candidate with images A and B (independent seeds, same spp) and the
/// reference R (independent seed, per-pixel variances), means over pixels and channels:
///   rmse   = sqrt(max(0, |A − R|² − var R))            the error at that time (§6b correction)
///   noise  = sqrt(|A − B|² / 2)                         the standard deviation of one image
///   bias²  = |(A+B)/2 − R|² − |A − B|²/4 − var R        (bias = sqrt(max(0, bias²)))
/// since E|X − R|² = bias² + var X + var R for independent X and R and E|A − B|²/4 = var of
/// (A+B)/2: bias is the RMSE the candidate would have if rendered to convergence, without
/// rendering it so. Its standard error comes from the spread of the per-value terms, so a
/// test can ask whether a bias is distinguishable from 0.
/// The fine grid has no bias (same model as R), so its error falls as t^{−1/2}: it needs
/// t_fine(E) = t_f · (rmse_f / E)² seconds to reach error E. A candidate with error E_c after
/// t_c seconds is `speedup` = t_fine(E_c) / t_c times faster than the fine grid at its accuracy.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "weft/core/front_end.h"
#include "weft/core/progress.h"
#include "weft/render/image.h"
#include "weft/render/scene.h"
#include "weft/study/bias_scales.h"
#include "weft/study/render_components.h"
#include "weft/study/resolution_floor.h"
#include "weft/volume/grid.h"

namespace weft::study {

/// Seeds of a study's images are its seed plus multiples of this step: A + 0, B + 1, the
/// reference + 2, the background + 3, and the components of each image (render_components.h)
/// + 8 and + 16 from that image's own (stream_for hashes (seed, index), so any distinct seed
/// gives independent noise).
constexpr std::uint64_t kStudySeedStep = 0x9E3779B97F4A7C15ULL;

/// With a fixed spp (StudySpec::spp > 0), run_study reports all its renders as one stage of this
/// label, counted in pixel samples (width × height × spp of every render), after the stages of
/// its preparation (validation, window statistics, local fields); with a time budget each render
/// is its own stage. A caller running many studies shows that stage as their share of one bar
/// (ProgressShare: the study matrix, docs/render.md §6e).
inline constexpr std::string_view kStudyRendersStage = "study renders";

/// The largest fixed spp per candidate image (`--study-spp`, Python's spp=): a candidate renders
/// two images at it, plus its component renders.
constexpr int kMaxStudySpp = 1 << 20;
/// The time budget per candidate image, seconds (`--study-time`, Python's seconds=).
constexpr double kMinStudySeconds = 1e-3;
constexpr double kMaxStudySeconds = 1e6;

struct StudySpec {
  std::vector<int> factors{2, 4, 8, 16};  ///< coarsening factors, each in [2, 4096], no repeats
  /// The caller chose `factors` (CLI --study-factors, Python factors=): each must suit the grid
  /// (check_factors_for_grid). Otherwise they are the defaults, and those too coarse for a small
  /// cloth are dropped with a line to `log` (factors_for_grid).
  bool factors_given = false;
  double seconds = 10.0;     ///< wall-time budget per candidate image (when spp == 0)
  int spp = 0;               ///< > 0: every candidate at this spp instead of a budget
  int max_spp = 1 << 16;     ///< cap of a budgeted render
  int reference_spp = 1024;  ///< the reference: the fine grid at this spp
  std::uint64_t seed = 1;    ///< first images; second images and the reference derive theirs
  /// The statistics scale of the slab's law and of the validation (fit::resolve_scale, as
  /// `weft validate --window`): "yarn" needs a grid whose provenance records the yarn diameter
  /// (otherwise weft::Error before anything is written: no voxel-dependent fallback).
  std::string scale = "yarn";
  /// The local-gamma candidates' memory rules (docs/render.md §5e; each once), one candidate per
  /// rule and factor: `local-gamma-Nx` for the medium's default rule (transmittance::kDefaultMemoryRule,
  /// optical-depth), `local-gamma-<rule>-Nx` for the others (e.g. local-gamma-segment-4x).
  std::vector<transmittance::MemoryRule> memory_rules{transmittance::kDefaultMemoryRule};
  /// (factor N, k_N): one `albedo-corrected-Nx` candidate per pair, exponential-N× with the
  /// albedo × k_N clamped to [0, 1] (fitted on another scene by fit_albedo_factors, albedo_fit.h;
  /// docs/render.md §6d). Each N must be one of `factors`, each k_N finite and > 0. Empty: none.
  std::vector<std::pair<int, double>> albedo_factors;
  /// The albedo factors are fitted before the study renders (`--study-albedo fit`, Python's
  /// albedo="fit", the matrix's per-cloth fit): there will be albedo-corrected candidates
  /// although albedo_factors is still empty when the spec is checked (candidate_families).
  bool albedo_fitted = false;
  /// Candidates whose error is split into transmission, single and multiple scattering
  /// (render_components.h): families such as "exponential" or "local-gamma-segment" (a
  /// candidate's name without "-Nx"), or "all"; the fine grid is split whenever anything is.
  /// Empty: no component renders (the scene must then have no reflecting surface: see
  /// check_component_scene).
  std::vector<std::string> components;
  /// Folder for the candidates' grids, fields and scene files (created; rank 0 writes).
  std::filesystem::path work_dir;
  /// The run's own folder (empty: work_dir): a file under it is named in the scene files relative
  /// to the scene file's folder, so the folder can be moved or copied whole and `weft render
  /// <candidate>.json` still finds its grids; a file outside it (the user's fine grid) stays
  /// absolute. The matrix sets its --out, whose cloths/ the cases' scenes name.
  std::filesystem::path files_root;
  /// Receives one line per stage ("rendering local-gamma-4x ..."); may be null.
  std::function<void(const std::string&)> log;
  /// Who asks: options in the lines said are spelled its way (`--study-window` or `window=`).
  FrontEnd front = FrontEnd::cli;
};

/// The defaults of a single study (docs/render.md §6c), where every front end (the CLI's
/// `--study`, Python's weft.render_study) starts: the spec's own values, and with `quick` a 1 s
/// budget per candidate image and a 256 spp reference.
[[nodiscard]] StudySpec default_study_spec(bool quick);

/// The candidates' families, a candidate's name without its "-Nx" (docs/render.md §6c): fine,
/// exponential, local-gamma, local-gamma-<rule> for each of StudySpec::memory_rules but the
/// default (whose candidates are local-gamma-Nx), shadow-corrected, shadow-directional,
/// albedo-corrected (when the study has albedo factors, given or to be fitted), slab-gamma. What
/// StudySpec::components takes (and "all").
[[nodiscard]] std::vector<std::string> candidate_families(const StudySpec& spec);

/// Throws weft::Error naming the bad field (factors out of range or repeated, a memory rule
/// repeated, seconds outside [kMinStudySeconds, kMaxStudySeconds], spp < 0 or > kMaxStudySpp,
/// max_spp < 1, reference_spp outside [1, render::kMaxSpp], an empty work_dir,
/// a component family that names no candidate: a local-gamma rule not among memory_rules is
/// named with the option that adds it, spelt for `front`).
void check_study_spec(const StudySpec& spec, FrontEnd front = FrontEnd::cli);

/// Throws weft::Error for a coarsening factor N of `factors` whose one coarse voxel (N voxels per
/// axis, anchored at the active box's lower corner: volume/block_lattice.h) holds the fine grid's
/// whole active box, i.e. N >= its largest extent in voxels (docs/render.md §6c "Factors"): the
/// coarse grid is then one voxel, every coarse candidate one homogeneous box of N³ voxels (larger
/// than the cloth, its mass spread over it) and the candidates differ by nothing a grid resolves;
/// the slab-gamma candidate is the one-box model, sized to the cloth. Checked where the fine grid
/// is loaded (run_study, fit_albedo), before anything is rendered or written.
void check_factors_for_grid(const std::vector<int>& factors, const volume::Grid& fine);

/// The factors a study of `fine` runs: `spec.factors` when the caller gave them (refused by
/// check_factors_for_grid if one is too coarse), else the defaults that suit the grid, each one
/// dropped said to `spec.log`: a small cloth's default 16× would be one voxel, and a user who
/// asked for no factor should get the study of those that mean something, not a refusal. Throws
/// weft::Error when no default suits it, or when an albedo factor names a dropped one.
[[nodiscard]] std::vector<int> factors_for_grid(const StudySpec& spec, const volume::Grid& fine);

/// Throws weft::Error unless `scene` has exactly one grid medium with an exponential law filling
/// one box shape (what run_study needs) that is a null boundary holding the grid's whole active
/// box (check_target_box: it loads the grid), and, when `spec` asks for components, no reflecting
/// surface (check_component_scene), before anything is computed or written.
void check_study_scene(const render::SceneDesc& scene, const StudySpec& spec = {});

/// One (spp, seconds, rmse) point of a candidate's first image on its way to its budget.
struct StudyPoint {
  int spp = 0;
  double seconds = 0.0;
  double rmse = 0.0;  ///< against the reference, its noise removed
};

struct StudyCandidate {
  std::string name;                  ///< "fine", "exponential-4x", "local-gamma-4x", "slab-gamma"
  std::string model;                 ///< "fine grid", "exponential", "local-gamma", "homogeneous gamma"
  int factor = 1;                    ///< coarsening factor (1 = fine; 0 = one homogeneous slab)
  std::filesystem::path scene_file;  ///< the candidate's scene (renders A at spp and seed_a)
  std::uint64_t seed_a = 0;
  std::uint64_t seed_b = 0;
  int spp = 0;
  double seconds = 0.0;      ///< wall time of image A (world build included)
  double cpu_seconds = 0.0;  ///< CPU time of this process during image A (all threads)
  double rmse = 0.0;
  double rmse_raw = 0.0;  ///< |A − R| without the reference-noise correction
  double noise = 0.0;
  double bias = 0.0;            ///< sqrt(max(0, bias_sq))
  double bias_sq = 0.0;         ///< the unbiased estimate of bias² (may be < 0 by noise)
  double bias_sq_stderr = 0.0;  ///< its standard error (per-value terms over √n)
  /// bias_sq in standard errors (0 when the error is 0): |z| < 5 is no detectable bias.
  [[nodiscard]] double bias_z() const { return bias_sq_stderr > 0.0 ? bias_sq / bias_sq_stderr : 0.0; }
  /// The same over the cloth's pixels (StudyResult::cloth_mask).
  double cloth_bias = 0.0;
  double cloth_bias_sq = 0.0;
  double cloth_bias_sq_stderr = 0.0;
  /// Mean of (A + B)/2 − R over the cloth's values: the sign of the bias (> 0: too bright).
  double cloth_difference = 0.0;
  /// The cloth bias against image scale: k × k pixel blocks (kBiasBlocks) and the level
  /// (bias_scales.h, docs/render.md §6e).
  ScaleBias cloth_scales;
  /// When StudySpec::components splits this candidate: its transmission, single and multiple
  /// scattering biases over the cloth (render_components.h); empty otherwise.
  std::vector<ComponentBias> components;
  /// The candidate's memory, every channel counted, from its scene file (representation_memory.h,
  /// docs/render.md §6e "Memory"): the values a renderer holds (compared), OpenVDB's trees
  /// (reported), the number of channels; the slab's law its parameters.
  std::uint64_t memory_bytes = 0;
  std::uint64_t memory_tree_bytes = 0;
  int memory_channels = 0;
  /// albedo-corrected candidates: the albedo multiplier k_N, fitted to images elsewhere (so
  /// `fitted_to_images`, and chosen against the fine grid: it uses the ground truth).
  double albedo_factor = 0.0;
  bool fitted_to_images = false;
  /// RMSE of A over the cloth's values (reference noise removed, §6b) and one image's noise there.
  double cloth_rmse = 0.0;
  double cloth_noise = 0.0;
  double speedup = 0.0;           ///< t_fine(rmse)/seconds (NaN for the fine grid itself)
  std::vector<StudyPoint> curve;  ///< at every power of two of spp, and at the end
  render::Image image;            ///< A
  render::Image error_map;        ///< |A − R| per channel (no variances)
};

struct StudyResult {
  render::Image reference;
  double reference_seconds = 0.0;
  double reference_mean = 0.0;  ///< mean pixel value of the reference (for relative errors)
  /// The cloth's pixels: where the reference differs from the scene without the cloth by more
  /// than 5 standard errors in a channel; their number and the reference's mean over them.
  std::vector<bool> cloth_mask;
  int cloth_pixels = 0;
  double cloth_mean = 0.0;
  std::filesystem::path reference_scene;
  std::uint64_t reference_seed = 0;
  std::string mode;  ///< "time budget of S s per candidate" or "fixed N spp per candidate"
  std::vector<StudyCandidate> candidates;
  /// Per coarsening factor, the fine grid's images smoothed over one block's footprint, judged as
  /// a candidate (resolution_floor.h): what the block size alone costs, whatever the law.
  std::vector<ResolutionFloor> resolution_floors;
  /// (c): the validation's best model per axis ("+x": "local-gamma", …), chosen by comparing
  /// with the ground truth (fit::best_by_ground_truth, so reported with "uses_ground_truth":
  /// true), the model the study takes (most axes; ties by the smaller mean ratio) and what became
  /// of it.
  std::vector<std::pair<std::string, std::string>> best_by_ground_truth_per_axis;
  std::string best_by_ground_truth;
  std::string best_by_ground_truth_note;
  double scale = 0.0;  ///< statistics scale L used (world units, the pooled axes' mean)
  double slab_mean_concentration = 0.0;
  double slab_var_concentration = 0.0;
  double slab_alpha = 0.0;
  double sigma = 1.0;
  std::vector<std::string> notes;
  std::string headline;  ///< "at N× coarser and M× less time, model X is within E of the fine grid"
};

/// Pixel samples of every render a study of `spec` makes on a width × height film (the reference
/// and its components, the background of the cloth's mask, each candidate's two images and their
/// components; with a time budget, the renders of known spp): the figure the work limit
/// (render::kMaxPixelSamples) is checked against, before anything is made.
[[nodiscard]] double study_pixel_samples(const StudySpec& spec, int width, int height);

/// The number of candidates run_study renders, two images each, when `albedo_candidates` of them
/// are albedo-corrected (spec.albedo_factors.size(), or the factors a matrix will fit): what a run
/// says it will cost before it starts.
[[nodiscard]] std::size_t candidate_count(const StudySpec& spec, std::size_t albedo_candidates);

/// @brief Runs the study on the one grid medium of `scene` (bounded by a box shape). Every MPI
/// rank must call it (the renders are collective); rank 0 writes the files under work_dir and
/// holds the images and statistics. Throws weft::Error for a scene without exactly one grid
/// medium of concentration or extinction values with an exponential law inside a box.
[[nodiscard]] StudyResult run_study(const render::SceneDesc& scene, const StudySpec& spec,
                                    ProgressSink& progress = null_progress());

}  // namespace weft::study
