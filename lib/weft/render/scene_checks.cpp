#include "weft/render/scene_checks.h"

#include <set>

#include <fmt/format.h>

#include "weft/render/geometry.h"
#include "weft/render/mesh.h"

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
  // A medium fills the inside of the shapes that bound it: a surface with no inside (a rectangle,
  // an open mesh) leaves every ray that crosses it in the medium until another of its boundaries,
  // so the medium fills the space behind it (an open rectangle rendered black, without a word).
  const auto& shapes = world.geometry->shapes();
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const ShapeInfo& s = shapes[i];
    if ((s.interior < 0 && s.exterior < 0) || (s.kind != ShapeKind::rectangle && s.kind != ShapeKind::mesh)) continue;
    const Closure c = s.kind == ShapeKind::rectangle ? Closure::open : closure(s.mesh);
    if (c == Closure::closed) continue;
    const int m = s.interior >= 0 ? s.interior : s.exterior;
    const std::string& medium = world.medium_names[static_cast<std::size_t>(m)];
    const char* side = s.interior >= 0 ? "interior" : "exterior";
    if (c == Closure::open) {
      out.push_back(fmt::format(
          "shapes[{}] ({}) is the {} of medium '{}' but is not closed ({}): a ray that crosses it stays in the "
          "medium until it crosses another of its boundaries, so the medium fills the space behind it; bound a "
          "medium with a box, a sphere or a closed mesh",
          i, s.kind == ShapeKind::rectangle ? "a rectangle" : "a mesh", side, medium,
          s.kind == ShapeKind::rectangle ? "a rectangle has no inside" : "an edge of one triangle"));
    } else {
      // The medium is entered and left by the triangles' windings: a flipped one swaps them there.
      out.push_back(fmt::format(
          "shapes[{}] (a mesh) is the {} of medium '{}' but some of its triangles are wound against their "
          "neighbours: where a ray crosses one, inside and outside swap and the medium is entered where it should "
          "be left; wind every triangle counter-clockwise seen from outside",
          i, side, medium));
    }
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
