// Randomized property tests of the fits (docs/robustness.md): on random valid inputs over their whole
// range (log-uniform, with zeros and extremes), gamma moment matching and the Levenberg–Marquardt
// least-squares fit return parameters that are never NaN (finite, or +∞ where the docs say so:
// the exponential limit) or throw weft::Error; the model law they give obeys T in [0, 1]. Every
// failure prints the inputs. Seeds are fixed. WEFT_PROPERTY_LONG=1 runs the long sweep (ctest
// `fit_property_tests.long_sweep`, label `slow`): ten times the draws.
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/fit/gamma_moments.h"
#include "weft/fit/least_squares.h"

namespace weft::fit {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// The short (default) or long (WEFT_PROPERTY_LONG=1) number of draws.
int draws(int short_sweep) {
  const char* env = std::getenv("WEFT_PROPERTY_LONG");
  const bool long_sweep = env != nullptr && std::string(env) != "0" && std::string(env) != "";
  return long_sweep ? 10 * short_sweep : short_sweep;
}

double log_uniform(Pcg32& rng, double lo, double hi) {
  return std::exp(std::log(lo) + rng.uniform() * (std::log(hi) - std::log(lo)));
}

/// 0 sometimes, an extreme sometimes, else log-uniform over [1e-12, 1e12].
double non_negative(Pcg32& rng) {
  const double u = rng.uniform();
  if (u < 0.1) return 0.0;
  if (u < 0.2) return rng.uniform() < 0.5 ? 1e-300 : 1e300;
  return log_uniform(rng, 1e-12, 1e12);
}

void expect_sane(const GammaFit& g, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_FALSE(std::isnan(g.alpha)) << "alpha";
  EXPECT_FALSE(std::isnan(g.beta)) << "beta";
  EXPECT_GT(g.alpha, 0.0) << "alpha";
  EXPECT_GT(g.beta, 0.0) << "beta";
  // +∞ only for the exponential limit (Var C = 0), as fit.h documents.
  if (std::isinf(g.alpha) || std::isinf(g.beta)) {
    EXPECT_TRUE(g.exponential()) << "infinite alpha/beta";
  }
  const auto law = model_law(g);
  for (double t : {0.0, 1e-6, 1.0, 1e6}) {
    const double tr = law->transmittance(t);
    EXPECT_FALSE(std::isnan(tr)) << "model T(" << t << ")";
    EXPECT_GE(tr, 0.0) << "model T(" << t << ")";
    EXPECT_LE(tr, 1.0) << "model T(" << t << ")";
  }
}

TEST(FitProperty, GammaMomentsAreNeverNan) {
  Pcg32 rng(20261122, 1);
  int accepted = 0;
  const int count = draws(2000);
  for (int i = 0; i < count; ++i) {
    const double mean = non_negative(rng);
    // Var C = C̄²·CV² with CV² in [1e-9, 1e9] where that is a double (C̄ < 1e100), else independent;
    // the test computes nothing that overflows, so it runs clean with FP traps (preset fp-trap).
    const bool relative = rng.uniform() < 0.5 && mean < 1e100;
    const double variance = relative ? mean * mean * log_uniform(rng, 1e-9, 1e9) : non_negative(rng);
    const double sigma = log_uniform(rng, 1e-6, 1e6);
    std::ostringstream what;
    what.precision(17);
    what << "gamma_from_moments(mean=" << mean << ", variance=" << variance << ", sigma=" << sigma << ")";
    try {
      const GammaFit g = gamma_from_moments(mean, variance, sigma);
      ++accepted;
      if (g.vacuum()) continue;  // C̄ = 0: T ≡ 1, α and β carry no meaning
      expect_sane(g, what.str());
      if (::testing::Test::HasFailure()) return;
    } catch (const Error&) {
      // a refusal with a reason is allowed
    } catch (const std::exception& e) {
      FAIL() << what.str() << " threw a non-weft exception: " << e.what();
    }
  }
  // Finite, non-negative moments are the valid range: most draws must be accepted.
  EXPECT_GT(accepted, count * 3 / 4);
}

TEST(FitProperty, LeastSquaresIsNeverNan) {
  Pcg32 rng(20261122, 2);
  const int count = draws(200);
  for (int i = 0; i < count; ++i) {
    // A gamma curve with random (α, μ̄), sampled at n random increasing depths, with noise.
    const double alpha = log_uniform(rng, 1e-3, 1e4);
    const double mu = log_uniform(rng, 1e-6, 1e6);
    const int n = 3 + static_cast<int>(rng.uniform_below(60));
    volume::TransmittanceCurve curve;
    double t = 0.0;
    double previous = 0.0;
    for (int k = 0; k < n; ++k) {
      const double log_t = std::min(previous, -alpha * std::log1p(mu * t / alpha) + 1e-3 * (rng.uniform() - 0.5));
      curve.depth.push_back(t);
      curve.log_t.push_back(k == 0 ? 0.0 : log_t);
      curve.rel_stderr.push_back(rng.uniform() < 0.1 ? 0.0 : log_uniform(rng, 1e-6, 1.0));
      previous = curve.log_t.back();
      t += log_uniform(rng, 1e-3, 1e3) / mu;
    }
    curve.rays = 1 + rng.uniform_below(10000);
    const double sigma = log_uniform(rng, 1e-3, 1e3);
    GammaFit start;
    start.sigma = sigma;
    const int kind = static_cast<int>(rng.uniform_below(3));
    if (kind == 0) {
      start = gamma_from_moments(mu / sigma, (mu / sigma) * (mu / sigma) / alpha, sigma);
    } else if (kind == 1) {
      start = gamma_from_moments(mu / sigma, 0.0, sigma);  // exponential start (α = ∞)
    }                                                      // kind 2: the degenerate default start
    std::ostringstream what;
    what.precision(17);
    what << "fit_gamma_to_curve(sigma=" << sigma << ", start alpha=" << start.alpha << " beta=" << start.beta
         << ") on a gamma curve alpha=" << alpha << " mu=" << mu << " with " << n << " depths up to " << t;
    try {
      const LeastSquaresFit fit = fit_gamma_to_curve(curve, sigma, start);
      EXPECT_FALSE(std::isnan(fit.rms)) << what.str();
      EXPECT_GE(fit.rms, 0.0) << what.str();
      if (!start.vacuum()) expect_sane(fit.fit, what.str());
      if (::testing::Test::HasFailure()) return;
    } catch (const Error&) {
    } catch (const std::exception& e) {
      FAIL() << what.str() << " threw a non-weft exception: " << e.what();
    }
  }
}

}  // namespace
}  // namespace weft::fit
