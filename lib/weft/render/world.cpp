#include "weft/render/world.h"

#include <map>
#include <string>

namespace weft::render {

World build_world(const SceneDesc& scene) {
  World w;
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
    // Built by parse_scene (read once); a description made in code is built here.
    w.media.push_back(m.loaded ? m.loaded : make_medium(m, "medium '" + name + "'"));
  }
  w.geometry = std::make_unique<Geometry>(scene, material_index, medium_index);
  w.extent = w.geometry->extent();
  w.lights = build_lights(scene, *w.geometry);
  return w;
}

}  // namespace weft::render
