#pragma once
/// @file
/// @brief Which models a validation computes, and which of the two statistics of the column
/// pass (fit/column_pass.h) they need: a run computes only what it was asked for.
///
/// The models (docs/validate.md "The scale of the statistics, and the models"), in report order:
///   gamma, empirical, gap-gamma, across-beam   the window statistics of length L along the beam
///   local-exponential, local-gamma,
///   local-gamma-renewal, local-gamma-two-scale  the block statistics of L³ (the local fields)
///   isotropic                                   the window statistics of all three axes
///   least-squares                               the gamma law fitted to T_gt (a reference that sees
///                                               the answer; started from the window moments)
/// `predicted` names the prediction (fit::kPredictedModel) and `all` every model. The exponential
/// baseline is always computed: every error is reported as a ratio to its error.
///
/// Why it matters: the window statistics (every window position of every column, the histogram of
/// Eq. 16) are the larger part of the pass, and the prediction needs only the blocks
/// (docs/benchmarks.md "Validate: the prediction alone").

#include <cstdint>
#include <string>
#include <string_view>

namespace weft::fit {

class ModelSelection {
 public:
  /// Every model (the default of `weft validate`).
  [[nodiscard]] static ModelSelection all();
  /// "all", "predicted", or model names separated by commas (the exponential may be named; it is
  /// always computed). Throws weft::Error naming the entry for an unknown, empty or repeated name,
  /// and for a list that names no model beside the exponential and the least-squares reference.
  [[nodiscard]] static ModelSelection parse(const std::string& text);

  [[nodiscard]] bool wants(std::string_view name) const;
  /// The selection less `name` (a model the caller never reports, e.g. a study without references).
  [[nodiscard]] ModelSelection without(std::string_view name) const;
  /// Any of gamma, empirical, gap-gamma, across-beam, isotropic, least-squares.
  [[nodiscard]] bool needs_windows() const;
  /// Any of the local-* models.
  [[nodiscard]] bool needs_blocks() const;
  /// Any model of fit::predict_axis (every model but isotropic and least-squares).
  [[nodiscard]] bool any_axis_model() const;
  /// "all", or the names in report order separated by commas (what report.json records).
  [[nodiscard]] std::string text() const;

  bool operator==(const ModelSelection& other) const { return bits_ == other.bits_; }

 private:
  std::uint32_t bits_ = 0;
};

}  // namespace weft::fit
