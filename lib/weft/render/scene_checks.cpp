#include "weft/render/scene_checks.h"

#include <set>

#include <fmt/format.h>

namespace weft::render {

std::vector<std::string> scene_warnings(const SceneDesc& scene) {
  std::set<std::string> used;
  for (const ShapeDesc& s : scene.shapes) {
    if (!s.interior.empty()) used.insert(s.interior);
    if (!s.exterior.empty()) used.insert(s.exterior);
  }
  std::vector<std::string> out;
  for (const auto& [name, medium] : scene.media) {
    if (!used.contains(name))
      out.push_back(fmt::format(
          "medium '{}' is not the interior or exterior of any shape, so it does not affect the image", name));
  }
  return out;
}

std::vector<std::string> world_warnings(const World& world) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < world.media.size(); ++i) {
    if (world.media[i]->traits().empty)
      out.push_back(fmt::format(
          "medium '{}' has zero extinction everywhere (its grid's active voxels are all 0, or its sigma or mu is 0), "
          "so it does not affect the image",
          world.medium_names[i]));
  }
  // Nothing emits: every path's radiance is 0 and the image is black whatever the scene holds
  // (weft.render({}) rendered a black 256×256 film without a word).
  if (world.lights.empty()) {
    out.emplace_back(
        "the scene has no light (nothing in \"lights\" and no shape with \"emission\"), so the image is black");
  } else if (!world.lights.emits()) {
    out.emplace_back(
        "every light of the scene emits nothing (intensity, irradiance, radiance or emission 0, or an environment "
        "image that is black or scaled by 0), so the image is black");
  }
  return out;
}

}  // namespace weft::render
