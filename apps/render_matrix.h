#pragma once
/// @file
/// @brief `weft render --study` with no scene: the study matrix (study::run_matrix) and its files
/// (docs/render.md §6e).

#include <filesystem>

#include "command.h"
#include "weft/study/render_matrix.h"
#include "written_files.h"

namespace weft::app {

/// Runs the matrix into `out` (spec.study.work_dir is set to it) and writes matrix.csv,
/// matrix.cost.csv, matrix.json, matrix.md, matrix.png (chart, needs a display) and, per case,
/// cases/<case>/ (the single study's files and chart). Finished cases are kept in
/// out/matrix.units/: with `resume` a rerun of the same spec takes them instead of rendering
/// them again (a different spec is refused).
void run_render_matrix(study::MatrixSpec spec, const std::filesystem::path& out, bool resume, const Context& ctx,
                       WrittenFiles& files);

}  // namespace weft::app
