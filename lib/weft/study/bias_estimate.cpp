#include "weft/study/bias_estimate.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "weft/core/error.h"

namespace weft::study {

using render::Image;

BiasEstimate estimate_bias(const Image& a, const Image& b, const Image& r, const std::vector<bool>* mask) {
  if (a.width != r.width || a.height != r.height || b.width != r.width || b.height != r.height ||
      a.rgb.size() != r.rgb.size() || b.rgb.size() != r.rgb.size())
    fail("bias estimate: images differ in size ({}x{}, {}x{}, reference {}x{})", a.width, a.height, b.width, b.height,
         r.width, r.height);
  std::size_t n = 0;
  double sum = 0.0;
  double sum2 = 0.0;
  double error = 0.0;
  double noise = 0.0;
  for (std::size_t i = 0; i < r.rgb.size(); ++i) {
    if (mask != nullptr && !(*mask)[i / 3]) continue;
    ++n;
    const double m = 0.5 * (static_cast<double>(a.rgb[i]) + b.rgb[i]) - r.rgb[i];
    const double d = static_cast<double>(a.rgb[i]) - b.rgb[i];
    const double var_r = r.variance.empty() ? 0.0 : static_cast<double>(r.variance[i]);
    const double x = m * m - d * d / 4.0 - var_r;
    const double err = static_cast<double>(a.rgb[i]) - r.rgb[i];
    error += err * err - var_r;
    noise += d * d / 2.0;
    sum += x;
    sum2 += x * x;
  }
  BiasEstimate e;
  if (n == 0) return e;
  const auto nn = static_cast<double>(n);
  e.bias_sq = sum / nn;
  e.error_sq = error / nn;
  e.noise_sq = noise / nn;
  e.stderr_sq = n > 1 ? std::sqrt(std::max(0.0, (sum2 - nn * e.bias_sq * e.bias_sq) / (nn - 1.0)) / nn) : 0.0;
  return e;
}

}  // namespace weft::study
