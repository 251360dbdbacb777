#pragma once
/// @file
/// @brief The lights of a scene and next-event sampling of them (docs/render.md §3).

#include <cstdint>
#include <memory>
#include <vector>

#include "weft/core/rng.h"
#include "weft/render/environment.h"
#include "weft/render/geometry.h"
#include "weft/render/scene.h"

namespace weft::render {

struct Light {
  enum class Kind { area, point, directional, environment } kind = Kind::point;
  int shape = -1;
  Vec3 position{0, 0, 0};
  Vec3 direction{0, -1, 0};
  Rgb radiance{0, 0, 0};
};

struct LightSample {
  Vec3 wi;
  double dist = 0.0;    ///< distance to the light point (∞ for directional/environment)
  Vec3 point{0, 0, 0};  ///< the light point (point and area lights)
  double margin = 0.0;  ///< a shadow ray stops this far short of an area light's surface
  Rgb le{0, 0, 0};
  double pdf = 0.0;  ///< solid-angle pdf including the light selection probability
  bool delta = false;
};

/// Every light of a scene: emitting shapes (area lights), point and directional lights, and at
/// most one environment (constant radiance, or a lat-long image).
struct LightSet {
  std::vector<Light> lights;
  std::vector<int> light_of_shape;  ///< light index of an emitting shape, else -1
  Rgb environment{0, 0, 0};
  int environment_light = -1;
  std::shared_ptr<const EnvironmentMap> environment_map;  ///< image environment (replaces the constant)

  [[nodiscard]] bool empty() const { return lights.empty(); }
  /// Whether any light carries power: a radiance or intensity > 0 in some channel, an
  /// environment image with a lit pixel and a scale > 0.
  [[nodiscard]] bool emits() const;
  [[nodiscard]] std::size_t size() const { return lights.size(); }

  /// A light chosen uniformly, then a point or direction on it, seen from `x`. A shadow ray keeps
  /// the integrator's ray offset (Geometry::spawn_offset) from an area light's surface.
  [[nodiscard]] LightSample sample(const Vec3& x, const Geometry& geometry, Pcg32& rng) const;
};

/// The lights of `scene`, whose shapes `geometry` holds.
[[nodiscard]] LightSet build_lights(const SceneDesc& scene, const Geometry& geometry);

}  // namespace weft::render
