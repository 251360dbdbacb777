#include "weft/render/local_gamma_beam.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include <fmt/format.h>

#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/render/local_gamma.h"
#include "weft/volume/curve_sums.h"
#include "weft/volume/dda.h"
#include "weft/volume/downsample.h"
#include "weft/volume/lattice.h"
#include "weft/volume/pass_budget.h"
#include "weft/volume/provenance.h"

namespace weft::render {
namespace {

constexpr std::size_t kShards = 64;  // fixed, so the sums do not depend on the thread count

/// Whether `length` is a whole number of voxels of width h (to rounding).
bool whole_voxels(double length, double h) {
  const double q = length / h;
  return std::abs(q - std::round(q)) <= 1e-6 * std::max(1.0, std::abs(q));
}

/// What the caller runs to make the fields of this grid, in its own words.
std::string make_them(FrontEnd asker) {
  return asker == FrontEnd::cli ? "make them from this grid (weft fit --grid GRID --block B)"
                                : "make them from this grid (weft.local_fields(grid, B).save(path))";
}

/// Fields record the value kind of the grid they were made from (its weft: metadata, carried on):
/// a kind other than the one the grid is read as is another grid's, or the grid read wrongly.
/// Each advice is something the caller can change in its own interface: Python has no --values,
/// it reads the grid's recorded kind (concentration when none).
void check_fields_kind(const volume::Grid& mean, const volume::Grid& grid, const FieldsSpec& fields,
                       const std::string& what) {
  const std::string kind = volume::read_provenance(mean).value_kind;
  if (kind != "concentration" && kind != "extinction") return;
  const std::string read_as = fields.extinction ? "extinction" : "concentration";
  if (kind == read_as) return;
  const std::string grid_kind = volume::read_provenance(grid).value_kind;
  if (grid_kind == "concentration" || grid_kind == "extinction")
    fail("{}: its metadata says its values are {}, grid '{}''s say {}: fields of another grid; {}", what, kind,
         grid.name(), grid_kind, make_them(fields.asker));
  fail("{}: its metadata says its values are {}, and grid '{}' (no kind recorded) is read as {}: {}, or {}", what, kind,
       grid.name(), read_as,
       fields.asker == FrontEnd::cli
           ? fmt::format("pass --values {} if the grid's values are {}", kind, kind)
           : fmt::format("record the grid's kind with grid.set_metadata('weft:value_kind', '{}') if its values are {}",
                         kind, kind),
       make_them(fields.asker));
}

/// The fields must be the grid's blocks: cells a whole number of voxels wide, their corners on the
/// grid's voxel corners, over the grid's active box, each holding the mean of the voxels under it.
void check_fields_on_grid(const volume::Grid& fields, const volume::Grid& grid, const std::string& what,
                          FrontEnd asker) {
  const double h = grid.voxel_size();
  if (fields.voxel_size() < h * (1.0 - 1e-6) || !whole_voxels(fields.voxel_size(), h))
    fail("{}: its cells ({:.6g}) are not a whole number of grid '{}''s voxels ({:.6g})", what, fields.voxel_size(),
         grid.name(), h);
  const auto of = fields.origin();
  const auto og = grid.origin();
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    if (!whole_voxels(of[i] - og[i], h))
      fail("{}: its cells are not on grid '{}''s voxel corners (origin {:.9g} against {:.9g} along {})", what,
           grid.name(), of[i], og[i], "xyz"[a]);
  }
  const volume::WorldBox f = volume::active_world_box(fields);
  const volume::WorldBox g = volume::active_world_box(grid);
  for (std::size_t a = 0; a < 3; ++a) {
    if (f.hi[a] <= g.lo[a] || g.hi[a] <= f.lo[a])
      fail("{}: its active cells do not overlap grid '{}'", what, grid.name());
  }
  // A cell whose mean is not the grid's voxels' mean there: another cloth, this one moved, or a
  // part of it (a cell missing over the grid's active box holds 0 against the voxels' mean).
  if (const auto m = volume::block_mean_mismatch(fields, grid)) {
    const auto factor = std::lround(fields.voxel_size() / h);
    fail(
        "{}: not grid '{}''s fields: its cell at ({:.6g}, {:.6g}, {:.6g}) holds a mean of {:.6g}, the grid's {}^3 "
        "voxels there average {:.6g}; {}",
        what, grid.name(), m->centre[0], m->centre[1], m->centre[2], m->coarse, factor, m->fine_mean, make_them(asker));
  }
}

volume::BeamLattice plan_of(const volume::Grid& grid, const volume::BeamSpec& spec, bool with_depths) {
  return volume::make_beam_lattice(volume::active_world_box(grid), grid.voxel_size(), spec, with_depths);
}

}  // namespace

void check_fields_beam(const volume::Grid& grid, const volume::BeamSpec& spec) {
  if (spec.rays_per_column < 1) fail("fields beam: rays per column must be >= 1, got {}", spec.rays_per_column);
  if (spec.column_stride < 1 || spec.column_stride > 4096)
    fail("fields beam: column stride must be in 1..4096, got {}", spec.column_stride);
  if (spec.depth_step != 0.0) require_positive("fields beam: depth step", spec.depth_step);
  const volume::BeamLattice plan = plan_of(grid, spec, false);
  const auto s = static_cast<double>(plan.stride);
  const double rays = std::ceil(static_cast<double>(plan.na) / s) * std::ceil(static_cast<double>(plan.nb) / s) *
                      static_cast<double>(plan.per_cell);
  const auto K = static_cast<double>(plan.depth_count);
  // A ray walks at most the fine box's cells (the coarse cells are fewer) and fills its depths;
  // the shards' two sums and every thread's profile and ends are the memory.
  const double workers = std::min<double>(kShards, thread_count());
  volume::check_pass_cost(fmt::format("fields beam {} ({:.4g} rays)", volume::direction_label(plan.d), rays), grid,
                          {rays * (plan.cells_crossed() + K),
                           (2.0 * static_cast<double>(kShards) + 4.0 + 2.0 * workers) * K * sizeof(double)});
}

CheckedFields check_fields(const FieldsSpec& fields, const volume::Grid& grid) {
  const std::string what = fmt::format("local-gamma fields '{}'", fields.file.string());
  // The medium's own reading and checks (one-line errors naming the file), then its cells
  // against the grid's voxels.
  // A file that is not fields (a cloth grid given for them, a file cut short) is refused with how
  // to make the fields.
  auto field = [&] {
    try {
      return std::make_shared<const LocalGammaField>(fields.file, fields.sigma, fields.memory);
    } catch (const Error& e) {
      fail("{}; {}", e.what(), make_them(fields.asker));
    }
  }();
  volume::Grid mean = [&] {
    try {
      return volume::Grid::load(fields.file, "mean_concentration");
    } catch (const Error& e) {
      fail("{}: {}", what, e.what());
    }
  }();
  check_fields_kind(mean, grid, fields, what);
  check_fields_on_grid(mean, grid, what, fields.asker);
  return {fields, std::move(field), std::move(mean)};
}

volume::TransmittanceCurve predict_fields_beam(const FieldsSpec& fields, const volume::Grid& grid,
                                               const volume::BeamSpec& spec, ProgressSink& progress) {
  check_fields_beam(grid, spec);
  return predict_fields_beam(check_fields(fields, grid), grid, spec, progress);
}

volume::TransmittanceCurve predict_fields_beam(const CheckedFields& checked, const volume::Grid& grid,
                                               const volume::BeamSpec& spec, ProgressSink& progress) {
  check_fields_beam(grid, spec);
  const FieldsSpec& fields = checked.spec;
  const LocalGammaField& field = *checked.field;
  const volume::Grid& mean = checked.mean;
  const volume::BeamLattice L = plan_of(grid, spec, true);
  const std::size_t K = L.depths.size();
  const auto units = static_cast<std::size_t>(L.na);
  const std::size_t shards = std::min(kShards, units);
  std::vector<volume::CurveSums> parts(shards, volume::CurveSums(K));
  // Counted in rays, every cell's per_cell rays kept or not, as the voxel beam's per-ray walk.
  const auto row_rays = static_cast<std::uint64_t>(L.nb) * static_cast<std::uint64_t>(L.per_cell);
  ProgressTask task(progress, "fields beam " + volume::direction_label(L.d) + " [local-gamma fields]", units * row_rays,
                    "rays");
  constexpr double kInf = std::numeric_limits<double>::infinity();
  parallel_units(shards, [&](std::size_t shard) {
    volume::CurveSums& sum = parts[shard];
    const std::unique_ptr<LocalGammaField> walker = field.clone();
    const volume::Tracer coarse(mean);
    std::vector<double> log_t(K);
    const std::size_t begin = shard * units / shards;
    const std::size_t end = (shard + 1) * units / shards;
    L.for_each_ray(
        begin, end,
        [&](std::array<double, 3> offset, std::int64_t, std::int64_t, int) {
          // The voxel beam's entry (trace_rays): an oblique ray starts where it enters the
          // grid's active box, an axis ray on the box's entry face; both in the box's frame.
          if (L.axis < 0) {
            const volume::BeamLattice::Chord c = L.chord(offset);
            if (!L.traces_chord(c)) return;
            for (int a = 0; a < 3; ++a) offset[a] += c.t_enter * L.d[a];
          }
          volume::Ray ray{{}, L.d};
          for (int a = 0; a < 3; ++a) ray.origin[a] = L.box_lo[a] + offset[a];
          // The memory starts at the medium's boundary, where a flight through it would start.
          const volume::BoxHit in = coarse.intersect_active_box(ray, -kInf);
          const double t0 = in.hit ? std::min(in.t_enter, 0.0) : 0.0;
          walker->log_transmittance_profile(ray, t0, L.depths, log_t);
          sum.add_log(log_t);
        },
        [&] { task.step(row_rays); });
  });
  std::uint64_t traced = 0;
  for (const volume::CurveSums& p : parts) traced += p.n;
  L.require_full_chord_rays(traced, "fields beam " + volume::direction_label(L.d));
  return volume::curve_of_sums(
      parts, L.depths, L.d,
      fmt::format("local-gamma fields ({} memory)", transmittance::memory_rule_name(fields.memory)),
      fmt::format("fields beam {} through grid '{}'", volume::direction_label(L.d), grid.name()));
}

}  // namespace weft::render
