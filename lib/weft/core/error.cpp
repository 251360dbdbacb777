#include "weft/core/error.h"

#include <cmath>

namespace weft {

std::string Error::one_line(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if ((u >= 0x20 && u != 0x7f) || c == '\t') {
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\0') {
      out += "\\0";
    } else {
      out += fmt::format("\\x{:02x}", u);
    }
  }
  return out;
}

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
