#pragma once
/// @file
/// @brief A grid and a ready scene for other renderers (`weft export`): Mitsuba 3 (XML scene +
/// binary .vol grid volume) and pbrt-v4 (scene file + NanoVDB .nvdb). docs/export.md lists
/// what each file holds and the format documentation it follows.

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "weft/core/progress.h"
#include "weft/volume/grid.h"

namespace weft::volume {

/// The medium the grid describes: μ = sigma × value, single-scattering albedo, HG asymmetry;
/// what the values are and the length unit, for the scenes' comment headers.
struct ExportMedium {
  double sigma = 1.0;                           ///< extinction per unit grid value [1/length]
  std::array<double, 3> albedo{0.8, 0.8, 0.8};  ///< per RGB channel, in [0, 1]
  double g = 0.0;                               ///< Henyey–Greenstein asymmetry in (−1, 1)
  bool extinction = false;                      ///< values are extinction μ (else concentration C)
  std::string units;  ///< length unit the grid's metadata records (UTF-8), "" or blank if none
};

/// @brief One sentence of what the exported grid holds: its values (concentration or extinction),
/// σ and the length unit as the grid's metadata records it ("no units recorded" otherwise).
[[nodiscard]] std::string medium_description(const ExportMedium& medium);

/// @brief Where pbrt-v4's medium differs from weft's and from the Mitsuba export: it interpolates
/// the density trilinearly (docs/export.md, "pbrt-v4 interpolates the density"). One line.
[[nodiscard]] std::string pbrt_interpolation_note();

/// Camera and film of the exported scenes; the camera looks at the grid's centre from above
/// and the front, far enough that the whole box is in view, lit by a white environment.
struct ExportView {
  int width = 256;
  int height = 192;
  int spp = 64;
  double fov_deg = 40.0;  ///< vertical field of view
  int max_depth = 64;
};

/// World-space box of the grid's active voxels (the medium's bounds in both scenes).
struct WorldBox {
  std::array<double, 3> min{};
  std::array<double, 3> max{};
};
[[nodiscard]] WorldBox world_box(const Grid& grid, const IndexBox& box);

/// The renderer a file is written for.
enum class ExportFormat { mitsuba, pbrt };

/// @brief Refuses (weft::Error, one line starting with `grid_label`) a box whose voxels the
/// renderer's single-precision arithmetic cannot resolve (docs/export.md "Where the renderers'
/// floats are"): every coordinate it computes a voxel from (world coordinates of the box for
/// both; pbrt-v4 also the grid's index coordinates, Mitsuba 3 the box-relative ones up to its
/// extent) must have a float spacing of at most kFloatVoxelShare of a voxel there.
void check_float_resolution(const Grid& grid, const IndexBox& box, ExportFormat format, const std::string& grid_label);

/// Largest float spacing a renderer's coordinate may have, in voxels: rounding then moves a voxel
/// face by at most half of it, so each voxel's width, and the optical depth across it, by at most
/// 1/256 ≈ 0.4 %.
inline constexpr double kFloatVoxelShare = 1.0 / 256.0;

/// @brief Refuses (weft::Error naming `path`) a dense volume of `box` above `max_bytes`, or with
/// more voxels along an axis than the format's int32 resolution: what mitsuba_volume checks, for
/// a front end to call before it writes any file.
void check_mitsuba_vol(const IndexBox& box, const std::filesystem::path& path, std::uint64_t max_bytes);

/// Mitsuba's binary grid volume in memory: the 48-byte header and the values.
struct MitsubaVolume {
  std::vector<char> header;
  std::vector<float> values;
};

/// @brief Mitsuba's binary grid volume ("VOL", version 3, encoding 1 = float32, one channel;
/// little endian): resolution, world bounding box, then values with x fastest. Covers `box`;
/// refuses a dense array above `max_bytes` (check_mitsuba_vol, naming `path`). The copy reports
/// to `progress`, whose Cancelled stops it.
[[nodiscard]] MitsubaVolume mitsuba_volume(const Grid& grid, const IndexBox& box, const std::filesystem::path& path,
                                           std::uint64_t max_bytes, ProgressSink& progress = null_progress());

/// Writes `volume` to `path` atomically.
void write_mitsuba_vol(const MitsubaVolume& volume, const std::filesystem::path& path);

/// mitsuba_volume, then write_mitsuba_vol.
void write_mitsuba_vol(const Grid& grid, const IndexBox& box, const std::filesystem::path& path,
                       std::uint64_t max_bytes);

/// @brief The Mitsuba 3 scene (XML, version 3.0.0): volpath integrator, perspective sensor,
/// constant environment, a null-BSDF cube bounding the grid box with a heterogeneous medium
/// inside whose sigma_t is the gridvolume `vol_file` (nearest filtering: weft's grids are
/// piecewise constant) scaled by medium.sigma.
[[nodiscard]] std::string mitsuba_scene_xml(const WorldBox& box, const std::string& vol_file,
                                            const ExportMedium& medium, const ExportView& view);

/// @brief The grid as a NanoVDB float grid named "density" (what pbrt-v4's nanovdb medium
/// reads), same index-to-world transform and values, in memory until written.
class NanoVdbGrid {
 public:
  /// Converts `grid`; reports its two stages (copy, conversion) to `progress`, whose Cancelled
  /// stops it between them (the conversion itself is one OpenVDB call).
  explicit NanoVdbGrid(const Grid& grid, const std::filesystem::path& path, ProgressSink& progress = null_progress());
  ~NanoVdbGrid();
  NanoVdbGrid(NanoVdbGrid&&) noexcept;
  NanoVdbGrid& operator=(NanoVdbGrid&&) noexcept;
  NanoVdbGrid(const NanoVdbGrid&) = delete;
  NanoVdbGrid& operator=(const NanoVdbGrid&) = delete;
  /// Writes it uncompressed to the path given at construction, atomically.
  void write() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// NanoVdbGrid(grid, path).write().
void write_nanovdb(const Grid& grid, const std::filesystem::path& path);

/// @brief The pbrt-v4 scene: volpath integrator, perspective camera, uniform infinite light, a
/// triangle-mesh box with an "interface" material bounding the "nanovdb" medium `nvdb_file`
/// (sigma_a = (1 − albedo)·sigma, sigma_s = albedo·sigma per unit density). Its header says
/// that pbrt-v4 interpolates the density (pbrt_interpolation_note).
[[nodiscard]] std::string pbrt_scene(const WorldBox& box, const std::string& nvdb_file, const ExportMedium& medium,
                                     const ExportView& view);

/// Checks the medium and view (σ > 0 finite, albedo in [0, 1], |g| < 1, positive sizes).
void validate(const ExportMedium& medium, const ExportView& view);

}  // namespace weft::volume
