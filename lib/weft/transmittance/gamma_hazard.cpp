// The gamma hazard with memory through cells (gamma_hazard.h; docs/render.md §5b, §5e).
#include "weft/transmittance/gamma_hazard.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace weft::transmittance {
namespace {
constexpr std::array<std::pair<MemoryRule, std::string_view>, 4> kRules{{{MemoryRule::segment, "segment"},
                                                                         {MemoryRule::renewal, "renewal"},
                                                                         {MemoryRule::optical_depth, "optical-depth"},
                                                                         {MemoryRule::carried, "carried"}}};
/// expm1(x), or +∞ where it would overflow (without raising FE_OVERFLOW: overflow.h's rule).
double expm1_or_infinity(double x) {
  static const double log_max = std::log(std::numeric_limits<double>::max());
  return x < log_max ? std::expm1(x) : std::numeric_limits<double>::infinity();
}
}  // namespace

std::string_view memory_rule_name(MemoryRule rule) {
  for (const auto& [r, name] : kRules)
    if (r == rule) return name;
  return "segment";
}

std::optional<MemoryRule> parse_memory_rule(std::string_view name) {
  for (const auto& [r, n] : kRules)
    if (n == name) return r;
  return std::nullopt;
}

GammaCell GammaCell::from_moments(double sigma, double mean, double var, Origin origin) {
  GammaCell c;
  if (!(mean > 0.0)) return c;
  // Σ_Q(s) = σα/(β + σs) = σC̄/(1 + κs), κ = σV/C̄ (α = C̄²/V, β = C̄/V); the partner
  // T_S = (1 + κs)^{−(α+1)} has Σ_S = (α + 1)κ/(1 + κs) = (σC̄ + κ)/(1 + κs).
  c.kappa = var > 0.0 ? sigma * var / mean : 0.0;
  c.mean_extinction = sigma * mean;
  c.rate = c.mean_extinction + (origin == Origin::scatterer ? c.kappa : 0.0);
  return c;
}

double GammaCell::integral(double s, double length) const {
  if (kappa == 0.0) return rate * length;
  return rate / kappa * std::log1p(kappa * length / (1.0 + kappa * s));
}

double GammaCell::length_to(double s, double h) const {
  if (!(rate > 0.0)) return std::numeric_limits<double>::infinity();
  if (kappa == 0.0) return h / rate;
  // Inverse of integral(): rate/κ·log((1 + κ(s + ℓ))/(1 + κs)) = h.
  return (1.0 + kappa * s) * expm1_or_infinity(h * kappa / rate) / kappa;
}

double GammaCell::memory_for(double hazard) const {
  if (kappa == 0.0 || !(rate > 0.0)) return 0.0;  // memoryless: any memory is the same
  return expm1_or_infinity(hazard * kappa / rate) / kappa;
}

void GammaHazard::enter(double sigma, double mean, double var, double x) {
  // A renewed memory is a fresh start (the cell face acts as a source), so only the first
  // cell of a renewal segment keeps the scatterer's partner (docs/render.md §5e).
  const Origin o = rule_ == MemoryRule::renewal && cells_ > 0 ? Origin::source : origin_;
  cell_ = GammaCell::from_moments(sigma, mean, var, o);
  ++cells_;
  switch (rule_) {
    case MemoryRule::segment:
      shift_ = 0.0;
      break;
    case MemoryRule::renewal:
      shift_ = x;
      break;
    case MemoryRule::optical_depth:
      // τ so far read as this cell's distance: hazard μ̄/(1 + τ/α), the law in optical depth.
      shift_ = cell_.mean_extinction > 0.0 ? x - tau_ / cell_.mean_extinction : x;
      break;
    case MemoryRule::carried:
      // The survival e^{−H} so far read as this cell's distance under its own law.
      shift_ = x - cell_.memory_for(h_);
      break;
  }
}

double GammaHazard::piece(double a, double b) const { return cell_.integral(memory(a), b - a); }

void GammaHazard::advance(double a, double b) {
  h_ += piece(a, b);
  tau_ += cell_.mean_extinction * (b - a);
}

double GammaHazard::advance_until(double a, double b, double target) {
  const double dh = piece(a, b);
  if (h_ + dh < target) {
    h_ += dh;
    tau_ += cell_.mean_extinction * (b - a);
    return std::numeric_limits<double>::infinity();
  }
  return std::min(a + cell_.length_to(memory(a), target - h_), b);
}

}  // namespace weft::transmittance
