#pragma once
/// @file
/// @brief Scene description: value types read from and written to JSON (docs/scene-format.md).
///
/// A SceneDesc is what the file says, checked (names resolved, parameters in range, files
/// present). It holds no built object: build_world (world.h) reads the files it names and
/// builds its media, geometry and lights, once per render, so a description made or edited in
/// code builds exactly like a parsed one.
/// Every object round-trips: parse_scene(scene_to_json(s)) == s up to float formatting.

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "weft/transmittance/gamma_hazard.h"
#include "weft/transmittance/pair.h"
#include "weft/transmittance/registry.h"

namespace weft::render {

using Vec3 = Eigen::Vector3d;
using Rgb = Eigen::Array3d;

/// Pinhole or thin-lens perspective camera looking from `position` at `look_at`.
struct CameraDesc {
  Vec3 position{0, 0, 5};
  Vec3 look_at{0, 0, 0};
  Vec3 up{0, 1, 0};
  double fov_deg = 40.0;         ///< vertical field of view
  double aperture_radius = 0.0;  ///< 0 = pinhole
  double focus_distance = 0.0;   ///< 0 = distance to look_at
  int width = 256;
  int height = 256;
};

/// The longest film side of a `--quick` render (the CLI's and Python's quick studies).
inline constexpr int kQuickFilmSide = 48;

/// The same view on a smaller film: the longest side `longest` pixels, the aspect ratio kept to
/// the nearest pixel (each side at least 1).
void shrink_film(CameraDesc& camera, int longest);

/// How pixels are estimated.
struct IntegratorDesc {
  int spp = 64;
  int max_depth = 64;  ///< scattering + surface events per path
  int rr_depth = 8;    ///< Russian roulette starts after this many events
  std::uint64_t seed = 1;
};

enum class MaterialKind { diffuse, mirror, dielectric, null };

struct MaterialDesc {
  MaterialKind kind = MaterialKind::diffuse;
  Rgb albedo{0.8, 0.8, 0.8};  ///< diffuse reflectance / mirror and dielectric tint
  double ior = 1.5;           ///< dielectric: interior over exterior index
};

enum class MediumKind {
  homogeneous,  ///< constant extinction; `law` in distance
  grid,         ///< voxel grid of concentration or extinction from a .vdb; `law` in optical depth τ
  local_gamma,  ///< per-voxel gamma laws from the `weft fit --block` fields (`file`, `sigma`)
};

/// How free flights through a grid medium are found.
enum class Tracking {
  delta,          ///< delta tracking + ratio tracking against the grid's majorant (exponential laws)
  optical_depth,  ///< DDA march to the sampled optical depth; the only choice for other laws
};

/// A participating medium bounded by shapes that name it as `interior` (or `exterior`).
struct MediumDesc {
  MediumKind kind = MediumKind::homogeneous;
  /// homogeneous: the law in distance; grid: the law in optical depth. Empty for local-gamma
  /// media, whose fields carry one gamma law per voxel (the medium kind says so, not a law name).
  transmittance::LawSpec law{"exponential", {{"mu", 1.0}}, "", ""};
  transmittance::PairMode mode = transmittance::PairMode::reciprocal;
  /// Which segments `law` describes; the partner is derived (reciprocal) or equal (same).
  transmittance::Origin given = transmittance::Origin::source;
  /// explicit mode: the law of segments that start at a scatterer.
  transmittance::LawSpec scatterer_law{};
  Rgb albedo{1, 1, 1};  ///< single-scattering albedo Λ
  double g = 0.0;       ///< Henyey–Greenstein asymmetry; 0 = isotropic
  // grid and local-gamma media
  std::string file;       ///< .vdb path (resolved against the scene folder); local-gamma: the fields
  std::string grid_name;  ///< grid in the file; empty = the first float grid
  /// grid: three grids of the file (x, y, z) for a direction-dependent extinction
  /// σ(ω) = Σ_a ω_a² σ_a (docs/render.md §6d); empty = the one grid above.
  std::vector<std::string> axis_grids;
  bool concentration = true;  ///< values are concentrations C (μ = σ·C) rather than μ
  double sigma = 1.0;         ///< σ for concentration grids and local-gamma fields
  Tracking tracking = Tracking::delta;
  /// local-gamma: how the hazard's memory passes from cell to cell (docs/render.md §5e).
  transmittance::MemoryRule memory = transmittance::kDefaultMemoryRule;
};

enum class ShapeKind { sphere, box, rectangle, mesh, curves };

struct ShapeDesc {
  ShapeKind kind = ShapeKind::sphere;
  // sphere
  Vec3 center{0, 0, 0};
  double radius = 1.0;
  // box (axis-aligned)
  Vec3 min{-1, -1, -1};
  Vec3 max{1, 1, 1};
  // rectangle: corner + two edges; the normal is edge_u × edge_v
  Vec3 corner{-1, -1, 0};
  Vec3 edge_u{2, 0, 0};
  Vec3 edge_v{0, 2, 0};
  // mesh: OBJ or PLY file; curves: BCC or OBJ polyline file (fibres as round tubes of `radius`).
  // Paths are resolved against the scene folder; points are scaled, then translated.
  std::string file;
  double scale = 1.0;
  Vec3 translate{0, 0, 0};

  std::string material;   ///< name in SceneDesc::materials
  std::string interior;   ///< medium inside (empty: none)
  std::string exterior;   ///< medium outside (empty: none)
  Rgb emission{0, 0, 0};  ///< radiance emitted from the front side (area light when > 0)
};

enum class LightKind { point, directional, environment };

struct LightDesc {
  LightKind kind = LightKind::point;
  Vec3 position{0, 0, 0};    ///< point
  Vec3 direction{0, -1, 0};  ///< directional: direction light travels
  Rgb intensity{1, 1, 1};    ///< point: W/sr; directional: irradiance; environment: radiance
  /// environment: lat-long radiance image (EXR; empty = constant `intensity`), times `scale`.
  std::string image;
  double scale = 1.0;
};

struct SceneDesc {
  CameraDesc camera;
  IntegratorDesc integrator;
  std::map<std::string, MaterialDesc> materials;
  std::map<std::string, MediumDesc> media;
  std::vector<ShapeDesc> shapes;
  std::vector<LightDesc> lights;
  /// Folder that relative file names are resolved against (the scene file's folder).
  std::filesystem::path base_dir;
  /// Names the input in errors of building the world (a path, "built-in scene x", "scene dict").
  std::string source = "scene";
};

/// Parses and checks a scene description. `source` names the input in errors (a path or
/// "built-in scene x"). Throws weft::Error with one line: invalid JSON with line and column,
/// unknown types or keys with the closest known name, out-of-range numbers, dangling names,
/// missing files. The description holds no built object: build_world (world.h) reads the files
/// it names and builds its media, once per render.
[[nodiscard]] SceneDesc parse_scene(std::string_view json_text, const std::string& source,
                                    const std::filesystem::path& base_dir);

/// Reads and parses a scene file.
[[nodiscard]] SceneDesc load_scene(const std::filesystem::path& path);

/// Writes the scene back to JSON (every field, canonical form).
[[nodiscard]] std::string scene_to_json(const SceneDesc& scene);

}  // namespace weft::render
