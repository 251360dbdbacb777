#include "weft/transmittance/tabulated.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>

#include "weft/core/error.h"
#include "weft/core/file_kind.h"
#include "weft/core/parse_number.h"
#include "weft/transmittance/overflow.h"

namespace weft::transmittance {

Tabulated::Tabulated(std::vector<double> t, std::vector<double> transmittance, std::string source)
    : t_(std::move(t)), value_(std::move(transmittance)), source_(std::move(source)) {
  if (t_.size() != value_.size()) {
    fail("tabulated law ({}): {} t values but {} T values", source_, t_.size(), value_.size());
  }
  if (t_.size() < 2) fail("tabulated law ({}): needs at least 2 samples, got {}", source_, t_.size());
  if (t_[0] != 0.0) fail("tabulated law ({}): the first sample must be at t = 0, got t = {}", source_, t_[0]);
  if (value_[0] != 1.0) fail("tabulated law ({}): T(0) must be 1, got {}", source_, value_[0]);
  for (std::size_t i = 0; i < t_.size(); ++i) {
    if (!std::isfinite(t_[i])) fail("tabulated law ({}): sample {}: t is not finite ({})", source_, i + 1, t_[i]);
    if (std::isnan(value_[i]) || !(value_[i] >= 0.0 && value_[i] <= 1.0)) {  // NaN first: no FE_INVALID
      fail("tabulated law ({}): sample {}: T must be in [0, 1], got {}", source_, i + 1, value_[i]);
    }
    if (i == 0) continue;
    if (!(t_[i] > t_[i - 1])) {
      fail("tabulated law ({}): sample {}: t must increase strictly, got {} after {}", source_, i + 1, t_[i],
           t_[i - 1]);
    }
    if (value_[i] > value_[i - 1]) {
      fail("tabulated law ({}): sample {}: T must not increase, got {} after {} (t = {})", source_, i + 1, value_[i],
           value_[i - 1], t_[i]);
    }
    if (value_[i - 1] == 0.0 && value_[i] != 0.0) {
      fail("tabulated law ({}): sample {}: T must stay 0 once it reaches 0", source_, i + 1);
    }
  }
  // Drop samples after the first zero: T is 0 from there on.
  const auto first_zero = std::find(value_.begin(), value_.end(), 0.0);
  if (first_zero != value_.end()) {
    const auto keep = static_cast<std::size_t>(first_zero - value_.begin()) + 1;
    t_.resize(keep);
    value_.resize(keep);
  }
  log_value_.resize(t_.size());
  for (std::size_t i = 0; i < t_.size(); ++i) log_value_[i] = value_[i] > 0.0 ? std::log(value_[i]) : -kInfinity;
  hazard_.resize(t_.size() - 1);
  for (std::size_t i = 0; i + 1 < t_.size(); ++i) {
    hazard_[i] = value_[i + 1] == 0.0 ? std::numeric_limits<double>::quiet_NaN()
                                      : (log_value_[i] - log_value_[i + 1]) / (t_[i + 1] - t_[i]);
  }
}

Tabulated Tabulated::from_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail("tabulated law: cannot open table file '{}'", path);
  {
    // A binary file (a .vdb, an image) is named, not quoted back line by line as garbage.
    char head[512];
    in.read(head, sizeof head);
    const std::string_view h(head, static_cast<std::size_t>(in.gcount()));
    if (!h.empty() && !looks_like_text(h))
      fail("tabulated law: {}: not a CSV table of t,T (looks like {})", path, file_kind(h));
    in.clear();
    in.seekg(0);
  }
  std::vector<double> t;
  std::vector<double> value;
  std::string line;
  int line_number = 0;
  bool seen_data = false;
  while (std::getline(in, line)) {
    ++line_number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::string spaced = line;  // the line as written stays for the messages
    std::replace(spaced.begin(), spaced.end(), ',', ' ');
    std::istringstream fields(spaced);
    std::string a;
    std::string b;
    std::string extra;
    fields >> a >> b;
    // parse_number: locale-free, subnormals (1e-320) are numbers, a value past double's range is not.
    const std::optional<double> tv = parse_number(a);
    const std::optional<double> vv = parse_number(b);
    if (!tv || !vv) {
      if (!seen_data && line_number == 1) continue;  // header row
      if (!line.empty() && line.back() == '\r') line.pop_back();
      fail("tabulated law: {}:{}: expected two numbers 't,T', got '{}'", path, line_number, line);
    }
    if (fields >> extra) fail("tabulated law: {}:{}: expected two columns 't,T', got more", path, line_number);
    seen_data = true;
    t.push_back(*tv);
    value.push_back(*vv);
  }
  if (t.empty()) fail("tabulated law: table file '{}' has no samples", path);
  return {std::move(t), std::move(value), path};
}

std::size_t Tabulated::interval(double t) const {
  // Last i with t_i ≤ t.
  const auto it = std::upper_bound(t_.begin(), t_.end(), t);
  return static_cast<std::size_t>(it - t_.begin()) - 1;
}

double Tabulated::log_transmittance(double t) const {
  if (t <= 0.0) return 0.0;
  const std::size_t i = interval(t);
  if (i + 1 >= t_.size()) {
    // Tail: the last interval's hazard goes on (+∞·0 avoided for a flat tail).
    if (value_.back() == 0.0) return -kInfinity;
    const double h = hazard_.back();
    if (h == 0.0) return log_value_.back();
    return log_value_.back() - product_or_infinity(h, t - t_.back());
  }
  if (std::isnan(hazard_[i])) return std::log(transmittance(t));
  return log_value_[i] - hazard_[i] * (t - t_[i]);
}

double Tabulated::transmittance(double t) const {
  if (t <= 0.0) return 1.0;
  const std::size_t i = interval(t);
  if (i + 1 < t_.size() && std::isnan(hazard_[i])) {
    // Linear to zero on the last interval.
    return value_[i] * (t_[i + 1] - t) / (t_[i + 1] - t_[i]);
  }
  return std::exp(log_transmittance(t));
}

double Tabulated::hazard(double t) const {
  const std::size_t i = interval(std::max(t, 0.0));
  if (i + 1 >= t_.size()) return value_.back() == 0.0 ? kInfinity : hazard_.back();
  if (std::isnan(hazard_[i])) return 1.0 / (t_[i + 1] - t);  // (T_i/Δ) / (T_i(t_{i+1} − t)/Δ)
  return hazard_[i];
}

double Tabulated::pdf(double t) const {
  const double value = transmittance(t);
  if (value == 0.0) return 0.0;
  return hazard(t) * value;
}

double Tabulated::sample(Pcg32& rng) const {
  const double u = 1.0 - rng.uniform();  // (0, 1]: the target T
  const double log_u = std::log(u);
  // First sample whose log T is below log u; the answer lies in the interval before it.
  const auto it = std::upper_bound(log_value_.begin(), log_value_.end(), log_u,
                                   [](double target, double lv) { return lv < target; });
  if (it == log_value_.end()) {
    // In the tail.
    const double h = hazard_.back();
    if (value_.back() == 0.0) return t_.back();
    if (h == 0.0) return kInfinity;  // never collides
    // Past DBL_MAX the draw saturates (law.h), without overflowing.
    constexpr double kMax = std::numeric_limits<double>::max();
    const double beyond = saturating_quotient(log_value_.back() - log_u, h);
    return beyond >= kMax - t_.back() ? kMax : t_.back() + beyond;
  }
  const auto j = static_cast<std::size_t>(it - log_value_.begin());  // j ≥ 1 since log T_0 = 0 ≥ log u
  const std::size_t i = j - 1;
  if (std::isnan(hazard_[i])) return t_[i] + (t_[j] - t_[i]) * (1.0 - u / value_[i]);
  return t_[i] + (log_value_[i] - log_u) / hazard_[i];
}

double Tabulated::mean_free_path() const {
  double sum = 0.0;
  for (std::size_t i = 0; i + 1 < t_.size(); ++i) {
    const double dt = t_[i + 1] - t_[i];
    if (std::isnan(hazard_[i])) {
      sum += 0.5 * value_[i] * dt;
    } else if (hazard_[i] == 0.0) {
      sum += value_[i] * dt;
    } else {
      sum += (value_[i] - value_[i + 1]) / hazard_[i];  // ∫ T_i e^{−h s} ds over the interval
    }
  }
  if (value_.back() > 0.0) {
    const double h = hazard_.back();
    if (h == 0.0) return kInfinity;
    sum += value_.back() / h;
  }
  return sum;
}

}  // namespace weft::transmittance
