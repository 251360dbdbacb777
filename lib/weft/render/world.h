#pragma once
/// @file
/// @brief The built world a render reads: materials, media, the Embree geometry and the lights.

#include <memory>
#include <vector>

#include "weft/render/geometry.h"
#include "weft/render/lights.h"
#include "weft/render/medium.h"
#include "weft/render/scene.h"

namespace weft::render {

/// Everything the integrator reads; built once per render.
struct World {
  std::vector<MaterialDesc> materials;
  std::vector<std::shared_ptr<const Medium>> media;
  std::unique_ptr<Geometry> geometry;
  LightSet lights;
  bool any_null = false;
  double eps = 1e-5;  ///< ray offsets, relative to coordinates and scene size (float hit points)
  double extent = 1.0;
  IntegratorDesc settings;
};

/// Builds the world of `scene` (its media as parse_scene built them, or built here for a
/// description made in code). Throws weft::Error for scenes that cannot be built.
[[nodiscard]] World build_world(const SceneDesc& scene);

}  // namespace weft::render
