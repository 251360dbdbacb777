// Every sampler against its own exact CDF: Kolmogorov–Smirnov, 1e5 samples, fixed seeds,
// critical value at significance 1e−4 (ks.h). Negative controls show the test catches a wrong
// inverse such as S.51 as printed.
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "ks.h"
#include "weft/transmittance/derived.h"
#include "weft/transmittance/erlang.h"
#include "weft/transmittance/exponential.h"
#include "weft/transmittance/gamma_concentration.h"
#include "weft/transmittance/gamma_path.h"
#include "weft/transmittance/linear.h"
#include "weft/transmittance/pair.h"
#include "weft/transmittance/tabulated.h"

namespace weft::transmittance {
namespace {

using testing::draw;
using testing::ks_critical_value;
using testing::ks_statistic;
using testing::kSamples;
using testing::law_cdf;

struct SamplerCase {
  std::string label;
  std::function<LawPtr()> make;
};

std::string test_name(const std::string& label) {
  std::string name = label;
  for (auto& c : name) {
    if (c == '-') c = 'm';
    if (c == '+') c = 'p';
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

Tabulated gamma_table(double alpha, int points, double last_t) {
  const GammaConcentration reference(1.0, alpha);
  std::vector<double> t{0.0};
  std::vector<double> value{1.0};
  for (int i = 1; i < points; ++i) {
    t.push_back(last_t * std::pow(1e-3, 1.0 - static_cast<double>(i) / (points - 1)));
    value.push_back(reference.transmittance(t.back()));
  }
  return {t, value, "gamma table"};
}

std::vector<SamplerCase> cases() {
  std::vector<SamplerCase> out;
  for (double mu : {1e-300, 1.0, 1e300}) {
    out.push_back({fmt::format("exponential mu={}", mu), [mu] { return std::make_shared<Exponential>(mu); }});
  }
  for (double alpha : {1e-6, 1e-3, 0.5, 1 - 1e-9, 1.0, 1 + 1e-9, 2.0, 1e3, 1e8, 1e15, kInfinity}) {
    out.push_back(
        {fmt::format("gamma alpha={}", alpha), [alpha] { return std::make_shared<GammaConcentration>(1.0, alpha); }});
  }
  out.push_back({"gamma mean=7.5 alpha=0.3", [] { return std::make_shared<GammaConcentration>(7.5, 0.3); }});
  for (double mu : {1.0, 3.0}) {
    out.push_back({fmt::format("linear mean={}", mu), [mu] { return std::make_shared<Linear>(mu); }});
  }
  // k = 10¹⁰, the largest the law accepts: inversion by the quantile's Cornish–Fisher branch
  // (gamma_path.h) against Boost's forward CDF.
  for (double k : {1e-3, 0.5, 1.0, 4.0, 100.0, 1e4, 1e10}) {
    for (auto sampler : {GammaSampler::marsaglia_tsang, GammaSampler::inversion}) {
      out.push_back({fmt::format("gamma-path k={} {}", k, to_string(sampler)),
                     [k, sampler] { return std::make_shared<GammaPath>(k, 2.5, sampler); }});
    }
  }
  for (double k : {1.0, 2.0, 5.0, 50.0}) {
    out.push_back({fmt::format("erlang k={}", k), [k] { return std::make_shared<Erlang>(k, 2.0); }});
  }
  for (double k : {2.0, 7.0, 40.0}) {
    out.push_back({fmt::format("erlang-source k={}", k), [k] { return std::make_shared<ErlangMixture>(k, 1.5); }});
  }
  out.push_back({"tabulated gamma alpha=0.7", [] { return std::make_shared<Tabulated>(gamma_table(0.7, 40, 1e4)); }});
  out.push_back({"tabulated to zero", [] {
                   return std::make_shared<Tabulated>(std::vector<double>{0, 0.5, 1.0, 2.0},
                                                      std::vector<double>{1, 0.6, 0.3, 0.0});
                 }});
  out.push_back({"tabulated never collides", [] {
                   return std::make_shared<Tabulated>(std::vector<double>{0, 1.0, 2.0, 3.0},
                                                      std::vector<double>{1, 0.5, 0.4, 0.4});
                 }});
  out.push_back({"derived scatterer of tabulated", [] {
                   return std::make_shared<ScattererFromSource>(std::make_shared<Tabulated>(gamma_table(1.5, 60, 1e3)));
                 }});
  out.push_back({"derived scatterer of erlang-source k=3",
                 [] { return std::make_shared<ScattererFromSource>(std::make_shared<ErlangMixture>(3.0, 1.0)); }});
  out.push_back({"derived source of linear",
                 [] { return std::make_shared<SourceFromScatterer>(std::make_shared<Linear>(2.0)); }});
  out.push_back({"derived source of gamma-path k=0.5",
                 [] { return std::make_shared<SourceFromScatterer>(std::make_shared<GammaPath>(0.5, 1.0)); }});
  out.push_back({"derived source of gamma-path k=4",
                 [] { return std::make_shared<SourceFromScatterer>(std::make_shared<GammaPath>(4.0, 0.25)); }});
  return out;
}

class SamplerMatchesCdf : public ::testing::TestWithParam<SamplerCase> {};

TEST_P(SamplerMatchesCdf, KolmogorovSmirnov) {
  const LawPtr law = GetParam().make();
  const auto samples = draw([&](Pcg32& rng) { return law->sample(rng); }, 20181);
  for (double x : samples) ASSERT_FALSE(std::isnan(x) || x < 0.0) << "sample " << x;
  const double d = ks_statistic(samples, law_cdf(*law));
  EXPECT_LT(d, ks_critical_value(kSamples)) << law->sampling_method();
}

INSTANTIATE_TEST_SUITE_P(Laws, SamplerMatchesCdf, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<SamplerCase>& info) { return test_name(info.param.label); });

TEST(ExponentialLaw, VacuumNeverCollides) {
  const Exponential vacuum(0.0);
  Pcg32 rng = stream_for(1, 0);
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(vacuum.sample(rng), kInfinity);
  EXPECT_EQ(vacuum.transmittance(kInfinity), 1.0);
  EXPECT_EQ(vacuum.transmittance(1e300), 1.0);
  EXPECT_EQ(vacuum.mean_free_path(), kInfinity);
}

TEST(GammaLaw, ProportionalToTransmittanceSamplingMatchesItsCdf) {
  for (double alpha : {1 + 1e-9, 1.5, 2.0, 1e3, 1e15, kInfinity}) {
    const GammaConcentration law(1.0, alpha);
    const auto samples = draw([&](Pcg32& rng) { return law.sample_proportional_to_transmittance(rng); }, 55);
    const double d = ks_statistic(samples, [&](double t) { return law.cdf_proportional_to_transmittance(t); });
    EXPECT_LT(d, ks_critical_value(kSamples)) << "alpha = " << alpha;
  }
}

TEST(GammaLaw, ProportionalToTransmittanceIsTheSourceLawOfThePairGivenAsScatterer) {
  // p ∝ T (S.55-S.57) is p_Q = T_S/l_S of the reciprocal pair given as T_S, which `weft model
  // --given S --from source` and Python's TransmittancePair.reciprocal(law, 'scatterer') draw:
  // the same draws from the same stream, up to rounding of the partner's parameters.
  for (double alpha : {1.5, 2.0, 7.0}) {
    const auto law = std::make_shared<GammaConcentration>(2.0, alpha);
    const TransmittancePair pair = TransmittancePair::reciprocal(law, Origin::scatterer);
    Pcg32 a = stream_for(11, 0);
    Pcg32 b = stream_for(11, 0);
    for (int i = 0; i < 1000; ++i) {
      const double direct = law->sample_proportional_to_transmittance(a);
      EXPECT_NEAR(pair.sample(Origin::source, b), direct, 1e-12 * direct) << "alpha = " << alpha;
    }
  }
}

TEST(GammaLaw, ProportionalToTransmittanceCdfIntegratesItsPdf) {
  // The CDF the KS test uses must itself be right: compare with T/ℓ integrated by the
  // trapezoid rule on a fine grid (independent of the closed form S.56).
  const GammaConcentration law(1.0, 2.5);
  double integral = 0.0;
  const int steps = 200000;
  const double t_end = 5.0;
  for (int i = 0; i < steps; ++i) {
    const double a = t_end * i / steps;
    const double b = t_end * (i + 1) / steps;
    integral += 0.5 * (b - a) * (law.pdf_proportional_to_transmittance(a) + law.pdf_proportional_to_transmittance(b));
  }
  EXPECT_NEAR(integral, law.cdf_proportional_to_transmittance(t_end), 1e-9);
}

// S.51 as printed: t = −(β/σ)(1 − (1−ξ)^{1/(1−α)}), i.e. S.57's inverse reused for p = −dT/dt.
double s51_as_printed(const GammaConcentration& law, Pcg32& rng) {
  const double xi = rng.uniform();
  const double scale = law.alpha() / law.mean_extinction();  // β/σ
  return -scale * (1.0 - std::pow(1.0 - xi, 1.0 / (1.0 - law.alpha())));
}

TEST(GammaLaw, KsTestRejectsTheMisprintedInverseOfS51) {
  // The misprint rescales E by α/(α−1); beyond α ≈ 50 that is below what 1e5 samples resolve.
  for (double alpha : {1.5, 2.0, 5.0, 20.0}) {
    const GammaConcentration law(1.0, alpha);
    const auto wrong = draw([&](Pcg32& rng) { return s51_as_printed(law, rng); }, 7);
    EXPECT_GT(ks_statistic(wrong, law_cdf(law)), ks_critical_value(kSamples)) << "alpha = " << alpha;
    // ... while the same samples are exactly what S.57 (p ∝ T) asks for.
    EXPECT_LT(ks_statistic(wrong, [&](double t) { return law.cdf_proportional_to_transmittance(t); }),
              ks_critical_value(kSamples))
        << "alpha = " << alpha;
  }
}

TEST(GammaPathLaw, KsTestRejectsAnOffByOneShape) {
  // A Marsaglia–Tsang without the k < 1 boost would draw G(k+1): the test must see it.
  const GammaPath law(0.5, 1.0);
  const GammaPath wrong(1.5, 1.0);
  const auto samples = draw([&](Pcg32& rng) { return wrong.sample(rng); }, 3);
  EXPECT_GT(ks_statistic(samples, law_cdf(law)), ks_critical_value(kSamples));
}

TEST(GammaPathLaw, SamplersAgreeWithEachOther) {
  // Two-sample KS between Marsaglia–Tsang and inversion: c(1e−4)·√(2/n).
  for (double k : {0.5, 4.0}) {
    const GammaPath mt(k, 1.0, GammaSampler::marsaglia_tsang);
    const GammaPath inv(k, 1.0, GammaSampler::inversion);
    auto a = draw([&](Pcg32& rng) { return mt.sample(rng); }, 11);
    auto b = draw([&](Pcg32& rng) { return inv.sample(rng); }, 12);
    std::sort(b.begin(), b.end());
    const auto empirical_b = [&](double t) {
      return static_cast<double>(std::upper_bound(b.begin(), b.end(), t) - b.begin()) / static_cast<double>(b.size());
    };
    const double d = ks_statistic(a, empirical_b);
    EXPECT_LT(d, ks_critical_value(kSamples) * std::sqrt(2.0)) << "k = " << k;
  }
}

TEST(Samplers, SameSeedSameSamples) {
  const GammaPath law(0.3, 1.0);
  EXPECT_EQ(draw([&](Pcg32& rng) { return law.sample(rng); }, 9, 1000),
            draw([&](Pcg32& rng) { return law.sample(rng); }, 9, 1000));
}

}  // namespace
}  // namespace weft::transmittance
