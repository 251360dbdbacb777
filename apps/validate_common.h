#pragma once
/// @file
/// @brief Small helpers shared by the `weft validate` front-ends (the validation and --sweep):
/// formatting of numbers for CSV/JSON and the colour of each beam axis in every picture.

#include <array>
#include <chrono>
#include <cmath>
#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "weft/volume/beam.h"

namespace weft::app {

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// JSON cannot hold ∞: such values are written as null.
inline nlohmann::json number_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

/// A CSV field: 10 significant digits, ±inf spelled out.
inline std::string fmt_csv(double x) { return std::isfinite(x) ? fmt::format("{:.10g}", x) : (x < 0 ? "-inf" : "inf"); }

/// Red, green, blue for beams along x, y, z (either sense), in every chart and 3D view.
inline std::array<unsigned char, 3> axis_color(const std::array<double, 3>& d) {
  switch (volume::beam_axis(d)) {
    case 0:
      return {220, 30, 30};
    case 1:
      return {30, 160, 40};
    default:
      return {30, 60, 220};
  }
}

/// What `weft validate --sweep` needs from the command line.
struct SweepOutputOptions {
  std::string out;
  bool no_plot = false;
  bool quick = false;
  bool resume = false;  ///< keep the units in out/units/ that a killed run finished
  std::string axes;     ///< as given, for the resume key
};

}  // namespace weft::app
