#include "data_gen/cloth/grid_fibres.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "data_gen/cloth/cloth.h"
#include "data_gen/cloth/pattern.h"
#include "weft/core/error.h"
#include "weft/core/parse_number.h"

namespace weft::cloth {

fibres::FibreSet fibre_geometry(const FiberSet& fibers) {
  fibres::FibreSet g;
  g.points = fibers.points;
  g.offsets = fibers.offsets;
  g.radius = fibers.radius;
  return g;
}

bool grid_names_its_fibres(const volume::Grid& grid) { return grid.metadata().count("generator") != 0; }

namespace {

using json = nlohmann::json;

std::string corners(const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
  return fmt::format("({:.6g}, {:.6g}, {:.6g})..({:.6g}, {:.6g}, {:.6g})", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
}

}  // namespace

void record_voxelized_lattice(volume::Grid& grid) {
  const volume::IndexBox box = grid.active_bbox();
  if (box.empty()) return;
  const json lattice = {{"voxel_size", grid.voxel_size()},
                        {"origin", grid.origin()},
                        {"active_index_min", box.min},
                        {"active_index_max", box.max}};
  grid.set_metadata(kVoxelizedLatticeKey, lattice.dump());
}

namespace {

// One index of the record: nlohmann's get<int> would truncate 2^40 to its low bits and -6.5 to
// -6, and a lattice read so is compared as if weft gen had written it.
int lattice_index(const json& v, const std::string& what, const std::string& text) {
  const bool in_range = v.is_number_unsigned() ? v.get<std::uint64_t>() <= static_cast<std::uint64_t>(volume::kMaxIndex)
                        : v.is_number_integer() ? std::abs(v.get<std::int64_t>()) <= volume::kMaxIndex
                                                : false;
  if (!in_range)
    fail("{}: metadata '{}' is not a lattice: index {} is not an integer with |index| <= {}: {}", what,
         kVoxelizedLatticeKey, v.dump(), volume::kMaxIndex, text);
  return static_cast<int>(v.get<std::int64_t>());
}

std::array<int, 3> lattice_indices(const json& v, const std::string& what, const std::string& text) {
  if (!v.is_array() || v.size() != 3)
    fail("{}: metadata '{}' is not a lattice: {} is not 3 indices: {}", what, kVoxelizedLatticeKey, v.dump(), text);
  return {lattice_index(v[0], what, text), lattice_index(v[1], what, text), lattice_index(v[2], what, text)};
}

}  // namespace

VoxelizedLattice read_voxelized_lattice(const volume::Grid& grid, const std::string& what) {
  const auto meta = grid.metadata();
  const auto it = meta.find(kVoxelizedLatticeKey);
  if (it == meta.end())
    fail(
        "{}: the grid does not record the lattice its fibres were voxelized on (metadata '{}'; an earlier weft gen "
        "did not write it), so its placement cannot be checked against them: generate it again with weft gen "
        "--config (its 'generator' metadata is that cloth.json)",
        what, kVoxelizedLatticeKey);
  VoxelizedLattice lattice;
  try {
    const json j = json::parse(it->second);
    lattice.voxel_size = j.at("voxel_size").get<double>();
    lattice.origin = j.at("origin").get<std::array<double, 3>>();
    lattice.active.min = lattice_indices(j.at("active_index_min"), what, it->second);
    lattice.active.max = lattice_indices(j.at("active_index_max"), what, it->second);
  } catch (const json::exception& e) {
    fail("{}: metadata '{}' is not a lattice: {}", what, kVoxelizedLatticeKey, e.what());
  }
  const auto& o = lattice.origin;
  if (!(lattice.voxel_size > 0.0) || !std::isfinite(lattice.voxel_size) || lattice.active.empty() ||
      !std::isfinite(o[0]) || !std::isfinite(o[1]) || !std::isfinite(o[2]))
    fail("{}: metadata '{}' is not a lattice: {}", what, kVoxelizedLatticeKey, it->second);
  return lattice;
}

void check_voxelized_lattice(const volume::Grid& grid, const std::string& what) {
  check_on_lattice(grid, read_voxelized_lattice(grid, what), what);
}

void check_on_lattice(const volume::Grid& grid, const VoxelizedLattice& lattice, const std::string& what) {
  const double h0 = lattice.voxel_size;
  const std::array<double, 3>& origin0 = lattice.origin;
  const volume::IndexBox& box0 = lattice.active;
  const double h = grid.voxel_size();
  const volume::IndexBox box = grid.active_bbox();
  if (box.empty()) fail("{}: the grid has no active voxels to compare with its fibres", what);
  const auto origin = grid.origin();
  std::array<double, 3> lo{}, hi{}, lo0{}, hi0{}, moved_lo{}, moved_hi{};
  bool moved = false;
  for (std::size_t a = 0; a < 3; ++a) {
    lo[a] = origin[a] + h * box.min[a];
    hi[a] = origin[a] + h * (box.max[a] + 1.0);
    lo0[a] = origin0[a] + h0 * box0.min[a];
    hi0[a] = origin0[a] + h0 * (box0.max[a] + 1.0);
    // Rounding only: of h·index and of the origin OpenVDB keeps as the centre of voxel 0.
    const double big = std::max({std::abs(lo[a]), std::abs(hi[a]), std::abs(lo0[a]), std::abs(hi0[a])});
    const double tol = 1e-6 * h0 + 8.0 * std::numeric_limits<double>::epsilon() * big;
    moved_lo[a] = (lo[a] - lo0[a]) / h0;
    moved_hi[a] = (hi[a] - hi0[a]) / h0;
    moved = moved || std::abs(lo[a] - lo0[a]) > tol || std::abs(hi[a] - hi0[a]) > tol;
  }
  const std::string placement = fmt::format(
      "its active voxels span {} (origin ({:.6g}, {:.6g}, {:.6g}), index box ({}, {}, {})..({}, {}, {})) where "
      "weft gen voxelized its fibres on {} (origin ({:.6g}, {:.6g}, {:.6g}), index box ({}, {}, {})..({}, {}, {}))",
      corners(lo, hi), origin[0], origin[1], origin[2], box.min[0], box.min[1], box.min[2], box.max[0], box.max[1],
      box.max[2], corners(lo0, hi0), origin0[0], origin0[1], origin0[2], box0.min[0], box0.min[1], box0.min[2],
      box0.max[0], box0.max[1], box0.max[2]);
  if (std::abs(h - h0) > 1e-9 * h0)
    fail(
        "{}: the grid was resampled relative to its fibres: voxels of {:.9g} against the {:.9g} they were voxelized "
        "on; {}; the fibres are compared only with the grid on their lattice",
        what, h, h0, placement);
  if (moved)
    fail(
        "{}: the grid was moved relative to its fibres: its active box's low corner by ({:+.6g}, {:+.6g}, {:+.6g}) "
        "voxels and its high corner by ({:+.6g}, {:+.6g}, {:+.6g}); {}; the fibres are compared only with the grid on "
        "their lattice",
        what, moved_lo[0], moved_lo[1], moved_lo[2], moved_hi[0], moved_hi[1], moved_hi[2], placement);
}

FiberSet fibers_of_grid(const volume::Grid& grid, const std::string& what, ProgressSink& progress) {
  const auto meta = grid.metadata();
  const auto it = meta.find("generator");
  if (it == meta.end())
    fail("{}: the grid does not name its fibres (no cloth spec in its metadata: not written by weft gen)", what);
  // The lattice first (cheap): a grid moved after weft gen keeps its provenance, and its fibres
  // would then be compared with voxels that are not theirs (T_fibre of other rays, silently).
  check_voxelized_lattice(grid, what);
  const ClothSpec spec = resolve(cloth_spec_from_json(it->second, what + " (metadata 'generator')"));
  FiberSet fibers = generate_fibers(spec, cloth_centerlines(spec), progress);
  // The regenerated fibres must be the voxelized ones: same volume as recorded at generation.
  const auto v = meta.find("fiber_volume_mm3");
  if (v != meta.end()) {
    const std::optional<double> recorded = parse_number(v->second);
    const double now = fibers.volume();
    if (!recorded || std::abs(now - *recorded) > 1e-9 * std::abs(*recorded))
      fail("{}: the fibres regenerated from its cloth spec ({} mm^3) are not the ones voxelized ({} mm^3)", what, now,
           v->second);
  }
  return fibers;
}

}  // namespace weft::cloth
