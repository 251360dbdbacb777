#pragma once
/// @file
/// @brief The gamma hazard with memory along a ray through cells of varying gamma statistics:
/// the one implementation the predicted local-field models (fit), the sweep's coarse beams and
/// the render's local-gamma medium share (derivation and the memory rules: docs/render.md §5b,
/// §5e).
///
/// A cell holding a gamma concentration law (mean C̄, variance V, cross-section σ) has, at
/// memory s (how far the flight has "already gone" in that law), the hazard
///   Σ(s) = σα/(β + σs) = μ̄/(1 + κs),  μ̄ = σC̄,  κ = σV/C̄  (α = C̄²/V, β = C̄/V),
/// so T = e^{−∫Σ} is (1 + κs)^{−α} in a constant field. The scatterer partner of the cell's law
/// (T_S = p_Q/p_Q(0) = (1 + κs)^{−(α+1)}) has the same κ and the rate μ̄ + κ. What a ray's
/// memory is when it crosses from one cell into the next is the memory rule (MemoryRule).

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string_view>

#include "weft/transmittance/pair.h"

namespace weft::transmittance {

/// How the hazard's memory passes from one cell to the next (docs/render.md §5e).
enum class MemoryRule {
  segment,        ///< memory = distance from the segment start, through every cell (and gap)
  renewal,        ///< memory restarts at every cell face (cells independent)
  optical_depth,  ///< memory = the segment's optical depth τ = ∫σC̄ over this cell's μ̄ (Bitterli et al. 2018)
  carried,        ///< the survival e^{−H} carried: memory = this cell's distance with the same H (Vicini et al. 2021)
};

inline constexpr MemoryRule kMemoryRules[] = {MemoryRule::segment, MemoryRule::renewal, MemoryRule::optical_depth,
                                              MemoryRule::carried};

/// The rule of the render's local-gamma medium when a scene names none, of the scenes `weft fit
/// --block` and `validate --scenes` write and of the image study's local-gamma candidates:
/// optical-depth, because a sparse margin or yarn edge in front of a dense cell then carries
/// almost no memory into it (docs/render.md §5e: `segment` leaks light through every yarn).
/// The predicted beam models of `weft validate` name their rules themselves (fit/local_models).
inline constexpr MemoryRule kDefaultMemoryRule = MemoryRule::optical_depth;

/// "segment", "renewal", "optical-depth", "carried".
[[nodiscard]] std::string_view memory_rule_name(MemoryRule rule);
/// The rule of a name above, or nothing.
[[nodiscard]] std::optional<MemoryRule> parse_memory_rule(std::string_view name);

/// @brief One cell's hazard Σ(s) = rate/(1 + κs) in its memory s.
struct GammaCell {
  double rate = 0.0;             ///< Σ(0): μ̄ = σC̄ for T_Q, μ̄ + κ for the partner T_S
  double kappa = 0.0;            ///< σV/C̄ (0: the exponential law of rate `rate`)
  double mean_extinction = 0.0;  ///< μ̄ = σC̄, the rate of the optical depth τ

  /// The cell of moments (mean, var) at σ, for segments that start at `origin`; mean ≤ 0 is
  /// vacuum (rate 0).
  [[nodiscard]] static GammaCell from_moments(double sigma, double mean, double var, Origin origin);
  /// The cell of mean extinction μ̄ = σC̄ and κ = σV/C̄ computed once (a medium's per-voxel
  /// records): from_moments is from_rates(σC̄, σV/C̄) bit for bit; μ̄ = 0 is vacuum.
  [[nodiscard]] static GammaCell from_rates(double mean_extinction, double kappa, Origin origin);
  /// ∫ Σ over memories [s, s + length]: (rate/κ)·log1p(κ·length/(1 + κs)), rate·length for κ = 0.
  [[nodiscard]] double integral(double s, double length) const;
  /// The length ℓ ≥ 0 with integral(s, ℓ) = h: (1 + κs)·expm1(hκ/rate)/κ (h/rate for κ = 0;
  /// +∞ when rate = 0).
  [[nodiscard]] double length_to(double s, double h) const;
  /// The memory s with integral(0, s) = H: where this cell's own law has survival e^{−H}.
  [[nodiscard]] double memory_for(double hazard) const;
};

/// @brief The hazard H accumulated along one segment, cell after cell, under a memory rule.
///
/// Distances x are measured from the segment start (where the memory of every rule starts).
/// Call enter() at the start of each cell the ray crosses (vacuum cells may be skipped), then
/// advance() (or advance_until()) over the cell's pieces in order; piece() looks ahead.
/// The scatterer partner applies while the memory runs on from the scatterer: in every cell for
/// segment/optical-depth/carried, in the first cell only for renewal (a renewed memory is a
/// fresh start, so later cells use T_Q).
class GammaHazard {
 public:
  GammaHazard(MemoryRule rule, Origin origin) : rule_(rule), origin_(origin) {}

  /// Enters a cell of moments (mean, var) at σ at distance x.
  void enter(double sigma, double mean, double var, double x);
  /// ∫Σ over [a, b] inside the current cell (a ≥ the entry distance).
  [[nodiscard]] double piece(double a, double b) const;
  /// Moves over [a, b] of the current cell: H += piece(a, b).
  void advance(double a, double b);
  /// Sampling a flight (target = −log u): the distance x in [a, b] where H reaches `target`
  /// (≥ hazard(); b when rounding puts the crossing just past it), the state left at a; or, if
  /// H stays below it over the piece, advance(a, b) and +∞.
  [[nodiscard]] double advance_until(double a, double b, double target);
  /// H so far: T = e^{−H}.
  [[nodiscard]] double hazard() const { return h_; }
  [[nodiscard]] const GammaCell& cell() const { return cell_; }

 private:
  [[nodiscard]] double memory(double x) const { return x - shift_; }
  /// Enters a cell of mean extinction μ̄ and κ (GammaCell::from_rates) at distance x.
  void enter_rates(double mean_extinction, double kappa, double x);

  MemoryRule rule_;
  Origin origin_;  ///< the origin of the next cell's law (renewal: the segment's for the first only)
  GammaCell cell_{};
  double shift_ = 0.0;  ///< memory(x) = x − shift in the current cell
  double h_ = 0.0;      ///< accumulated hazard
  double tau_ = 0.0;    ///< accumulated optical depth ∫μ̄ (optical_depth rule)
};

// The per-piece steps, inline: a medium walks them once per voxel of every flight and shadow
// (docs/render.md §6 "Coarse grids").

inline GammaCell GammaCell::from_moments(double sigma, double mean, double var, Origin origin) {
  if (!(mean > 0.0)) return GammaCell{};
  // Σ_Q(s) = σα/(β + σs) = σC̄/(1 + κs), κ = σV/C̄ (α = C̄²/V, β = C̄/V).
  return from_rates(sigma * mean, var > 0.0 ? sigma * var / mean : 0.0, origin);
}

inline void GammaHazard::enter(double sigma, double mean, double var, double x) {
  const GammaCell c = GammaCell::from_moments(sigma, mean, var, Origin::source);
  enter_rates(c.mean_extinction, c.kappa, x);
}

inline GammaCell GammaCell::from_rates(double mean_extinction, double kappa, Origin origin) {
  // The partner T_S = (1 + κs)^{−(α+1)} has Σ_S = (α + 1)κ/(1 + κs) = (σC̄ + κ)/(1 + κs).
  GammaCell c;
  c.kappa = kappa;
  c.mean_extinction = mean_extinction;
  c.rate = mean_extinction + (origin == Origin::scatterer ? kappa : 0.0);
  return c;
}

inline double GammaCell::integral(double s, double length) const {
  if (kappa == 0.0) return rate * length;
  const double scale = rate / kappa;  // before log1p: one number kept across the call, not two
  return scale * std::log1p(kappa * length / (1.0 + kappa * s));
}

inline void GammaHazard::enter_rates(double mean_extinction, double kappa, double x) {
  // A renewed memory is a fresh start (the cell face acts as a source), so only the first
  // cell of a renewal segment keeps the scatterer's partner (docs/render.md §5e).
  cell_ = GammaCell::from_rates(mean_extinction, kappa, origin_);
  if (rule_ == MemoryRule::renewal) origin_ = Origin::source;
  switch (rule_) {
    case MemoryRule::segment:
      shift_ = 0.0;
      break;
    case MemoryRule::renewal:
      shift_ = x;
      break;
    case MemoryRule::optical_depth:
      // τ so far read as this cell's distance: hazard μ̄/(1 + τ/α), the law in optical depth.
      shift_ = cell_.mean_extinction > 0.0 ? x - tau_ / cell_.mean_extinction : x;
      break;
    case MemoryRule::carried:
      // The survival e^{−H} so far read as this cell's distance under its own law.
      shift_ = x - cell_.memory_for(h_);
      break;
  }
}

inline double GammaHazard::piece(double a, double b) const { return cell_.integral(memory(a), b - a); }

inline void GammaHazard::advance(double a, double b) {
  // τ first: its terms need not be kept across piece()'s log1p.
  tau_ += cell_.mean_extinction * (b - a);
  h_ += piece(a, b);
}

inline double GammaHazard::advance_until(double a, double b, double target) {
  const double dh = piece(a, b);
  if (h_ + dh < target) {
    h_ += dh;
    tau_ += cell_.mean_extinction * (b - a);
    return std::numeric_limits<double>::infinity();
  }
  return std::min(a + cell_.length_to(memory(a), target - h_), b);
}

}  // namespace weft::transmittance
