#include "weft/render/world.h"

#include <map>
#include <string>

#include "weft/core/error.h"

namespace weft::render {

namespace {

/// What the scene uses; media are asked about themselves (their traits), so the integrator's
/// specialisation never depends on which kind of medium it holds (docs/render.md §1).
Features features_of(const SceneDesc& scene, const World& w) {
  Features f;
  for (const auto& s : scene.shapes) {
    if ((s.emission > 0.0).any()) f.area_lights = true;
    if (!s.interior.empty() || !s.exterior.empty()) f.media = true;
    if (s.kind == ShapeKind::curves) f.curves = true;
  }
  for (const auto& l : scene.lights)
    if (l.kind == LightKind::environment && ((l.intensity > 0.0).any() || !l.image.empty())) {
      f.environment = true;
      if (!l.image.empty()) f.environment_image = true;
    }
  if (f.media) {
    for (std::size_t i = 0; i < w.media.size(); ++i) {
      const MediumTraits t = w.media[i]->traits();
      if (!t.exponential) f.general_media = true;
      if (t.heterogeneous) f.heterogeneous = true;
      if (t.non_reciprocal) f.non_reciprocal = true;
      f.media_described.push_back("medium '" + w.medium_names[i] + "': " + t.describe());
    }
  }
  return f;
}

}  // namespace

std::shared_ptr<const Medium> build_medium(const SceneDesc& scene, const std::string& name) {
  const auto it = scene.media.find(name);
  if (it == scene.media.end()) fail("{}: no medium '{}'", scene.source, name);
  return make_medium(it->second, scene.source + ": media." + name);
}

World build_world(const SceneDesc& scene) {
  World w;
  w.camera = scene.camera;
  w.settings = scene.integrator;
  std::map<std::string, int> material_index;
  for (const auto& [name, m] : scene.materials) {
    material_index[name] = static_cast<int>(w.materials.size());
    w.materials.push_back(m);
    if (m.kind == MaterialKind::null) w.any_null = true;
  }
  std::map<std::string, int> medium_index;
  for (const auto& [name, m] : scene.media) {
    medium_index[name] = static_cast<int>(w.media.size());
    w.media.push_back(build_medium(scene, name));
    w.medium_names.push_back(name);
  }
  w.geometry = std::make_unique<Geometry>(scene, material_index, medium_index);
  w.extent = w.geometry->extent();
  w.lights = build_lights(scene, *w.geometry);
  w.features = features_of(scene, w);
  return w;
}

}  // namespace weft::render
