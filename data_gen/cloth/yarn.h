#pragma once
/// @file
/// @brief The procedural yarn model of Zhao, Luan and Bala 2016: fibres → plies → yarn around
/// any centreline.

#include <cstdint>
#include <vector>

#include "data_gen/cloth/fibers.h"
#include "data_gen/cloth/spec.h"
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

/// @brief Stations at uniform arc length (spacing ≤ `step`) along `curve`, with frames by the
/// double-reflection rotation-minimising method of Wang et al. 2008 (TOG 27(1)), so fibres do
/// not pick up a spurious twist from the frame. Throws weft::Error for curves shorter than
/// `step`/1000 or with repeated points only.
std::vector<Station> centerline_stations(const Curve& curve, double step);

/// @brief All fibres of one yarn around `centerline`: `ply_count` plies at `ply_offset` twisted
/// with `ply_pitch`; in each, `fiber_count` regular fibres twisted with `fiber_pitch` whose
/// radius migrates as R(s) = R_j/2·(ρmax + ρmin + (ρmax − ρmin)·cos(θ_j + 2πs/period))
/// (Zhao et al. 2016, Eq. 3, with the migration period as a length), loop flyaways (one
/// migration cycle of a fibre pulled out to R_loop) and hair flyaways (free ends rising from the
/// ply surface). Each ply draws from stream_for(seed, (yarn_id, ply)), so yarns can be built in
/// any order.
FiberSet yarn_fibers(const Curve& centerline, const YarnParams& yarn, std::uint64_t seed, std::int32_t yarn_id);

}  // namespace weft::cloth
