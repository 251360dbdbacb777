#pragma once
/// @file
/// @brief The ray lattice of a beam (docs/validate.md §Ground truth): parallel rays on a lattice
/// of square cells on the plane perpendicular to the direction, covering a world box, with the
/// cells' in-cell ray offsets (centre, or jittered from one PCG stream per cell) and the optional
/// column thinning of BeamSpec::column_stride. The voxel beam (beam.h) and the fibre beam
/// (weft/fibres/fibre_beam.h) trace the same rays from this one definition.

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "weft/core/rng.h"
#include "weft/volume/beam.h"
#include "weft/volume/grid.h"

namespace weft::volume {

/// A box in world coordinates, lo ≤ hi per axis.
struct WorldBox {
  std::array<double, 3> lo{0.0, 0.0, 0.0};
  std::array<double, 3> hi{0.0, 0.0, 0.0};
  /// hi − lo as the grid knows it (voxels × h, rounded once), when the box is a grid's: far from
  /// the origin hi − lo loses the digits the two large coordinates share, and a beam's depths and
  /// lattice would then move with the grid's index origin. 0 = take hi − lo.
  std::array<double, 3> span{0.0, 0.0, 0.0};
  [[nodiscard]] double size(int a) const {
    const auto i = static_cast<std::size_t>(a);
    return span[i] > 0.0 ? span[i] : hi[i] - lo[i];
  }
};

/// The world box of a grid's active voxels (what its beams cover); empty grids throw weft::Error.
[[nodiscard]] WorldBox active_world_box(const Grid& grid);

/// The unit vector of `d`; throws weft::Error (prefixed by `what`) for a zero or non-finite one.
/// Any finite non-zero `d` has one: it is scaled by its largest component first, so neither
/// 1e308 (whose squares overflow) nor a subnormal 1e-320 (whose squares underflow) loses it.
[[nodiscard]] std::array<double, 3> unit_direction(const std::array<double, 3>& d, const char* what);

/// The depth grid's largest number of points (400 MB of depths).
inline constexpr double kMaxBeamDepths = 50'000'000;

/// Points of beam_depth_grid(length, step), counted in double (length/step may exceed any
/// integer; a step of 1e-300 is ~1e300 points): refuses more than kMaxBeamDepths with weft::Error.
[[nodiscard]] std::size_t beam_depth_count(double length, double step);

/// Depths 0, step, 2·step, … up to and including `length` (the last one clamped to it).
[[nodiscard]] std::vector<double> beam_depth_grid(double length, double step);

/// @brief The in-cell offsets of one lattice cell's rays, drawn one ray at a time from the cell's
/// own PCG stream (stream_for(seed, i·nb + j)), so a ray does not depend on which thread traces
/// it and a cell of 2³¹ rays takes no memory for them.
class CellOffsets {
 public:
  CellOffsets(std::uint64_t seed, std::uint64_t cell, bool jitter) : rng_(stream_for(seed, cell)), jitter_(jitter) {}
  /// The next ray's offset in [0,1)²: the centre, or two uniform draws.
  std::array<double, 2> next() {
    if (!jitter_) return {0.5, 0.5};
    const double a = rng_.uniform();
    return {a, rng_.uniform()};
  }

 private:
  Pcg32 rng_;
  bool jitter_ = false;
};

struct BeamLattice {
  std::array<double, 3> d{};  ///< unit direction
  int axis = -1;              ///< beam_axis(direction): 0, 1, 2, or −1 for an oblique beam
  std::array<double, 3> e1{};
  std::array<double, 3> e2{};
  std::array<double, 3> origin{};  ///< world point of cell (0,0)'s corner (on the entry face for axis beams)
  /// The box's lower corner (world) and its size: the lattice is laid out relative to the
  /// corner, so where a ray enters and how long its chord is are computed from small numbers
  /// and do not move with where the box sits (a grid's index origin, docs/validate.md
  /// "Beams far from index 0").
  std::array<double, 3> box_lo{};
  std::array<double, 3> box_size{};
  std::array<double, 3> corner_offset{};  ///< origin − box_lo, computed without box_lo
  std::int64_t na = 0;                    ///< cells along e1
  std::int64_t nb = 0;                    ///< cells along e2
  int per_cell = 1;
  bool jitter = false;
  std::uint64_t seed = 1;
  std::int64_t stride = 1;      ///< BeamSpec::column_stride
  bool full_chords = false;     ///< BeamSpec::full_chords
  double h = 1.0;               ///< cell width
  double depth_length = 0.0;    ///< the depth grid's end: the box's depth (axis) or shortest chord (oblique)
  double depth_step = 1.0;      ///< its spacing
  std::size_t depth_count = 0;  ///< beam_depth_count(depth_length, depth_step): depths.size() once filled
  std::vector<double> depths;   ///< empty from make_beam_lattice(..., false)

  /// The origin of the ray at offset (ja, jb) ∈ [0,1)² in cell (i, j), relative to box_lo.
  [[nodiscard]] std::array<double, 3> ray_offset(std::int64_t i, std::int64_t j, double ja, double jb) const;
  /// The same origin in world coordinates (box_lo + ray_offset).
  [[nodiscard]] std::array<double, 3> ray_origin(std::int64_t i, std::int64_t j, double ja, double jb) const;
  /// The most cells of width h one ray crosses in the box: its chord's length·(|dx| + |dy| +
  /// |dz|)/h, plus its two ends and one for rounding (the work of a ray beyond its depths).
  [[nodiscard]] double cells_crossed() const {
    return depth_length * (std::abs(d[0]) + std::abs(d[1]) + std::abs(d[2])) / h + 3.0;
  }
  /// Whether cell (i, j) is one of the kept cells of a thinned beam (always true for stride 1).
  [[nodiscard]] bool keeps(std::int64_t i, std::int64_t j) const;
  /// The in-cell offsets of the per_cell rays of cell (i, j), one at a time (CellOffsets).
  [[nodiscard]] CellOffsets offsets(std::int64_t i, std::int64_t j) const;
  /// Calls ray(offset, i, j, r), offset = ray_offset(...), for every kept ray of the cell rows [row_begin, row_end), in
  /// the beam's fixed order with each cell's own offsets, and row_done() after each row: the walk a shard of a beam
  /// makes whatever it traces the rays through.
  template <typename RayFn, typename RowFn>
  void for_each_ray(std::size_t row_begin, std::size_t row_end, RayFn&& ray, RowFn&& row_done) const {
    for (std::size_t row = row_begin; row < row_end; ++row) {
      const auto i = static_cast<std::int64_t>(row);
      for (std::int64_t j = 0; j < nb; ++j) {
        if (!keeps(i, j)) continue;
        CellOffsets cell = offsets(i, j);
        for (int r = 0; r < per_cell; ++r) {
          const std::array<double, 2> off = cell.next();
          ray(ray_offset(i, j, off[0], off[1]), i, j, r);
        }
      }
      row_done();
    }
  }
  /// Where the ray from `offset` (relative to box_lo) enters and leaves the box [0, box_size]:
  /// world distances along d, in the box's own coordinates (the same numbers wherever the box
  /// sits); `hit` false when it misses.
  struct Chord {
    bool hit = false;
    double t_enter = 0.0;
    double t_exit = 0.0;
  };
  [[nodiscard]] Chord chord(const std::array<double, 3>& offset) const;
  /// Whether a ray whose chord through the box is `c` is traced: whenever it enters the box,
  /// unless full_chords asks for chords as long as the depth grid (to kChordTolerance).
  [[nodiscard]] bool traces_chord(const Chord& c) const {
    return c.hit && (!full_chords || c.t_exit - c.t_enter >= depth_length * (1.0 - kChordTolerance));
  }
  /// The relative shortfall a full chord may have: rounding of the chord's two ends.
  static constexpr double kChordTolerance = 1e-9;
  /// The area, on the plane ⊥ d, of the rays whose chord is the whole depth (those entering and
  /// leaving through the two faces that set depth_length); the whole projection for axis beams.
  double full_chord_area = 0.0;
  /// Why full_chords would keep no ray of this lattice (empty when it keeps some): the rays with
  /// full chords cover no area (two faces tie, as across a square face at exactly 45°), or
  /// fewer than one lattice ray's share of it. Phrased for "<beam> with full chords: …".
  [[nodiscard]] std::string full_chord_problem() const;
  /// After tracing `rays` rays of a full_chords beam named `what`: throws weft::Error when none
  /// had a full chord (the lattice missed a small area), naming full chords, not a ray missing
  /// the box.
  void require_full_chord_rays(std::uint64_t rays, const std::string& what) const;
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
/// Without `with_depths` the depth grid is only counted (depth_count), for estimates made
/// before anything is allocated.
/// Throws weft::Error, before anything is allocated, when spec.full_chords would keep no ray
/// (full_chord_problem).
[[nodiscard]] BeamLattice make_beam_lattice(const WorldBox& box, double h, const BeamSpec& spec,
                                            bool with_depths = true);

/// BeamLattice::full_chord_problem of the lattice of `spec` over `box` (empty when spec.full_chords
/// is off or keeps rays), for the front ends' checks in their own words (beam_checks.h).
[[nodiscard]] std::string full_chord_problem(const WorldBox& box, double h, const BeamSpec& spec);

}  // namespace weft::volume
