#pragma once
/// @file
/// @brief The scene that shows a `weft gen` cloth: its fibre-volume-fraction grid as a grid
/// medium with physical extinction, lit from behind (transmission) and at a grazing angle from
/// the front (the weave's relief), seen from above at an angle (docs/render.md §"Cloth scenes").

#include <filesystem>
#include <string>

#include "weft/render/scene.h"

namespace weft::render {

/// What the cloth's grid says about it (from the metadata `weft gen` stores in cloth.vdb).
struct ClothLook {
  double fiber_radius_mm = 0.006;  ///< r of the fibres (the warp yarn's); σ = 2/(π r)
  std::string preset = "cotton";   ///< yarn preset the warp started from
  Rgb albedo{0.95, 0.9, 0.8};      ///< single-scattering albedo of that preset's fibre
};

/// Extinction per unit fibre volume fraction of randomly placed parallel fibres of radius r
/// crossed at right angles: a fibre of length L has volume πr²L and shadow 2rL, so
/// μ = C·2rL/(πr²L) = C·2/(πr).
[[nodiscard]] double fiber_sigma(double fiber_radius);

/// Single-scattering albedo of a yarn preset's undyed fibre (cotton, polyester, silk, wool,
/// linen; a look, not a measurement: docs/render.md). Throws weft::Error for other names.
[[nodiscard]] Rgb preset_albedo(const std::string& preset);

/// Reads the look of the cloth in `vdb` (fibre radius and preset from the "generator"
/// metadata; defaults when the grid has none, e.g. a grid from elsewhere).
[[nodiscard]] ClothLook cloth_look(const std::filesystem::path& vdb);

/// The scene JSON for the cloth grid `vdb`, naming it as `file_in_scene` (relative to the
/// scene file's folder, e.g. "cloth.vdb" beside scene.json): camera framing the grid's active
/// box, the grid as a delta-tracked exponential medium with σ = fiber_sigma(r) per unit C, a
/// backlight (area light below) and a grazing directional light from the front.
[[nodiscard]] std::string cloth_scene_json(const std::filesystem::path& vdb, const std::string& file_in_scene);

/// cloth_scene_json parsed with `vdb`'s folder as the scene folder.
[[nodiscard]] SceneDesc cloth_scene(const std::filesystem::path& vdb);

}  // namespace weft::render
