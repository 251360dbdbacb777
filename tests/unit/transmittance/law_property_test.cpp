// Randomized property tests (docs/robustness.md): every law of the registry, with parameters drawn
// log-uniformly over its whole valid range (plus the range's extremes), obeys the Law contract
// (law.h): no NaN anywhere; T(0) = 1; T in [0, 1] and non-increasing; log T consistent with T
// and non-increasing; p ≥ 0; Σ ≥ 0; sampled distances ≥ 0, +∞ only for laws with T(∞) > 0 and
// DBL_MAX (a draw beyond the doubles) only where T(DBL_MAX) > 0;
// ℓ ≥ 0. Reciprocal and `same` pairs built from each law obey the same contract (or refuse with
// weft::Error where the derivation does not exist). A failure prints the law and its parameters.
// Seeds are fixed: the same parameter sets run every time.
//
// Draw counts: the default suite runs a short sweep (a few seconds); WEFT_PROPERTY_LONG=1 runs
// the long one (ctest `transmittance_property_tests.long_sweep`, label `slow`). Both run every
// law at the corners of its valid range (corner_draws), so the short sweep keeps the extremes.
// WEFT_PROPERTY_VERBOSE=1 prints why each refused reciprocal pair was refused.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "weft/core/error.h"
#include "weft/core/rng.h"
#include "weft/transmittance/pair.h"
#include "weft/transmittance/registry.h"
#include "weft/transmittance/tabulated.h"

namespace weft::transmittance {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kMax = std::numeric_limits<double>::max();
constexpr double kMinNormal = std::numeric_limits<double>::min();

/// 1/x, x·y and x/y for the length scales of a draw, +∞ where they leave the doubles; computed
/// without overflow or division by zero, so the test itself runs clean with FP traps (fp-trap).
double reciprocal(double x) { return x >= kMinNormal ? 1.0 / x : std::numeric_limits<double>::infinity(); }
double times(double x, double y) { return y > 1.0 && x > kMax / y ? std::numeric_limits<double>::infinity() : x * y; }
double ratio(double x, double y) { return times(x, reciprocal(y)); }

/// Log-uniform in [lo, hi].
double log_uniform(Pcg32& rng, double lo, double hi) {
  return std::exp(std::log(lo) + rng.uniform() * (std::log(hi) - std::log(lo)));
}

/// A value for a positive scale parameter: mostly log-uniform over [1e-12, 1e12], sometimes one
/// of the representable extremes.
/// Extreme values mixed into the draws: the whole double range, or only the range that the laws
/// currently handle (see ContractHoldsAtRepresentableExtremes).
const std::vector<double> kAllExtremes = {kMinNormal, 1e-300, 1e-100, 1e100, 1e300, kMax};
const std::vector<double> kModerateExtremes = {1e-100, 1e-30, 1e30, 1e100};
const std::vector<double>* g_extremes = &kModerateExtremes;

/// Erlang shapes: the whole valid range [1, 1e6] at the extremes, up to 1000 otherwise.
double max_erlang_k() { return g_extremes == &kAllExtremes ? 1e6 : 1000.0; }

/// The short (default) or long (WEFT_PROPERTY_LONG=1) number of draws.
int draws(int short_sweep, int long_sweep) {
  const char* env = std::getenv("WEFT_PROPERTY_LONG");
  return env != nullptr && std::string(env) != "0" && std::string(env) != "" ? long_sweep : short_sweep;
}

double positive_scale(Pcg32& rng) {
  const std::vector<double>& extremes = *g_extremes;
  if (rng.uniform() < 0.15) return extremes[rng.uniform_below(static_cast<std::uint32_t>(extremes.size()))];
  return log_uniform(rng, 1e-12, 1e12);
}

/// Depths that probe every scale: 0, a log-spaced sweep from 1e-310 (subnormal) to the largest
/// double, points around the law's own length scales, and +∞.
std::vector<double> probe_depths(const std::vector<double>& scales) {
  std::vector<double> t = {0.0, 5e-324, 1e-310};
  for (int e = -300; e <= 308; e += 4) t.push_back(std::pow(10.0, e));
  for (double s : scales) {
    if (!(s > 0.0) || !std::isfinite(s)) continue;
    for (double f : {1e-9, 1e-3, 0.1, 0.5, 0.999999, 1.0, 1.000001, 2.0, 10.0, 1e3, 1e9}) {
      const double v = times(s, f);
      if (std::isfinite(v)) t.push_back(v);
    }
  }
  t.push_back(kMax);
  t.push_back(std::numeric_limits<double>::infinity());
  std::sort(t.begin(), t.end());
  t.erase(std::unique(t.begin(), t.end()), t.end());
  return t;
}

std::string describe(const Law& law) {
  std::ostringstream out;
  out.precision(17);
  out << law.name() << " {";
  for (const auto& p : law.parameters()) out << " " << p.name << "=" << p.value;
  out << " }";
  return out.str();
}

/// The Law contract at every probe depth and for `samples` draws. `what` names the law and how it
/// was built; it is printed with every failure.
void check_contract(const Law& law, const std::string& what, const std::vector<double>& scales, Pcg32& rng,
                    int samples = 64) {
  SCOPED_TRACE(what + " = " + describe(law));
  const double t0 = law.transmittance(0.0);
  ASSERT_EQ(t0, 1.0) << "T(0)";
  ASSERT_EQ(law.log_transmittance(0.0), 0.0) << "log T(0)";
  double previous_t = 1.0;
  double previous_log = 0.0;
  double previous_depth = 0.0;
  for (double t : probe_depths(scales)) {
    const double tr = law.transmittance(t);
    const double log_tr = law.log_transmittance(t);
    const double p = law.pdf(t);
    const double hazard = law.hazard(t);
    ASSERT_FALSE(std::isnan(tr)) << "T(" << t << ") is NaN";
    ASSERT_FALSE(std::isnan(log_tr)) << "log T(" << t << ") is NaN";
    ASSERT_FALSE(std::isnan(p)) << "p(" << t << ") is NaN";
    ASSERT_FALSE(std::isnan(hazard)) << "hazard(" << t << ") is NaN";
    ASSERT_GE(tr, 0.0) << "T(" << t << ")";
    ASSERT_LE(tr, 1.0) << "T(" << t << ")";
    ASSERT_LE(log_tr, 0.0) << "log T(" << t << ")";
    // Non-increasing up to rounding of the last few bits (a few ulps of the previous value).
    ASSERT_LE(tr, previous_t * (1.0 + 8.0 * kEps)) << "T increases from t=" << previous_depth << " to t=" << t;
    const double log_slack = std::isfinite(previous_log) ? 8.0 * kEps * std::max(1.0, std::abs(previous_log)) : 0.0;
    ASSERT_LE(log_tr, previous_log + log_slack) << "log T increases from t=" << previous_depth << " to t=" << t;
    ASSERT_GE(p, 0.0) << "p(" << t << ")";
    ASSERT_GE(hazard, 0.0) << "hazard(" << t << ")";
    // log T agrees with T where T is a normal number.
    if (tr > 1e-290) {
      ASSERT_NEAR(std::exp(log_tr), tr, 1e-9 * tr + 1e-300) << "exp(log T(" << t << ")) vs T";
    }
    // Σ finite wherever T > 0 (as a double), 0 < t < ∞ and p is finite (for gamma-path with
    // k < 1, p and Σ diverge at t → 0 and overflow near it).
    if (t > 0.0 && std::isfinite(t) && tr > 0.0 && std::isfinite(p)) {
      ASSERT_TRUE(std::isfinite(hazard)) << "hazard(" << t << ") = " << hazard << " where T = " << tr;
    }
    previous_t = tr;
    previous_log = log_tr;
    previous_depth = t;
  }
  const double at_infinity = law.transmittance(std::numeric_limits<double>::infinity());
  // Mass beyond the largest double: a draw there saturates at DBL_MAX.
  const double beyond_max = law.transmittance(kMax);
  const double ell = law.mean_free_path();
  ASSERT_FALSE(std::isnan(ell)) << "mean free path";
  ASSERT_GE(ell, 0.0) << "mean free path";
  if (at_infinity > 0.0) {
    ASSERT_EQ(ell, std::numeric_limits<double>::infinity()) << "T(inf) > 0 but a finite mean free path";
  }
  for (int i = 0; i < samples; ++i) {
    const double t = law.sample(rng);
    ASSERT_FALSE(std::isnan(t)) << "sample " << i << " is NaN";
    ASSERT_GE(t, 0.0) << "sample " << i;
    // +∞ only for mass that never collides (T(∞) > 0); a draw beyond DBL_MAX is DBL_MAX (law.h).
    if (std::isinf(t)) {
      ASSERT_GT(at_infinity, 0.0) << "sample " << i << " is +inf but T(inf) = " << at_infinity;
    }
    if (t == kMax) {
      ASSERT_GT(beyond_max, 0.0) << "sample " << i << " is DBL_MAX but T(DBL_MAX) = " << beyond_max;
    }
  }
}

/// The contract for the laws of every pair that can be built from `law`.
void check_pairs(const LawPtr& law, const std::string& what, const std::vector<double>& scales, Pcg32& rng,
                 int& refused) {
  for (Origin origin : {Origin::source, Origin::scatterer}) {
    try {
      const auto pair = TransmittancePair::reciprocal(law, origin);
      for (Origin side : {Origin::source, Origin::scatterer}) {
        check_contract(pair.law(side),
                       what + ", reciprocal pair given as " + to_string(origin) + ", law " + to_string(side), scales,
                       rng, 16);
      }
    } catch (const Error& e) {
      if (std::getenv("WEFT_PROPERTY_VERBOSE")) std::fprintf(stderr, "REFUSED %s: %s\n", what.c_str(), e.what());
      // The derivation does not exist: p_Q(0) infinite or 0, ℓ_S infinite, a non-convex table as
      // T_Q, or ℓ_S outside the normal doubles (its reciprocal would overflow).
      ++refused;
    }
  }
  const auto same = TransmittancePair::same(law);
  EXPECT_EQ(&same.law(Origin::source), &same.law(Origin::scatterer)) << what;
}

/// A random parameter set of the registry law `name` (its whole valid range), with the length
/// scales at which its curve changes.
struct Draw {
  LawSpec spec;
  std::vector<double> scales;
};

using Generator = std::function<Draw(Pcg32&)>;

LawSpec spec(const std::string& name, std::map<std::string, double> params) {
  LawSpec s;
  s.name = name;
  s.params = std::move(params);
  return s;
}

/// A gamma-mixture spec from (weight, alpha, mean_extinction) triples, as the registry reads them.
LawSpec mixture_spec(const std::vector<std::array<double, 3>>& components) {
  LawSpec s;
  s.name = "gamma-mixture";
  for (std::size_t i = 0; i < components.size(); ++i) {
    s.params[list_parameter_key("weight", i)] = components[i][0];
    s.params[list_parameter_key("alpha", i)] = components[i][1];
    s.params[list_parameter_key("mean_extinction", i)] = components[i][2];
  }
  return s;
}

/// A gamma shape over the whole valid range: log-uniform, sometimes ∞ or an extreme.
double any_alpha(Pcg32& rng) {
  const double u = rng.uniform();
  if (u < 0.1) return std::numeric_limits<double>::infinity();
  if (u < 0.2) return rng.uniform() < 0.5 ? 1e-300 : 1e300;
  return log_uniform(rng, 1e-6, 1e6);
}

/// A gap fraction in [0, 1): sometimes 0, tiny or within an ulp of 1.
double any_gap(Pcg32& rng) {
  const double u = rng.uniform();
  if (u < 0.1) return 0.0;
  if (u < 0.15) return 1e-300;
  if (u < 0.2) return std::nextafter(1.0, 0.0);
  if (u < 0.25) return 1.0 - 1e-12;
  return rng.uniform();
}

const std::map<std::string, Generator>& generators() {
  static const std::map<std::string, Generator> table = {
      {"exponential",
       [](Pcg32& rng) {
         const double mu = rng.uniform() < 0.1 ? 0.0 : positive_scale(rng);
         return Draw{spec("exponential", {{"mu", mu}}), {reciprocal(mu)}};
       }},
      {"gamma",
       [](Pcg32& rng) {
         const double u = rng.uniform();
         double alpha = log_uniform(rng, 1e-6, 1e6);
         if (u < 0.1) {
           alpha = std::numeric_limits<double>::infinity();
         } else if (u < 0.2) {
           alpha = rng.uniform() < 0.5 ? 1e-300 : 1e300;
         }
         const int form = static_cast<int>(rng.uniform_below(3));
         if (form == 0) {
           const double mu = rng.uniform() < 0.1 ? 0.0 : positive_scale(rng);
           return Draw{spec("gamma", {{"mean_extinction", mu}, {"alpha", alpha}}), {reciprocal(mu), ratio(alpha, mu)}};
         }
         const double sigma = positive_scale(rng);
         if (form == 1) {
           // α = ∞ with a finite β would be an infinite mean extinction: this form needs α finite.
           if (!std::isfinite(alpha)) alpha = log_uniform(rng, 1e-6, 1e6);
           const double beta = positive_scale(rng);
           return Draw{spec("gamma", {{"sigma", sigma}, {"alpha", alpha}, {"beta", beta}}), {ratio(beta, sigma)}};
         }
         const double mean = rng.uniform() < 0.1 ? 0.0 : log_uniform(rng, 1e-6, 1.0);
         const double var = rng.uniform() < 0.15 ? 0.0 : mean * mean * log_uniform(rng, 1e-6, 1e6);
         return Draw{spec("gamma", {{"sigma", sigma}, {"mean_concentration", mean}, {"var_concentration", var}}),
                     {reciprocal(times(sigma, mean))}};
       }},
      {"gap-gamma",
       [](Pcg32& rng) {
         const double gap = any_gap(rng);
         double alpha = any_alpha(rng);
         const int form = static_cast<int>(rng.uniform_below(3));
         if (form == 0) {
           const double mu = rng.uniform() < 0.1 ? 0.0 : positive_scale(rng);
           return Draw{spec("gap-gamma", {{"gap", gap}, {"mean_extinction", mu}, {"alpha", alpha}}),
                       {reciprocal(mu), ratio(alpha, mu)}};
         }
         const double sigma = positive_scale(rng);
         if (form == 1) {
           if (!std::isfinite(alpha)) alpha = log_uniform(rng, 1e-6, 1e6);
           const double beta = positive_scale(rng);
           return Draw{spec("gap-gamma", {{"gap", gap}, {"sigma", sigma}, {"alpha", alpha}, {"beta", beta}}),
                       {ratio(beta, sigma)}};
         }
         const double mean = rng.uniform() < 0.1 ? 0.0 : log_uniform(rng, 1e-6, 1.0);
         const double var = rng.uniform() < 0.15 ? 0.0 : mean * mean * log_uniform(rng, 1e-6, 1e6);
         return Draw{spec("gap-gamma",
                          {{"gap", gap}, {"sigma", sigma}, {"mean_concentration", mean}, {"var_concentration", var}}),
                     {reciprocal(times(sigma, mean))}};
       }},
      {"gamma-mixture",
       [](Pcg32& rng) {
         // 1 to 5 components, some of weight 0, some gaps (mean extinction 0), weights normalised
         // in double (their sum is 1 only to rounding, as a user's would be).
         const auto n = 1 + rng.uniform_below(5);
         std::vector<std::array<double, 3>> components;
         std::vector<double> scales;
         double total = 0.0;
         for (std::uint32_t i = 0; i < n; ++i) {
           const double w = rng.uniform() < 0.1 ? 0.0 : log_uniform(rng, 1e-6, 1.0);
           const double alpha = any_alpha(rng);
           const double mu = rng.uniform() < 0.15 ? 0.0 : positive_scale(rng);
           components.push_back({w, alpha, mu});
           scales.push_back(reciprocal(mu));
           scales.push_back(ratio(alpha, mu));
           total += w;
         }
         if (total == 0.0) {
           components[0][0] = 1.0;
           total = 1.0;
         }
         for (auto& c : components) c[0] /= total;
         return Draw{mixture_spec(components), scales};
       }},
      {"linear",
       [](Pcg32& rng) {
         const double mu = rng.uniform() < 0.1 ? 0.0 : positive_scale(rng);
         return Draw{spec("linear", {{"mean_extinction", mu}}), {reciprocal(mu)}};
       }},
      {"gamma-path",
       [](Pcg32& rng) {
         const double k = rng.uniform() < 0.1 ? (rng.uniform() < 0.5 ? 1e-6 : 1e6) : log_uniform(rng, 1e-3, 1e4);
         const double theta = positive_scale(rng);
         Draw d{spec("gamma-path", {{"k", k}, {"theta", theta}}), {theta, times(k, theta)}};
         d.spec.sampler = rng.uniform() < 0.5 ? "marsaglia-tsang" : "inversion";
         return d;
       }},
      {"erlang",
       [](Pcg32& rng) {
         const double k =
             rng.uniform() < 0.5 ? 1.0 + rng.uniform_below(4) : std::floor(log_uniform(rng, 1.0, max_erlang_k()));
         const double rate = positive_scale(rng);
         return Draw{spec("erlang", {{"k", k}, {"rate", rate}}), {reciprocal(rate), ratio(k, rate)}};
       }},
      {"erlang-source",
       [](Pcg32& rng) {
         const double k =
             rng.uniform() < 0.5 ? 1.0 + rng.uniform_below(4) : std::floor(log_uniform(rng, 1.0, max_erlang_k()));
         const double rate = positive_scale(rng);
         return Draw{spec("erlang-source", {{"k", k}, {"rate", rate}}), {reciprocal(rate), ratio(k, rate)}};
       }},
  };
  return table;
}

/// The corners of every law's valid range, run by ContractHoldsAtRepresentableExtremes before
/// its random draws: each scale parameter at DBL_MIN and DBL_MAX, shapes at their documented
/// limits, and the degenerate values (0, ∞) that the law accepts.
const std::map<std::string, std::vector<Draw>>& corner_draws() {
  static const std::map<std::string, std::vector<Draw>> table = [] {
    std::map<std::string, std::vector<Draw>> c;
    const std::vector<double> ends = {kMinNormal, kMax};
    for (double mu : {0.0, kMinNormal, kMax}) c["exponential"].push_back({spec("exponential", {{"mu", mu}}), {1.0}});
    for (double mu : {0.0, kMinNormal, kMax}) c["linear"].push_back({spec("linear", {{"mean_extinction", mu}}), {1.0}});
    for (double mu : ends) {
      for (double alpha : {1e-300, 1e-6, 1.0 + 1e-15, 1e300, std::numeric_limits<double>::infinity()}) {
        c["gamma"].push_back(
            {spec("gamma", {{"mean_extinction", mu}, {"alpha", alpha}}), {reciprocal(mu), ratio(alpha, mu)}});
      }
    }
    c["gamma"].push_back({spec("gamma", {{"sigma", kMax}, {"alpha", 1e-6}, {"beta", kMax}}), {1.0}});
    c["gamma"].push_back({spec("gamma", {{"sigma", kMinNormal}, {"alpha", 1e6}, {"beta", 1e6}}), {1.0}});
    c["gamma"].push_back(
        {spec("gamma", {{"sigma", kMax}, {"mean_concentration", 1.0}, {"var_concentration", 0.0}}), {1.0}});
    c["gamma"].push_back(
        {spec("gamma", {{"sigma", kMinNormal}, {"mean_concentration", 1e-6}, {"var_concentration", 1e6}}), {1.0}});
    const double inf = std::numeric_limits<double>::infinity();
    for (double gap : {0.0, 1e-300, 0.5, std::nextafter(1.0, 0.0)}) {
      for (double mu : {0.0, kMinNormal, kMax}) {
        for (double alpha : {1e-300, 1e-6, 1.0 + 1e-15, 1e300, inf}) {
          c["gap-gamma"].push_back({spec("gap-gamma", {{"gap", gap}, {"mean_extinction", mu}, {"alpha", alpha}}),
                                    {reciprocal(mu), ratio(alpha, mu)}});
        }
      }
    }
    c["gap-gamma"].push_back(
        {spec("gap-gamma", {{"gap", 0.25}, {"sigma", kMax}, {"alpha", 1e-6}, {"beta", kMax}}), {1.0}});
    c["gap-gamma"].push_back(
        {spec("gap-gamma",
              {{"gap", 0.25}, {"sigma", kMinNormal}, {"mean_concentration", 1e-6}, {"var_concentration", 1e6}}),
         {1.0}});
    // Mixtures: one component, a pure gap, gap + exponential at the scale extremes, components at
    // opposite ends of the double range, a zero-weight component, many equal components.
    c["gamma-mixture"].push_back({mixture_spec({{1.0, 2.0, 1.0}}), {1.0}});
    c["gamma-mixture"].push_back({mixture_spec({{1.0, 2.0, 0.0}}), {1.0}});
    for (double mu : {kMinNormal, kMax}) {
      c["gamma-mixture"].push_back({mixture_spec({{0.5, inf, 0.0}, {0.5, inf, mu}}), {reciprocal(mu)}});
      c["gamma-mixture"].push_back({mixture_spec({{0.3, 1e-300, mu}, {0.7, 1e300, mu}}), {reciprocal(mu)}});
      c["gamma-mixture"].push_back({mixture_spec({{0.25, inf, mu}, {0.75, inf, 1.0}}), {reciprocal(mu), 1.0}});
    }
    c["gamma-mixture"].push_back(
        {mixture_spec({{0.5, 1e-6, kMax}, {0.5, 1e6, kMinNormal}}), {reciprocal(kMax), ratio(1e6, kMinNormal)}});
    c["gamma-mixture"].push_back({mixture_spec({{0.0, 2.0, 5.0}, {1.0, 1.0 + 1e-15, 3.0}}), {1.0}});
    c["gamma-mixture"].push_back(
        {mixture_spec(std::vector<std::array<double, 3>>(1000, {1e-3, 3.0, 2.0})), {0.5, 1.5}});
    for (double k : {1e-6, 1.0, 1e6}) {
      for (double theta : ends) {
        for (const char* sampler : {"marsaglia-tsang", "inversion"}) {
          Draw d{spec("gamma-path", {{"k", k}, {"theta", theta}}), {theta, times(k, theta)}};
          d.spec.sampler = sampler;
          c["gamma-path"].push_back(d);
        }
      }
    }
    for (const char* name : {"erlang", "erlang-source"}) {
      for (double k : {1.0, 2.0, 1750.0, 1e6}) {
        for (double rate : ends)
          c[name].push_back({spec(name, {{"k", k}, {"rate", rate}}), {reciprocal(rate), ratio(k, rate)}});
      }
    }
    return c;
  }();
  return table;
}

/// A random valid table: 2 to 24 samples, depths with log-uniform gaps, T falling by random
/// factors (sometimes flat, sometimes to exactly 0, sometimes to a subnormal). With `convex`,
/// the interval hazards do not increase (then p_Q = −dT/dt never jumps up and the table has a
/// reciprocal scatterer partner): each hazard is the previous one times a factor in (1/2, 1],
/// sometimes 0 from there on (a flat tail); T may still fall to subnormals.
Tabulated random_table(Pcg32& rng, std::vector<double>& scales, bool convex = false) {
  const int n = 2 + static_cast<int>(rng.uniform_below(23));
  std::vector<double> t = {0.0};
  std::vector<double> value = {1.0};
  const double scale = log_uniform(rng, 1e-9, 1e9);
  double hazard = log_uniform(rng, 1e-3, 1e3) / scale;
  for (int i = 1; i < n; ++i) {
    const double dt = scale * log_uniform(rng, 1e-6, 1e3);
    t.push_back(t.back() + dt);
    const double u = rng.uniform();
    double next = value.back();
    if (convex) {
      if (i > 1 && u < 0.02) hazard = 0.0;  // flat from here: T_N never collides, ℓ = ∞
      hazard *= 0.5 + 0.5 * rng.uniform_open();
      next = value.back() * std::exp(-hazard * dt);
    } else if (u < 0.15) {
      // flat: zero hazard on this interval
    } else if (u < 0.2) {
      next = 0.0;
    } else if (u < 0.25) {
      next = value.back() * 1e-310;
    } else {
      next = value.back() * rng.uniform();
    }
    value.push_back(next);
  }
  scales = {scale, t.back()};
  return Tabulated(t, value, convex ? "random convex table" : "random table");
}

/// Failures recorded so far in the running test (to stop a test after a few failing draws).
int failure_count() { return ::testing::UnitTest::GetInstance()->current_test_info()->result()->total_part_count(); }
bool failed_since(int parts) { return failure_count() > parts; }

TEST(LawProperty, EveryRegisteredLawHasAGenerator) {
  for (const auto& name : law_names()) {
    if (name == "tabulated") continue;  // built from random tables below (the registry reads a file)
    EXPECT_EQ(generators().count(name), 1u) << "law '" << name << "' has no property test generator";
    EXPECT_EQ(corner_draws().count(name), 1u) << "law '" << name << "' has no corner cases";
  }
}

/// Counts over the draws of one law.
struct Tally {
  int built = 0;
  int overflowing = 0;
  int refused_pairs = 0;
};

/// Builds the law of `draw` and checks it and its pairs; `what` names the draw in failures.
void check_draw(const Draw& draw, const std::string& label, Pcg32& rng, Tally& tally) {
  std::ostringstream what;
  what.precision(17);
  what << label << " from {";
  for (const auto& [key, value] : draw.spec.params) what << " " << key << "=" << value;
  if (!draw.spec.sampler.empty()) what << " sampler=" << draw.spec.sampler;
  what << " }";
  LawPtr law;
  try {
    law = make_law(draw.spec);
  } catch (const Error& e) {
    // Parameters drawn independently may combine to a law outside the doubles (gamma's
    // σα/β > DBL_MAX); that refusal must say so. Any other refusal of a drawn set is a bug.
    if (std::string(e.what()).find("overflows") != std::string::npos) {
      ++tally.overflowing;
    } else {
      ADD_FAILURE() << what.str() << " refused: " << e.what();
    }
    return;
  }
  ++tally.built;
  try {
    check_contract(*law, what.str(), draw.scales, rng);
    check_pairs(law, what.str(), draw.scales, rng, tally.refused_pairs);
  } catch (const std::exception& e) {
    ADD_FAILURE() << what.str() << ": unexpected exception (only weft::Error may leave a law): " << e.what();
  }
}

/// `count` random draws of every registered law, after its corner cases if `corners`.
void check_registered_laws(int count, std::uint64_t seed, bool corners) {
  for (const auto& [name, generate] : generators()) {
    Pcg32 rng(seed, std::hash<std::string>{}(name));
    Tally tally;
    int failing_draws = 0;
    int attempted = 0;
    if (corners) {
      const auto& cases = corner_draws().at(name);
      for (std::size_t i = 0; i < cases.size(); ++i) {
        const int parts = failure_count();
        check_draw(cases[i], "corner " + std::to_string(i) + " of " + name, rng, tally);
        ++attempted;
        if (failed_since(parts) && ++failing_draws >= 5) break;
      }
    }
    for (int i = 0; i < count && failing_draws < 5; ++i) {
      const int parts = failure_count();
      check_draw(generate(rng), "draw " + std::to_string(i) + " of " + name, rng, tally);
      ++attempted;
      if (failed_since(parts)) ++failing_draws;
    }
    if (failing_draws >= 5) ADD_FAILURE() << name << ": stopping after 5 failing draws";
    EXPECT_EQ(tally.built + tally.overflowing, attempted) << name;
    EXPECT_LE(tally.overflowing, attempted / 10) << name << ": too many draws outside the doubles";
    ::testing::Test::RecordProperty(name + "_refused_pairs", tally.refused_pairs);
  }
}

TEST(LawProperty, ContractHoldsOverRandomParameters) {
  g_extremes = &kModerateExtremes;
  check_registered_laws(draws(30, 400), 20261122, false);
}

// Scales at the ends of the double range (DBL_MIN, 1e-300, 1e300, DBL_MAX) and shapes over the
// whole valid range, after the corner cases of every law.
TEST(LawProperty, ContractHoldsAtRepresentableExtremes) {
  g_extremes = &kAllExtremes;
  check_registered_laws(draws(20, 600), 20261123, true);
  g_extremes = &kModerateExtremes;
}

void check_random_tables(bool pairs) {
  Pcg32 rng(20261122, 77);
  int refused_pairs = 0;
  int refused_convex_pairs = 0;
  int failing_draws = 0;
  const int count = draws(120, 3000);
  for (int i = 0; i < count; ++i) {
    const int parts = failure_count();
    std::vector<double> scales;
    // With pairs, every other table is convex, so that the scatterer partner exists.
    const bool convex = pairs && i % 2 == 1;
    const auto table = std::make_shared<Tabulated>(random_table(rng, scales, convex));
    std::ostringstream what;
    what.precision(17);
    what << table->source() << " " << i << ": t = [";
    for (double v : table->t_samples()) what << " " << v;
    what << " ], T = [";
    for (double v : table->transmittance_samples()) what << " " << v;
    what << " ]";
    try {
      check_contract(*table, what.str(), scales, rng);
      if (pairs) check_pairs(table, what.str(), scales, rng, convex ? refused_convex_pairs : refused_pairs);
    } catch (const std::exception& e) {
      ADD_FAILURE() << what.str() << ": unexpected exception (only weft::Error may leave a law): " << e.what();
    }
    if (failed_since(parts) && ++failing_draws >= 5) {
      ADD_FAILURE() << "stopping after 5 failing tables";
      break;
    }
  }
  // Each convex table has both partners; a non-convex one only the source partner.
  // A convex table has both partners unless its tail is flat (ℓ = ∞: no source partner).
  if (pairs) {
    EXPECT_LE(refused_convex_pairs, count / 6) << "reciprocal pairs refused for convex tables";
    ::testing::Test::RecordProperty("refused_pairs", refused_pairs);
  }
}

TEST(LawProperty, ContractHoldsForRandomTables) { check_random_tables(false); }

// The numerically derived reciprocal partners of random tables (as source: T_S = p_Q/p_Q(0),
// refused with weft::Error for a non-convex table; as scatterer: T_Q = ∫T_S/ℓ_S).
TEST(LawProperty, ContractHoldsForPairsOfRandomTables) { check_random_tables(true); }

}  // namespace
}  // namespace weft::transmittance
