#pragma once
/// @file
/// @brief Streaming access to a grid as columns of voxels along one axis.
///
/// An axis beam crosses every voxel of the active bounding box once, so everything an axis beam
/// or a window statistic needs is one pass over the active voxels, tile by tile: the columns of
/// an 8×8 patch of the face, densely, along the whole depth of the box. Work units are those
/// patches; they are independent, so callers run them in parallel and reduce in index order.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "weft/volume/grid.h"
#include "weft/volume/pass_budget.h"

namespace weft::volume {

/// Dense values of the columns of one patch of the face perpendicular to `axis`.
struct ColumnTile {
  int axis = 2;
  /// Index coordinates (on the two transverse axes (axis+1)%3 and (axis+2)%3) of the first column.
  std::int64_t u0 = 0;
  std::int64_t v0 = 0;
  int nu = 0;  ///< columns along the first transverse axis
  int nv = 0;  ///< columns along the second transverse axis
  /// Index coordinate along `axis` of the first voxel of every column (the box's lower face).
  std::int64_t depth0 = 0;
  int depth = 0;  ///< voxels per column (the box's extent along `axis`)
  /// values[(iu·nv + iv)·depth + k]: the value of voxel k of column (iu, iv); 0 where inactive.
  std::vector<float> values;
  [[nodiscard]] const float* column(int iu, int iv) const {
    return values.data() +
           (static_cast<std::size_t>(iu) * static_cast<std::size_t>(nv) + static_cast<std::size_t>(iv)) *
               static_cast<std::size_t>(depth);
  }
};

/// Where a face patch lies, as in ColumnTile: its first column's transverse index coordinates,
/// its columns along each transverse axis, the box's lower face and depth along the axis.
struct PatchFrame {
  std::int64_t u0 = 0;
  std::int64_t v0 = 0;
  int nu = 0;
  int nv = 0;
  std::int64_t depth0 = 0;
  int depth = 0;
};

/// The active voxels of one face patch, depth slice by depth slice: the sparse counterpart of
/// ColumnTile for passes whose work should follow the active voxels, not the box.
struct SparseColumnTile : PatchFrame {
  int axis = 2;
  /// A depth slice holding active voxels: its index k along the axis (from depth0) and its
  /// voxels' range [begin, end) in `column`/`value`.
  struct Slice {
    int k = 0;
    std::uint32_t begin = 0;
    std::uint32_t end = 0;
  };
  std::vector<Slice> slices;  ///< in increasing k; slices without active voxels are absent
  /// iu·nv + iv of each active voxel, and its value; entries past the last slice's end are
  /// unused (the storage is reused from patch to patch and only grows).
  std::vector<std::uint16_t> column;
  std::vector<float> value;
};

/// The active voxels of non-zero value of one face patch, column by column: the layout a pass
/// over each column's voxels in depth order wants (fit's statistics pass), read straight from
/// the leaves.
struct SparseColumns : PatchFrame {
  /// Column c = iu·nv + iv holds count[c] active voxels, in increasing depth: index k along the
  /// axis (from depth0) at k[c·depth + j] and value at value[c·depth + j], j < count[c]. The
  /// storage is reused from patch to patch and only grows.
  std::array<std::uint32_t, 64> count{};
  std::vector<int> k;
  std::vector<float> value;
};

/// What a ColumnReader over `box` holds (its index: one list of leaves per face patch, the
/// patches of the whole face, empty or not) and the voxels a pass over its columns reads (the
/// box's, since `read` gives every column whole): what its constructor checks.
[[nodiscard]] PassCost column_pass_cost(const IndexBox& box, int axis);

/// Buckets the grid's leaves and active tiles by face patch once; `read` is then thread-safe.
class ColumnReader {
 public:
  /// Throws weft::Error for an axis outside 0..2, and, naming the grid and the size, for a box
  /// whose column_pass_cost is over the budgets of check_pass_cost (pass_budget.h): a sparse grid
  /// with voxels far apart has a face of billions of patches. An empty grid has no tiles.
  ColumnReader(const Grid& grid, int axis);
  ~ColumnReader();
  ColumnReader(const ColumnReader&) = delete;
  ColumnReader& operator=(const ColumnReader&) = delete;

  [[nodiscard]] int axis() const;
  [[nodiscard]] IndexBox box() const;
  /// Number of face patches (work units).
  [[nodiscard]] std::size_t tile_count() const;
  /// Number of columns (rays of a column-centred beam) over the whole face.
  [[nodiscard]] std::uint64_t column_count() const;
  /// Fills `out` with the dense columns of patch `tile` (reusing its storage).
  void read(std::size_t tile, ColumnTile& out) const;
  /// Fills `out` with the active voxels of patch `tile` (reusing its storage), in work
  /// proportional to them. Returns false, and leaves `out` unspecified, when an active tile
  /// above leaf level (a constant 8³ block or larger) overlaps the patch: `read` handles those.
  [[nodiscard]] bool read_sparse(std::size_t tile, SparseColumnTile& out) const;
  /// Fills `out` with the active voxels of non-zero value of patch `tile` column by column, in
  /// work proportional to them; false, as read_sparse, when an active tile above leaf level
  /// overlaps the patch.
  [[nodiscard]] bool read_columns(std::size_t tile, SparseColumns& out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace weft::volume
