#include "weft/core/error.h"

#include <cmath>

namespace weft {

double require_finite(const char* what, double value) {
  if (!std::isfinite(value)) fail("{} must be finite, got {}", what, value);
  return value;
}

double require_positive(const char* what, double value) {
  if (!(std::isfinite(value) && value > 0.0)) fail("{} must be finite and > 0, got {}", what, value);
  return value;
}

double require_non_negative(const char* what, double value) {
  if (!(std::isfinite(value) && value >= 0.0)) fail("{} must be finite and >= 0, got {}", what, value);
  return value;
}

}  // namespace weft
