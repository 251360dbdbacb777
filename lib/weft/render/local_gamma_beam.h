#pragma once
/// @file
/// @brief A beam's transmittance predicted by local-gamma fields: the rays of a voxel beam
/// (weft/volume/lattice.h, the same lattice, offsets and entries as volume::measure_beam) walked
/// through the coarse fields under a memory rule, exactly as the render's local-gamma medium
/// walks a flight (LocalGammaField, docs/render.md §5b, §5e). T_fields(t) = mean over rays of
/// e^{−H_i(t)}, set beside the voxel beam's T_gt(t) on the same depths: the fields' law judged
/// along any direction, where `weft validate` judges it along the axes the fields were measured
/// on (docs/validate.md "Fields along any direction").

#include <filesystem>

#include "weft/core/progress.h"
#include "weft/transmittance/gamma_hazard.h"
#include "weft/volume/beam.h"
#include "weft/volume/grid.h"

namespace weft::render {

/// The fields a beam is predicted from: a `weft fit --block` file, the σ of its values (the fine
/// grid's: μ = σ·C̄) and the memory rule across its cells.
struct FieldsSpec {
  std::filesystem::path file;
  double sigma = 1.0;
  /// The values are extinctions (σ = 1), as the grid is read; refused when the file records
  /// the other kind (volume::require_value_kind).
  bool extinction = false;
  transmittance::MemoryRule memory = transmittance::kDefaultMemoryRule;
};

/// What predicting a beam from the fields would cost, checked against the budgets of every pass
/// (volume/pass_budget.h) before anything is read: throws weft::Error naming the beam.
void check_fields_beam(const volume::Grid& grid, const volume::BeamSpec& spec);

/// T_fields(t) on measure_beam(grid, spec)'s depths and rays (spec.scale and method are the voxel
/// beam's and are ignored). Each ray's memory starts where it enters the fields' active box (an
/// axis beam's fields may begin upstream of the grid's box when the blocks pad it); depth t is
/// measured from the grid's box, as the voxel beam's. Every ray is a sample (distinct_rays =
/// rays). Same bytes for any thread count. Throws weft::Error for a fields file the local-gamma
/// medium refuses, fields whose cells are not a whole number of the grid's voxels, fields that do
/// not overlap the grid, a bad spec, or a beam over the budgets.
[[nodiscard]] volume::TransmittanceCurve predict_fields_beam(const FieldsSpec& fields, const volume::Grid& grid,
                                                             const volume::BeamSpec& spec,
                                                             ProgressSink& progress = null_progress());

}  // namespace weft::render
