// Closed forms against numerical integration, independent of the formulas under test:
// ∫₀ᵗ p = 1 − T(t), ∫₀^∞ T = ℓ, Σ = p/T, log T = log(T), and for reciprocal pairs
// T_S/ℓ_S = p_Q (times 1 − T_Q(∞) for laws whose rays may never collide) and T_S(0) = 1.
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <boost/math/quadrature/exp_sinh.hpp>
#include <boost/math/quadrature/tanh_sinh.hpp>

#include "weft/core/error.h"
#include "weft/transmittance/derived.h"
#include "weft/transmittance/erlang.h"
#include "weft/transmittance/exponential.h"
#include "weft/transmittance/gamma_concentration.h"
#include "weft/transmittance/gamma_mixture.h"
#include "weft/transmittance/gamma_path.h"
#include "weft/transmittance/gap_gamma.h"
#include "weft/transmittance/linear.h"
#include "weft/transmittance/pair.h"
#include "weft/transmittance/tabulated.h"

namespace weft::transmittance {
namespace {

struct LawCase {
  std::string label;
  std::function<LawPtr()> make;
  double scale;                    ///< a length where T has changed appreciably
  std::vector<double> kinks = {};  ///< where p jumps (piecewise laws): quadrature splits there
};

/// ∫_a^b f, split at the kinks and into 16 pieces between them.
double integrate(const std::function<double(double)>& f, double a, double b, const std::vector<double>& kinks) {
  boost::math::quadrature::tanh_sinh<double> integrator;
  std::vector<double> cuts{a};
  for (double k : kinks) {
    if (k > a && k < b) cuts.push_back(k);
  }
  cuts.push_back(b);
  double sum = 0.0;
  for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
    for (int i = 0; i < 16; ++i) {
      const double lo = cuts[c] + (cuts[c + 1] - cuts[c]) * i / 16;
      const double hi = cuts[c] + (cuts[c + 1] - cuts[c]) * (i + 1) / 16;
      sum += integrator.integrate(f, lo, hi);
    }
  }
  return sum;
}

std::vector<LawCase> laws() {
  std::vector<LawCase> out;
  out.push_back({"exponential", [] { return std::make_shared<Exponential>(2.0); }, 0.5});
  for (double alpha : {0.3, 1.0, 1.5, 2.0, 10.0, 1e6}) {
    out.push_back(
        {fmt::format("gamma a={}", alpha), [alpha] { return std::make_shared<GammaConcentration>(1.5, alpha); }, 1.0});
  }
  for (double alpha : {0.6, 2.5}) {
    out.push_back(
        {fmt::format("gap-gamma a={}", alpha), [alpha] { return std::make_shared<GapGamma>(0.3, 1.5, alpha); }, 1.0});
  }
  out.push_back({"gamma-mixture",
                 [] {
                   return std::make_shared<GammaMixture>(
                       std::vector<GammaComponent>{{0.2, 0.0, 1.0}, {0.5, 3.0, 2.5}, {0.3, 1.0, kInfinity}});
                 },
                 1.0});
  out.push_back(
      {"gamma-mixture no gap",
       [] {
         return std::make_shared<GammaMixture>(std::vector<GammaComponent>{{0.4, 0.5, 1.5}, {0.6, 4.0, kInfinity}});
       },
       1.0});
  out.push_back({"linear", [] { return std::make_shared<Linear>(0.8); }, 0.4, {1.25}});
  for (double k : {0.3, 1.0, 2.5, 30.0}) {
    out.push_back({fmt::format("gamma-path k={}", k), [k] { return std::make_shared<GammaPath>(k, 0.7); }, 0.7 * k});
  }
  out.push_back({"erlang k=3", [] { return std::make_shared<Erlang>(3.0, 2.0); }, 1.5});
  out.push_back({"erlang-source k=4", [] { return std::make_shared<ErlangMixture>(4.0, 2.0); }, 1.5});
  out.push_back({"tabulated",
                 [] {
                   return std::make_shared<Tabulated>(std::vector<double>{0, 0.3, 1.0, 2.5, 4.0},
                                                      std::vector<double>{1, 0.7, 0.4, 0.1, 0.02});
                 },
                 1.0,
                 {0.3, 1.0, 2.5, 4.0}});
  out.push_back({"derived source of gamma-path k=2",
                 [] { return std::make_shared<SourceFromScatterer>(std::make_shared<GammaPath>(2.0, 1.0)); }, 2.0});
  out.push_back({"derived scatterer of erlang-source k=3",
                 [] { return std::make_shared<ScattererFromSource>(std::make_shared<ErlangMixture>(3.0, 1.0)); }, 2.0});
  return out;
}

class ClosedForms : public ::testing::TestWithParam<LawCase> {};

TEST_P(ClosedForms, IntegralOfPdfIsOneMinusTransmittance) {
  const LawPtr law = GetParam().make();
  const double scale = GetParam().scale;
  for (double factor : {0.01, 0.3, 1.0, 2.0, 5.0}) {
    const double t = factor * scale;
    const double integral = integrate([&](double s) { return law->pdf(s); }, 0.0, t, GetParam().kinks);
    EXPECT_NEAR(integral, 1.0 - law->transmittance(t), 1e-8) << "t = " << t;
  }
}

TEST_P(ClosedForms, IntegralOfTransmittanceIsMeanFreePath) {
  const LawPtr law = GetParam().make();
  const double ell = law->mean_free_path();
  if (!std::isfinite(ell)) {
    // Divergent: ∫₀^L T keeps growing with L (substituting t = e^u keeps the quadrature sane).
    const auto partial = [&](double upper) {
      boost::math::quadrature::tanh_sinh<double> integrator;
      return integrator.integrate([&](double u) { return law->transmittance(std::exp(u)) * std::exp(u); }, -30.0,
                                  std::log(upper));
    };
    EXPECT_GT(partial(1e12), 2.0 * partial(1e3));
    return;
  }
  boost::math::quadrature::exp_sinh<double> tail;
  const double split = 4.0 * GetParam().scale;
  double integral = integrate([&](double s) { return law->transmittance(s); }, 0.0, split, GetParam().kinks);
  integral += tail.integrate([&](double s) { return law->transmittance(split + s); });
  EXPECT_NEAR(integral / ell, 1.0, 1e-7);
}

TEST_P(ClosedForms, HazardAndLogAreConsistent) {
  const LawPtr law = GetParam().make();
  for (double factor : {0.001, 0.1, 0.5, 1.0, 3.0}) {
    const double t = factor * GetParam().scale;
    const double value = law->transmittance(t);
    ASSERT_GT(value, 0.0);
    EXPECT_NEAR(law->hazard(t), law->pdf(t) / value, 1e-10 * law->hazard(t)) << "t = " << t;
    EXPECT_NEAR(law->log_transmittance(t), std::log(value), 1e-12 * (1.0 + std::fabs(std::log(value)))) << "t = " << t;
  }
}

TEST_P(ClosedForms, ReciprocalPartnerSatisfiesPq_eq_Ts_over_Ls) {
  const LawPtr law = GetParam().make();
  for (const Origin origin : {Origin::source, Origin::scatterer}) {
    std::optional<TransmittancePair> pair;
    try {
      pair = TransmittancePair::reciprocal(law, origin);
    } catch (const Error&) {
      continue;  // the derivation does not exist for this law and origin; pair_test checks why
    }
    const Law& q = pair->law(Origin::source);
    const Law& s = pair->law(Origin::scatterer);
    const double ell_s = s.mean_free_path();
    // Rays that never collide (T_Q(∞) > 0: gaps) carry no scatterers: ∫p_Q = 1 − T_Q(∞), so
    // p_Q = (1 − T_Q(∞))·T_S/ℓ_S (docs/transmittance.md, gap-gamma).
    const double colliding = 1.0 - q.transmittance(kInfinity);
    EXPECT_DOUBLE_EQ(s.transmittance(0.0), 1.0);
    for (double factor : {0.0, 0.05, 0.5, 1.0, 2.5}) {
      const double t = factor * GetParam().scale;
      EXPECT_NEAR(colliding * s.transmittance(t) / ell_s, q.pdf(t), 1e-8 * q.pdf(0.0))
          << to_string(origin) << " t = " << t;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Laws, ClosedForms, ::testing::ValuesIn(laws()),
                         [](const ::testing::TestParamInfo<LawCase>& info) {
                           std::string name = info.param.label;
                           for (auto& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

TEST(GammaLaw, LargeAlphaIsExponentialTo1e12) {
  for (double alpha : {1e15, 1e18, 1e300, kInfinity}) {
    const GammaConcentration law(1.0, alpha);
    for (double t : {0.0, 1e-300, 1e-10, 0.5, 1.0, 10.0, 30.0}) {
      EXPECT_NEAR(law.transmittance(t), std::exp(-t), 1e-12 * std::exp(-t)) << alpha << " " << t;
      EXPECT_NEAR(law.log_transmittance(t), -t, 1e-12 * t) << alpha << " " << t;
      EXPECT_NEAR(law.pdf(t), std::exp(-t), 1e-12 * std::exp(-t)) << alpha << " " << t;
      EXPECT_NEAR(law.hazard(t), 1.0, 1e-12) << alpha << " " << t;
    }
  }
}

TEST(GammaLaw, ZeroVarianceIsExactlyExponential) {
  const auto law = GammaConcentration::from_concentration(2.0, 0.25, 0.0);
  const Exponential exponential(0.5);
  EXPECT_EQ(law.alpha(), kInfinity);
  for (double t : {0.0, 1e-300, 0.3, 7.0, 1e300, kInfinity}) {
    EXPECT_EQ(law.transmittance(t), exponential.transmittance(t));
    EXPECT_EQ(law.pdf(t), exponential.pdf(t));
    EXPECT_EQ(law.hazard(t), exponential.hazard(t));
    EXPECT_FALSE(std::isnan(law.log_transmittance(t)));
  }
  EXPECT_EQ(law.mean_free_path(), 2.0);
}

TEST(GammaLaw, ParametrisationsAgree) {
  // σ = 2, C̄ = 0.3, Var C = 0.045 ⇒ α = 2, β = 0.3/0.045, μ̄ = 0.6.
  const auto a = GammaConcentration::from_concentration(2.0, 0.3, 0.045);
  const auto b = GammaConcentration::from_sigma_alpha_beta(2.0, 2.0, 0.3 / 0.045);
  const GammaConcentration c(0.6, 2.0);
  for (double t : {0.1, 1.0, 10.0}) {
    // Eq. 20 in the paper's form (1 + σt/β)^−α.
    const double paper = std::pow(1.0 + 2.0 * t / (0.3 / 0.045), -2.0);
    EXPECT_NEAR(a.transmittance(t), paper, 1e-14);
    EXPECT_NEAR(b.transmittance(t), paper, 1e-14);
    EXPECT_NEAR(c.transmittance(t), paper, 1e-14);
  }
}

TEST(LinearLaw, EdgeOfSupport) {
  const Linear law(4.0);
  const double edge = 0.25;
  EXPECT_EQ(law.transmittance(edge), 0.0);
  EXPECT_EQ(law.hazard(edge), kInfinity);
  EXPECT_EQ(law.pdf(edge), 0.0);
  const double below = std::nextafter(edge, 0.0);
  EXPECT_GT(law.transmittance(below), 0.0);
  EXPECT_NEAR(law.transmittance(below), 4.0 * (edge - below), 1e-30);
  EXPECT_TRUE(std::isfinite(law.hazard(below)));
  EXPECT_EQ(law.pdf(below), 4.0);
  EXPECT_EQ(law.transmittance(1.0), 0.0);
  EXPECT_EQ(law.log_transmittance(1.0), -kInfinity);
  EXPECT_DOUBLE_EQ(law.mean_free_path(), 0.125);
}

TEST(ExponentialLaw, HugeExtinction) {
  const Exponential law(1e300);
  EXPECT_EQ(law.transmittance(1.0), 0.0);
  EXPECT_EQ(law.log_transmittance(1.0), -1e300);
  EXPECT_DOUBLE_EQ(law.transmittance(1e-300), std::exp(-1.0));
  EXPECT_EQ(law.hazard(5.0), 1e300);
  EXPECT_EQ(law.mean_free_path(), 1e-300);
}

TEST(ErlangLaw, Gamma2IsDEonsCorrelatedLaw) {
  // d'Eon's Gamma-2 pair: T_c(s) = (1 + s)e^{−s} (scatterer), T_u(s) = (1 + s/2)e^{−s} (source).
  const auto pair = TransmittancePair::reciprocal(std::make_shared<Erlang>(2.0, 1.0), Origin::scatterer);
  const SourceFromScatterer numerical(std::make_shared<Erlang>(2.0, 1.0));
  for (double s : {0.0, 0.1, 1.0, 3.0, 20.0}) {
    EXPECT_NEAR(pair.transmittance(Origin::scatterer, s), (1.0 + s) * std::exp(-s), 1e-14);
    EXPECT_NEAR(pair.transmittance(Origin::source, s), (1.0 + 0.5 * s) * std::exp(-s), 1e-14);
    EXPECT_NEAR(numerical.transmittance(s), (1.0 + 0.5 * s) * std::exp(-s), 1e-12);
  }
  EXPECT_DOUBLE_EQ(pair.law(Origin::source).mean_free_path(), 1.5);
  EXPECT_NEAR(numerical.mean_free_path(), 1.5, 1e-10);
}

TEST(ErlangLaw, IsGammaPathWithIntegerShape) {
  const Erlang erlang(5.0, 4.0);
  const GammaPath gamma(5.0, 0.25);
  for (double t : {0.01, 0.5, 2.0, 30.0}) {
    EXPECT_DOUBLE_EQ(erlang.transmittance(t), gamma.transmittance(t));
    // The Poisson sum e^{−λt} Σ_{n<k} (λt)^n/n!.
    double term = 1.0;
    double sum = 0.0;
    for (int n = 0; n < 5; ++n) {
      sum += term;
      term *= 4.0 * t / (n + 1);
    }
    EXPECT_NEAR(erlang.transmittance(t), std::exp(-4.0 * t) * sum, 1e-14);
  }
}

TEST(DerivedLaws, NumericalPartnersMatchClosedForms) {
  // The gamma law's closed-form partners against the numerical derivations.
  const auto gamma = std::make_shared<GammaConcentration>(1.0, 3.0);
  const ScattererFromSource numerical_s(gamma);
  const auto closed_s = gamma->closed_form_scatterer_partner();
  const SourceFromScatterer numerical_q(std::make_shared<GammaConcentration>(1.0, 6.0));
  const auto closed_q = GammaConcentration(1.0, 6.0).closed_form_source_partner();
  for (double t : {0.0, 0.2, 1.0, 4.0, 20.0}) {
    EXPECT_NEAR(numerical_s.transmittance(t), closed_s->transmittance(t), 1e-14);
    EXPECT_NEAR(numerical_s.pdf(t), closed_s->pdf(t), 1e-8);
    EXPECT_NEAR(numerical_q.transmittance(t), closed_q->transmittance(t), 1e-9);
    EXPECT_NEAR(numerical_q.pdf(t), closed_q->pdf(t), 1e-9);
  }
  EXPECT_DOUBLE_EQ(numerical_s.mean_free_path(), closed_s->mean_free_path());
  EXPECT_NEAR(numerical_q.mean_free_path(), closed_q->mean_free_path(), 1e-6);
  // Linear T_S gives T_Q = (1 − μ̄t)².
  const SourceFromScatterer linear_q(std::make_shared<Linear>(2.0));
  for (double t : {0.0, 0.1, 0.3, 0.49}) {
    EXPECT_NEAR(linear_q.transmittance(t), (1 - 2 * t) * (1 - 2 * t), 1e-12);
  }
}

}  // namespace
}  // namespace weft::transmittance

namespace weft::transmittance {
namespace {

TEST(GammaPathLaw, HazardStaysFiniteWherePdfAndTransmittanceUnderflow) {
  for (double k : {1e-3, 0.5, 1.0, 4.0, 100.0}) {
    for (double theta : {1.0, 0.25}) {
      const GammaPath law(k, theta);
      const double t = 1e4 * theta;  // x = 1e4: Q(k, x) ≈ e^{−1e4} underflows, as does the pdf
      EXPECT_EQ(law.transmittance(t), 0.0) << k;
      EXPECT_EQ(law.pdf(t), 0.0) << k;
      const double hazard = law.hazard(t);
      ASSERT_TRUE(std::isfinite(hazard)) << k;
      // Σ = 1/(θ x CF) with x·CF = 1 + (k−1)/x + O(x^−2): Σθ = 1 − (k−1)/x + O(x^−2).
      EXPECT_NEAR(hazard * theta, 1.0 - (k - 1.0) / 1e4, 1e-6) << k;
      // log Q = −x + (k−1) log x − log Γ(k) + log(x·CF)
      const double expected = -1e4 + (k - 1.0) * std::log(1e4) - std::lgamma(k) - std::log(hazard * theta);
      EXPECT_NEAR(law.log_transmittance(t), expected, 1e-9 * 1e4) << k;
    }
  }
  EXPECT_DOUBLE_EQ(GammaPath(3.0, 2.0).hazard(kInfinity), 0.5);
}

}  // namespace
}  // namespace weft::transmittance
