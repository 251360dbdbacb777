#pragma once
/// @file
/// @brief The ray lattice of a beam (docs/validate.md §Ground truth): parallel rays on a lattice
/// of square cells on the plane perpendicular to the direction, covering a world box, with the
/// cells' in-cell ray offsets (centre, or jittered from one PCG stream per cell) and the optional
/// column thinning of BeamSpec::column_stride. The voxel beam (beam.h) and the fibre beam
/// (weft/fibres/fibre_beam.h) trace the same rays from this one definition.

#include <array>
#include <cstdint>
#include <vector>

#include "weft/volume/beam.h"
#include "weft/volume/grid.h"

namespace weft::volume {

/// A box in world coordinates, lo ≤ hi per axis.
struct WorldBox {
  std::array<double, 3> lo{0.0, 0.0, 0.0};
  std::array<double, 3> hi{0.0, 0.0, 0.0};
};

/// The world box of a grid's active voxels (what its beams cover); empty grids throw weft::Error.
[[nodiscard]] WorldBox active_world_box(const Grid& grid);

/// The unit vector of `d`; throws weft::Error (prefixed by `what`) for a zero or non-finite one.
[[nodiscard]] std::array<double, 3> unit_direction(const std::array<double, 3>& d, const char* what);

/// Depths 0, step, 2·step, … up to and including `length` (the last one clamped to it).
[[nodiscard]] std::vector<double> beam_depth_grid(double length, double step);

struct BeamLattice {
  std::array<double, 3> d{};  ///< unit direction
  int axis = -1;              ///< beam_axis(direction): 0, 1, 2, or −1 for an oblique beam
  std::array<double, 3> e1{};
  std::array<double, 3> e2{};
  std::array<double, 3> origin{};  ///< world point of cell (0,0)'s corner (on the entry face for axis beams)
  std::int64_t na = 0;             ///< cells along e1
  std::int64_t nb = 0;             ///< cells along e2
  int per_cell = 1;
  bool jitter = false;
  std::uint64_t seed = 1;
  std::int64_t stride = 1;  ///< BeamSpec::column_stride
  double h = 1.0;           ///< cell width
  std::vector<double> depths;

  /// The origin of the ray at offset (ja, jb) ∈ [0,1)² in cell (i, j).
  [[nodiscard]] std::array<double, 3> ray_origin(std::int64_t i, std::int64_t j, double ja, double jb) const;
  /// Whether cell (i, j) is one of the kept cells of a thinned beam (always true for stride 1).
  [[nodiscard]] bool keeps(std::int64_t i, std::int64_t j) const;
  /// The in-cell offsets of the per_cell rays of cell (i, j): the centre, or jittered from
  /// the cell's own PCG stream (stream_for(seed, i·nb + j)), so a ray does not depend on which
  /// thread traces it.
  void offsets(std::int64_t i, std::int64_t j, std::vector<std::array<double, 2>>& out) const;
  /// The index of the cell (i, j)'s ray r in the beam's fixed ray order.
  [[nodiscard]] std::uint64_t ray_index(std::int64_t i, std::int64_t j, int r) const {
    return (static_cast<std::uint64_t>(i) * static_cast<std::uint64_t>(nb) + static_cast<std::uint64_t>(j)) *
               static_cast<std::uint64_t>(per_cell) +
           static_cast<std::uint64_t>(r);
  }
};

/// The lattice of `spec`'s beam over `box` with cells of width `h` (a grid's voxel size):
/// axis beams start on the box's entry face, with one cell per voxel column when the box is a
/// whole number of cells; oblique beams start one cell upstream of the box's projection.
[[nodiscard]] BeamLattice make_beam_lattice(const WorldBox& box, double h, const BeamSpec& spec);

}  // namespace weft::volume
