// The two-scale prediction's quadrature nodes (fit/gamma_nodes.h): Boost's gamma_p_inv iteration
// from a shared table's guess gives gamma_p_inv's nodes within rounding, and a node depends on
// its shape alone.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <vector>

#include "weft/fit/gamma_nodes.h"

namespace weft::fit::detail {
namespace {

/// Shapes from below the table (α < 1/8) to above it (α > 10⁸), log-spaced, plus shapes drawn at
/// random (fixed seed) between the lattice points.
std::vector<double> sweep() {
  std::vector<double> shapes;
  for (double lg = -2.0; lg <= 9.0; lg += 0.05) shapes.push_back(std::pow(10.0, lg));
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(std::log(0.125), std::log(1e4));
  for (int i = 0; i < 200; ++i) shapes.push_back(std::exp(u(rng)));
  return shapes;
}

TEST(GammaNodes, AreGammaPInvWithinRounding) {
  // Both are Halley iterates stopped after a step below 2⁻²⁴ of x, so their truncation error is
  // of order 2⁻⁷²; they differ by the rounding of P(α, x) near the root over x·P'(x), a few ulp
  // times p/(x f(x)) ≤ 1/α ≤ 8 relative on the table's range: 10⁻¹³ bounds it with room.
  const auto shapes = sweep();
  const GammaNodes table(shapes);
  double worst = 0.0;
  for (double a : shapes) {
    double nodes[kNodes];
    table.nodes(a, nodes);
    for (int j = 0; j < kNodes; ++j) {
      const double exact = exact_gamma_node(a, j);
      ASSERT_GT(nodes[j], 0.0) << "shape " << a << " node " << j;
      worst = std::max(worst, std::abs(nodes[j] - exact) / exact);
      EXPECT_NEAR(nodes[j], exact, 1e-13 * exact) << "shape " << a << " node " << j;
      if (j > 0) {
        EXPECT_GT(nodes[j], nodes[j - 1]) << "shape " << a << " node " << j;
      }
    }
  }
  std::ostringstream text;
  text << worst;
  RecordProperty("worst_relative_difference", text.str());
}

TEST(GammaNodes, DependOnTheShapeAlone) {
  // The lattice is fixed, so a column's nodes are the same bits whichever other shapes the table
  // was built for (other coarse columns, another thread count, another grid).
  const auto shapes = sweep();
  const GammaNodes all(shapes);
  for (double a : {0.3, 1.7, 12.5, 480.0}) {
    const GammaNodes alone(std::vector<double>{a});
    double x[kNodes];
    double y[kNodes];
    all.nodes(a, x);
    alone.nodes(a, y);
    for (int j = 0; j < kNodes; ++j) EXPECT_EQ(x[j], y[j]) << "shape " << a << " node " << j;
  }
}

TEST(GammaNodes, ANearlyUniformColumnHasNodesNearOne) {
  // α = 1/v_p beyond 2·10¹⁰ (a column whose persistent factor barely varies) is beyond Boost's
  // gamma_p_inv; the nodes are 1 + z_j/√α + O(1/α), increasing, within 3/√α of 1.
  const GammaNodes table(std::vector<double>{3e10, 1e14});
  for (double a : {3e10, 1e14, 1e300}) {
    double x[kNodes];
    ASSERT_NO_THROW(table.nodes(a, x)) << "shape " << a;
    for (int j = 0; j < kNodes; ++j) {
      EXPECT_NEAR(x[j], 1.0, 3.0 / std::sqrt(a) + 4e-16) << "shape " << a << " node " << j;
      if (j > 0) {
        EXPECT_GE(x[j], x[j - 1]) << "shape " << a << " node " << j;
      }
    }
  }
}

TEST(GammaNodes, AShapeOutsideTheTableIsGammaPInvItself) {
  const GammaNodes empty(std::vector<double>{});
  for (double a : {0.01, 0.1, 2.0, 3e8, 3e10, 1e14}) {
    double x[kNodes];
    empty.nodes(a, x);
    for (int j = 0; j < kNodes; ++j) EXPECT_EQ(x[j], exact_gamma_node(a, j)) << "shape " << a << " node " << j;
  }
}

}  // namespace
}  // namespace weft::fit::detail
