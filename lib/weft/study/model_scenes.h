#pragma once
/// @file
/// @brief The scenes of `weft validate --scenes`: render scenes of the cloth and of what each model predicts,
/// all with the same camera, lights and box (render::cloth_scene_json), so `weft render` shows
/// the fine grid, its local fields and a homogeneous slab per predicted law side by side.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "weft/core/progress.h"
#include "weft/fit/validation.h"
#include "weft/volume/grid.h"

namespace weft::study {

/// What write_model_scenes wrote (path, what it is, in order) and what it could not write.
struct ModelScenes {
  std::vector<std::pair<std::filesystem::path, std::string>> written;
  std::vector<std::string> notes;
};

/// Writes into `folder`: grid.json (the fine grid `vdb`, named as `vdb_in_scene`),
/// local_fields.vdb + local_gamma.json (the fields of blocks L³, L the validation's scale along
/// the cloth's normal), and slab_<model>.json for each predictive model of the normal axis
/// that is one homogeneous law (gamma, gap-gamma, across-beam, isotropic, exponential; never
/// the least-squares reference). The normal is the thinnest axis of the active box; without a
/// beam along it no slab is written and `notes` says so.
[[nodiscard]] ModelScenes write_model_scenes(const fit::Validation& v, const volume::Grid& grid,
                                             const std::filesystem::path& vdb, const std::string& vdb_in_scene,
                                             const std::filesystem::path& folder, ProgressSink& progress);

}  // namespace weft::study
