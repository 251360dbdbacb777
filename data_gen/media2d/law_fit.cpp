#include "data_gen/media2d/law_fit.h"

#include <algorithm>
#include <cmath>
#include <exception>

#include <Eigen/Dense>
#include <unsupported/Eigen/LevenbergMarquardt>
#include <unsupported/Eigen/NumericalDiff>

#include "weft/core/error.h"
#include "weft/transmittance/registry.h"

namespace weft::media2d {
namespace {

// A law's parameters, their starting values from the curve's mean free path ℓ = ∫T, and their
// bounds in log space (α ≤ 1e8 is exponential to double precision).
struct Model {
  std::vector<std::string> names;
  std::vector<double> start;
  std::vector<double> log_max;
};

Model model_for(const std::string& law, double ell) {
  const double inv = 1.0 / ell;
  if (law == "exponential") return {{"mu"}, {inv}, {std::log(1e12)}};
  if (law == "gamma") return {{"mean_extinction", "alpha"}, {inv, 4.0}, {std::log(1e12), std::log(1e8)}};
  if (law == "linear") return {{"mean_extinction"}, {0.5 * inv}, {std::log(1e12)}};
  if (law == "gamma-path") return {{"k", "theta"}, {1.0, ell}, {std::log(1e6), std::log(1e12)}};
  fail("sim2d fit: no fit model for law '{}' (known: exponential, gamma, linear, gamma-path)", law);
}

struct Residuals : Eigen::DenseFunctor<double> {
  const std::string* law;
  const Model* model;
  const std::vector<double>* t;
  const std::vector<double>* T;
  const std::vector<double>* sigma;
  bool binned;  ///< T holds bin densities (T(t_k) − T(t_{k+1}))/(t_{k+1} − t_k), t the K+1 edges

  Residuals(const std::string& l, const Model& m, const std::vector<double>& tt, const std::vector<double>& TT,
            const std::vector<double>& s, bool b)
      : Eigen::DenseFunctor<double>(static_cast<int>(m.names.size()), static_cast<int>(TT.size())),
        law(&l),
        model(&m),
        t(&tt),
        T(&TT),
        sigma(&s),
        binned(b) {}

  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& f) const {
    transmittance::LawSpec spec;
    spec.name = *law;
    for (std::size_t i = 0; i < model->names.size(); ++i) {
      spec.params[model->names[i]] = std::exp(std::min(x[static_cast<Eigen::Index>(i)], model->log_max[i]));
    }
    try {
      const transmittance::LawPtr l = transmittance::make_law(spec);
      for (std::size_t k = 0; k < T->size(); ++k) {
        const double model_value =
            binned ? (l->transmittance((*t)[k]) - l->transmittance((*t)[k + 1])) / ((*t)[k + 1] - (*t)[k])
                   : l->transmittance((*t)[k]);
        f[static_cast<Eigen::Index>(k)] = (model_value - (*T)[k]) / (*sigma)[k];
      }
    } catch (const std::exception&) {
      f.setConstant(1e6);
    }
    return 0;
  }
};

}  // namespace

namespace {

LawFit fit_impl(const std::string& law, const std::vector<double>& t, const std::vector<double>& T,
                const std::vector<double>& sigma, double sigma_floor, bool binned) {
  if (t.size() != T.size() + (binned ? 1 : 0) || T.size() != sigma.size() || T.size() < 3) {
    fail("sim2d fit: need matching t, {}, sigma with at least 3 points", binned ? "bin densities" : "T");
  }
  LawFit out;
  out.law = law;
  // ℓ = ∫T (trapezoid rule), or the histogram's mean free path Σ t_c p w: a starting value only.
  double ell = 0.0;
  if (binned) {
    for (std::size_t k = 0; k < T.size(); ++k) ell += 0.5 * (t[k] + t[k + 1]) * T[k] * (t[k + 1] - t[k]);
  } else {
    for (std::size_t k = 1; k < t.size(); ++k) ell += 0.5 * (T[k] + T[k - 1]) * (t[k] - t[k - 1]);
  }
  ell = std::max(ell, 1e-6);
  const Model model = model_for(law, ell);
  out.names = model.names;
  std::vector<double> s(sigma.size());
  for (std::size_t k = 0; k < s.size(); ++k) s[k] = std::max(sigma[k], sigma_floor);

  Residuals residuals(law, model, t, T, s, binned);
  Eigen::NumericalDiff<Residuals> numeric(residuals);
  Eigen::LevenbergMarquardt<Eigen::NumericalDiff<Residuals>> lm(numeric);
  lm.setMaxfev(4000);
  Eigen::VectorXd x(static_cast<Eigen::Index>(model.start.size()));
  for (std::size_t i = 0; i < model.start.size(); ++i) x[static_cast<Eigen::Index>(i)] = std::log(model.start[i]);
  const auto status = lm.minimize(x);
  out.converged = status == Eigen::LevenbergMarquardtSpace::RelativeReductionTooSmall ||
                  status == Eigen::LevenbergMarquardtSpace::RelativeErrorTooSmall ||
                  status == Eigen::LevenbergMarquardtSpace::RelativeErrorAndReductionTooSmall ||
                  status == Eigen::LevenbergMarquardtSpace::CosinusTooSmall;
  if (!out.converged) out.note = fmt::format("Levenberg-Marquardt stopped with status {}", static_cast<int>(status));

  Eigen::VectorXd f(static_cast<Eigen::Index>(T.size()));
  residuals(x, f);
  out.chi2 = f.squaredNorm();
  const std::size_t p = model.names.size();
  out.dof = T.size() > p ? T.size() - p : 0;
  Eigen::MatrixXd jac(static_cast<Eigen::Index>(T.size()), static_cast<Eigen::Index>(p));
  numeric.df(x, jac);
  const Eigen::MatrixXd normal = jac.transpose() * jac;
  const double scale = out.dof > 0 ? std::max(1.0, out.chi2 / static_cast<double>(out.dof)) : 1.0;
  Eigen::FullPivLU<Eigen::MatrixXd> lu(normal);
  const bool invertible = lu.isInvertible();
  const Eigen::MatrixXd cov = invertible ? Eigen::MatrixXd(lu.inverse() * scale) : Eigen::MatrixXd();
  for (std::size_t i = 0; i < p; ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    const double clamped = std::min(x[ii], model.log_max[i]);
    const double value = std::exp(clamped);
    out.params.push_back(value);
    // Errors in log space carried to the parameter: σ_p = p·σ_log p.
    out.errors.push_back(invertible ? value * std::sqrt(std::max(0.0, cov(ii, ii)))
                                    : std::numeric_limits<double>::infinity());
    if (x[ii] >= model.log_max[i]) {
      out.note += (out.note.empty() ? "" : "; ") + model.names[i] + " at its upper bound";
    }
  }
  return out;
}

}  // namespace

LawFit fit_law(const std::string& law, const std::vector<double>& t, const std::vector<double>& T,
               const std::vector<double>& sigma, double sigma_floor) {
  return fit_impl(law, t, T, sigma, sigma_floor, false);
}

LawFit fit_law_binned(const std::string& law, const std::vector<double>& edges, const std::vector<double>& density,
                      const std::vector<double>& sigma, double sigma_floor) {
  return fit_impl(law, edges, density, sigma, sigma_floor, true);
}

double bic(const LawFit& fit) {
  const auto p = static_cast<double>(fit.params.size());
  const double n = static_cast<double>(fit.dof) + p;
  return fit.chi2 + p * std::log(std::max(n, 1.0));
}

LawSelection select_law(const std::vector<LawFit>& fits, const std::string& curve) {
  std::vector<const LawFit*> pool;
  for (const auto& f : fits) {
    if (f.curve == curve && f.converged && std::isfinite(f.chi2)) pool.push_back(&f);
  }
  if (pool.empty()) {
    for (const auto& f : fits) {
      if (f.curve == curve && std::isfinite(f.chi2)) pool.push_back(&f);
    }
  }
  if (pool.empty()) fail("sim2d fit: no finite fit of curve '{}' to select from", curve);
  // Stable: on a tie the earlier (simpler, as fitted: exponential first) law wins.
  std::vector<const LawFit*> by_bic = pool;
  std::stable_sort(by_bic.begin(), by_bic.end(), [](const LawFit* a, const LawFit* b) { return bic(*a) < bic(*b); });
  const LawFit* lowest =
      *std::min_element(pool.begin(), pool.end(), [](const LawFit* a, const LawFit* b) { return a->chi2 < b->chi2; });
  LawSelection s;
  s.curve = curve;
  s.selected = by_bic.front()->law;
  s.lowest_chi2 = lowest->law;
  s.delta_chi2 = by_bic.front()->chi2 - lowest->chi2;
  s.delta_bic = bic(*lowest) - bic(*by_bic.front());
  if (by_bic.size() > 1) {
    s.runner_up = by_bic[1]->law;
    s.runner_up_delta_bic = bic(*by_bic[1]) - bic(*by_bic.front());
  }
  return s;
}

}  // namespace weft::media2d
