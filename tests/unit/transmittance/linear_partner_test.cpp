// The closed-form reciprocal partner of the linear law (docs/render.md §2): T_Q = max(0, 1 − μ̄t)
// has p_Q = μ̄ on [0, 1/μ̄), so T_S = p_Q/p_Q(0) is a step at 1/μ̄ and p_S is a point mass there.
// Checked against the numerical partner (ScattererFromSource), against numerical integration of
// the reciprocity relations, and at extreme μ̄.
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <boost/math/quadrature/gauss_kronrod.hpp>

#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/transmittance/derived.h"
#include "weft/transmittance/linear.h"
#include "weft/transmittance/pair.h"

namespace weft::transmittance {
namespace {

const std::vector<double> kMeans = {1e-3, 0.3, 1.0, 2.5, 7.0, 1e4};

/// Depths across the support and around the jump, down to single ulps on each side of it.
std::vector<double> depths_around(double end) {
  std::vector<double> t = {0.0, 1e-9 * end, 0.1 * end, 0.5 * end, 0.9 * end, 0.999999 * end, 1.000001 * end, 2 * end};
  double below = end;
  double above = end;
  for (int i = 0; i < 4; ++i) {
    below = std::nextafter(below, 0.0);
    above = std::nextafter(above, kInfinity);
    t.push_back(below);
    t.push_back(above);
  }
  t.push_back(end);
  return t;
}

TEST(LinearPartner, ReciprocalPairUsesTheClosedForm) {
  const auto pair = TransmittancePair::reciprocal(std::make_shared<Linear>(2.0), Origin::source);
  const auto* s = dynamic_cast<const LinearScatterer*>(&pair.law(Origin::scatterer));
  ASSERT_NE(s, nullptr) << "the scatterer law is " << pair.law(Origin::scatterer).name();
  EXPECT_EQ(s->mean_extinction(), 2.0);
  // And back: the scatterer step as the given law has Linear as its source partner.
  const auto back = TransmittancePair::reciprocal(pair.law_ptr(Origin::scatterer), Origin::scatterer);
  const auto* q = dynamic_cast<const Linear*>(&back.law(Origin::source));
  ASSERT_NE(q, nullptr) << back.law(Origin::source).name();
  EXPECT_EQ(q->mean_extinction(), 2.0);
}

// Same T_S at every depth as the numerical partner (p_Q/p_Q(0) evaluated through Linear::pdf),
// the same ℓ_S, and the numerical sampler's inversion lands on the same atom.
TEST(LinearPartner, EqualsTheNumericalPartner) {
  for (const double mu : kMeans) {
    const auto source = std::make_shared<Linear>(mu);
    const LinearScatterer closed(mu);
    const ScattererFromSource numerical(source);
    for (const double t : depths_around(closed.end())) {
      EXPECT_EQ(closed.transmittance(t), numerical.transmittance(t)) << "mu " << mu << " t " << t;
    }
    EXPECT_NEAR(closed.mean_free_path(), numerical.mean_free_path(), 1e-15 * numerical.mean_free_path()) << mu;
    Pcg32 rng = stream_for(5, static_cast<std::uint64_t>(mu * 1000));
    for (int i = 0; i < 200; ++i) {
      const double t = numerical.sample(rng);
      EXPECT_EQ(t, closed.end()) << "mu " << mu << " numerical sample " << i;
    }
  }
}

// The step sits exactly where Linear's p_Q drops to 0: T_S = p_Q/p_Q(0) holds at every double.
TEST(LinearPartner, StepIsWhereSourceDensityEndsAtExtremeMeans) {
  const std::vector<double> extremes = {std::numeric_limits<double>::min(), 1e-300, 1e-12, 1.0, 3.0, 1e12, 1e300,
                                        std::numeric_limits<double>::max()};
  for (const double mu : extremes) {
    const Linear q(mu);
    const LinearScatterer s(mu);
    ASSERT_TRUE(std::isfinite(s.end())) << mu;
    ASSERT_GT(s.end(), 0.0) << mu;
    EXPECT_GT(q.pdf(std::nextafter(s.end(), 0.0)), 0.0) << mu;
    EXPECT_EQ(q.pdf(s.end()), 0.0) << mu;
    EXPECT_NEAR(s.end() * mu, 1.0, 1e-12) << mu;
    for (const double t : depths_around(s.end())) {
      EXPECT_EQ(s.transmittance(t), q.pdf(t) / q.pdf(0.0)) << "mu " << mu << " t " << t;
      const double tr = s.transmittance(t);  // log(0) would raise FE_DIVBYZERO (fp-trap build)
      EXPECT_EQ(s.log_transmittance(t), tr > 0.0 ? std::log(tr) : -kInfinity) << "mu " << mu << " t " << t;
    }
  }
}

// Reciprocity by numerical integration: ℓ_S = ∫T_S; p_Q = T_S/ℓ_S; and T_Q(t) = ∫_t^∞ T_S/ℓ_S
// (Gauss–Kronrod over [t, end], where T_S is 1; beyond it T_S is 0).
TEST(LinearPartner, ReciprocityHoldsByNumericalIntegration) {
  using Kronrod = boost::math::quadrature::gauss_kronrod<double, 15>;
  for (const double mu : kMeans) {
    const Linear q(mu);
    const LinearScatterer s(mu);
    const double end = s.end();
    const auto t_s = [&](double x) { return s.transmittance(x); };
    // Split at the jump so the quadrature sees two smooth pieces.
    const double ell = Kronrod::integrate(t_s, 0.0, end, 8, 1e-14) + Kronrod::integrate(t_s, end, 3.0 * end, 8, 1e-14);
    EXPECT_NEAR(ell, s.mean_free_path(), 1e-12 * end) << mu;
    for (const double f : {0.0, 0.2, 0.5, 0.8, 0.999}) {
      const double t = f * end;
      EXPECT_NEAR(q.pdf(t), s.transmittance(t) / ell, 1e-12 * mu) << "mu " << mu << " t " << t;
      const double tail = Kronrod::integrate(t_s, t, end, 8, 1e-14) / ell;
      EXPECT_NEAR(tail, q.transmittance(t), 1e-12) << "mu " << mu << " t " << t;
    }
  }
}

// The sampler draws the law's only atom, every time: the empirical CDF is the step 1 − T_S, and
// the sample mean is ∫t dP_S = end = ℓ_S (the atom carries all the mass).
TEST(LinearPartner, SamplerIsThePointMass) {
  const LinearScatterer s(1.7);
  Pcg32 rng = stream_for(9, 0);
  double sum = 0.0;
  constexpr int kN = 1000;
  for (int i = 0; i < kN; ++i) {
    const double t = s.sample(rng);
    ASSERT_EQ(t, s.end());
    ASSERT_EQ(1.0 - s.transmittance(std::nextafter(t, 0.0)), 0.0);  // no mass before the atom
    ASSERT_EQ(1.0 - s.transmittance(t), 1.0);                       // all of it at the atom
    sum += t;
  }
  EXPECT_NEAR(sum / kN, s.mean_free_path(), 1e-12 * s.mean_free_path());  // summation rounding only
  // No density anywhere (the law is singular), hazard 0 before the atom and +∞ from it on.
  for (const double t : {0.0, 0.3, std::nextafter(s.end(), 0.0), s.end(), 2.0}) EXPECT_EQ(s.pdf(t), 0.0) << t;
  EXPECT_EQ(s.hazard(0.5 * s.end()), 0.0);
  EXPECT_EQ(s.hazard(s.end()), kInfinity);
}

TEST(LinearPartner, BadMeanIsRefused) {
  EXPECT_THROW((void)LinearScatterer(-1.0), Error);
  EXPECT_THROW((void)LinearScatterer(std::nan("")), Error);
  EXPECT_THROW((void)LinearScatterer(kInfinity), Error);
  const LinearScatterer clear(0.0);
  EXPECT_EQ(clear.end(), kInfinity);
  EXPECT_EQ(clear.transmittance(1e300), 1.0);
}

}  // namespace
}  // namespace weft::transmittance
