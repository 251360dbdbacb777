// The gamma hazard with memory through cells (transmittance/gamma_hazard.h): every memory rule
// on the fields where its answer is known in closed form (docs/render.md §5e).
#include "weft/transmittance/gamma_hazard.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace weft::transmittance {
namespace {

constexpr MemoryRule kRules[] = {MemoryRule::segment, MemoryRule::renewal, MemoryRule::optical_depth,
                                 MemoryRule::carried};

struct Cell {
  double length;
  double mean;
  double var;
};

/// H over the cells in order (or reversed), σ given.
double walk(const std::vector<Cell>& cells, double sigma, MemoryRule rule, Origin origin, bool reverse = false) {
  GammaHazard h(rule, origin);
  double x = 0.0;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const Cell& c = cells[reverse ? cells.size() - 1 - i : i];
    h.enter(sigma, c.mean, c.var, x);
    h.advance(x, x + c.length);
    x += c.length;
  }
  return h.hazard();
}

/// The same statistics cut into pieces of unequal lengths (a seam inside each cell).
std::vector<Cell> split(const std::vector<Cell>& cells) {
  std::vector<Cell> out;
  for (const Cell& c : cells) {
    out.push_back({0.3 * c.length, c.mean, c.var});
    out.push_back({0.5 * c.length, c.mean, c.var});
    out.push_back({0.2 * c.length, c.mean, c.var});
  }
  return out;
}

TEST(GammaHazard, RuleNamesRoundTrip) {
  for (const MemoryRule r : kRules) EXPECT_EQ(parse_memory_rule(memory_rule_name(r)), r);
  EXPECT_FALSE(parse_memory_rule("reset").has_value());
}

// A constant field is the homogeneous gamma law (1 + κt)^{−α} (T_S: exponent α + 1) under every
// rule that carries the memory across faces; renewal makes the cells independent instead:
// Π (1 + κℓ_i)^{−α} (and T_S in the first cell only).
TEST(GammaHazard, ConstantFieldIsTheHomogeneousLawExceptUnderRenewal) {
  const double sigma = 2.0, mean = 1.5, var = 0.9;
  const double alpha = mean * mean / var, kappa = sigma * var / mean;
  const std::vector<Cell> cells{{0.4, mean, var}, {1.1, mean, var}, {0.25, mean, var}, {2.0, mean, var}};
  double t = 0.0;
  double independent = 0.0;
  for (const Cell& c : cells) {
    t += c.length;
    independent += alpha * std::log1p(kappa * c.length);
  }
  for (const Origin o : {Origin::source, Origin::scatterer}) {
    const double a = o == Origin::scatterer ? alpha + 1.0 : alpha;
    const double law = a * std::log1p(kappa * t);
    for (const MemoryRule r : {MemoryRule::segment, MemoryRule::optical_depth, MemoryRule::carried})
      EXPECT_NEAR(walk(cells, sigma, r, o), law, 1e-12 * law) << memory_rule_name(r);
  }
  EXPECT_NEAR(walk(cells, sigma, MemoryRule::renewal, Origin::source), independent, 1e-12 * independent);
  const double first_s = std::log1p(kappa * cells[0].length);  // the extra exponent of T_S in cell 1
  EXPECT_NEAR(walk(cells, sigma, MemoryRule::renewal, Origin::scatterer), independent + first_s, 1e-12 * independent);
  EXPECT_GT(independent, alpha * std::log1p(kappa * t) * 1.5);  // renewal is far more opaque here
}

// The seam test: cutting each cell of a varying field into pieces with identical statistics
// changes nothing for segment, optical-depth and carried (their memory is continuous across a
// face between equal laws), and changes renewal (every face restarts it).
TEST(GammaHazard, SeamsBetweenEqualCellsChangeNothingExceptUnderRenewal) {
  const std::vector<Cell> cells{{0.5, 0.2, 0.3}, {0.8, 2.0, 0.5}, {0.3, 0.0, 0.0}, {0.6, 1.0, 0.0}, {1.2, 0.7, 2.0}};
  for (const Origin o : {Origin::source, Origin::scatterer}) {
    for (const MemoryRule r : {MemoryRule::segment, MemoryRule::optical_depth, MemoryRule::carried}) {
      const double whole = walk(cells, 1.3, r, o);
      EXPECT_NEAR(walk(split(cells), 1.3, r, o), whole, 1e-12 * whole) << memory_rule_name(r);
    }
    const double whole = walk(cells, 1.3, MemoryRule::renewal, o);
    EXPECT_GT(std::abs(walk(split(cells), 1.3, MemoryRule::renewal, o) - whole), 1e-3 * whole);
  }
}

// Constant α, varying mean: the law in optical depth (Bitterli et al. 2018),
// H = α log1p(τ/α), τ = Σ σC̄ℓ; optical-depth and carried give it exactly (and the partner
// (α + 1) log1p(τ/α)), segment does not (its memory is a distance, not a depth).
TEST(GammaHazard, ConstantAlphaIsTheLawInOpticalDepth) {
  const double sigma = 1.7, alpha = 0.6;
  std::vector<Cell> cells;
  double tau = 0.0;
  for (const double m : {0.3, 2.5, 0.05, 1.0, 4.0}) {
    cells.push_back({0.4, m, m * m / alpha});
    tau += sigma * m * 0.4;
  }
  for (const Origin o : {Origin::source, Origin::scatterer}) {
    const double law = (o == Origin::scatterer ? alpha + 1.0 : alpha) * std::log1p(tau / alpha);
    EXPECT_NEAR(walk(cells, sigma, MemoryRule::optical_depth, o), law, 1e-12 * law);
    EXPECT_NEAR(walk(cells, sigma, MemoryRule::carried, o), law, 1e-12 * law);
    EXPECT_GT(std::abs(walk(cells, sigma, MemoryRule::segment, o) - law), 0.05 * law);
  }
}

// Reciprocity between two surfaces: T_Q(x → y) = T_Q(y → x). Renewal's product is symmetric
// always; optical-depth and carried are when α is constant (a function of τ); segment is not
// (a sparse stretch walked first lowers the hazard of the dense one behind it, not in reverse).
TEST(GammaHazard, SourceTransmittanceIsSymmetricWhereDerived) {
  const double sigma = 1.0, alpha = 0.8;
  std::vector<Cell> fixed_alpha;
  for (const double m : {0.1, 0.2, 3.0, 5.0}) fixed_alpha.push_back({0.5, m, m * m / alpha});
  const std::vector<Cell> varying{{0.5, 0.1, 0.5}, {0.5, 0.2, 0.01}, {0.5, 3.0, 9.0}, {0.5, 5.0, 2.0}};
  const auto asym = [&](const std::vector<Cell>& c, MemoryRule r) {
    return std::abs(walk(c, sigma, r, Origin::source) - walk(c, sigma, r, Origin::source, true));
  };
  EXPECT_LT(asym(varying, MemoryRule::renewal), 1e-12);
  EXPECT_LT(asym(fixed_alpha, MemoryRule::renewal), 1e-12);
  EXPECT_LT(asym(fixed_alpha, MemoryRule::optical_depth), 1e-12);
  EXPECT_LT(asym(fixed_alpha, MemoryRule::carried), 1e-12);
  EXPECT_GT(asym(fixed_alpha, MemoryRule::segment), 0.1);
  EXPECT_GT(asym(varying, MemoryRule::optical_depth), 1e-3);
  EXPECT_GT(asym(varying, MemoryRule::carried), 1e-3);
}

// advance_until inverts the hazard inside the piece where it crosses the target.
TEST(GammaHazard, AdvanceUntilInvertsTheHazard) {
  const std::vector<Cell> cells{{0.5, 0.2, 0.3}, {0.8, 2.0, 0.5}, {0.3, 0.0, 0.0}, {0.6, 1.0, 0.0}, {1.2, 0.7, 2.0}};
  for (const MemoryRule r : kRules) {
    const double total = walk(cells, 1.3, r, Origin::scatterer);
    for (const double target : {0.01, 0.3, 0.5 * total, 0.99 * total}) {
      GammaHazard h(r, Origin::scatterer);
      double x = 0.0;
      double hit = INFINITY;
      for (const Cell& c : cells) {
        h.enter(1.3, c.mean, c.var, x);
        hit = h.advance_until(x, x + c.length, target);
        if (!std::isinf(hit)) {
          EXPECT_GE(hit, x);
          EXPECT_LE(hit, x + c.length);
          EXPECT_NEAR(h.hazard() + h.piece(x, hit), target, 1e-12 * (1.0 + target)) << memory_rule_name(r);
          break;
        }
        x += c.length;
      }
      EXPECT_FALSE(std::isinf(hit)) << memory_rule_name(r) << " target " << target;
    }
    // Beyond the total hazard the flight leaves the cells.
    GammaHazard h(r, Origin::scatterer);
    double x = 0.0;
    for (const Cell& c : cells) {
      h.enter(1.3, c.mean, c.var, x);
      EXPECT_TRUE(std::isinf(h.advance_until(x, x + c.length, 1.01 * total)));
      x += c.length;
    }
    EXPECT_NEAR(h.hazard(), total, 1e-12 * total);
  }
}

// Past any representable survival (H/α beyond log DBL_MAX) the memory is +∞ and the hazard of
// what follows 0, never NaN; a flight then does not end there.
TEST(GammaHazard, OpaqueSegmentsStayFinite) {
  for (const MemoryRule r : kRules) {
    const std::vector<Cell> cells{{10.0, 50.0, 0.0}, {1.0, 2.0, 400.0}, {1.0, 3.0, 900.0}};
    const double h = walk(cells, 10.0, r, Origin::scatterer);
    EXPECT_FALSE(std::isnan(h)) << memory_rule_name(r);
    EXPECT_GE(h, 5000.0) << memory_rule_name(r);
    GammaHazard g(r, Origin::source);
    g.enter(10.0, 2.0, 400.0, 0.0);
    EXPECT_FALSE(std::isnan(g.advance_until(0.0, 1.0, 1e4))) << memory_rule_name(r);
  }
}

}  // namespace
}  // namespace weft::transmittance
