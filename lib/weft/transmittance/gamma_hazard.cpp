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

}  // namespace weft::transmittance
