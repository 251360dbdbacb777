// Concentration moments → gamma shape and rate (shape_rate.h).
#include "weft/transmittance/shape_rate.h"

#include <limits>

#include "weft/transmittance/overflow.h"

namespace weft::transmittance {

ShapeRate gamma_shape_rate(double mean, double var) {
  if (!(var > 0.0)) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    return {inf, inf};
  }
  ShapeRate s;
  s.beta = quotient_or_infinity(mean, var);
  s.alpha = product_or_infinity(mean, s.beta);
  return s;
}

}  // namespace weft::transmittance
