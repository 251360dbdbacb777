#pragma once
/// @file
/// @brief The built world a render reads: materials, media, the Embree geometry and the lights,
/// built from a scene description (scene.h) in one place.
///
/// The description is what the user wrote (parse_scene checks its keys and that its files
/// exist); the world is what those words build: media from their laws and grids, meshes and
/// fibre curves read into Embree, environment images loaded. Nothing built is stored back into
/// the description, so a description made in code and a parsed one build the same way, once.

#include <memory>
#include <string>
#include <vector>

#include "weft/render/features.h"
#include "weft/render/geometry.h"
#include "weft/render/lights.h"
#include "weft/render/medium.h"
#include "weft/render/scene.h"

namespace weft::render {

/// Everything the integrator reads; built once per render.
struct World {
  std::string source = "scene";  ///< the scene's SceneDesc::source, naming it in render errors
  CameraDesc camera;
  IntegratorDesc settings;
  std::vector<MaterialDesc> materials;
  std::vector<std::shared_ptr<const Medium>> media;
  std::vector<std::string> medium_names;  ///< parallel to `media`
  std::unique_ptr<Geometry> geometry;
  LightSet lights;
  Features features;  ///< what the scene uses (the integrator specialises on it)
  bool any_null = false;
  /// The medium camera paths start in (-1: vacuum), found from the scene's boundaries
  /// (docs/scene-format.md "The camera's medium").
  int camera_medium = -1;
};

/// Reads every file `scene` names and builds its media, geometry and lights. Throws weft::Error
/// naming the scene's source and the key (e.g. "scene.json: media.cloth: …",
/// "scene.json: shapes[2]: …") for what cannot be built, and for a camera whose medium the
/// boundaries do not decide (probes from it disagree).
[[nodiscard]] World build_world(const SceneDesc& scene);

/// The media of `scene` alone, built (in name order): for callers that ask a medium about itself
/// without rendering (e.g. the image study checks its fine grid's law).
[[nodiscard]] std::shared_ptr<const Medium> build_medium(const SceneDesc& scene, const std::string& name);

}  // namespace weft::render
