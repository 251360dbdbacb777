#pragma once
/// @file
/// @brief The grid-input options shared by `weft validate`, `weft measure` and `weft fit`
/// (--grid, --grid-name, --values, --sigma), their checks, and σ resolved from the options and
/// the grid's provenance (physical σ by default, never a silent σ = 1; docs/validate.md).

#include <cstdint>
#include <string>

#include <CLI/CLI.hpp>

#include "weft/volume/grid.h"
#include "weft/volume/provenance.h"

namespace weft::app {

struct GridInputOptions {
  std::string grid;
  std::string grid_name;
  std::string values = "concentration";
  double sigma = 0.0;
  CLI::Option* grid_option = nullptr;
  CLI::Option* sigma_option = nullptr;
  [[nodiscard]] bool sigma_given() const { return sigma_option != nullptr && sigma_option->count() > 0; }
  [[nodiscard]] bool extinction() const { return values == "extinction"; }
};

/// Declares the four options on `sub`; `required` makes --grid mandatory.
void add_grid_input(CLI::App& sub, GridInputOptions& o, bool required);

/// Checks the options themselves (σ > 0 when given; no --sigma with --values extinction).
void check_grid_input(const GridInputOptions& o);
/// Loads the grid (refusing an empty one, and --values against the kind its metadata records:
/// volume::require_value_kind) and resolves σ: --values extinction → 1; --sigma;
/// the provenance's σ; otherwise an error that says what to pass.
struct LoadedGrid {
  volume::Grid grid;
  volume::Provenance provenance;
  volume::SigmaChoice sigma;
};
[[nodiscard]] LoadedGrid load_grid_input(const GridInputOptions& o);
/// σ from the options and a grid's provenance (volume::resolve_sigma); `what` names the grid.
[[nodiscard]] volume::SigmaChoice resolve_sigma(const GridInputOptions& o, const volume::Provenance& p,
                                                const std::string& what);

/// The chart/summary title of a grid input: the file name, and the grid name when it is not the default.
[[nodiscard]] std::string grid_title(const GridInputOptions& o, const volume::Grid& grid);

/// What a beams.csv was measured with (its first line, "# weft measure: sigma=…; …").
struct BeamsRecord {
  double sigma = 0.0;
  std::string values;
  double voxel_size = 0.0;
  std::uint64_t active_voxels = 0;
  double value_sum = 0.0;  ///< Σ of the grid's active values: tells one grid from another
};
[[nodiscard]] std::string beams_record_line(const BeamsRecord& r);
/// Parses that line; throws weft::Error naming `path` when it is missing or malformed.
[[nodiscard]] BeamsRecord parse_beams_record(const std::string& line, const std::string& path);
/// Refuses (one line naming `path`) beams measured with another σ, value kind or grid than `now`.
/// log T of a beam is not linear in σ (a mean of exponentials), so no rescaling is possible.
void check_beams_record(const BeamsRecord& measured, const BeamsRecord& now, const std::string& path);

}  // namespace weft::app
