#pragma once
/// @file
/// @brief The science part of `weft validate`'s report.json as JSON text: per axis, every model
/// with its parameters and `uses_ground_truth`, its errors, its ratio to the exponential
/// baseline and the best predictive model. The CLI and the Python module emit the same text.

#include <string>

#include "weft/fit/validation.h"

namespace weft::fit {

/// The errors of every model of one axis over the exponential baseline's RMS error on T.
struct ModelRatio {
  std::string name;
  double rms_abs_t = 0.0;
  double ratio = 0.0;  ///< rms_abs_t / exponential's (NaN when the exponential is exact)
  bool uses_ground_truth = false;
};
[[nodiscard]] std::vector<ModelRatio> model_ratios(const AxisValidation& axis);
/// The predictive model (uses_ground_truth false, not the exponential baseline) with the
/// smallest RMS error on T.
[[nodiscard]] ModelRatio best_predictive(const AxisValidation& axis);

/// {"sigma": …, "exponential": …, "isotropic": …, "axes": [ … ]} as pretty-printed JSON.
[[nodiscard]] std::string validation_json(const Validation& v);

}  // namespace weft::fit
