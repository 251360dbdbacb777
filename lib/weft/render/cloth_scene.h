#pragma once
/// @file
/// @brief The scene that shows a `weft gen` cloth: its fibre-volume-fraction grid as a grid
/// medium with physical extinction, framed so that it fills most of the film, under one of a
/// few light set-ups (by default a key light from the camera's side and a back light behind the
/// cloth), seen from above at an angle (docs/render.md §5c).

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "weft/render/scene.h"
#include "weft/transmittance/law.h"
#include "weft/volume/grid.h"

namespace weft::render {

/// What the cloth's grid says about it (from the metadata `weft gen` stores in cloth.vdb).
struct ClothLook {
  /// σ per unit concentration, from the grid's provenance (volume::read_provenance: the one rule
  /// validate, measure, fit and export use), never a default.
  double sigma = 0.0;
  std::string preset = "cotton";  ///< yarn preset the warp started from
  Rgb albedo{0.95, 0.9, 0.8};     ///< single-scattering albedo of that preset's fibre
};

/// Single-scattering albedo of a yarn preset's undyed fibre (cotton, polyester, silk, wool,
/// linen; a look, not a measurement: docs/render.md). Throws weft::Error for other names.
[[nodiscard]] Rgb preset_albedo(const std::string& preset);

/// Reads the look of the cloth grid loaded from `vdb`: σ from its provenance (throws weft::Error
/// naming `vdb` when it has none: a grid not written by weft gen), the preset from the
/// "generator" metadata (the cotton look when there is none or it is not in the table).
[[nodiscard]] ClothLook cloth_look(const volume::Grid& grid, const std::filesystem::path& vdb);

/// What fills the cloth's box in a cloth scene. Every kind gets the same camera, lights and
/// box (framed on the fine grid), so the images of the fine grid, its local fields and the
/// homogeneous slabs of each law compare pixel by pixel.
struct ClothSceneMedium {
  enum class Kind {
    grid,          ///< the fine grid itself (`file_in_scene` names the .vdb): the ground truth
    local_fields,  ///< the local-gamma fields of `weft fit --block` (`file_in_scene` names them)
    homogeneous,   ///< one law in distance over the whole box (`law`; `file_in_scene` unused)
  };
  Kind kind = Kind::grid;
  /// local_fields: the fields file as it is now (its blocks may reach past the fine grid's
  /// active box; the medium's box then covers them, so no block is cut).
  std::filesystem::path fields;
  /// homogeneous: the law (e.g. a predictive model of `weft validate`).
  transmittance::LawPtr law;
};

/// How a cloth scene is lit (docs/render.md §5c). Every set-up but the default has a black
/// background, so a pixel off the cloth is 0.
enum class ClothLighting {
  key_and_back,  ///< the default picture: a key light from the camera's side, a back light, a dim sky
  back,          ///< transmission: only the emitting panel behind the cloth
  front,         ///< reflection: only a key light beside the camera
  grazing,       ///< relief: only a light 12° above the cloth's plane, from the side
};

/// Every set-up by name ("key-and-back", "back", "front", "grazing"), in that order: the one
/// table names are parsed from and listed by.
[[nodiscard]] const std::vector<std::pair<std::string, ClothLighting>>& cloth_lightings();
/// The set-up called `name`; throws weft::Error naming the known ones otherwise.
[[nodiscard]] ClothLighting cloth_lighting(const std::string& name);
[[nodiscard]] std::string cloth_lighting_name(ClothLighting lighting);

/// Camera tilts the cloth scene frames: degrees off the cloth's normal in [0, kMaxClothTilt).
/// Towards 90° the cloth is seen edge-on: the framing (cloth_scene.cpp) fits its height
/// foreshortened by cos(tilt), and past 80° that is under a sixth of the film. The one range of
/// `weft render --tilt`, `--study-tilts`, the render matrix and Python's cloth_scene/render_matrix.
inline constexpr double kMaxClothTilt = 80.0;
/// "[0, 80)", for messages.
[[nodiscard]] std::string cloth_tilt_range();
/// True if `degrees` is a tilt the cloth scene frames (finite, in [0, kMaxClothTilt)).
[[nodiscard]] bool is_cloth_tilt(double degrees);
/// Throws weft::Error "<what>: tilt <degrees> degrees is not in [0, 80)" unless is_cloth_tilt.
void check_cloth_tilt(const std::string& what, double degrees);

/// Where the camera is and what lights the cloth.
struct ClothView {
  ClothLighting lighting = ClothLighting::key_and_back;
  double tilt_degrees = 30.0;  ///< the camera's angle off the cloth's normal (0: straight down)
  int width = 320;             ///< film size in pixels
  int height = 240;
};

/// The scene JSON for the cloth grid `vdb`, naming it as `file_in_scene` (relative to the
/// scene file's folder, e.g. "cloth.vdb" beside scene.json): camera framing the grid's active
/// box, the grid as a delta-tracked exponential medium with the provenance's σ per unit C, lit
/// and seen as `view` says. `medium` replaces the grid by its local fields (same σ) or by a
/// homogeneous law. Throws weft::Error
/// for an empty grid, a homogeneous kind without a law, or a law parameter that is NaN or −∞
/// (+∞, e.g. α of an exponential mixture component, is written as "inf").
[[nodiscard]] std::string cloth_scene_json(const std::filesystem::path& vdb, const std::string& file_in_scene,
                                           const ClothSceneMedium& medium = {}, const ClothView& view = {});
/// The same for a grid already in memory (what was just saved as `file_in_scene`): `weft gen`
/// uses it so that writing the scene does not read the grid back (a second copy of the tree).
[[nodiscard]] std::string cloth_scene_json(const volume::Grid& grid, const std::string& file_in_scene,
                                           const ClothSceneMedium& medium = {}, const ClothView& view = {});

/// cloth_scene_json parsed with `vdb`'s folder as the scene folder.
[[nodiscard]] SceneDesc cloth_scene(const std::filesystem::path& vdb, const ClothView& view = {});

}  // namespace weft::render
