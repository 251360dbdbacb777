// Invalid parameters give a clear weft::Error naming the law and the parameter; the registry
// builds every parametrisation and suggests the closest name for a misspelling; reciprocal
// pairs refuse, saying why, where the derivation does not exist.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "error_matchers.h"
#include "weft/core/error.h"
#include "weft/transmittance/erlang.h"
#include "weft/transmittance/exponential.h"
#include "weft/transmittance/gamma_concentration.h"
#include "weft/transmittance/gamma_path.h"
#include "weft/transmittance/linear.h"
#include "weft/transmittance/pair.h"
#include "weft/transmittance/registry.h"
#include "weft/transmittance/tabulated.h"

namespace weft::transmittance {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

/// Runs `f`, expects weft::Error, and checks that the one-line message contains every `part`.
void expect_error(const std::function<void()>& f, std::initializer_list<std::string> parts) {
  EXPECT_THAT(f, weft::test::throws_one_line_error_with(parts));
}

TEST(LawValidation, RejectsNanNegativeAndNonPositive) {
  expect_error([] { (void)Exponential{kNan}; }, {"exponential", "mu"});
  expect_error([] { (void)Exponential{-1.0}; }, {"exponential", "mu", "-1"});
  expect_error([] { (void)Exponential{kInfinity}; }, {"mu"});
  expect_error([] { (void)GammaConcentration(kNan, 1.0); }, {"gamma", "mean_extinction"});
  expect_error([] { (void)GammaConcentration(1.0, 0.0); }, {"gamma", "alpha", "> 0"});
  expect_error([] { (void)GammaConcentration(1.0, -2.0); }, {"alpha"});
  expect_error([] { (void)GammaConcentration(1.0, kNan); }, {"alpha", "nan"});
  expect_error([] { (void)GammaConcentration::from_sigma_alpha_beta(1.0, 1.0, 0.0); }, {"beta"});
  expect_error([] { (void)GammaConcentration::from_sigma_alpha_beta(-1.0, 1.0, 1.0); }, {"sigma"});
  expect_error([] { (void)GammaConcentration::from_concentration(1.0, -0.1, 0.1); }, {"mean_concentration"});
  expect_error([] { (void)GammaConcentration::from_concentration(1.0, 0.1, kNan); }, {"var_concentration"});
  expect_error([] { (void)GammaConcentration::from_concentration(1.0, 0.0, 0.1); }, {"mean 0"});
  expect_error([] { (void)Linear(-0.5); }, {"linear", "mean_extinction"});
  expect_error([] { (void)GammaPath(0.0, 1.0); }, {"gamma-path", "k"});
  expect_error([] { (void)GammaPath(3e10, 1.0); }, {"gamma-path", "k must be at most 1e+10", "3e+10"});
  expect_error([] { (void)GammaPath(1.0, kNan); }, {"gamma-path", "theta"});
  expect_error([] { (void)Erlang(2.5, 1.0); }, {"erlang", "integer"});
  expect_error([] { (void)Erlang(2.0, 0.0); }, {"erlang", "rate"});
  expect_error([] { (void)parse_gamma_sampler("marsaglia"); }, {"sampler", "marsaglia-tsang"});
}

TEST(GammaLaw, ProportionalSamplingNeedsAlphaAboveOne) {
  for (double alpha : {0.5, 1.0, 1.0 - 1e-9}) {
    const GammaConcentration law(1.0, alpha);
    Pcg32 rng;
    expect_error([&] { (void)law.sample_proportional_to_transmittance(rng); }, {"alpha > 1"});
    expect_error([&] { (void)law.pdf_proportional_to_transmittance(1.0); }, {"alpha > 1"});
  }
  const GammaConcentration ok(1.0, 1.0 + 1e-9);
  Pcg32 rng;
  EXPECT_GE(ok.sample_proportional_to_transmittance(rng), 0.0);
}

TEST(TabulatedLaw, RejectsBadTables) {
  expect_error([] { (void)Tabulated({}, {}); }, {"tabulated", "at least 2"});
  expect_error([] { (void)Tabulated({0.0}, {1.0}); }, {"at least 2"});
  expect_error([] { (void)Tabulated({0.0, 1.0, 2.0}, {1.0, 0.5, 0.6}); }, {"must not increase", "sample 3"});
  expect_error([] { (void)Tabulated({0.0, 1.0, 1.0}, {1.0, 0.5, 0.4}); }, {"increase strictly"});
  expect_error([] { (void)Tabulated({0.0, 1.0}, {0.9, 0.5}); }, {"T(0) must be 1"});
  expect_error([] { (void)Tabulated({0.5, 1.0}, {1.0, 0.5}); }, {"t = 0"});
  expect_error([] { (void)Tabulated({0.0, 1.0}, {1.0, kNan}); }, {"[0, 1]"});
  expect_error([] { (void)Tabulated({0.0, 1.0}, {1.0, -0.1}); }, {"[0, 1]"});
  expect_error([] { (void)Tabulated({0.0, kNan}, {1.0, 0.5}); }, {"not finite"});
  expect_error([] { (void)Tabulated({0.0, 1.0}, {1.0}); }, {"2 t values but 1"});
}

TEST(TabulatedLaw, ReadsCsvAndRejectsBadFiles) {
  const auto dir = std::filesystem::temp_directory_path() / "weft_tabulated_test";
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream((dir / name).string()) << text;
    return (dir / name).string();
  };
  const Tabulated law = Tabulated::from_csv(write("ok.csv", "t,T\n# comment\n0,1\n1,0.5\n\n2,0.25\n"));
  EXPECT_EQ(law.t_samples().size(), 3U);
  EXPECT_NEAR(law.transmittance(1.5), std::sqrt(0.5) * 0.5, 1e-15);  // log-linear between samples
  EXPECT_NEAR(law.transmittance(3.0), 0.125, 1e-15);                 // tail: last hazard goes on
  EXPECT_NEAR(law.mean_free_path(), 1.0 / std::log(2.0), 1e-14);     // exactly exp(−t ln 2)
  expect_error([&] { (void)Tabulated::from_csv(write("empty.csv", "t,T\n")); }, {"empty.csv", "no samples"});
  expect_error([&] { (void)Tabulated::from_csv(write("bad.csv", "0,1\n1,abc\n")); }, {"bad.csv:2", "t,T"});
  expect_error([&] { (void)Tabulated::from_csv(write("up.csv", "0,1\n1,0.5\n2,0.7\n")); }, {"up.csv", "not increase"});
  expect_error([&] { (void)Tabulated::from_csv((dir / "missing.csv").string()); }, {"missing.csv", "cannot open"});
  std::filesystem::remove_all(dir);
}

TEST(Registry, BuildsEveryParametrisation) {
  EXPECT_EQ(make_law({"exponential", {{"mu", 2.0}}, {}})->mean_free_path(), 0.5);
  EXPECT_EQ(make_law({"gamma", {{"mean_extinction", 1.0}, {"alpha", 2.0}}, {}})->mean_free_path(), 2.0);
  const auto paper = make_law({"gamma", {{"sigma", 2.0}, {"alpha", 2.0}, {"beta", 4.0}}, {}});
  EXPECT_DOUBLE_EQ(paper->transmittance(1.0), std::pow(1.0 + 2.0 / 4.0, -2.0));
  const auto stats = make_law({"gamma", {{"sigma", 2.0}, {"mean_concentration", 0.5}, {"var_concentration", 0.0}}, {}});
  EXPECT_DOUBLE_EQ(stats->transmittance(1.0), std::exp(-1.0));
  EXPECT_EQ(make_law({"linear", {{"mean_extinction", 2.0}}, {}})->mean_free_path(), 0.25);
  EXPECT_EQ(make_law({"gamma-path", {{"k", 2.0}, {"theta", 3.0}}, {}})->mean_free_path(), 6.0);
  EXPECT_EQ(make_law({"gamma-path", {{"k", 2.0}, {"theta", 3.0}}, {}, "inversion"})->sampling_method().rfind("inv", 0),
            0U);
  EXPECT_EQ(make_law({"erlang", {{"k", 2.0}, {"rate", 1.0}}, {}})->mean_free_path(), 2.0);
  for (const auto& name : law_names()) EXPECT_FALSE(describe_law(name).empty()) << name;
}

TEST(Registry, MisspellingsSuggestTheClosestName) {
  expect_error(
      [] {
        (void)make_law({"gamme", {}, {}});
      },
      {"unknown transmittance law 'gamme'", "did you mean 'gamma'"});
  expect_error([] { (void)make_law({"gama-path", {}, {}}); }, {"did you mean 'gamma-path'"});
  expect_error(
      [] {
        (void)make_law({"gamma", {{"alpah", 1.0}, {"mean_extinction", 1.0}}, {}});
      },
      {"gamma law", "unknown parameter 'alpah'", "did you mean 'alpha'"});
  expect_error([] { (void)make_law({"gamma", {{"alpha", 1.0}}, {}}); }, {"gamma law", "accepted set"});
  expect_error([] { (void)make_law({"gamma-path", {{"k", 1.0}}, {}}); }, {"missing parameter theta"});
  expect_error([] { (void)make_law({"tabulated", {}, {}}); }, {"table file"});
  expect_error([] { (void)make_law({"linear", {{"mean_extinction", 1.0}}, "x.csv"}); }, {"only used by the tabulated"});
  expect_error([] { (void)make_law({"gamma", {{"mean_extinction", -1.0}, {"alpha", 1.0}}, {}}); }, {"mean_extinction"});
}

TEST(TransmittancePair, RefusesWhereTheDerivationDoesNotExist) {
  // Gamma T_S with α ≤ 1: ℓ_S = ∞.
  expect_error(
      [] { (void)TransmittancePair::reciprocal(std::make_shared<GammaConcentration>(1.0, 0.5), Origin::scatterer); },
      {"infinite mean free path"});
  expect_error(
      [] { (void)TransmittancePair::reciprocal(std::make_shared<GammaConcentration>(1.0, 1.0), Origin::scatterer); },
      {"infinite mean free path"});
  // Gamma-path k < 1 as T_Q: p_Q(0) = ∞; k > 1: p_Q(0) = 0.
  expect_error([] { (void)TransmittancePair::reciprocal(std::make_shared<GammaPath>(0.5, 1.0), Origin::source); },
               {"p_Q(0) = +inf"});
  expect_error([] { (void)TransmittancePair::reciprocal(std::make_shared<GammaPath>(2.0, 1.0), Origin::source); },
               {"p_Q(0) = 0"});
  expect_error([] { (void)TransmittancePair::reciprocal(std::make_shared<Exponential>(0.0), Origin::source); },
               {"p_Q(0) = 0"});
  // A tabulated T_Q whose hazard rises makes p_Q rise: T_S would increase.
  expect_error(
      [] {
        (void)TransmittancePair::reciprocal(
            std::make_shared<Tabulated>(std::vector<double>{0, 1, 2}, std::vector<double>{1, 0.9, 0.1}),
            Origin::source);
      },
      {"increases"});
  expect_error([] { (void)parse_pair_mode("reciprocals"); }, {"reciprocal, same, explicit"});
  expect_error([] { (void)parse_origin("X"); }, {"Q or source"});
}

TEST(TransmittancePair, ModesAndClosedForms) {
  const auto gamma = std::make_shared<GammaConcentration>(2.0, 0.5);
  const auto pair = TransmittancePair::reciprocal(gamma, Origin::source);
  const auto& s = dynamic_cast<const GammaConcentration&>(pair.law(Origin::scatterer));
  EXPECT_DOUBLE_EQ(s.alpha(), 1.5);
  EXPECT_DOUBLE_EQ(s.mean_extinction(), 2.0 * 1.5 / 0.5);
  EXPECT_DOUBLE_EQ(s.mean_free_path(), 0.5);  // ℓ_S = 1/μ̄
  EXPECT_EQ(pair.law(Origin::source).mean_free_path(), kInfinity);
  const auto back = TransmittancePair::reciprocal(pair.law_ptr(Origin::scatterer), Origin::scatterer);
  const auto& q = dynamic_cast<const GammaConcentration&>(back.law(Origin::source));
  EXPECT_DOUBLE_EQ(q.alpha(), 0.5);
  EXPECT_DOUBLE_EQ(q.mean_extinction(), 2.0);
  const auto same = TransmittancePair::same(gamma);
  EXPECT_EQ(same.mode(), PairMode::same);
  EXPECT_EQ(&same.law(Origin::source), &same.law(Origin::scatterer));
  const auto both = TransmittancePair::explicit_pair(gamma, std::make_shared<Exponential>(1.0));
  EXPECT_EQ(both.law(Origin::scatterer).name(), "exponential");
}

}  // namespace
}  // namespace weft::transmittance
