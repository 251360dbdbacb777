#pragma once
/// @file
/// @brief The science part of `weft validate`'s report.json as JSON text: per axis, every model
/// with its parameters and `uses_ground_truth`, its errors, its ratio to the exponential
/// baseline, the prediction and the best model chosen with the ground truth. The CLI and the Python module emit the
/// same text.

#include <string>

#include "weft/fit/validation.h"

namespace weft::fit {

/// The errors of every model of one axis over the exponential baseline's RMS error on T.
struct ModelRatio {
  std::string name;
  double rms_abs_t = 0.0;
  double ratio = 0.0;  ///< rms_abs_t / exponential's (NaN when undefined: ratios_undefined)
  bool uses_ground_truth = false;
};
[[nodiscard]] std::vector<ModelRatio> model_ratios(const AxisValidation& axis);

/// Why the axis's ratios to the exponential are undefined, "" when they are defined: the
/// exponential baseline's RMS error on T is 0, i.e. it is exact at this σ (at σ = 1e−300 every
/// optical depth rounds to 0 and T = 1 everywhere), so there is no error to improve on and a
/// ratio to it is 0/0 or x/0. Reported as such (ratios and acceptance null with this reason,
/// docs/validate.md "An exact exponential"), never as a NaN that misses ⅓.
[[nodiscard]] std::string ratios_undefined(const AxisValidation& axis);

/// The prediction of the axis: the one model fixed before measuring (fit::kPredictedModel,
/// docs/validate.md "The prediction"); uses_ground_truth false.
[[nodiscard]] ModelRatio predicted(const AxisValidation& axis);
/// Diagnostic, chosen WITH the ground truth: the model (among those that do not see T_gt, the
/// exponential baseline excluded) with the smallest RMS error on T against T_gt. Its
/// uses_ground_truth is true: which model wins is known only after measuring.
[[nodiscard]] ModelRatio best_by_ground_truth(const AxisValidation& axis);

/// {"sigma": …, "exponential": …, "isotropic": …, "axes": [ … ]} as pretty-printed JSON.
[[nodiscard]] std::string validation_json(const Validation& v);

}  // namespace weft::fit
