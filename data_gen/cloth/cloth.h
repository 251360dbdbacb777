#pragma once
/// @file
/// @brief The cloth pipeline in one call: spec → fibres → voxel grid (what `weft validate`
/// and `weft gen` run). The yarn model, patterns, importers and voxelizer have headers of
/// their own in this folder.

#include <filesystem>
#include <string>
#include <vector>

#include "weft/core/front_end.h"
#include "weft/core/progress.h"
#include "weft/volume/grid.h"
#include "weft/volume/provenance.h"

namespace weft::cloth {

struct ClothSpec;  // every generator parameter; see spec.h
struct FiberSet;   // fibres as polylines with radii and yarn/ply/fibre ids; see fibers.h

/// What voxelization measured (volume conservation, overlap), reported by gen and validate.
struct VoxelizeReport {
  double fiber_volume = 0.0;      ///< Σ length·πr² (length units³)
  double grid_volume = 0.0;       ///< Σ C·voxel volume
  double relative_error = 0.0;    ///< (grid − fibre) / fibre volume
  double overlap_fraction = 0.0;  ///< fraction of fibre volume lost to clamping at C = 1
  std::uint64_t active_voxels = 0;
  std::uint64_t fiber_count = 0;
  double generate_seconds = 0.0;
  double voxelize_seconds = 0.0;
};

/// The default cloth of `weft gen` and `weft validate`: a small plain weave that voxelizes in
/// seconds on 2 cores.
ClothSpec default_cloth_spec();
/// Reads a cloth.json written by `weft gen` (or by hand); throws weft::Error naming the file
/// and the bad field.
ClothSpec load_cloth_spec(const std::filesystem::path& path);
/// The full parameter set as JSON text (what cloth.json holds).
std::string cloth_spec_json(const ClothSpec& spec);

/// Result of the whole pipeline; FiberSet kept for writers (vtp, bcc).
struct ClothBuild;

/// How far build_cloth goes: a run computes only what its outputs need (`weft gen --write`).
/// Each stage includes the ones before it.
enum class ClothStage {
  spec,         ///< the resolved spec (cloth.json)
  centerlines,  ///< and the yarn centrelines (yarns.bcc)
  fibers,       ///< and the fibres (fibers.vtp, fibers.bcc): checked against the budget without a grid
  grid,         ///< and the voxel grid (cloth.vdb): the whole pipeline
};
/// Generates fibres and voxelizes them to a grid of volume fraction C with provenance metadata.
/// The cost is estimated from the centrelines first (estimate.h) and a build over
/// spec.max_memory_mb is refused before any fibre is made. `spread_over_ranks`: the voxelizer's
/// leaves go over the MPI ranks and only rank 0 gets the grid (VoxelizeOptions::spread; weft gen).
/// `asker`: whose words the budget errors use (`--max-memory` or `max_memory_mb=`). `upto`: the
/// last stage built (the build's later members stay empty, its report zero).
ClothBuild build_cloth(const ClothSpec& spec, ProgressSink& progress, bool spread_over_ranks = false,
                       FrontEnd asker = FrontEnd::cli, ClothStage upto = ClothStage::grid);

}  // namespace weft::cloth

// The value types the declarations above name, complete for every includer.
#include "data_gen/cloth/estimate.h"
#include "data_gen/cloth/fibers.h"
#include "data_gen/cloth/spec.h"

namespace weft::cloth {

/// @brief Everything one run of the pipeline made: the grid and the fibres it came from.
struct ClothBuild {
  volume::Grid grid;
  FiberSet fibers;
  VoxelizeReport report;
  CurveSet centerlines;    ///< yarn centrelines the fibres were generated around
  ClothSpec spec;          ///< the spec with automatic values resolved (what cloth.json records)
  ClothEstimate estimate;  ///< what the build was expected to cost (checked against the budget first)
};

/// @brief The grid's provenance (units, σ per unit concentration from the fibres, yarn
/// diameter) that build_cloth writes into the grid's metadata (weft/volume/provenance.h).
volume::Provenance cloth_provenance(const ClothBuild& build);

/// @brief Share of the fibre volume clamped at C = 1 above which a build warns (cloth_warnings).
/// Fibres are placed apart in each ply cross-section, so overlap comes only from fibres crossing
/// as they twist and migrate: every preset and pattern at voxels of 3–50 µm loses under 7 % (the
/// most, wool at 4 µm: 6.2 %; the default cloth 0.6 %). Past 10 % yarns pass through each other
/// (the default weave at a spacing of 0.1 mm, a third of its yarn diameter: 35 %) and the grid,
/// whose extinction is σ·C, holds that much less fibre than the fibres it was made from.
inline constexpr double kOverlapWarning = 0.10;

/// @brief What a build did that the user would want to know, one line each (the CLI prints them
/// as `weft: warning: …`, the Python module raises weft.Warning): a yarn whose loops are past
/// saturation (loop_coverage > 1: each fibre point under more than one loop on average, so more
/// loops change the cloth little but cost time), and a clamped overlap over kOverlapWarning.
/// Options are named in the words of `asker`.
std::vector<std::string> cloth_warnings(const ClothBuild& build, FrontEnd asker = FrontEnd::cli);

/// @brief The fibres of a spec (centrelines → yarns), yarns built in parallel and concatenated
/// in yarn order; `spec` is resolved first.
FiberSet generate_fibers(const ClothSpec& spec, const CurveSet& centerlines, ProgressSink& progress);

}  // namespace weft::cloth
