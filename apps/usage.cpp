#include "usage.h"

#include <cstdlib>

namespace weft::app {

double usage_positive(const char* option, double value) {
  if (!(std::isfinite(value) && value > 0.0)) usage_fail("{} must be finite and > 0, got {}", option, value);
  return value;
}

double usage_non_negative(const char* option, double value) {
  if (!(std::isfinite(value) && value >= 0.0)) usage_fail("{} must be finite and >= 0, got {}", option, value);
  return value;
}

namespace {

/// The option's text as a double, or NaN (CLI11 has already refused non-numbers for numeric
/// options; "nan" and "inf" parse and are refused by the callers).
double number_of(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  return end == text.c_str() || *end != '\0' ? std::nan("") : v;
}

}  // namespace

const CLI::Validator positive(
    [](std::string& text) -> std::string {
      const double v = number_of(text);
      return std::isfinite(v) && v > 0.0 ? std::string() : fmt::format("must be finite and > 0, got {}", text);
    },
    "> 0", "positive");

const CLI::Validator non_negative(
    [](std::string& text) -> std::string {
      const double v = number_of(text);
      return std::isfinite(v) && v >= 0.0 ? std::string() : fmt::format("must be finite and >= 0, got {}", text);
    },
    ">= 0", "non_negative");

CLI::Validator at_least(long long min) {
  return CLI::Validator(
      [min](std::string& text) -> std::string {
        const double v = number_of(text);
        return std::isfinite(v) && v >= static_cast<double>(min) ? std::string()
                                                                 : fmt::format("must be >= {}, got {}", min, text);
      },
      fmt::format(">= {}", min), "at_least");
}

CLI::Validator in_range(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        const double v = number_of(text);
        return std::isfinite(v) && v >= lo && v <= hi
                   ? std::string()
                   : fmt::format("must be a number in [{}, {}], got {}", lo, hi, text);
      },
      fmt::format("[{}, {}]", lo, hi), "in_range");
}

}  // namespace weft::app
