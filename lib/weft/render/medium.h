#pragma once
/// @file
/// @brief A homogeneous medium ready to render: its T_Q/T_S pair and how free flights are weighted.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "weft/render/local_gamma.h"
#include "weft/render/scene.h"
#include "weft/transmittance/pair.h"
#include "weft/volume/grid.h"

namespace weft::render {

/// Builds the source/scatterer pair a medium description asks for. Throws weft::Error naming
/// `where` for an unknown law, bad parameters, or a reciprocal partner that does not exist.
[[nodiscard]] transmittance::TransmittancePair make_medium_pair(const MediumDesc& desc, const std::string& where);

/// @brief Upper bounds of extinction per block of voxels, for delta and ratio tracking (the role
/// of pbrt-v4's majorant grid): a dense array of cells of `cell` world units over the grid's
/// active box, each the maximum μ over its voxels and their neighbours.
struct MajorantGrid {
  Vec3 lo{0, 0, 0};
  double cell = 1.0;
  std::array<int, 3> n{0, 0, 0};
  std::vector<double> mu;
  [[nodiscard]] double at(int i, int j, int k) const { return mu[(static_cast<std::size_t>(k) * n[1] + j) * n[0] + i]; }
};

/// Calls visit(t_a, t_b, majorant) for the cells the ray o + t·d crosses over [t0, t1], in
/// order (Amanatides–Woo over the majorant cells); stops when visit returns false.
template <typename Visit>
void walk_majorants(const MajorantGrid& g, const Vec3& o, const Vec3& d, double t0, double t1, Visit&& visit) {
  double tn = t0;
  double tf = t1;
  for (int a = 0; a < 3; ++a) {
    const double lo = g.lo[a];
    const double hi = g.lo[a] + g.cell * g.n[a];
    if (d[a] == 0.0) {
      if (o[a] < lo || o[a] >= hi) return;
      continue;
    }
    double ta = (lo - o[a]) / d[a];
    double tb = (hi - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    tn = std::max(tn, ta);
    tf = std::min(tf, tb);
  }
  if (!(tn < tf)) return;
  std::array<int, 3> idx{};
  std::array<int, 3> step{};
  std::array<double, 3> t_max{};
  std::array<double, 3> t_delta{};
  const Vec3 p = o + tn * d;
  for (int a = 0; a < 3; ++a) {
    idx[a] = std::clamp(static_cast<int>(std::floor((p[a] - g.lo[a]) / g.cell)), 0, g.n[a] - 1);
    if (d[a] == 0.0) {
      step[a] = 0;
      t_max[a] = std::numeric_limits<double>::infinity();
      t_delta[a] = std::numeric_limits<double>::infinity();
    } else {
      step[a] = d[a] > 0.0 ? 1 : -1;
      const double boundary = g.lo[a] + g.cell * (idx[a] + (d[a] > 0.0 ? 1 : 0));
      t_max[a] = (boundary - o[a]) / d[a];
      t_delta[a] = g.cell / std::abs(d[a]);
    }
  }
  double t = tn;
  for (;;) {
    const int axis = t_max[0] < t_max[1] ? (t_max[0] < t_max[2] ? 0 : 2) : (t_max[1] < t_max[2] ? 1 : 2);
    const double end = std::min(std::max(t_max[axis], t), tf);
    if (!visit(t, end, g.at(idx[0], idx[1], idx[2]))) return;
    if (end >= tf) return;
    t = end;
    idx[axis] += step[axis];
    if (idx[axis] < 0 || idx[axis] >= g.n[axis]) return;
    t_max[axis] += t_delta[axis];
  }
}

/// @brief The free-flight bookkeeping of one medium (derivation in docs/render.md §2).
///
/// The path tracer samples each flight from the law of the vertex it leaves (camera side);
/// the physical law of a segment is set by the vertex light comes from. The two differ by
/// ratios that are exactly 1 in reciprocal mode and for exponential media:
///   surface → collision at t:  w_in(t)  = T_S(t) / (c·p_Q(t))
///   collision → surface at t:  w_out(t) = c·p_Q(t) / T_S(t) = 1 / w_in(t)
///   shadow ray leaving a collision, first segment of length t: c·p_Q(t)  (= T_S(t) if reciprocal)
/// with c = ℓ_S when finite (else 1), a constant that cancels along every path.
struct Medium {
  explicit Medium(transmittance::TransmittancePair p) : pair(std::move(p)) {}

  transmittance::TransmittancePair pair;
  bool exponential = false;   ///< T_Q = T_S = e^{−μt}: the fast path
  double mu = 0.0;            ///< extinction of the exponential fast path
  bool unit_weights = false;  ///< w_in = w_out = 1 (reciprocal mode or exponential)
  double c = 1.0;
  Rgb albedo{1, 1, 1};
  double g = 0.0;

  /// Grid media: the law is in optical depth τ = ∫ scale·value dt, and every `t` argument
  /// below is a τ. A grid medium never takes the homogeneous fast path (`exponential` false);
  /// `grid_exponential_mu` > 0 marks an exponential law e^{−μτ} for delta/ratio tracking.
  std::shared_ptr<const volume::Grid> grid;
  double scale = 1.0;                             ///< σ (concentration grids) or 1
  double majorant = 0.0;                          ///< max of scale·value·grid_exponential_mu over the grid
  std::shared_ptr<const MajorantGrid> majorants;  ///< per-block majorants (delta tracking)
  double grid_exponential_mu = 0.0;
  Tracking tracking = Tracking::optical_depth;

  /// Local-gamma media: the fields of `weft fit --block`, flights by inverting the accumulated
  /// hazard (T_Q from a source, the per-voxel partner T_S from a scatterer; local_gamma.h).
  /// Always sampled from the physical law of the segment, so its weights are 1. The integrator
  /// clones it per thread (it holds a DDA tracer); this instance is never traced.
  std::shared_ptr<const LocalGammaField> local_gamma;

  /// w_in(t), evaluated in log space (T_S and p_Q may both underflow).
  [[nodiscard]] double entry_weight(double t) const;
  /// w_out(t).
  [[nodiscard]] double exit_weight(double t) const;
  /// Transmittance factor of a shadow segment of length t that starts at a vertex of kind `origin`.
  [[nodiscard]] double shadow_factor(transmittance::Origin origin, double t) const;
};

/// Builds the runtime medium (and its fast-path flags) from its description.
[[nodiscard]] Medium make_medium(const MediumDesc& desc, const std::string& where);

}  // namespace weft::render
