// The gap-aware gamma law and the gamma mixture: samplers by KS against their own CDF
// plus a binomial test of the "no collision" fraction, the hard limits (f0 → 0 is the gamma law,
// α → ∞ gap + exponential, μ̄ = 0), the reciprocal partners derived in docs/transmittance.md
// checked against the numerical derivation, and the registry laws through TransmittancePair (the
// way a renderer's homogeneous slab uses them).
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <boost/math/quadrature/tanh_sinh.hpp>

#include "error_matchers.h"
#include "ks.h"
#include "weft/core/error.h"
#include "weft/transmittance/derived.h"
#include "weft/transmittance/exponential.h"
#include "weft/transmittance/gamma_concentration.h"
#include "weft/transmittance/gamma_mixture.h"
#include "weft/transmittance/gap_gamma.h"
#include "weft/transmittance/pair.h"
#include "weft/transmittance/registry.h"

namespace weft::transmittance {
namespace {

using testing::draw;
using testing::ks_critical_value;
using testing::ks_statistic;
using testing::kSamples;
using testing::law_cdf;

/// Two-sided normal quantile at the KS tests' significance 1e−4: P(|Z| > 3.8906) = 1e−4.
constexpr double kZ = 3.8906;

/// The escapes (+∞ draws) number k ~ Binomial(n, f0): |k − n f0| ≤ z·√(n f0 (1 − f0)), plus one
/// draw of slack for the discreteness when f0 is tiny.
::testing::AssertionResult escape_fraction_matches(const std::vector<double>& samples, double f0) {
  double escapes = 0.0;
  for (double t : samples) escapes += t == kInfinity ? 1.0 : 0.0;
  const double n = static_cast<double>(samples.size());
  const double tolerance = kZ * std::sqrt(n * f0 * (1.0 - f0)) + 1.0;
  if (std::fabs(escapes - n * f0) <= tolerance) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << escapes << " escapes of " << n << ", expected " << n * f0 << " ± "
                                       << tolerance;
}

/// KS of the finite draws against the law's CDF conditional on a collision, (1 − T)/(1 − T(∞)).
double conditional_ks(const std::vector<double>& samples, const Law& law, double& critical) {
  std::vector<double> finite;
  for (double t : samples) {
    if (t != kInfinity) finite.push_back(t);
  }
  const double escape = law.transmittance(kInfinity);
  critical = ks_critical_value(static_cast<int>(finite.size()));
  return ks_statistic(finite, [&](double t) { return (1.0 - law.transmittance(t)) / (1.0 - escape); });
}

struct GapCase {
  double gap, mean, alpha;
};

class GapGammaSampler : public ::testing::TestWithParam<GapCase> {};

TEST_P(GapGammaSampler, MatchesItsCdfAndEscapeFraction) {
  const auto [gap, mean, alpha] = GetParam();
  const GapGamma law(gap, mean, alpha);
  const auto samples = draw([&](Pcg32& rng) { return law.sample(rng); }, 1301);
  EXPECT_TRUE(escape_fraction_matches(samples, gap));
  double critical = 0.0;
  EXPECT_LT(conditional_ks(samples, law, critical), critical) << "conditional on a collision";
  EXPECT_LT(ks_statistic(samples, law_cdf(law)), ks_critical_value(kSamples)) << "unconditional";
}

INSTANTIATE_TEST_SUITE_P(Cases, GapGammaSampler,
                         ::testing::Values(GapCase{0.0, 2.5, 2.0}, GapCase{0.05, 2.5, 1e-3}, GapCase{0.3, 2.5, 0.5},
                                           GapCase{0.3, 2.5, 2.0}, GapCase{0.3, 2.5, 1e8}, GapCase{0.3, 2.5, kInfinity},
                                           GapCase{0.9, 2.5, 3.0}, GapCase{0.3, 1e-300, 2.0}, GapCase{0.3, 1e300, 2.0}),
                         [](const ::testing::TestParamInfo<GapCase>& info) { return std::to_string(info.index); });

TEST(GapGammaSampler, TestsRejectAWrongGapAndAMissingGap) {
  // Negative controls: draws of f0 = 0.32 tested as f0 = 0.3 fail the binomial test (13 standard
  // errors), draws without the gap fail the unconditional KS.
  const GapGamma law(0.3, 2.5, 2.0);
  const GapGamma wrong(0.32, 2.5, 2.0);
  EXPECT_FALSE(escape_fraction_matches(draw([&](Pcg32& rng) { return wrong.sample(rng); }, 5), 0.3));
  const GammaConcentration no_gap(2.5, 2.0);
  EXPECT_GT(ks_statistic(draw([&](Pcg32& rng) { return no_gap.sample(rng); }, 5), law_cdf(law)),
            ks_critical_value(kSamples));
}

TEST(GapGammaLaw, ZeroGapIsTheGammaLaw) {
  for (double alpha : {1e-6, 0.5, 2.0, 1e15, kInfinity}) {
    const GapGamma law(0.0, 1.5, alpha);
    const GammaConcentration gamma(1.5, alpha);
    for (double t : {0.0, 1e-300, 1e-3, 1.0, 40.0, 1e10, 1e300, kInfinity}) {
      SCOPED_TRACE(fmt::format("alpha = {}, t = {}", alpha, t));
      EXPECT_EQ(law.transmittance(t), gamma.transmittance(t));
      if (std::isinf(gamma.log_transmittance(t))) {
        EXPECT_EQ(law.log_transmittance(t), gamma.log_transmittance(t));
      } else {
        EXPECT_NEAR(law.log_transmittance(t), gamma.log_transmittance(t),
                    4e-16 * std::fabs(gamma.log_transmittance(t)));
      }
      EXPECT_NEAR(law.pdf(t), gamma.pdf(t), 1e-14 * gamma.pdf(t));
      EXPECT_NEAR(law.hazard(t), gamma.hazard(t), 1e-14 * gamma.hazard(t));
    }
    EXPECT_EQ(law.mean_free_path(), gamma.mean_free_path());
  }
}

TEST(GapGammaLaw, LargeAlphaIsGapPlusExponential) {
  const GapGamma law(0.4, 3.0, kInfinity);
  const GapGamma nearly(0.4, 3.0, 1e15);
  for (double t : {1e-3, 0.5, 2.0, 10.0}) {
    const double exact = 0.4 + 0.6 * std::exp(-3.0 * t);
    EXPECT_NEAR(law.transmittance(t), exact, 1e-15);
    EXPECT_NEAR(nearly.transmittance(t), exact, 1e-12);
    EXPECT_NEAR(law.pdf(t), 0.6 * 3.0 * std::exp(-3.0 * t), 1e-14);
  }
}

TEST(GapGammaLaw, PlateauInfiniteMeanFreePathAndVacuum) {
  const GapGamma law(0.25, 2.0, 1.5);
  EXPECT_EQ(law.transmittance(kInfinity), 0.25);
  EXPECT_EQ(law.mean_free_path(), kInfinity);
  EXPECT_EQ(law.hazard(kInfinity), 0.0);
  // Gap near 1: log T keeps its digits (log1p of the fibre deficit, no cancellation).
  const double f0 = 1.0 - 1e-12;
  const GapGamma open(f0, 2.0, 1.5);
  const double deficit = (1.0 - f0) * -std::expm1(-1.5 * std::log1p(2.0 * 10.0 / 1.5));
  EXPECT_NEAR(open.log_transmittance(10.0), std::log1p(-deficit), 1e-15 * deficit);
  // Mean extinction 0: nothing collides anywhere.
  const GapGamma vacuum(0.3, 0.0, 2.0);
  Pcg32 rng = stream_for(3, 0);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(vacuum.sample(rng), kInfinity);
  EXPECT_EQ(vacuum.transmittance(1e300), 1.0);
  EXPECT_EQ(vacuum.pdf(1.0), 0.0);
  EXPECT_EQ(vacuum.hazard(1.0), 0.0);
}

/// ∫_a^b f by tanh-sinh on 32 pieces.
double integrate(const std::function<double(double)>& f, double a, double b) {
  boost::math::quadrature::tanh_sinh<double> integrator;
  double sum = 0.0;
  for (int i = 0; i < 32; ++i) sum += integrator.integrate(f, a + (b - a) * i / 32, a + (b - a) * (i + 1) / 32);
  return sum;
}

TEST(GapGammaLaw, ScattererPartnerHasNoGapAndMatchesTheNumericalDerivation) {
  const double f0 = 0.35;
  const double mean = 2.0;
  const double alpha = 1.7;
  const auto law = std::make_shared<GapGamma>(f0, mean, alpha);
  const auto pair = TransmittancePair::reciprocal(law, Origin::source);
  const Law& s = pair.law(Origin::scatterer);
  const ScattererFromSource numerical(law);
  EXPECT_EQ(s.name(), "gamma");
  EXPECT_EQ(s.transmittance(kInfinity), 0.0) << "a scatterer sits in a yarn: T_S has no gap";
  EXPECT_NEAR(s.mean_free_path(), 1.0 / mean, 1e-15);
  EXPECT_NEAR(numerical.mean_free_path(), 1.0 / mean, 1e-15);
  for (double t : {0.0, 0.01, 0.3, 1.0, 4.0, 30.0}) {
    SCOPED_TRACE(fmt::format("t = {}", t));
    const double ts = std::pow(1.0 + mean * t / alpha, -(alpha + 1.0));  // the derivation, independently
    EXPECT_NEAR(s.transmittance(t), ts, 1e-14);
    EXPECT_NEAR(numerical.transmittance(t), ts, 1e-14);
    EXPECT_NEAR(s.pdf(t), numerical.pdf(t), 1e-7 * mean);
    // The reciprocity on the rays that collide: p_Q = (1 − f0)·T_S/ℓ_S, i.e. T_S = p_Q/p_Q(0).
    EXPECT_NEAR(law->pdf(t), (1.0 - f0) * s.transmittance(t) / s.mean_free_path(), 1e-13);
    // ∫₀ᵗ p_Q = 1 − T_Q.
    if (t > 0.0) {
      EXPECT_NEAR(integrate([&](double v) { return law->pdf(v); }, 0.0, t), 1.0 - law->transmittance(t), 1e-10);
    }
  }
  // ℓ_S = ∫T_S: quadrature to L = 50 plus the tail ∫_L^∞ (1 + μ̄t/α)^−(α+1) dt = (1 + μ̄L/α)^−α/μ̄.
  const double tail = std::pow(1.0 + mean * 50.0 / alpha, -alpha) / mean;
  EXPECT_NEAR(integrate([&](double v) { return s.transmittance(v); }, 0.0, 50.0) + tail, s.mean_free_path(), 1e-9);
  // The scatterer samples: KS against (1 + μ̄t/α)^−(α+1).
  const auto samples = draw([&](Pcg32& rng) { return pair.sample(Origin::scatterer, rng); }, 71);
  EXPECT_LT(ks_statistic(samples, [&](double t) { return 1.0 - std::pow(1.0 + mean * t / alpha, -(alpha + 1.0)); }),
            ks_critical_value(kSamples));
}

TEST(GapGammaLaw, AsScattererLawThePairRefuses) {
  const auto law = std::make_shared<GapGamma>(0.2, 1.0, 3.0);
  EXPECT_THAT([&] { (void)TransmittancePair::reciprocal(law, Origin::scatterer); },
              ::testing::ThrowsMessage<Error>(::testing::HasSubstr("infinite mean free path")));
  // Without a gap it is the gamma law, whose source partner has shape α − 1.
  const auto no_gap = std::make_shared<GapGamma>(0.0, 1.0, 3.0);
  const auto pair = TransmittancePair::reciprocal(no_gap, Origin::scatterer);
  EXPECT_NEAR(pair.law(Origin::source).transmittance(2.0), std::pow(1.0 + 2.0 / 3.0, -2.0), 1e-15);
}

// ---- gamma-mixture ----

LawSpec mixture_spec(const std::vector<std::array<double, 3>>& components) {
  LawSpec spec;
  spec.name = "gamma-mixture";
  for (std::size_t i = 0; i < components.size(); ++i) {
    spec.params[list_parameter_key("weight", i)] = components[i][0];
    spec.params[list_parameter_key("alpha", i)] = components[i][1];
    spec.params[list_parameter_key("mean_extinction", i)] = components[i][2];
  }
  return spec;
}

/// (1 + μ̄t/α)^−shape, or e^{−μ̄t} for α = ∞, without overflowing μ̄t (the KS test asks for the CDF
/// at DBL_MAX, just below an atom at +∞): for t > 1e300, log(1 + x) = log x to double precision.
double gamma_power(double mu, double alpha, double shape, double t) {
  if (t == kInfinity) return 0.0;
  if (t > 1e300) return alpha == kInfinity ? 0.0 : std::exp(-shape * (std::log(mu) + std::log(t) - std::log(alpha)));
  return alpha == kInfinity ? std::exp(-mu * t) : std::pow(1.0 + mu * t / alpha, -shape);
}

/// T of a mixture written out from its definition (independent of GammaMixture's evaluation).
double mixture_t(const std::vector<std::array<double, 3>>& c, double t) {
  double sum = 0.0;
  for (const auto& [w, alpha, mu] : c) sum += mu == 0.0 ? w : w * gamma_power(mu, alpha, alpha, t);
  return sum;
}

const std::vector<std::vector<std::array<double, 3>>>& mixtures() {
  static const std::vector<std::vector<std::array<double, 3>>> all = {
      {{0.2, 1.0, 0.0}, {0.8, 3.0, 5.0}},
      {{0.25, 0.5, 1.0}, {0.75, kInfinity, 10.0}},
      {{0.1, 2.0, 0.0}, {0.0, 4.0, 3.0}, {0.3, 1.5, 0.5}, {0.6, 8.0, 6.0}},
      {{0.5, kInfinity, 1.0}, {0.5, kInfinity, 3.0}},
  };
  return all;
}

class MixtureCase : public ::testing::TestWithParam<std::size_t> {};

TEST_P(MixtureCase, EvaluatesItsDefinition) {
  const auto& c = mixtures()[GetParam()];
  const LawPtr law = make_law(mixture_spec(c));
  for (double t : {0.0, 1e-3, 0.1, 1.0, 3.0, 20.0, kInfinity}) {
    SCOPED_TRACE(fmt::format("t = {}", t));
    const double want = mixture_t(c, t);
    EXPECT_NEAR(law->transmittance(t), want, 1e-14);
    if (want > 0.0) {
      EXPECT_NEAR(law->log_transmittance(t), std::log(want), 1e-13);
    }
    if (t > 0.0 && std::isfinite(t)) {
      const double h = 1e-6 * t;  // p = −dT/dt by central differences of the definition
      EXPECT_NEAR(law->pdf(t), (mixture_t(c, t - h) - mixture_t(c, t + h)) / (2 * h), 1e-6 * law->pdf(0.0));
      EXPECT_NEAR(law->hazard(t), law->pdf(t) / law->transmittance(t), 1e-12 * law->hazard(t));
    }
  }
  double gaps = 0.0;
  for (const auto& comp : c) gaps += comp[2] == 0.0 ? comp[0] : 0.0;
  EXPECT_EQ(law->transmittance(kInfinity), gaps);
  if (gaps > 0.0) {
    EXPECT_EQ(law->mean_free_path(), kInfinity);
  }
}

TEST_P(MixtureCase, SamplerMatchesItsCdfAndEscapeFraction) {
  const auto& c = mixtures()[GetParam()];
  const LawPtr law = make_law(mixture_spec(c));
  const auto samples = draw([&](Pcg32& rng) { return law->sample(rng); }, 4401 + GetParam());
  EXPECT_TRUE(escape_fraction_matches(samples, law->transmittance(kInfinity)));
  EXPECT_LT(ks_statistic(samples, [&](double t) { return 1.0 - mixture_t(c, t); }), ks_critical_value(kSamples));
}

TEST_P(MixtureCase, ScattererPartnerIsWeightedByExtinction) {
  // T_S = Σ w_i μ̄_i (1 + μ̄_i t/α_i)^−(α_i+1) / Σ w_i μ̄_i, written out; and the numerical T_S.
  const auto& c = mixtures()[GetParam()];
  const LawPtr law = make_law(mixture_spec(c));
  const auto pair = TransmittancePair::reciprocal(law, Origin::source);
  const Law& s = pair.law(Origin::scatterer);
  const ScattererFromSource numerical(law);
  const auto ts = [&](double t) {
    double num = 0.0;
    double den = 0.0;
    for (const auto& [w, alpha, mu] : c) {
      den += w * mu;
      num += w * mu * gamma_power(mu, alpha, alpha + 1.0, t);
    }
    return num / den;
  };
  EXPECT_EQ(s.transmittance(kInfinity), 0.0);
  EXPECT_NEAR(s.mean_free_path(), numerical.mean_free_path(), 1e-13 * s.mean_free_path());
  const double escape = law->transmittance(kInfinity);
  for (double t : {0.0, 0.01, 0.2, 1.0, 5.0}) {
    SCOPED_TRACE(fmt::format("t = {}", t));
    EXPECT_NEAR(s.transmittance(t), ts(t), 1e-14);
    EXPECT_NEAR(numerical.transmittance(t), ts(t), 1e-14);
    EXPECT_NEAR(s.pdf(t), numerical.pdf(t), 1e-6 * s.pdf(0.0));
    EXPECT_NEAR(law->pdf(t), (1.0 - escape) * s.transmittance(t) / s.mean_free_path(), 1e-13 * law->pdf(0.0));
  }
  const auto samples = draw([&](Pcg32& rng) { return pair.sample(Origin::scatterer, rng); }, 91 + GetParam());
  EXPECT_LT(ks_statistic(samples, [&](double t) { return 1.0 - ts(t); }), ks_critical_value(kSamples));
}

INSTANTIATE_TEST_SUITE_P(Mixtures, MixtureCase, ::testing::Range<std::size_t>(0, 4));

TEST(GammaMixtureLaw, SourcePartnerMatchesTheNumericalDerivation) {
  const auto law = make_law(mixture_spec({{0.3, 2.5, 1.0}, {0.7, kInfinity, 4.0}}));
  const auto pair = TransmittancePair::reciprocal(law, Origin::scatterer);
  const SourceFromScatterer numerical(law);
  EXPECT_EQ(pair.law(Origin::source).name(), "gamma-mixture");
  EXPECT_NEAR(pair.law(Origin::source).mean_free_path(), numerical.mean_free_path(), 1e-9);
  for (double t : {0.0, 0.1, 0.7, 3.0, 12.0}) {
    EXPECT_NEAR(pair.law(Origin::source).transmittance(t), numerical.transmittance(t), 1e-10) << t;
    EXPECT_NEAR(pair.law(Origin::source).pdf(t), law->transmittance(t) / law->mean_free_path(), 1e-14) << t;
  }
}

TEST(GammaMixtureLaw, GapGammaIsTheTwoComponentMixture) {
  const GapGamma gap(0.3, 2.0, 1.5);
  const auto mixture = make_law(mixture_spec({{0.3, kInfinity, 0.0}, {0.7, 1.5, 2.0}}));
  for (double t : {0.0, 0.5, 3.0, 1e6}) {
    EXPECT_NEAR(gap.transmittance(t), mixture->transmittance(t), 1e-16);
    EXPECT_NEAR(gap.pdf(t), mixture->pdf(t), 1e-15);
  }
}

TEST(GammaMixtureLaw, ParametersRoundTripThroughTheRegistry) {
  const auto law = make_law(mixture_spec({{0.2, 1.0, 0.0}, {0.8, kInfinity, 5.0}}));
  LawSpec again;
  again.name = law->name();
  for (const auto& p : law->parameters()) again.params[p.name] = p.value;
  const auto copy = make_law(again);
  EXPECT_EQ(copy->parameters().size(), 6u);
  for (double t : {0.0, 0.3, 2.0}) EXPECT_EQ(copy->transmittance(t), law->transmittance(t));
  const auto gap =
      make_law(LawSpec{"gap-gamma", {{"gap", 0.1}, {"sigma", 2.0}, {"alpha", 3.0}, {"beta", 6.0}}, "", ""});
  EXPECT_EQ(gap->parameters()[1].name, "mean_extinction");
  EXPECT_DOUBLE_EQ(gap->parameters()[1].value, 1.0);  // σα/β
}

/// The registry law through TransmittancePair in reciprocal mode, as a homogeneous slab of a
/// renderer uses it: segments from a surface see T_Q (with its escapes), from a scatterer T_S.
TEST(RegistryLaws, WorkAsReciprocalSlabLaws) {
  const LawSpec specs[] = {
      {"gap-gamma", {{"gap", 0.3}, {"mean_extinction", 4.0}, {"alpha", 1.2}}, "", ""},
      mixture_spec({{0.2, 1.0, 0.0}, {0.8, 3.0, 5.0}}),
  };
  for (const auto& spec : specs) {
    SCOPED_TRACE(spec.name);
    const auto pair = TransmittancePair::reciprocal(make_law(spec), Origin::source);
    EXPECT_EQ(pair.mode(), PairMode::reciprocal);
    const auto q = draw([&](Pcg32& rng) { return pair.sample(Origin::source, rng); }, 17);
    EXPECT_TRUE(escape_fraction_matches(q, 0.3 - (spec.name == "gamma-mixture" ? 0.1 : 0.0)));
    const auto s = draw([&](Pcg32& rng) { return pair.sample(Origin::scatterer, rng); }, 18);
    for (double t : s) ASSERT_TRUE(std::isfinite(t)) << "a scatterer segment always collides";
    EXPECT_LT(ks_statistic(s, law_cdf(pair.law(Origin::scatterer))), ks_critical_value(kSamples));
    // A slab of thickness d: the transmitted fraction of source segments is T_Q(d).
    const double d = 0.4;
    double through = 0.0;
    for (double t : q) through += t > d ? 1.0 : 0.0;
    const double tq = pair.transmittance(Origin::source, d);
    EXPECT_NEAR(through / kSamples, tq, kZ * std::sqrt(tq * (1 - tq) / kSamples));
  }
}

TEST(GammaMixtureLaw, RejectsBadParametersInOneLine) {
  const auto expect_error = [](const LawSpec& spec, std::initializer_list<std::string> parts) {
    EXPECT_THAT([&] { (void)make_law(spec); }, weft::test::throws_one_line_error_with(parts)) << spec.name;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  expect_error(mixture_spec({{0.5, 1.0, 1.0}, {0.4, 1.0, 2.0}}), {"gamma-mixture", "sum to 0.9", "1"});
  expect_error(mixture_spec({{1.2, 1.0, 1.0}, {-0.2, 1.0, 2.0}}), {"weight_2", ">= 0"});
  expect_error(mixture_spec({{nan, 1.0, 1.0}}), {"weight_1", "nan"});
  expect_error(mixture_spec({{1.0, nan, 1.0}}), {"alpha_1", "nan"});
  expect_error(mixture_spec({{1.0, 0.0, 1.0}}), {"alpha_1", "> 0"});
  expect_error(mixture_spec({{1.0, 1.0, nan}}), {"mean_extinction_1"});
  expect_error(mixture_spec({{1.0, 1.0, kInfinity}}), {"mean_extinction_1", "finite"});
  expect_error(LawSpec{"gamma-mixture", {}, "", ""}, {"gamma-mixture", "no components"});
  auto unequal = mixture_spec({{0.5, 1.0, 1.0}, {0.5, 1.0, 2.0}});
  unequal.params.erase("alpha_2");
  expect_error(unequal, {"missing parameter alpha_2", "same length"});
  auto misspelt = mixture_spec({{1.0, 1.0, 1.0}});
  misspelt.params["wieght_2"] = 0.0;
  expect_error(misspelt, {"unknown parameter 'wieght_2'", "weight"});
  auto zero_padded = mixture_spec({{1.0, 1.0, 1.0}});
  zero_padded.params["alpha_01"] = 1.0;
  expect_error(zero_padded, {"unknown parameter 'alpha_01'"});
  expect_error(LawSpec{"gap-gamma", {{"gap", 1.0}, {"mean_extinction", 1.0}, {"alpha", 2.0}}, "", ""},
               {"gap-gamma", "gap", "[0, 1)", "vacuum"});
  expect_error(LawSpec{"gap-gamma", {{"gap", nan}, {"mean_extinction", 1.0}, {"alpha", 2.0}}, "", ""}, {"gap", "nan"});
  expect_error(LawSpec{"gap-gamma", {{"gap", 0.1}, {"mean_extinction", -1.0}, {"alpha", 2.0}}, "", ""},
               {"gap-gamma", "mean_extinction"});
  expect_error(LawSpec{"gap-gamma", {{"gap", 0.1}, {"sigma", 1.0}, {"alpha", 2.0}, {"beta", 0.0}}, "", ""},
               {"gap-gamma law", "beta"});
  expect_error(LawSpec{"gap-gamma", {{"mean_extinction", 1.0}, {"alpha", 2.0}}, "", ""}, {"gap-gamma", "gap"});
}

}  // namespace
}  // namespace weft::transmittance
