#pragma once
/// @file
/// @brief What `weft validate` writes and prints about a validation: curves.csv, the
/// transmittance figure (one panel per axis, every model visible) and the summary table.

#include <filesystem>
#include <string>
#include <vector>

#include "weft/fit/validation.h"
#include "weft/viz/chart.h"

namespace weft::app {

/// curves.csv: one row per depth of the longest axis; per axis T_gt, its standard error,
/// log T_gt and T of every model (`<model>_<axis>`); shorter axes leave blanks.
/// `fibre`: T_fibre per axis of `v` (validate --fibres), written after each axis's ground truth
/// as `T_fibre_<ax>, stderr_fibre_<ax>`.
[[nodiscard]] std::string curves_csv(const fit::Validation& v,
                                     const std::vector<volume::TransmittanceCurve>* fibre = nullptr);

/// The colour and line style of each model in every figure (ground truth is the axis colour).
struct ModelStyle {
  viz::Rgb color;
  viz::LineStyle style;
  viz::Marker marker;
};
[[nodiscard]] ModelStyle model_style(const std::string& model);

/// transmittance.png: small multiples, one panel per axis: ground truth with its ±2 standard
/// error band, the paper's gamma law, every predictive model, the least-squares reference and
/// the exponential; log T over depth in `units`. `fibres` (weft validate --fibres): T_fibre per
/// axis of `v`, drawn as a thin curve in the axis colour.
[[nodiscard]] viz::RenderOutcome save_transmittance_figure(
    const fit::Validation& v, const std::string& title, const std::string& units, const std::filesystem::path& path,
    const std::vector<volume::TransmittanceCurve>* fibres = nullptr);

/// The summary table: per axis, RMS error on T of every model and its ratio to the exponential.
[[nodiscard]] std::vector<std::string> summary_table(const fit::Validation& v);

}  // namespace weft::app
