#pragma once
/// @file
/// @brief `weft render --study`: runs study::run_study and writes its files (docs/render.md §6c).

#include <filesystem>
#include <string>

#include "command.h"
#include "weft/render/scene.h"
#include "weft/study/render_study.h"
#include "weft/viz/chart.h"
#include "written_files.h"

namespace weft::app {

/// The study's chart (VTK, needs a display): left RMSE vs seconds per candidate, right bias and
/// noise vs the coarsening factor.
viz::RenderOutcome write_study_chart(const study::StudyResult& r, const std::filesystem::path& path,
                                     const std::string& label);

/// Runs the study on `scene` and writes, beside `exr` (the reference image, EXR and PNG):
/// <stem>.study.csv, .study.curves.csv, .study.json, .study.png (chart, needs a display),
/// .study.contact.png, and the candidates' grids, fields and scenes in <stem>.study/.
/// `fit_albedo`: first fit the albedo factors k_N on this scene (study::fit_albedo_factors) and
/// run the albedo-corrected candidates with them (in-sample; the factors are printed, to be
/// passed to other set-ups as --study-albedo).
void run_render_study(const render::SceneDesc& scene, study::StudySpec spec, const std::string& label,
                      const std::filesystem::path& exr, double exposure, const Context& ctx, WrittenFiles& files,
                      bool fit_albedo = false);

}  // namespace weft::app
