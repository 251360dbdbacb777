#pragma once
/// @file
/// @brief The image study's reports (docs/render.md §6c): its table, its curves and its JSON,
/// and the tiles of its contact sheet, from a StudyResult (render_study.h).

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "weft/render/contact_sheet.h"
#include "weft/study/render_study.h"

namespace weft::study {

/// @brief Each candidate's speedup against the fine grid's t^{−1/2} law (render_study.h) and the
/// study's headline (run_study calls it on rank 0, whose result holds the images' statistics).
void judge_study(StudyResult& result);

/// One row per candidate: candidate,model,factor,spp,seconds,cpu_seconds,seconds_per_spp,
/// rmse,rmse_raw,bias,bias_sq,bias_sq_stderr,bias_z,noise,relative_rmse,speedup,seed,scene.
[[nodiscard]] std::string study_csv(const StudyResult& result);
/// Long form of the curves: candidate,spp,seconds,rmse.
[[nodiscard]] std::string study_curves_csv(const StudyResult& result);
/// @brief A candidate as JSON, written once: `candidates[i]` of the study's JSON and, less its
/// scene path and with the matrix's memory, of a matrix case (render_matrix.h: what crosses ranks,
/// the --resume store and matrix.json). Every field of StudyCandidate but the images, plus the
/// derived bias_z and uses_ground_truth (= fitted_to_images); the fine grid's speedup (NaN) as
/// null; the curve as [{spp, seconds, rmse}] (docs/render.md §6c).
[[nodiscard]] nlohmann::json study_candidate_json(const StudyCandidate& c);
/// The candidate back (images empty; derived fields ignored; no "scene": an empty path).
[[nodiscard]] StudyCandidate study_candidate_from_json(const nlohmann::json& j);
/// Everything above as pretty-printed JSON (images excluded).
[[nodiscard]] std::string study_json(const StudyResult& result);

/// @brief The contact sheet's tiles (write_contact_sheet_png, in `columns` columns): each
/// image with its error map |A − R| (channel mean, grey, linear scale 1/error_white) under it.
/// Rows: reference and exponential-Nx images; the reference's standard error and their error
/// maps; fine and local-gamma-Nx images; their error maps; the slab and its error map.
/// Captions name the candidate, its spp and seconds, its RMSE and bias.
struct StudySheet {
  std::vector<render::SheetTile> tiles;
  int columns = 1;
};
[[nodiscard]] StudySheet study_sheet(const StudyResult& result, double exposure, double error_white);

/// A file the study wrote and what it holds (the app lists them).
struct StudyFile {
  std::filesystem::path path;
  std::string what;
};
/// @brief Writes the study's files (rank 0): the reference beside `exr` (EXR and PNG at
/// `exposure`), each candidate's image A as `work_dir`/<name>.exr, and beside `exr`
/// <stem>.study.csv, .study.curves.csv, .study.json and .study.contact.png (error maps white at
/// 4x the fine grid's RMSE). The chart (VTK) is the caller's.
std::vector<StudyFile> write_study_files(const StudyResult& result, const std::filesystem::path& exr,
                                         const std::filesystem::path& work_dir, double exposure);

}  // namespace weft::study
