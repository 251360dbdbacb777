#include "weft/render/cloth_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include <nlohmann/json.hpp>

#include "weft/core/error.h"
#include "weft/transmittance/law_json.h"
#include "weft/volume/grid.h"
#include "weft/volume/provenance.h"

namespace weft::render {

Rgb preset_albedo(const std::string& preset) {
  // Undyed fibres scatter almost all light; the small absorption differs by material and tints
  // the multiply scattered light (raw cotton and linen yellowish, wool cream, polyester and
  // silk nearly white). Chosen for the look; the study compares models, not materials.
  if (preset == "cotton") return {0.95, 0.90, 0.80};
  if (preset == "polyester") return {0.97, 0.97, 0.96};
  if (preset == "silk") return {0.96, 0.94, 0.88};
  if (preset == "wool") return {0.93, 0.88, 0.78};
  if (preset == "linen") return {0.92, 0.88, 0.76};
  fail("unknown yarn preset '{}' (known: cotton, polyester, silk, wool, linen)", preset);
}

ClothLook cloth_look(const volume::Grid& grid, const std::filesystem::path& vdb) {
  ClothLook look;
  const volume::Provenance provenance = volume::read_provenance(grid);
  if (!provenance.sigma)
    fail(
        "{}: no sigma in the grid's metadata (weft:sigma_per_concentration): cloth scenes are made for grids of "
        "weft gen",
        vdb.string());
  look.sigma = *provenance.sigma;
  const auto meta = grid.metadata();
  const auto it = meta.find("generator");
  if (it != meta.end()) {
    // The ClothSpec JSON of `weft gen` (cloth.json): the warp yarn's preset.
    const nlohmann::json spec = nlohmann::json::parse(it->second, nullptr, false);
    if (!spec.is_discarded() && spec.contains("warp_yarn") && spec["warp_yarn"].is_object()) {
      const auto& yarn = spec["warp_yarn"];
      // The label is the preset's name, or "wool (modified: ...)" (docs/cloth.md "Presets and
      // explicit fields"): the look follows the preset the yarn started from.
      if (yarn.contains("preset") && yarn["preset"].is_string()) {
        const auto label = yarn["preset"].get<std::string>();
        look.preset = label.substr(0, label.find(" ("));
      }
    }
  }
  try {
    look.albedo = preset_albedo(look.preset);
  } catch (const Error&) {
    look.albedo = preset_albedo("cotton");  // a preset this table does not know: the default look
  }
  return look;
}

const std::vector<std::pair<std::string, ClothLighting>>& cloth_lightings() {
  static const std::vector<std::pair<std::string, ClothLighting>> table = {
      {"key-and-back", ClothLighting::key_and_back},
      {"back", ClothLighting::back},
      {"front", ClothLighting::front},
      {"grazing", ClothLighting::grazing}};
  return table;
}

ClothLighting cloth_lighting(const std::string& name) {
  std::string known;
  for (const auto& [n, l] : cloth_lightings()) {
    if (n == name) return l;
    known += (known.empty() ? "" : ", ") + n;
  }
  fail("unknown cloth lighting '{}' (known: {})", name, known);
}

std::string cloth_lighting_name(ClothLighting lighting) {
  for (const auto& [n, l] : cloth_lightings())
    if (l == lighting) return n;
  return "?";
}

std::string cloth_tilt_range() { return fmt::format("[0, {:g})", kMaxClothTilt); }

bool is_cloth_tilt(double degrees) { return degrees >= 0.0 && degrees < kMaxClothTilt; }  // false for NaN

void check_cloth_tilt(const std::string& what, double degrees) {
  if (!is_cloth_tilt(degrees)) fail("{}: tilt {} degrees is not in {}", what, degrees, cloth_tilt_range());
}

namespace {

/// The default picture (docs/render.md §5c): samples per pixel, the back light's radiance and
/// the key light's irradiance.
constexpr int kDefaultSpp = 128;
constexpr double kDefaultPanel = 0.5;
constexpr double kDefaultKey = 3.0;

/// A directional light arriving from elevation `elevation` (degrees above the cloth's plane)
/// and azimuth `azimuth` (degrees from the camera's side, −ev, towards −eu): its direction of
/// travel, as the scene format wants it.
Vec3 light_travel(const Vec3& normal, const Vec3& eu, const Vec3& ev, double elevation, double azimuth) {
  const double el = elevation * std::numbers::pi / 180.0;
  const double az = azimuth * std::numbers::pi / 180.0;
  const Vec3 from = std::cos(el) * (-std::cos(az) * ev - std::sin(az) * eu) + std::sin(el) * normal;
  return -from.normalized();
}

// The scene of `grid`, saved as `file_in_scene`; errors name `where`.
std::string scene_json(const volume::Grid& grid, const std::string& file_in_scene, const std::filesystem::path& where,
                       const ClothSceneMedium& medium, const ClothView& view) {
  if (view.width < 1 || view.height < 1)
    fail("cloth scene for '{}': a film of {}x{} px (need >= 1 px)", where.string(), view.width, view.height);
  check_cloth_tilt(fmt::format("cloth scene for '{}'", where.string()), view.tilt_degrees);
  const volume::IndexBox box = grid.active_bbox();
  if (box.empty()) fail("cloth grid '{}' is empty", where.string());
  const ClothLook look = cloth_look(grid, where);
  const double h = grid.voxel_size();
  const auto org = grid.origin();
  Vec3 lo;
  Vec3 hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = org[a] + h * box.min[a];
    hi[a] = org[a] + h * (static_cast<double>(box.max[a]) + 1.0);
  }
  // The medium's bound: the active box plus one voxel for a grid (index-matched, so it is
  // invisible; no voxel is cut), the active box itself for a homogeneous slab (the thickness
  // its law was predicted for), and for local fields the box also covers every active block.
  Vec3 bmin = lo - Vec3::Constant(h);
  Vec3 bmax = hi + Vec3::Constant(h);
  if (medium.kind == ClothSceneMedium::Kind::homogeneous) {
    bmin = lo;
    bmax = hi;
  } else if (medium.kind == ClothSceneMedium::Kind::local_fields) {
    const volume::Grid fields = volume::Grid::load(medium.fields, "mean_concentration");
    const volume::IndexBox fb = fields.active_bbox();
    if (fb.empty()) fail("local fields '{}' are empty", medium.fields.string());
    const double fh = fields.voxel_size();
    const auto fo = fields.origin();
    for (int a = 0; a < 3; ++a) {
      bmin[a] = std::min(bmin[a], fo[a] + fh * fb.min[a]);
      bmax[a] = std::max(bmax[a], fo[a] + fh * (static_cast<double>(fb.max[a]) + 1.0));
    }
  }
  const Vec3 size = hi - lo;
  const Vec3 centre = 0.5 * (lo + hi);
  // The cloth's normal is its thinnest axis; u, v span its plane (v the longer side).
  int n = 0;
  for (int a = 1; a < 3; ++a)
    if (size[a] < size[n]) n = a;
  const int u = (n + 1) % 3;
  const int v = (n + 2) % 3;
  const Vec3 normal = Vec3::Unit(n);
  const Vec3 eu = Vec3::Unit(u);
  const Vec3 ev = Vec3::Unit(v);
  const double extent = std::max(size[u], size[v]);
  // The camera looks at the cloth `tilt` off its normal from the −v side, so close that the
  // smaller of the cloth's projected sides spans kFill times the film (> 1: both are cropped a
  // little, and the active box's loose fibre ends at the border leave the frame): the weave
  // fills the picture (docs/render.md §5c). Projected half sizes at distance d from the
  // centre: u over d·tan(fov_u/2), v foreshortened by cos(tilt) over d·tan(fov/2).
  constexpr double kFov = 35.0;
  constexpr double kFill = 1.25;
  const double tilt = view.tilt_degrees * std::numbers::pi / 180.0;
  const double tan_v = std::tan(0.5 * kFov * std::numbers::pi / 180.0);
  const double tan_u = tan_v * static_cast<double>(view.width) / static_cast<double>(view.height);
  const double distance =
      std::min(0.5 * size[u] / (kFill * tan_u), 0.5 * size[v] * std::cos(tilt) / (kFill * tan_v)) + size[n];
  const Vec3 towards_camera = (std::cos(tilt) * normal - std::sin(tilt) * ev).normalized();
  const Vec3 camera = centre + distance * towards_camera;
  // The film's up is the normal's projection orthogonal to the view, n − (n·w)w = sin t (sin t n +
  // cos t ev) for the view w = cos t n − sin t ev: written as the unit sin t n + cos t ev, exactly
  // orthogonal to w at every tilt, ev face-on (where the normal has no projection), and never
  // degenerate for a tilt of 1e-300 (a projection computed from n alone would be).
  const Vec3 up = std::sin(tilt) * normal + std::cos(tilt) * ev;
  // The back light: an emitting rectangle 1.2× the patch, half the patch below it, facing it
  // (its normal edge_u × edge_v points at the cloth).
  const double below = 0.5 * extent;
  const Vec3 lu = 1.2 * size[u] * eu;
  const Vec3 lv = 1.2 * size[v] * ev;
  Vec3 corner = centre - below * normal - 0.5 * lu - 0.5 * lv;
  Vec3 edge_u = lu;
  Vec3 edge_v = lv;
  if (edge_u.cross(edge_v).dot(normal) < 0.0) std::swap(edge_u, edge_v);
  // Strengths: radiance of the panel, irradiance of the directional light, radiance of the sky.
  // The default picture's are set so that the brightest yarns and the panel seen through the
  // gaps stay below 1 at exposure 1 (docs/render.md §5c: measured clipped share).
  double panel = 0.0;
  double sky = 0.0;
  std::optional<Vec3> key;
  double key_irradiance = 0.0;
  switch (view.lighting) {
    case ClothLighting::key_and_back:
      panel = kDefaultPanel;
      sky = 0.02;
      key = light_travel(normal, eu, ev, 50.0, 35.0);
      key_irradiance = kDefaultKey;
      break;
    case ClothLighting::back:
      panel = 1.0;
      break;
    case ClothLighting::front:
      key = light_travel(normal, eu, ev, 60.0, 20.0);
      key_irradiance = 3.0;
      break;
    case ClothLighting::grazing:
      key = light_travel(normal, eu, ev, 12.0, 90.0);
      key_irradiance = 3.0;
      break;
  }
  nlohmann::json j;
  j["camera"] = {{"position", {camera.x(), camera.y(), camera.z()}},
                 {"look_at", {centre.x(), centre.y(), centre.z()}},
                 {"up", {up.x(), up.y(), up.z()}},
                 {"fov", kFov},
                 {"width", view.width},
                 {"height", view.height}};
  j["integrator"] = {{"spp", kDefaultSpp}, {"max_depth", 64}, {"rr_depth", 6}, {"seed", 1}};
  j["materials"] = {{"boundary", {{"type", "null"}}}};
  const nlohmann::json albedo = {look.albedo.x(), look.albedo.y(), look.albedo.z()};
  nlohmann::json cloth;
  switch (medium.kind) {
    case ClothSceneMedium::Kind::grid:
      cloth = {{"type", "grid"},
               {"file", file_in_scene},
               {"values", "concentration"},
               {"sigma", look.sigma},
               {"tracking", "delta"}};
      break;
    case ClothSceneMedium::Kind::local_fields:
      // The memory rule written out, so the scene says what it renders (docs/render.md §5e).
      cloth = {{"type", "local-gamma"},
               {"fields", file_in_scene},
               {"sigma", look.sigma},
               {"memory", transmittance::memory_rule_name(transmittance::kDefaultMemoryRule)}};
      break;
    case ClothSceneMedium::Kind::homogeneous: {
      if (!medium.law) fail("cloth scene for '{}': a homogeneous medium needs a law", where.string());
      cloth = {{"type", "homogeneous"}, {"law", transmittance::law_to_json(transmittance::spec_of(*medium.law))}};
      break;
    }
  }
  cloth["albedo"] = albedo;
  cloth["g"] = 0.3;
  j["media"] = {{"cloth", cloth}};
  j["shapes"] = nlohmann::json::array({{{"type", "box"},
                                        {"min", {bmin.x(), bmin.y(), bmin.z()}},
                                        {"max", {bmax.x(), bmax.y(), bmax.z()}},
                                        {"material", "boundary"},
                                        {"interior", "cloth"}}});
  if (panel > 0.0)
    j["shapes"].push_back({{"type", "rectangle"},
                           {"corner", {corner.x(), corner.y(), corner.z()}},
                           {"edge_u", {edge_u.x(), edge_u.y(), edge_u.z()}},
                           {"edge_v", {edge_v.x(), edge_v.y(), edge_v.z()}},
                           {"emission", panel}});
  j["lights"] = nlohmann::json::array();
  if (key)
    j["lights"].push_back(
        {{"type", "directional"}, {"direction", {key->x(), key->y(), key->z()}}, {"irradiance", key_irradiance}});
  if (sky > 0.0) j["lights"].push_back({{"type", "environment"}, {"radiance", sky}});
  return j.dump(2) + "\n";
}

}  // namespace

std::string cloth_scene_json(const std::filesystem::path& vdb, const std::string& file_in_scene,
                             const ClothSceneMedium& medium, const ClothView& view) {
  return scene_json(volume::Grid::load(vdb), file_in_scene, vdb, medium, view);
}

std::string cloth_scene_json(const volume::Grid& grid, const std::string& file_in_scene, const ClothSceneMedium& medium,
                             const ClothView& view) {
  return scene_json(grid, file_in_scene, file_in_scene, medium, view);
}

SceneDesc cloth_scene(const std::filesystem::path& vdb, const ClothView& view) {
  const std::filesystem::path folder = vdb.has_parent_path() ? vdb.parent_path() : std::filesystem::path(".");
  return parse_scene(cloth_scene_json(vdb, vdb.filename().string(), {}, view), "cloth scene for '" + vdb.string() + "'",
                     folder);
}

}  // namespace weft::render
