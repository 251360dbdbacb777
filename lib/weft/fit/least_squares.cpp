// Levenberg–Marquardt fit of the gamma law (Eq. 20) to a measured T(t): the best any gamma
// law can do, as a reference for the moment-matched (predicted) model.
#include "weft/fit/least_squares.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <unsupported/Eigen/LevenbergMarquardt>

#include "weft/core/error.h"
#include "weft/fit/gamma_moments.h"
#include "weft/transmittance/overflow.h"

namespace weft::fit {
namespace {

using transmittance::quotient_or_infinity;
using transmittance::saturating_quotient;

/// e^v for a log-parameter of the fit, kept inside [e^−700, e^700]: Levenberg–Marquardt may
/// step log α or log β far out, and α = ∞ or β = 0 would turn the residuals into ∞·0 = NaN
/// (and overflow on the way). The bound is far beyond any meaningful α or β.
double bounded_exp(double v) { return std::exp(std::clamp(v, -700.0, 700.0)); }

/// Residuals T_model(t_k) − T_gt(t_k) in the parameters x = (log α, log β), which keeps both
/// positive. T = exp(−α log1p(σt/β)); the Jacobian is analytic:
/// ∂T/∂log α = −T·α·log1p(σt/β),  ∂T/∂log β = T·α·(σt/β)/(1 + σt/β).
struct GammaResiduals : Eigen::DenseFunctor<double> {
  const std::vector<double>& t;
  const std::vector<double>& target;
  double sigma;
  GammaResiduals(const std::vector<double>& depths, const std::vector<double>& values, double s)
      : Eigen::DenseFunctor<double>(2, static_cast<int>(depths.size())), t(depths), target(values), sigma(s) {}

  int operator()(const InputType& x, ValueType& f) const {
    const double alpha = bounded_exp(x[0]);
    const double beta = bounded_exp(x[1]);
    for (std::size_t k = 0; k < t.size(); ++k) {
      // σt/β saturates at DBL_MAX (T is 0 to double precision there), so log1p stays finite.
      const double u = saturating_quotient(sigma * t[k], beta);
      f[static_cast<Eigen::Index>(k)] = std::exp(-alpha * std::log1p(u)) - target[k];
    }
    return 0;
  }
  int df(const InputType& x, JacobianType& j) const {
    const double alpha = bounded_exp(x[0]);
    const double beta = bounded_exp(x[1]);
    for (std::size_t k = 0; k < t.size(); ++k) {
      const double u = saturating_quotient(sigma * t[k], beta);
      const double l = std::log1p(u);
      const double T = std::exp(-alpha * l);
      const auto r = static_cast<Eigen::Index>(k);
      j(r, 0) = -T * alpha * l;
      j(r, 1) = T * alpha * u / (1.0 + u);
    }
    return 0;
  }
};

}  // namespace

LeastSquaresFit fit_gamma_to_curve(const volume::TransmittanceCurve& gt, double sigma, const GammaFit& start) {
  require_positive("least-squares fit: sigma", sigma);
  if (gt.size() < 3) fail("least-squares fit: need at least 3 depths, got {}", gt.size());
  LeastSquaresFit out;
  out.fit = start;
  std::vector<double> target(gt.size());
  bool drops = false;
  for (std::size_t k = 0; k < gt.size(); ++k) {
    target[k] = gt.transmittance(k);
    if (target[k] < 1.0) drops = true;
  }
  if (!drops) {
    out.converged = true;
    return out;
  }
  double alpha = start.alpha;
  double beta = start.beta;
  if (!(std::isfinite(alpha) && std::isfinite(beta) && alpha > 0.0 && beta > 0.0)) {
    // Start at α = 1 with the curve's mean slope over its first half: μ̄ ≈ −log T(t)/t.
    const std::size_t k = gt.size() / 2;
    const double mu = std::max(1e-12, -gt.log_t[k] / std::max(gt.depth[k], 1e-300));
    alpha = 1.0;
    beta = sigma * alpha / mu;
  }
  Eigen::VectorXd x(2);
  x << std::log(alpha), std::log(beta);
  GammaResiduals f(gt.depth, target, sigma);
  Eigen::LevenbergMarquardt<GammaResiduals> lm(f);
  lm.setMaxfev(2000);
  const auto status = lm.minimize(x);
  out.iterations = static_cast<int>(lm.iterations());
  out.converged = status != Eigen::LevenbergMarquardtSpace::ImproperInputParameters &&
                  status != Eigen::LevenbergMarquardtSpace::TooManyFunctionEvaluation;
  Eigen::VectorXd fv(static_cast<Eigen::Index>(gt.size()));
  f(x, fv);
  out.rms = std::sqrt(fv.squaredNorm() / static_cast<double>(gt.size()));
  const double a = bounded_exp(x[0]);
  const double b = bounded_exp(x[1]);
  // Report the fit as the moments it implies: C̄ = α/β, Var C = α/β² (refused with weft::Error
  // by gamma_from_moments if the fit ran off to moments beyond the doubles).
  out.fit = gamma_from_moments(quotient_or_infinity(a, b), quotient_or_infinity(quotient_or_infinity(a, b), b), sigma);
  out.fit.alpha = a;
  out.fit.beta = b;
  return out;
}

}  // namespace weft::fit
