#pragma once
/// @file
/// @brief A handle to a sparse scalar voxel grid (OpenVDB FloatGrid behind a wall).
///
/// Public headers never include OpenVDB (docs/architecture.md §1); code that needs the tree itself includes
/// weft/volume/grid_openvdb.h from a .cpp file.

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

namespace weft::volume {

/// An inclusive box of voxel indices; empty when any min > max.
struct IndexBox {
  std::array<int, 3> min{0, 0, 0};
  std::array<int, 3> max{-1, -1, -1};
  [[nodiscard]] bool empty() const { return min[0] > max[0] || min[1] > max[1] || min[2] > max[2]; }
  [[nodiscard]] std::array<std::int64_t, 3> extent() const {
    return {std::int64_t{max[0]} - min[0] + 1, std::int64_t{max[1]} - min[1] + 1, std::int64_t{max[2]} - min[2] + 1};
  }
};

/// @brief The largest |index| a grid's voxel or a dense copy's box may have: 2³¹ − 4097.
///
/// OpenVDB's coordinates are 32-bit and its tree walks step from one node to the next by
/// origin + node size (tools::copyToDense, copyFromDense): past the origin of the outermost
/// root child, 2³¹ − 4096 (a child of the 5-4-3 tree is 4096 voxels a side), that step
/// overflows and a walk loops forever or writes out of its buffer. weft keeps every voxel out
/// of the outermost children on both sides (docs/robustness.md "Index range").
inline constexpr int kMaxIndex = 2147483647 - 4096;

/// "the index range of a grid, |index| <= 2147479551 (…why…)": what every refusal says.
[[nodiscard]] std::string index_range_text();

/// Throws weft::Error ("{what} (…)..(…) reaches beyond the index range …") when a corner of a
/// non-empty `box` has a coordinate with |index| > kMaxIndex.
void require_index_range(const IndexBox& box, const std::string& what);

/// What a grid's values mean.
enum class ValueKind {
  concentration,  ///< fibre volume fraction C ∈ [0, 1]; extinction is σ·C
  extinction,     ///< extinction coefficient μ ≥ 0 in 1/length
};

class Grid {
 public:
  struct Impl;

  /// An empty grid with cubic voxels of `voxel_size` (length units) and background 0.
  explicit Grid(double voxel_size = 1.0, const std::string& name = "density");

  /// Reads a float grid from a .vdb file: the grid named `grid_name`, or the first float grid
  /// when empty. Throws weft::Error (naming the file) when the file is missing or corrupt, the
  /// name does not exist, the grid is not a float grid, the transform is not a uniform scale
  /// (plus translation), an active value is NaN, infinite or negative, or an active voxel is
  /// beyond kMaxIndex.
  static Grid load(const std::filesystem::path& path, const std::string& grid_name = "");

  /// Writes the grid (with its metadata) to a .vdb file atomically. Throws weft::Error, writing
  /// nothing, when load would refuse the file for what the writing did (require_writable,
  /// grid_openvdb.h: a value a half file turns into ±∞) or the grid's transform or index range.
  void save(const std::filesystem::path& path) const;

  /// An independent copy: the tree, the metadata (half storage included) and the transform.
  /// Copying a Grid object shares its tree (a handle); this one does not.
  [[nodiscard]] Grid deep_copy() const;

  [[nodiscard]] std::string name() const;
  [[nodiscard]] double voxel_size() const;
  /// World position of the centre of voxel (0,0,0) minus half a voxel: index (i,j,k) covers
  /// [origin + voxel_size·i, origin + voxel_size·(i+1)) per axis.
  [[nodiscard]] std::array<double, 3> origin() const;
  /// Throws weft::Error for a non-finite origin or one so far from 0 (near 2⁵³ voxels) that
  /// OpenVDB, which recomputes the voxel size as (origin + h) − origin on every copy and write,
  /// gets 0 (grid.cpp, require_copyable_transform); Grid::load refuses such a file too.
  void set_origin(const std::array<double, 3>& origin);

  [[nodiscard]] std::uint64_t active_voxel_count() const;
  /// Bytes the tree takes in memory, as OpenVDB counts them (Tree::memUsage(): nodes, values,
  /// masks); what memory figures per active voxel are measured against.
  [[nodiscard]] std::uint64_t memory_bytes() const;
  /// Bounding box of active voxels and tiles; empty for an empty grid.
  [[nodiscard]] IndexBox active_bbox() const;
  /// Value at a voxel (background 0 where inactive). For tests and small tools; hot loops use
  /// OpenVDB accessors through grid_openvdb.h.
  [[nodiscard]] float value(int i, int j, int k) const;
  /// Throws weft::Error for an index beyond kMaxIndex (require_index_range) and, in a grid stored
  /// as half, for a value beyond kHalfMax; a grid stored as half keeps half_precision(v), what its
  /// file gives back.
  void set_value(int i, int j, int k, float v);
  /// Sum of all active values (voxels and tiles, tiles weighted by their voxel count), in double:
  /// each leaf summed on any thread, then the leaves in tree order, so the same for any thread count.
  [[nodiscard]] double sum() const;

  /// @brief Stores the grid's values as 16-bit floats from now on: every active value (voxels
  /// and tiles) is rounded to the nearest half (half_precision) and the grid is flagged so that
  /// its files hold 2 bytes a value (OpenVDB's saveFloatAsHalf; reading gives the same floats
  /// back). Rounding here, not at the write, keeps what is rendered or measured from memory and
  /// what a file gives back the same values. Throws weft::Error naming the grid when a value is
  /// beyond half's range (|v| > kHalfMax).
  void store_as_half();
  /// Whether the grid's files hold its values as 16-bit floats (store_as_half, or read so).
  [[nodiscard]] bool stored_as_half() const;
  /// Bytes a stored value takes: 2 for a grid stored as half, 4 otherwise.
  [[nodiscard]] int value_bytes() const { return stored_as_half() ? 2 : 4; }

  /// String metadata stored in the .vdb (provenance: generator parameters, units, seed).
  void set_metadata(const std::string& key, const std::string& value);
  [[nodiscard]] std::map<std::string, std::string> metadata() const;

  [[nodiscard]] const Impl& impl() const { return *impl_; }
  [[nodiscard]] Impl& impl() { return *impl_; }

 private:
  explicit Grid(std::shared_ptr<Impl> impl) : impl_(std::move(impl)) {}
  friend Grid make_grid(std::shared_ptr<Impl> impl);
  std::shared_ptr<Impl> impl_;
};

/// The smallest voxel edge OpenVDB represents: its scale map refuses h³ below 3·10⁻¹⁵
/// (math::Tolerance<double>), h ≈ 1.442·10⁻⁵ length units.
[[nodiscard]] double min_voxel_size();

/// The largest finite 16-bit IEEE half; store_as_half refuses a grid with a value beyond it.
inline constexpr float kHalfMax = 65504.0F;

/// The float nearest to `v` that a 16-bit IEEE half holds (round to nearest even; 11 significant
/// bits: a relative error ≤ 2⁻¹¹ above 6.1·10⁻⁵, an absolute one ≤ 2⁻²⁵ below). ±∞ beyond 65504.
[[nodiscard]] float half_precision(float v);

/// @brief Cached read access to one grid's voxels, for hot loops outside volume/ (Grid::value
/// walks the tree from its root on every call). One per thread; the grid must outlive it.
class VoxelReader {
 public:
  explicit VoxelReader(const Grid& grid);
  ~VoxelReader();
  VoxelReader(VoxelReader&&) noexcept;
  VoxelReader& operator=(VoxelReader&&) noexcept;
  VoxelReader(const VoxelReader&) = delete;
  VoxelReader& operator=(const VoxelReader&) = delete;

  /// Value at voxel (i, j, k): the voxel's or its tile's value, 0 where inactive.
  [[nodiscard]] float value(const std::array<int, 3>& ijk);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace weft::volume
