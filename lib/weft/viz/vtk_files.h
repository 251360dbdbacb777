#pragma once
/// @file
/// @brief Geometry and volumes as VTK XML files for ParaView (.vtp, .vti), written atomically.

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "weft/volume/grid.h"

namespace weft::viz {

/// Polylines (fibres, yarn centrelines, rays) with per-cell and per-point data.
struct PolylineSet {
  std::vector<std::array<double, 3>> points;
  /// offsets[i]..offsets[i+1] index `points` for polyline i; size = polylines + 1.
  std::vector<std::uint64_t> offsets{0};
  std::map<std::string, std::vector<std::int32_t>> cell_ints;
  std::map<std::string, std::vector<double>> cell_scalars;
  std::map<std::string, std::vector<double>> point_scalars;
  /// Store coordinates as float32 (7 significant digits): half the bytes of the dominant array,
  /// for files that are looked at rather than computed on (fibres of `weft gen`).
  bool float_points = false;
};

/// Points (particles) with per-point data.
struct PointSet {
  std::vector<std::array<double, 3>> points;
  std::map<std::string, std::vector<double>> point_scalars;
};

void write_vtp(const PolylineSet& lines, const std::filesystem::path& path);
void write_vtp(const PointSet& points, const std::filesystem::path& path);
/// The bytes write_vtp would write to `path` (which names the file in errors), made in memory:
/// for a caller that makes them beside other work and writes them once that work succeeded
/// (`weft sim2d`'s particles, compressed while the realizations run).
[[nodiscard]] std::string vtp_bytes(const PointSet& points, const std::filesystem::path& path);

/// Why write_vti would refuse `grid` before writing anything (no active voxels, or a box over
/// `max_voxels`), or "" when it would write it: a caller for which the .vti is optional skips it
/// for these reasons, and lets a failed write (a full disk) fail the run like any other output.
[[nodiscard]] std::string vti_refusal(const volume::Grid& grid, std::uint64_t max_voxels = 256ULL << 20U);

/// The grid's active bounding box as dense image data (cell values = voxel values), named
/// after the grid. Throws weft::Error when the box would exceed `max_voxels`. Written in pieces
/// of at most `piece_voxels` voxels (several <Piece> elements of one file, which VTK and
/// ParaView read as one image): memory is the grid plus one piece, not the dense box. Each
/// piece is filled and its LZ4 blocks compressed on all threads; the file is the bytes VTK's
/// writer makes alone with vtkLZ4DataCompressor, for any thread count.
void write_vti(const volume::Grid& grid, const std::filesystem::path& path, std::uint64_t max_voxels = 256ULL << 20U,
               std::uint64_t piece_voxels = 1ULL << 22U);

}  // namespace weft::viz
