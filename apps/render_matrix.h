#pragma once
/// @file
/// @brief `weft render --study` with no scene: the study matrix (study::run_matrix) and its files
/// (docs/render.md §6e).

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "command.h"
#include "weft/study/render_matrix.h"
#include "written_files.h"

namespace weft::app {

/// The study matrix's own options of `weft render --study` (docs/render.md §6e).
struct MatrixCliOptions {
  std::vector<std::string> cloths;
  std::vector<std::string> lightings;
  std::vector<double> tilts;
  std::vector<int> film;
  int yarns = 0;
  bool resume = false;
};

/// Camera tilts of the default cloth's scene (--tilt, --study-tilts): the library's one range,
/// render::is_cloth_tilt (NaN and inf refused too).
extern const CLI::Validator cloth_tilt;

/// Registers --study-cloths, --study-lightings, --study-tilts, --study-film, --study-yarns and
/// --resume on `weft render`.
void add_matrix_options(CLI::App& sub, MatrixCliOptions& o);

/// What the rest of `weft render --study`'s command line says, for the matrix's defaults and
/// refusals: which study options were given, the spp, seed, --quick, and the outputs.
struct MatrixStudyChoices {
  bool factors = false;  ///< --study-factors given (else 2, 4, 8)
  bool memory = false;   ///< --study-memory given (else segment, optical-depth)
  int spp = 0;           ///< --study-spp (0: 64, 8 with --quick)
  int reference_spp = 0;
  std::optional<std::uint64_t> seed;
  bool quick = false;
  bool study_time = false;   ///< --study-time given: refused (the matrix renders at a fixed spp)
  bool output_file = false;  ///< -o given: refused (the matrix writes a folder)
  std::string out_dir;       ///< --out (default ./render_study)
};

/// @brief `weft render --study` with no scene: the matrix's spec from `study` (the study options
/// already parsed), `m` and `given` (usage errors exit 2 before anything is written), then
/// run_render_matrix into the --out folder.
void run_render_matrix_command(const study::StudySpec& study, const MatrixCliOptions& m,
                               const MatrixStudyChoices& given, const Context& ctx, WrittenFiles& files);

/// Runs the matrix into `out` (spec.study.work_dir is set to it) and writes matrix.csv,
/// matrix.cost.csv, matrix.json, matrix.md, matrix.png (chart, needs a display) and, per case,
/// cases/<case>/ (the single study's files and chart). Finished cases are kept in
/// out/matrix.units/: with `resume` a rerun of the same spec takes them instead of rendering
/// them again (a different spec is refused).
void run_render_matrix(study::MatrixSpec spec, const std::filesystem::path& out, bool resume, const Context& ctx,
                       WrittenFiles& files);

}  // namespace weft::app
