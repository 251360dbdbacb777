// Law selection with parsimony (law_fit.h): on free-path histograms drawn from a law with
// independent Gaussian noise, the richer laws' lower chi2 does not win unless the data need it.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "data_gen/media2d/law_fit.h"
#include "weft/core/error.h"
#include "weft/core/rng.h"

namespace weft::media2d {
namespace {

struct Data {
  std::vector<double> t, T, sigma;
};

// Bin densities (T(t_k) − T(t_{k+1}))/w of a law over edges t_k = 0.1 k, k = 0..60, plus
// N(0, s_k²) with s_k = sqrt(density/(N w)) (the Poisson error of N free paths), by Box–Muller
// from a fixed PCG stream.
template <typename Law>
Data noisy_histogram(Law T, double N, std::uint64_t seed) {
  Data d;
  Pcg32 rng = stream_for(seed, 0);
  const double w = 0.1;
  for (int k = 0; k <= 60; ++k) d.t.push_back(w * k);
  for (int k = 0; k < 60; ++k) {
    const double p = (T(d.t[k]) - T(d.t[k + 1])) / w;
    const double s = std::sqrt(p / (N * w));
    const double z = std::sqrt(-2.0 * std::log(rng.uniform_open())) * std::cos(2.0 * std::numbers::pi * rng.uniform());
    d.T.push_back(p + s * z);
    d.sigma.push_back(s);
  }
  return d;
}

std::vector<LawFit> fit_all(const Data& d) {
  const std::string curve = "p";
  std::vector<LawFit> fits;
  for (const char* law : {"exponential", "gamma", "linear", "gamma-path"}) {
    LawFit f = fit_law_binned(law, d.t, d.T, d.sigma, 1e-9);
    f.curve = curve;
    fits.push_back(std::move(f));
  }
  return fits;
}

const LawFit& find(const std::vector<LawFit>& fits, const std::string& law) {
  for (const auto& f : fits) {
    if (f.law == law) return f;
  }
  throw Error("no fit of " + law);
}

TEST(LawSelection, BicIsChi2PlusParametersTimesLogPoints) {
  LawFit f;
  f.chi2 = 10.0;
  f.params = {1.0, 2.0};
  f.dof = 59;
  EXPECT_DOUBLE_EQ(bic(f), 10.0 + 2.0 * std::log(61.0));
}

TEST(LawSelection, ExponentialDataSelectTheExponentialOverRicherLawsThatFitAsWell) {
  for (std::uint64_t seed : {1, 2, 3}) {
    const auto fits = fit_all(noisy_histogram([](double t) { return std::exp(-t); }, 2e4, seed));
    const LawSelection s = select_law(fits, "p");
    EXPECT_EQ(s.selected, "exponential") << "seed " << seed;
    EXPECT_NEAR(find(fits, "exponential").params[0], 1.0, 5.0 * find(fits, "exponential").errors[0]);
    // gamma and gamma-path contain the exponential: their chi2 is never meaningfully above it.
    EXPECT_LE(find(fits, "gamma-path").chi2, find(fits, "exponential").chi2 * (1.0 + 1e-6));
    EXPECT_GE(s.delta_bic, 0.0);
    EXPECT_FALSE(s.runner_up.empty());
    EXPECT_GT(s.runner_up_delta_bic, 0.0);
  }
}

TEST(LawSelection, GammaDataSelectTheGammaLaw) {
  const double alpha = 1.5;
  for (std::uint64_t seed : {1, 2, 3}) {
    const auto fits = fit_all(noisy_histogram([&](double t) { return std::pow(1.0 + t / alpha, -alpha); }, 2e4, seed));
    const LawSelection s = select_law(fits, "p");
    EXPECT_EQ(s.selected, "gamma") << "seed " << seed;
    EXPECT_EQ(s.lowest_chi2, "gamma") << "seed " << seed;
    EXPECT_DOUBLE_EQ(s.delta_chi2, 0.0);
  }
}

TEST(LawSelection, RefusesACurveWithNoFits) { EXPECT_THROW((void)select_law({}, "T_Q_iso"), Error); }

}  // namespace
}  // namespace weft::media2d
