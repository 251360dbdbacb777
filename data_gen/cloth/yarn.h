#pragma once
/// @file
/// @brief The procedural yarn model of Zhao, Luan and Bala 2016: fibres → plies → yarn around
/// any centreline.

#include <cstdint>
#include <string>
#include <vector>

#include "data_gen/cloth/fibers.h"
#include "data_gen/cloth/spec.h"
#include "weft/core/progress.h"
#include "weft/core/rng.h"

namespace weft::cloth {

/// @brief Unnormalised radial fibre density of a ply cross-section (Zhao et al. 2016, Eq. 2):
/// p(R) = (1 − 2ε)·((e − e^R)/(e − 1))^β + ε for R ∈ [0, 1] (R in units of the ply radius),
/// 0 outside. It is a density per unit cross-section *area*, so the marginal density of R is
/// ∝ R·p(R).
double fiber_density(double R, double epsilon, double beta);

/// @brief CDF of R for fibre positions with areal density p(R) on the unit disk:
/// F(R) = ∫₀ᴿ r p(r) dr / ∫₀¹ r p(r) dr, by composite Simpson on 4096 panels (smooth integrand).
double fiber_radius_cdf(double R, double epsilon, double beta);

/// A fibre's place in its ply cross-section: R in units of the ply radius, angle θ in radians.
struct FiberSeed {
  double R = 0.0;
  double theta = 0.0;
};

/// @brief Rejection-samples `count` fibre positions in a ply cross-section with areal density
/// p(R), keeping centres at least `fiber_min_spacing`·2·fiber_radius apart in the (elliptical)
/// physical cross-section. Throws weft::Error when the ply cannot hold that many fibres.
std::vector<FiberSeed> sample_ply_cross_section(const YarnParams& yarn, int count, Pcg32& rng);

/// A point on a centreline with its rotation-minimising frame (t, n, b) and arc length s.
struct Station {
  Point3 p{}, t{}, n{}, b{};
  double s = 0.0;
};

/// @brief Why `curve` cannot carry a yarn sampled every `step` mm ("has …" or "is …", to follow
/// the curve's name), or "" when it can: it needs two
/// points more than 1e-12 mm apart (repeated points have no tangent) and a length over `step`/1000.
std::string centerline_problem(const Curve& curve, double step);

/// @brief Stations at uniform arc length (spacing ≤ `step`) along `curve`, with frames by the
/// double-reflection rotation-minimising method of Wang et al. 2008 (TOG 27(1)), so fibres do
/// not pick up a spurious twist from the frame. Throws weft::Error for a curve with a
/// centerline_problem.
std::vector<Station> centerline_stations(const Curve& curve, double step);

/// @brief All fibres of one yarn around `centerline`: `ply_count` plies at `ply_offset` twisted
/// with `ply_pitch`; in each, `fiber_count` regular fibres twisted with `fiber_pitch` whose
/// radius migrates as R(s) = R_j/2·(ρmax + ρmin + (ρmax − ρmin)·cos(θ_j + 2πs/period))
/// (Zhao et al. 2016, Eq. 3, with the migration period as a length), loop flyaways (one
/// migration cycle of a fibre pulled out to R_loop) and hair flyaways (free ends rising from the
/// ply surface). Each ply draws its cross-section from stream_for(seed, (yarn_id, ply)), so yarns
/// can be built in any order; see build_yarns for the pieces.
FiberSet yarn_fibers(const Curve& centerline, const YarnParams& yarn, std::uint64_t seed, std::int32_t yarn_id);

/// @brief Mean number of loop flyaways over one point of a regular fibre: c = loop_density ×
/// migration_period / fiber_count (a loop covers one migration period of one of the ply's
/// fibres). Loops are Poisson along each fibre, so a share 1 − e^(−c) of the fibre length lies in
/// a loop; past c ≈ 1 every fibre is pulled out nearly everywhere and more loops change the
/// cloth little but cost time (each point blends every loop over it, build_yarns).
double loop_coverage(const YarnParams& yarn);

/// @brief E[max(floor, X)] for X ~ N(mean, sd): the mean of a quantity the generator draws from a
/// normal law and floors (a loop radius at rho_max, a hair's length at sample_step, its rise at
/// 0): mean + (floor − mean)·Φ(z) + sd·φ(z), z = (floor − mean)/sd.
double mean_of_floored_normal(double floor, double mean, double sd);

/// @brief What build_yarns spends on one yarn whose centreline is `length` mm long, in
/// expectation (the estimate of estimate.h adds it up before anything is made).
struct YarnCost {
  double stations = 0.0;     ///< centreline stations (points of each regular fibre)
  double hair_length = 0.0;  ///< mean axial length of a hair, mm (within the yarn's length)
  double points = 0.0;       ///< fibre points, regular and hair, all plies
  double loops = 0.0;        ///< loop flyaways drawn, all plies
  double hairs = 0.0;        ///< hair flyaways drawn, all plies
  double plan_bytes = 0.0;   ///< the random part held while points are made: stations, loops, hairs
  double loop_bytes = 0.0;   ///< the loops' share of plan_bytes
  double steps = 0.0;        ///< a point made, a loop drawn, sorted or blended at a point
  double loop_steps = 0.0;   ///< the loops' share of steps
};
YarnCost yarn_cost(const YarnParams& yarn, double length);

/// Stations (points along every regular fibre) per yarn piece: about 20 mm of yarn at the
/// default 0.02 mm step, so the built-in weaves have one piece per yarn and a long imported yarn
/// has hundreds.
inline constexpr std::size_t kPieceStations = 1024;

/// Work (a point made, a loop blended into a point, a flyaway drawn) a thread does between two
/// progress reports of build_yarns: a few milliseconds (6 ns a loop at a point, yarn_cost).
inline constexpr std::uint64_t kReportSteps = std::uint64_t{1} << 20U;

/// One yarn to build: its centreline, its parameters and its id (the `yarn` of its fibres).
struct YarnJob {
  const Curve* centerline = nullptr;
  const YarnParams* params = nullptr;
  std::int32_t yarn_id = 0;
};

/// @brief The fibres of many yarns (as yarn_fibers, concatenated in job order), built in parallel
/// within each yarn as well as across yarns.
///
/// A yarn is cut into pieces of kPieceStations stations. The random part is drawn first and
/// serially per yarn, O(fibres + flyaways): the cross-section of each ply, then per piece its
/// loops and hairs, expected counts density × piece length, from piece 0's own continuation of
/// the ply stream and, for piece p > 0, from stream (seed, yarn, ply, p); so a one-piece yarn is
/// exactly what it was before pieces existed. That fixes every polyline's length and place in the
/// output; the points (the cost) are then made per (yarn, ply, piece) in parallel and written in
/// place. Fibres stay whole polylines across pieces (the path at arc length s depends on s only),
/// and the output is identical for any thread count. Loops are found per station from a list
/// sorted by centre, so time is linear in length (testing every loop at every station, as before,
/// made one yarn quadratic: 0.5 / 1.8 / 6.7 s at 2 500 / 5 000 / 10 000 centreline points), and
/// the loops over a point are kept in draw order from one point to the next (a point costs
/// 1 + its loops, yarn_cost). Progress ("generating fibres", one unit a regular fibre point) is
/// reported at least every kReportSteps steps of a thread, drawing included, so a Cancelled
/// from the sink stops a run of dense loops within that much work.
FiberSet build_yarns(const std::vector<YarnJob>& jobs, std::uint64_t seed, ProgressSink& progress = null_progress());

}  // namespace weft::cloth
