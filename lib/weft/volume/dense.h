#pragma once
/// @file
/// @brief Dense copies of a sub-box of a sparse grid and back (numpy arrays, renderer exports).

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include "weft/core/progress.h"
#include "weft/volume/grid.h"

namespace weft::volume {

/// Bytes of a dense float array covering `box` (0 for an empty box; saturates at UINT64_MAX).
[[nodiscard]] std::uint64_t dense_bytes(const IndexBox& box);

/// @brief The values of `box` as a dense array, x-major: element (i, j, k) of the box (relative
/// to box.min) is at ((i·ny) + j)·nz + k; inactive voxels read as 0.
///
/// Refuses (weft::Error naming the box) a box beyond the index range (|index| <= kMaxIndex,
/// grid.h), and (naming the box and the size) when the array would exceed `max_bytes`:
/// a dense copy of a large sparse grid is mostly zeros and can be far larger than the grid.
/// Reports to `progress` as copy_to_dense.
[[nodiscard]] std::vector<float> to_dense(const Grid& grid, const IndexBox& box, std::uint64_t max_bytes,
                                          ProgressSink& progress = null_progress());

/// Memory order of a dense copy.
enum class DenseLayout {
  x_major,  ///< k fastest: C order of an array indexed [i][j][k] (numpy's default)
  z_major,  ///< i fastest: ((k·ny) + j)·nx + i (Mitsuba's .vol, Fortran order of [i][j][k])
};

/// @brief The values of `box` into a caller-owned buffer of dense_bytes(box) bytes (no size
/// check; the index range is checked as by to_dense). Reports one unit per slab of 8 voxels
/// along the layout's slowest axis to `progress`, whose Cancelled stops the copy.
void copy_to_dense(const Grid& grid, const IndexBox& box, float* out, DenseLayout layout = DenseLayout::x_major,
                   ProgressSink& progress = null_progress());

/// @brief Writes a dense x-major array of extent `extent` into `grid` starting at index `min`:
/// non-zero values become active voxels, zeros inactive background. Throws weft::Error for a
/// NaN, infinite or negative value (naming its index), which no weft grid may hold, and before
/// writing anything when the box leaves the index range (|index| <= kMaxIndex, grid.h). The
/// errors begin with `what`, the caller's name for the copy (Python's is "from_numpy").
void from_dense(Grid& grid, const std::array<int, 3>& min, const std::array<std::int64_t, 3>& extent,
                const float* values, std::string_view what = "dense copy");

}  // namespace weft::volume
