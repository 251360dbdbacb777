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

  MemoryRule rule_;
  Origin origin_;
  GammaCell cell_{};
  double shift_ = 0.0;  ///< memory(x) = x − shift in the current cell
  double h_ = 0.0;      ///< accumulated hazard
  double tau_ = 0.0;    ///< accumulated optical depth ∫μ̄ (optical_depth rule)
  int cells_ = 0;       ///< cells entered
};

}  // namespace weft::transmittance
