#pragma once
/// @file
/// @brief Monte Carlo transmittance of explicit 2D media (supplement S.11.2–S.11.3).
///
/// For each η, `realizations` media are generated and traced, each with its own RNG streams
/// (stream_for(seed, unit)) and reduced in index order, so results do not depend on the thread
/// count. Distances t are in units of the target mean free path λ.
///
/// Per realization and per quantity, `samples` rays are traced:
///  - T_Q(t; θ): sources on the line x = 0 (uniform y, redrawn if inside a disk), direction θ from +x;
///  - T_Q,iso: sources uniform in the void, uniform directions (the partner of T_S in reciprocity);
///  - T_S, p_S: a uniformly chosen scatterer, uniform direction ω, leaving the disk along a chord
///    whose offset b is uniform in (−r, r) (the measure of lines through the disk);
///  - boundary: sources at x = 0 along +x through the first medium until t = t_b, then through a
///    second medium: the first translated rigidly by ω s, s = −log(ξ)(1 − η₁,₂)² (unit-square
///    lengths), drawn once per realization. Both media have the same statistics; η₁,₂ = 1
///    continues the same medium, η₁,₂ = 0 moves it by about a domain length (uncorrelated).
///  - scatterer rays start only on the exposed boundary of the union of disks (an exit point
///    inside an overlapping disk is redrawn).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "data_gen/media2d/medium.h"
#include "data_gen/media2d/structure.h"
#include "weft/core/progress.h"

namespace weft::media2d {

/// @brief What to simulate.
struct SimulationSpec {
  std::vector<double> etas{-0.5, 0.0, 0.5};
  double radius = 1e-5;
  double mean_free_path = 0.025;  ///< target λ (unit-square units): the length unit of t
  std::size_t cluster_size = 1000;
  double step_unit = 0.0;  ///< 0 = mean inter-particle distance
  std::vector<double> thetas_deg{0.0, 30.0, 60.0};
  std::size_t realizations = 16;
  std::size_t samples = 1000;  ///< rays per quantity per realization
  double t_max = 40.0;         ///< in λ
  std::size_t bins = 200;
  bool boundary = true;
  double boundary_t = 20.0;  ///< in λ
  std::vector<double> eta12{0.0, 0.9};
  std::size_t structure_realizations = 1;  ///< realizations per η whose structure is analysed
  /// Above this many particles the structure is measured on a stand-in: a realization of the same
  /// generator (same η, cluster size, steps in units of the mean spacing) with this many particles.
  /// Its statistics, in units of the mean spacing, have the same distribution; CGAL's periodic
  /// triangulation of millions of points would dominate the run.
  std::size_t structure_max_points = 30000;
  std::uint64_t seed = 1;
};

/// Longest ray, t_max·λ, in domain lengths. The medium is a periodic unit square: beyond one
/// domain length a ray revisits its own images (the run warns), and a ray that hits nothing walks
/// about √2·(cells per side) grid cells per domain length (disk_grid.h stops only axis-aligned
/// rays, which repeat exactly). 100 leaves room to study that bias and bounds every ray's walk.
inline constexpr double kMaxReach = 100.0;
/// Realizations per η: the work unit key holds the realization in 36 bits (realization_tallies.h).
inline constexpr std::size_t kMaxRealizations = std::size_t{1} << 36U;

/// @brief Checks every field (and the media specs) before anything is generated: ranges, the
/// longest ray (kMaxReach) and the memory the reduction holds (reduction_bytes) against the
/// default memory budget; throws weft::Error naming the problem.
void validate(const SimulationSpec& spec);

/// @brief Bytes of tallies held for the reduction of a run (every η's realizations), estimated
/// before any realization is generated.
[[nodiscard]] double reduction_bytes(const SimulationSpec& spec);

/// @brief A measured curve on the simulation's grid with its standard error over realizations.
struct Curve {
  std::vector<double> value;
  std::vector<double> stderr_;
};

/// @brief Reciprocity p_Q(t) = T_S(t)/ℓ_S checked bin by bin: z_k = (P_Q,k − c·I_S,k)/σ_k with
/// P_Q,k = ∫_bin p_Q and I_S,k = ∫_bin T_S, both estimated exactly from the free paths, and
/// c = 1/ℓ_S fitted by weighted least squares (ℓ_S = ∫₀^∞ T_S includes the tail beyond t_max that
/// the measured integral cannot see). σ_k comes from the spread over realizations of the
/// per-realization differences, so the correlation of p_Q and T_S within a medium is kept.
struct Reciprocity {
  double ell_s = 0.0;  ///< ∫₀^{t_max} T_S measured, in λ (a lower bound of ℓ_S)
  double ell_s_stderr = 0.0;
  double tail_t_s = 0.0;   ///< T_S(t_max): 0 means the measured integral is all of ℓ_S
  double ell_s_fit = 0.0;  ///< ℓ_S that best satisfies p_Q = T_S/ℓ_S, in λ
  double ell_s_fit_stderr = 0.0;
  double chi2 = 0.0;
  std::size_t dof = 0;  ///< bins used (σ_k > 0 and ≥ 20 source paths in the bin) − 1
  double max_abs_z = 0.0;
  double max_abs_z_t = 0.0;
  std::vector<double> residual;  ///< P_Q,k − I_S,k/ℓ_S per bin
  std::vector<double> residual_stderr;
};

struct BoundaryCurves {
  double eta12 = 0.0;
  Curve transmittance;  ///< at edges
  Curve pdf;            ///< at centres
};

/// @brief A law fitted to a measured transmittance curve (least squares, weights 1/σ²).
struct LawFit {
  std::string curve;  ///< "T_Q_iso", "T_S", ...
  std::string law;    ///< registry name
  std::vector<std::string> names;
  std::vector<double> params;
  std::vector<double> errors;  ///< 1σ, scaled by √(χ²/dof) when that exceeds 1
  double chi2 = 0.0;
  std::size_t dof = 0;
  bool converged = false;
  std::string note;
};

struct EtaResult {
  double eta = 0.0;
  std::string generator;
  std::size_t particles = 0;
  double santalo_mfp = 0.0;        ///< Santaló λ of this medium's count, in units of the target λ
  double exact_poisson_mfp = 0.0;  ///< 1/(2nr) in λ: the exact source mean free path of overlapping Poisson disks
  double step_unit = 0.0;
  double perturbed_fraction = 0.0;  ///< mean over realizations (lattice)
  LatticeLayout lattice;            ///< η < 0 only
  std::vector<Curve> t_q;           ///< per θ, at edges
  std::vector<Curve> p_q;           ///< per θ, at centres
  Curve t_q_iso;
  Curve p_q_iso;
  Curve t_s;
  Curve p_s;
  double ell_q_iso = 0.0;  ///< ∫₀^{t_max} T_Q,iso, in λ
  double ell_q_iso_stderr = 0.0;
  Reciprocity reciprocity;
  std::vector<BoundaryCurves> boundary;
  std::vector<StructureStats> structure;
  std::vector<LawFit> fits;
};

struct SimulationResult {
  SimulationSpec spec;
  std::vector<double> edges;    ///< t_k = k·t_max/bins, in λ
  std::vector<double> centres;  ///< bin centres, in λ
  std::vector<EtaResult> etas;
  std::vector<std::string> warnings;
};

/// @brief Runs the whole sweep; progress counts work units (structure statistics, realizations).
///
/// The units — every η's structure statistics, then every η's realizations — are spread over the
/// threads and, under mpirun, the ranks (dist::run_units, one call) and reduced on rank 0; on the
/// other ranks the result holds the spec, the grid and the warnings but no `etas` (they write
/// nothing).
[[nodiscard]] SimulationResult simulate(const SimulationSpec& spec, ProgressSink& progress = null_progress());

/// @brief The medium of realization `realization` for η = spec.etas[eta_index], exactly as
/// `simulate` generates it (same RNG stream).
[[nodiscard]] Medium realization(const SimulationSpec& spec, std::size_t eta_index, std::size_t index);

/// @brief Free paths (in λ, +∞ beyond t_max) of source rays at angle θ in one medium; for tests.
[[nodiscard]] std::vector<double> source_free_paths(const Medium& medium, double mean_free_path, double theta_deg,
                                                    std::size_t samples, double t_max, Pcg32& rng);

}  // namespace weft::media2d
