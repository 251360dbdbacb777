#include "weft/render/convergence.h"

#include <algorithm>
#include <cmath>

#include "weft/core/error.h"

namespace weft::render {

LogLogFit fit_log_log(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size()) fail("log-log fit: {} x values but {} y values", x.size(), y.size());
  std::vector<double> lx;
  std::vector<double> ly;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (std::isfinite(x[i]) && std::isfinite(y[i]) && x[i] > 0.0 && y[i] > 0.0) {
      lx.push_back(std::log(x[i]));
      ly.push_back(std::log(y[i]));
    }
  }
  const auto n = static_cast<double>(lx.size());
  if (lx.size() < 2) fail("log-log fit: {} usable points (x > 0 and y > 0), need 2", lx.size());
  double mx = 0.0;
  double my = 0.0;
  for (std::size_t i = 0; i < lx.size(); ++i) {
    mx += lx[i];
    my += ly[i];
  }
  mx /= n;
  my /= n;
  double sxx = 0.0;
  double sxy = 0.0;
  for (std::size_t i = 0; i < lx.size(); ++i) {
    sxx += (lx[i] - mx) * (lx[i] - mx);
    sxy += (lx[i] - mx) * (ly[i] - my);
  }
  if (!(sxx > 0.0)) fail("log-log fit: all x values are equal");
  LogLogFit fit;
  fit.slope = sxy / sxx;
  fit.intercept = my - fit.slope * mx;
  fit.points = static_cast<int>(lx.size());
  if (lx.size() > 2) {
    double rss = 0.0;
    for (std::size_t i = 0; i < lx.size(); ++i) {
      const double r = ly[i] - (fit.intercept + fit.slope * lx[i]);
      rss += r * r;
    }
    fit.slope_stderr = std::sqrt(rss / (n - 2.0) / sxx);
  }
  return fit;
}

void check_reference(const Image& reference, const std::string& source) {
  for (std::size_t i = 0; i < reference.rgb.size(); ++i) {
    const float v = reference.rgb[i];
    if (std::isfinite(v) && v >= 0.0F) continue;
    const std::size_t pixel = i / 3;
    const auto width = static_cast<std::size_t>(std::max(1, reference.width));
    fail("reference '{}': pixel (x {}, y {}) channel {} is {}: a radiance image has no negative or non-finite value",
         source, pixel % width, pixel / width, "RGB"[i % 3], v);
  }
}

double mean_variance(const Image& image) {
  if (image.variance.empty()) return 0.0;
  double sum = 0.0;
  for (const float v : image.variance) sum += static_cast<double>(v);
  return sum / static_cast<double>(image.variance.size());
}

double rmse_against_noisy_reference(const Image& image, const Image& reference) {
  const double e = rmse(image, reference);
  return std::sqrt(std::max(0.0, e * e - mean_variance(reference)));
}

}  // namespace weft::render
