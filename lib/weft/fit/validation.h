#pragma once
/// @file
/// @brief The main job as one computation (supplement Fig. S.13): beams along axes through a
/// grid, ground truth by DDA, the gamma model from window statistics per axis, the isotropic
/// variant, the best least-squares gamma, the exponential baseline, and their errors.
/// Writing files and plots is the app's business; this returns value types.

#include <array>
#include <string>
#include <vector>

#include "weft/core/progress.h"
#include "weft/fit/gamma_moments.h"
#include "weft/fit/least_squares.h"
#include "weft/fit/model_selection.h"
#include "weft/fit/models.h"
#include "weft/fit/window_stats.h"
#include "weft/volume/beam.h"
#include "weft/volume/grid.h"

namespace weft::fit {

struct ValidationSpec {
  /// Axis beams, e.g. {+x, +y, +z}; each an axis direction (either sense).
  std::vector<std::array<double, 3>> directions{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  /// μ = sigma × value. For extinction grids pass 1 (values are then μ, "C" below is μ).
  double sigma = 1.0;
  /// Scale L of the statistics per axis (world units; 0 = the extent along that axis), from
  /// fit::resolve_scale (the yarn diameter by default).
  std::array<double, 3> scale{0.0, 0.0, 0.0};
  /// The models to compute beside the exponential baseline (fit/model_selection.h); the
  /// least-squares reference row only on axes with at least 3 depths.
  ModelSelection models = ModelSelection::all();
  int rays_per_column = 1;
  std::uint64_t seed = 1;
  volume::BeamMethod method = volume::BeamMethod::automatic;
};

/// One model's curve and its errors against one axis's ground truth.
struct ModelCurve {
  std::string name;  ///< "gamma", "empirical", …, "least-squares", "isotropic", "exponential"
  std::string description;
  bool uses_ground_truth = false;  ///< true only for fits to T_gt (labelled references)
  std::vector<std::pair<std::string, double>> parameters;
  std::vector<double> log_t;
  CurveError error;
  /// The homogeneous law in distance the model predicts (PredictedModel::law), or null.
  transmittance::LawPtr law;
};

struct AxisValidation {
  std::array<double, 3> direction{};
  std::string label;  ///< "+x"
  volume::TransmittanceCurve ground_truth;
  /// The window statistics of length L along this axis and their gamma fit (Eq. 19–20): only
  /// when a model computed needs them (has_stats).
  bool has_stats = false;
  ConcentrationStats stats;
  GammaFit moment_fit;
  LeastSquaresFit lsq_fit;
  std::string least_squares_note;  ///< why the least-squares reference is missing, when it was asked for
  std::vector<ModelCurve> models;
  double scale = 0.0;  ///< L used along this axis (world units)
  /// Wall and process-CPU seconds (every thread) of the ground-truth beam, of the statistics
  /// pass over the columns (the models' pass, or window_stats when no models run) and of the
  /// models and fits built from it: the cost of the prediction against the truth's.
  double beam_seconds = 0.0;
  double beam_cpu_seconds = 0.0;
  double stats_seconds = 0.0;
  double stats_cpu_seconds = 0.0;
  double fit_seconds = 0.0;
  double fit_cpu_seconds = 0.0;
  [[nodiscard]] const ModelCurve& model(const std::string& name) const;
};

struct Validation {
  ModelSelection models = ModelSelection::all();  ///< what was computed (ValidationSpec::models)
  double sigma = 1.0;
  double voxel_size = 1.0;
  volume::IndexBox box;
  std::uint64_t active_voxels = 0;
  double mean_concentration = 0.0;  ///< over the active bounding box
  GammaFit exponential;             ///< the baseline: σ·C̄, Var ignored
  bool has_isotropic = false;
  ConcentrationStats isotropic_stats;
  GammaFit isotropic_fit;
  double isotropic_seconds = 0.0;
  std::vector<AxisValidation> axes;
};

/// Throws weft::Error for an empty grid, non-axis directions, σ ≤ 0, or a negative scale.
/// The ground truth is measured after every prediction is made, and no prediction receives it.
[[nodiscard]] Validation validate(const volume::Grid& grid, const ValidationSpec& spec,
                                  ProgressSink& progress = null_progress());

/// Parses "x,z" / "+x,-y" into axis directions (no repeats); throws weft::Error otherwise.
[[nodiscard]] std::vector<std::array<double, 3>> parse_axes(const std::string& text);

}  // namespace weft::fit
