// The image study's fine grid in its scene and the candidates' scenes (study_target.h).
#include "weft/study/study_target.h"

#include <memory>
#include <optional>
#include <vector>

#include "weft/core/error.h"
#include "weft/render/medium.h"
#include "weft/render/world.h"

namespace weft::study {

using namespace weft::render;  // NOLINT(google-build-using-namespace)
using nlohmann::json;

Box world_box(const volume::Grid& grid) {
  const volume::IndexBox b = grid.active_bbox();
  const auto o = grid.origin();
  const double h = grid.voxel_size();
  Box w;
  for (int a = 0; a < 3; ++a) {
    w.min[a] = o[static_cast<std::size_t>(a)] + h * b.min[static_cast<std::size_t>(a)];
    w.max[a] = o[static_cast<std::size_t>(a)] + h * (static_cast<double>(b.max[static_cast<std::size_t>(a)]) + 1.0);
  }
  return w;
}

namespace {
json vec_json(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }
}  // namespace

Target find_target(const SceneDesc& scene) {
  Target t;
  std::vector<std::string> grids;
  for (const auto& [name, m] : scene.media)
    if (m.kind == MediumKind::grid) grids.push_back(name);
  if (grids.size() != 1)
    fail("study: the scene needs exactly one grid medium (the fine grid), it has {}", grids.size());
  t.medium = grids.front();
  const MediumDesc& m = scene.media.at(t.medium);
  const std::shared_ptr<const Medium> built = build_medium(scene, t.medium);
  if (built->traits().law != "exponential")
    fail("study: medium '{}' must have the exponential law (the reference is exponential per voxel), it has '{}'",
         t.medium, built->traits().law);
  int found = 0;
  for (std::size_t i = 0; i < scene.shapes.size(); ++i) {
    const ShapeDesc& s = scene.shapes[i];
    if (s.interior != t.medium && s.exterior != t.medium) continue;
    ++found;
    if (s.kind != ShapeKind::box || s.interior != t.medium)
      fail("study: medium '{}' must fill one box shape (shapes[{}] is not a box holding it inside)", t.medium, i);
    t.shape = i;
    t.box = {s.min, s.max};
  }
  if (found != 1) fail("study: medium '{}' must fill exactly one box shape, {} shapes name it", t.medium, found);
  t.scene = json::parse(scene_to_json(scene));
  t.medium_json = t.scene["media"][t.medium];
  // σ scales the statistics of every candidate (Eq. 19–20 in σ units): with σ = 0 the cloth has
  // no extinction and the study nothing to compare. Said with the scene's key, before any work.
  if (m.concentration && !(m.sigma > 0.0))
    fail(
        "study: media.{}.sigma is {}: the study needs sigma > 0 (with 0 the cloth does not attenuate light and "
        "there is nothing to downsample)",
        t.medium, m.sigma);
  // The extinction per grid value is the law's μ times σ (docs/scene-format.md "media"): every
  // candidate, the fields, the self-shadowing correction and the slab take that product, so a
  // law with μ ≠ 1 describes the same cloth in all of them.
  const std::optional<double> mu = exponential_pair_rate(m, make_medium_pair(m, "study: media." + t.medium));
  if (!mu || !(*mu > 0.0))
    fail(
        "study: media.{}.law.mu is {}: the study needs mu > 0 (with 0 the cloth does not attenuate light and "
        "there is nothing to downsample)",
        t.medium, mu ? *mu : 0.0);
  t.sigma_stats = *mu * (m.concentration ? m.sigma : 1.0);
  return t;
}

void check_target_box(const Target& t, const SceneDesc& scene, const volume::Grid& fine) {
  const ShapeDesc& shape = scene.shapes.at(t.shape);
  const auto material = scene.materials.find(shape.material);
  if (material == scene.materials.end() || material->second.kind != MaterialKind::null)
    fail(
        "study: shapes[{}], the box holding medium '{}', has material '{}': the study fits each candidate's box "
        "to its grid, so the box must be a null boundary (a material of type \"null\") that no ray sees",
        t.shape, t.medium, shape.material);
  const Box grid = world_box(fine);
  // The box's faces are where the scene puts them, the grid's where its voxels end: equal up to
  // the rounding of the numbers that wrote them, hence the relative slack.
  const double slack = 1e-9 * (grid.max - grid.min).cwiseAbs().maxCoeff();
  if (((grid.min - t.box.min).array() < -slack).any() || ((grid.max - t.box.max).array() > slack).any())
    fail(
        "study: shapes[{}], the box holding medium '{}' ({:g}, {:g}, {:g})..({:g}, {:g}, {:g}), cuts the active "
        "voxels of grid '{}' ({:g}, {:g}, {:g})..({:g}, {:g}, {:g}): a coarse grid's blocks would be cut elsewhere "
        "and its candidates render another cloth; give a box that holds the whole grid",
        t.shape, t.medium, t.box.min.x(), t.box.min.y(), t.box.min.z(), t.box.max.x(), t.box.max.y(), t.box.max.z(),
        fine.name(), grid.min.x(), grid.min.y(), grid.min.z(), grid.max.x(), grid.max.y(), grid.max.z());
}

json candidate_scene(const Target& t, const json& medium, const Box& box) {
  json j = t.scene;
  j["media"][t.medium] = medium;
  j["shapes"][t.shape]["min"] = vec_json(box.min);
  j["shapes"][t.shape]["max"] = vec_json(box.max);
  return j;
}

Box union_box(const Box& a, const Box& b) { return {a.min.cwiseMin(b.min), a.max.cwiseMax(b.max)}; }

}  // namespace weft::study
