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
#include <memory>
#include <utility>

#include "weft/core/front_end.h"
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
  /// Who asks: a refusal says what to change in the caller's words (`--values`, `weft fit --block`
  /// on the command line; the grid's metadata, `weft.local_fields` in Python).
  FrontEnd asker = FrontEnd::cli;
};

class LocalGammaField;

/// The fields read once and checked against the grid, for every beam of a run.
struct CheckedFields {
  CheckedFields(FieldsSpec spec_, std::shared_ptr<const LocalGammaField> field_, volume::Grid mean_)
      : spec(std::move(spec_)), field(std::move(field_)), mean(std::move(mean_)) {}
  FieldsSpec spec;
  std::shared_ptr<const LocalGammaField> field;  ///< the render medium's own reading of the file
  volume::Grid mean;                             ///< its mean_concentration grid (the coarse cells)
};

/// @brief Reads the fields and checks that they are `grid`'s (docs/validate.md "Fields along any
/// direction"), before any beam is traced: the file is one the local-gamma medium reads; its value
/// kind (when it records one) is the one the grid is read as; its cells are a whole number of the
/// grid's voxels wide, on the grid's voxel corners, over the grid's active box; and every cell
/// holds the mean of the grid's voxels under it (volume::block_mean_mismatch), so fields of
/// another cloth, of this cloth moved or of a part of it are refused. Throws weft::Error naming
/// the file. One pass over the grid's active voxels.
[[nodiscard]] CheckedFields check_fields(const FieldsSpec& fields, const volume::Grid& grid);

/// What predicting a beam from the fields would cost, checked against the budgets of every pass
/// (volume/pass_budget.h) before anything is read: throws weft::Error naming the beam.
void check_fields_beam(const volume::Grid& grid, const volume::BeamSpec& spec);

/// T_fields(t) on measure_beam(grid, spec)'s depths and rays (spec.scale and method are the voxel
/// beam's and are ignored). Each ray's memory starts where it enters the fields' active box (an
/// axis beam's fields may begin upstream of the grid's box when the blocks pad it); depth t is
/// measured from the grid's box, as the voxel beam's. Every ray is a sample (distinct_rays =
/// rays). Same bytes for any thread count. Throws weft::Error for fields check_fields refuses, a
/// bad spec, or a beam over the budgets.
[[nodiscard]] volume::TransmittanceCurve predict_fields_beam(const FieldsSpec& fields, const volume::Grid& grid,
                                                             const volume::BeamSpec& spec,
                                                             ProgressSink& progress = null_progress());

/// The same for fields check_fields(…, grid) read and checked (several beams, one reading).
[[nodiscard]] volume::TransmittanceCurve predict_fields_beam(const CheckedFields& fields, const volume::Grid& grid,
                                                             const volume::BeamSpec& spec,
                                                             ProgressSink& progress = null_progress());

}  // namespace weft::render
