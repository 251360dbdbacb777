#pragma once
/// @file
/// @brief Local statistic fields per block of voxels, and what they will cost, known before they
/// are computed: `weft fit --block` checks its block size and refuses an estimate over the budget
/// before it spends anything.

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "weft/core/progress.h"
#include "weft/volume/grid.h"

namespace weft::fit {

/// Largest block edge local_fields accepts (voxels): the edge of OpenVDB's root tiles, and small
/// enough that block index × edge stays inside int coordinates.
inline constexpr int kMaxLocalBlock = 4096;

/// Throws weft::Error naming the block size unless 1 ≤ block ≤ kMaxLocalBlock.
void check_local_block(int block);

/// @brief A block (a coarsening factor) that holds the grid's whole active box: its one coarse
/// voxel would spread the cloth's concentration over the block's vacuum, a homogeneous box larger
/// than the cloth (docs/validate.md "Local fields"). `text` says so ("one coarse voxel of N voxels
/// (side S) holds the whole active box of grid 'G' (AxBxC voxels)") and `below` is the largest
/// extent, the bound a block must stay under. The one rule of `weft fit --block`, Python's
/// local_fields and the study's factors (study::check_factors_for_grid).
struct WholeBoxBlock {
  std::string text;
  std::int64_t below = 0;
};
[[nodiscard]] std::optional<WholeBoxBlock> whole_box_block(int block, const volume::Grid& grid);

/// @brief "" or a warning that blocks of `block` voxels are thicker than the cloth along an axis
/// (the active box's extent there): an edge block spreads the cloth over the block there, at a
/// fraction extent/block of its density, and the fields reach past the cloth.
[[nodiscard]] std::string thick_block_note(int block, const volume::Grid& grid);

/// @brief Upper bounds of the work and memory of local_fields(grid, block), from the leaf nodes
/// alone (O(leaves), nothing allocated per voxel or per block).
///
/// The fields are computed block by block from the grid's own leaves: a block's columns are
/// accumulated densely only for blocks of at most 64³ voxels and in a hash map of its non-empty
/// columns otherwise, so memory grows with the grid's active voxels and the number of blocks,
/// never with B³ (before: a dense B³ copy per block and thread, 8 GB per thread at B = 1000).
struct LocalFieldsEstimate {
  std::uint64_t leaf_entries = 0;  ///< (block, leaf or tile) pairs the blocks are built from
  std::uint64_t blocks = 0;        ///< upper bound of the blocks with data
  std::uint64_t bytes = 0;         ///< upper bound of the peak memory beyond the input grid
};
[[nodiscard]] LocalFieldsEstimate estimate_local_fields(const volume::Grid& grid, int block);

/// Local statistic fields: per block of B³ voxels (anchored to the cloth, at the active box's
/// lower corner: volume/block_lattice.h; the grids' index 0 and origin are that corner's),
/// the block mean C̄ and, per axis, the variance of the B² column means across the block and
/// the (α, β) they give. Blocks without any concentration are left inactive. α = β = +∞ mark
/// blocks with zero variance (exponential).
struct LocalFields {
  int block = 8;
  volume::Grid mean;  ///< "mean_concentration"
  /// "var_concentration_{x,y,z}", stored as half floats when every variance fits half's range
  /// (Grid::store_as_half: 11 significant bits, far below a block variance's own sampling error;
  /// always for concentrations in [0, 1]), as floats otherwise; α and β are those of the stored
  /// values.
  std::array<volume::Grid, 3> variance;
  std::array<volume::Grid, 3> alpha;  ///< "alpha_{x,y,z}"
  std::array<volume::Grid, 3> beta;   ///< "beta_{x,y,z}"
  std::uint64_t blocks = 0;
};
[[nodiscard]] LocalFields local_fields(const volume::Grid& grid, int block, ProgressSink& progress = null_progress());
/// Which grids of LocalFields a file holds (docs/render.md §5b).
enum class FieldChannels {
  /// What the local-gamma medium reads, and all it needs: mean_concentration and
  /// var_concentration_{x,y,z}, 4 channels (α, β follow from them per voxel).
  render,
  /// Those and alpha_{x,y,z}, beta_{x,y,z}: 10 channels, for analysis (α = β = +∞ on
  /// exponential blocks).
  all,
};
/// "render", "all".
[[nodiscard]] std::string_view field_channels_name(FieldChannels channels);
/// The channels of a name above, or nothing.
[[nodiscard]] std::optional<FieldChannels> parse_field_channels(std::string_view name);

/// Writes the grids of `fields` that `channels` names into one .vdb file, atomically.
void save_local_fields(const LocalFields& fields, const std::filesystem::path& path, FieldChannels channels);

}  // namespace weft::fit
