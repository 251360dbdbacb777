#include "weft/core/number_name.h"

#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "weft/core/parse_number.h"

namespace weft {

// fmt's {} is the shortest round-trip form; + 0.0 turns −0 into 0.
std::string number_name(double x) { return fmt::format("{}", x + 0.0); }

std::string signed_number_name(double x) { return fmt::format("{}{}", x + 0.0 < 0.0 ? "" : "+", number_name(x)); }

std::string bound_text(double bound, BoundSide side) {
  if (!std::isfinite(bound) || bound == 0.0) return fmt::format("{}", bound + 0.0);
  // Read back as weft reads options (parse_number: the same in every locale).
  const auto accepted = [&](const std::string& text) {
    const std::optional<double> v = parse_number(text);
    return v && (side == BoundSide::at_least ? *v >= bound : *v <= bound);
  };
  for (int digits = 4; digits <= 17; ++digits) {
    std::string text = fmt::format("{:.{}g}", bound, digits);
    if (accepted(text)) return text;
    // Rounded to the nearest it fell on the refused side: one unit of the last digit the other way.
    const double unit = std::pow(10.0, std::floor(std::log10(std::fabs(bound))) - (digits - 1));
    const double stepped =
        side == BoundSide::at_least ? std::ceil(bound / unit) * unit : std::floor(bound / unit) * unit;
    text = fmt::format("{:.{}g}", stepped, digits);
    if (accepted(text)) return text;
  }
  return fmt::format("{}", bound);  // the shortest round-trip form is the bound itself
}

}  // namespace weft
