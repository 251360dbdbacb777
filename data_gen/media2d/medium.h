#pragma once
/// @file
/// @brief Explicit 2D media of equal disks on the periodic unit square (supplement S.11.1).
///
/// Three generators, selected by the degree of correlation η:
///  - η ∈ [−1, 0): a sheared hexagonal lattice (a Lorentz gas whose rows rise by one shadow width
///    per column, so that along +x no particle hides behind its row neighbour), each site perturbed
///    with probability 1 − |η| by ω s, s = −log(ξ)(1 − |η|)² ℓ_step;
///  - η = 0: uniform (Poisson) positions;
///  - η ∈ (0, 1): random-walk clusters of `cluster_size` particles, x_i = x_{i−1} + ω s,
///    s = −log(ξ)(1 − η)² ℓ_step (Shaw et al. 2002; Larsen and Clark 2014).
/// ℓ_step is the mean inter-particle distance 1/√n unless set (the supplement gives no unit).
/// The particle count n follows from a target mean free path λ by the Santaló/Cauchy relation
/// λ = (1 − nπr²)/(2nr) (see docs/sim2d.md).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "weft/core/rng.h"

namespace weft::media2d {

/// @brief A point of the plane (the unit square's coordinates; positions are kept in [0, 1)).
struct Point2 {
  double x = 0.0;
  double y = 0.0;
};

/// @brief Largest packing fraction nπr² accepted: beyond it more than ~4 % of Poisson-placed disks
/// would overlap a neighbour (1 − exp(−4nπr²)), and the disks stop being "small scatterers".
inline constexpr double kMaxPackingFraction = 0.01;

/// @brief What to generate.
struct MediumSpec {
  double eta = 0.0;                 ///< degree of correlation, [−1, 1)
  double radius = 1e-5;             ///< disk radius r, unit-square units, > 0
  double mean_free_path = 0.025;    ///< target Santaló mean free path λ, unit-square units, > 0
  std::size_t cluster_size = 1000;  ///< particles per random-walk cluster (η > 0)
  double step_unit = 0.0;           ///< ℓ_step; 0 = mean inter-particle distance 1/√n
};

/// @brief The hexagonal lattice of the negatively correlated generator (η < 0).
///
/// Site (i, j), i < nx, j < ny (ny even), h = (j mod 2)/2: x = (i + h)/nx, y = j/ny + (i + h)·rise
/// (mod 1): a Bravais lattice with basis (1/nx, rise), (1/(2nx), 1/ny + rise/2).
/// `rise` = k/n with k the smallest even integer ≥ 2rn, so consecutive sites of a row are at least
/// one shadow width 2r apart across +x, and row j continues seamlessly into row j + k at x = 1.
struct LatticeLayout {
  std::size_t nx = 0;
  std::size_t ny = 0;
  std::size_t rise_steps = 0;  ///< k
  double rise = 0.0;           ///< k/n
  [[nodiscard]] std::size_t count() const { return nx * ny; }
};

/// @brief One realization: disk centres in [0, 1)² and the common radius.
struct Medium {
  double radius = 0.0;
  std::vector<Point2> centers;
  std::string generator;         ///< "lattice", "poisson" or "random-walk"
  double step_unit = 0.0;        ///< ℓ_step used for perturbations / walk steps
  std::size_t cluster_size = 0;  ///< walk length per cluster (random-walk only)
  /// Number of lattice sites that were perturbed (lattice only).
  std::size_t perturbed = 0;
};

/// @brief Checks η, r, λ, cluster size, packing and lattice spacing; throws weft::Error naming the
/// problem.
void validate(const MediumSpec& spec);

/// @brief n = 1/(2rλ + πr²), the solution of λ = (1 − nπr²)/(2nr) for n, rounded.
[[nodiscard]] std::size_t particle_count(double radius, double mean_free_path);

/// @brief λ = (1 − nπr²)/(2nr): Santaló's mean chord of the void between n disks of radius r in a
/// unit area (Cauchy: π·area/perimeter), the mean free path from a source.
[[nodiscard]] double santalo_mean_free_path(std::size_t count, double radius);

/// @brief The lattice a negatively correlated medium of this spec starts from.
[[nodiscard]] LatticeLayout lattice_layout(const MediumSpec& spec);

/// @brief The unperturbed sites of `layout`, in row-major order (j outer, i inner).
[[nodiscard]] std::vector<Point2> lattice_sites(const LatticeLayout& layout);

/// @brief The number of particles `generate` will produce for this spec.
[[nodiscard]] std::size_t planned_count(const MediumSpec& spec);

/// @brief The longest step unit a medium of disks of `radius` takes: a step is added to a position
/// in [0, 1) and wrapped, which rounds the position by the step's last bit; kept under a thousandth
/// of the radius (r = 1e−5: 2.25e6). Past the square's side 1 a step already spreads the
/// particles uniformly, so nothing physical is lost (a step unit of 1e20 collapsed the medium
/// onto a few points).
[[nodiscard]] double max_step_unit(double radius);

/// @brief ℓ_step for this spec: spec.step_unit, or 1/√n when 0.
[[nodiscard]] double step_unit(const MediumSpec& spec);

/// @brief Generates one realization from `rng` (validate(spec) first; this checks again).
[[nodiscard]] Medium generate(const MediumSpec& spec, Pcg32& rng);

/// @brief x − ⌊x⌋: the periodic wrap into [0, 1) (never returns 1.0).
[[nodiscard]] double wrap_unit(double x);

/// @brief Shortest periodic displacement from a to b (each component in [−½, ½]).
[[nodiscard]] Point2 periodic_delta(Point2 a, Point2 b);

}  // namespace weft::media2d
