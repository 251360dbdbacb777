#pragma once
/// @file
/// @brief The image study's fine grid in its scene, and the candidates' scenes made from it by
/// replacing that medium (docs/render.md §6c): what run_study (render_study.h) edits per candidate.

#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

#include "weft/render/scene.h"
#include "weft/volume/grid.h"

namespace weft::study {

struct Box {
  render::Vec3 min;
  render::Vec3 max;
};

/// World box of a grid's active voxels: index i covers origin + h·[i, i + 1).
[[nodiscard]] Box world_box(const volume::Grid& grid);

[[nodiscard]] Box union_box(const Box& a, const Box& b);

/// Where the study's grid medium is in the scene.
struct Target {
  std::string medium;  ///< its name
  std::size_t shape = 0;
  nlohmann::json scene;  ///< the scene as canonical JSON, to edit per candidate
  nlohmann::json medium_json;
  /// What turns grid values into extinction: the law's μ times σ (μ for an extinction grid).
  double sigma_stats = 1.0;
  Box box;  ///< the bounding box shape
};

/// Throws weft::Error unless `scene` has exactly one grid medium, with the exponential law,
/// filling exactly one box shape.
[[nodiscard]] Target find_target(const render::SceneDesc& scene);

/// @brief Throws weft::Error unless the target's box leaves every candidate the same cloth: a
/// null boundary (the candidates' boxes are fitted to their grids, which only an invisible box
/// allows) that holds the whole of `fine`'s active box (a box that cut the grid would cut each
/// coarse grid's blocks elsewhere, so the candidates would render other cloths).
void check_target_box(const Target& t, const render::SceneDesc& scene, const volume::Grid& fine);

/// The scene with the target medium replaced and its box grown to `box` (the box is an
/// index-matched boundary, so a larger one changes nothing but what it may hold).
[[nodiscard]] nlohmann::json candidate_scene(const Target& t, const nlohmann::json& medium, const Box& box);

}  // namespace weft::study
