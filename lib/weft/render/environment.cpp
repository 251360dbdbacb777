#include "weft/render/environment.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "weft/core/error.h"

namespace weft::render {
namespace {

constexpr double kPi = std::numbers::pi;

/// Index i of the interval [cdf[i], cdf[i+1]) that holds ξ: the last i with cdf[i] ≤ ξ, which
/// never lands on an empty interval (cdf[i+1] > ξ ≥ cdf[i]).
std::size_t find_interval(const double* cdf, std::size_t n, double xi) {
  const double* it = std::upper_bound(cdf, cdf + n + 1, xi);
  const auto i = static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, it - cdf - 1));
  return std::min(i, n - 1);
}

}  // namespace

Distribution2D::Distribution2D(std::vector<double> f, int nu, int nv) : nu_(nu), nv_(nv), f_(std::move(f)) {
  if (nu < 1 || nv < 1 || f_.size() != static_cast<std::size_t>(nu) * nv)
    fail("Distribution2D: {}x{} cells but {} values", nu, nv, f_.size());
  const auto nus = static_cast<std::size_t>(nu);
  row_cdf_.assign(static_cast<std::size_t>(nv) * (nus + 1), 0.0);
  row_int_.assign(static_cast<std::size_t>(nv), 0.0);
  marginal_.assign(static_cast<std::size_t>(nv) + 1, 0.0);
  for (std::size_t v = 0; v < static_cast<std::size_t>(nv); ++v) {
    double* cdf = &row_cdf_[v * (nus + 1)];
    for (std::size_t u = 0; u < nus; ++u) {
      const double x = f_[v * nus + u];
      if (!(x >= 0.0) || !std::isfinite(x)) fail("Distribution2D: cell ({}, {}) is {}", u, v, x);
      cdf[u + 1] = cdf[u] + x / nu;
    }
    row_int_[v] = cdf[nus];
    for (std::size_t u = 1; u <= nus; ++u) cdf[u] = row_int_[v] > 0.0 ? cdf[u] / row_int_[v] : double(u) / nu;
    marginal_[v + 1] = marginal_[v] + row_int_[v] / nv;
  }
  integral_ = marginal_.back();
  for (std::size_t v = 1; v <= static_cast<std::size_t>(nv); ++v)
    marginal_[v] = integral_ > 0.0 ? marginal_[v] / integral_ : double(v) / nv;
}

Distribution2D::Sample Distribution2D::sample(double xi1, double xi2) const {
  Sample s;
  if (!(integral_ > 0.0)) return s;
  const auto nus = static_cast<std::size_t>(nu_);
  const std::size_t v = find_interval(marginal_.data(), static_cast<std::size_t>(nv_), xi1);
  const double dv = (xi1 - marginal_[v]) / (marginal_[v + 1] - marginal_[v]);
  const double* cdf = &row_cdf_[v * (nus + 1)];
  const std::size_t u = find_interval(cdf, nus, xi2);
  const double du = (xi2 - cdf[u]) / (cdf[u + 1] - cdf[u]);
  s.u = std::clamp((static_cast<double>(u) + du) / nu_, 0.0, 1.0);
  s.v = std::clamp((static_cast<double>(v) + dv) / nv_, 0.0, 1.0);
  // p(v)·p(u|v) = (I_v/I)·(f/I_v) = f/I.
  s.pdf = f_[v * nus + u] / integral_;
  return s;
}

double Distribution2D::pdf(double u, double v) const {
  if (!(integral_ > 0.0)) return 0.0;
  const auto iu = static_cast<std::size_t>(std::clamp(static_cast<int>(u * nu_), 0, nu_ - 1));
  const auto iv = static_cast<std::size_t>(std::clamp(static_cast<int>(v * nv_), 0, nv_ - 1));
  return f_[iv * static_cast<std::size_t>(nu_) + iu] / integral_;
}

namespace {
std::vector<double> sampling_weights(int width, int height, const std::vector<float>& rgb) {
  std::vector<double> f(static_cast<std::size_t>(width) * height);
  for (int y = 0; y < height; ++y) {
    // The (u, v) → ω map stretches each cell by sin θ: weigh by it so samples follow L dω.
    const double sin_theta = std::sin(kPi * (y + 0.5) / height);
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * width + x;
      f[i] = sin_theta * (double(rgb[3 * i]) + rgb[3 * i + 1] + rgb[3 * i + 2]) / 3.0;
    }
  }
  return f;
}
}  // namespace

EnvironmentMap::EnvironmentMap(int width, int height, std::vector<float> rgb, double scale)
    : width_(width),
      height_(height),
      rgb_(std::move(rgb)),
      scale_(scale),
      dist_(sampling_weights(width, height, rgb_), width, height) {}

bool EnvironmentMap::emits() const {
  return scale_ > 0.0 && std::any_of(rgb_.begin(), rgb_.end(), [](float x) { return x > 0.0f; });
}

Vec3 EnvironmentMap::direction(double u, double v) {
  const double theta = kPi * v;
  const double phi = 2.0 * kPi * u - kPi;
  const double s = std::sin(theta);
  return {s * std::sin(phi), std::cos(theta), -s * std::cos(phi)};
}

void EnvironmentMap::coordinates(const Vec3& dir, double& u, double& v) {
  const Vec3 d = dir.normalized();
  v = std::acos(std::clamp(d.y(), -1.0, 1.0)) / kPi;
  u = (std::atan2(d.x(), -d.z()) + kPi) / (2.0 * kPi);
  u = std::clamp(u, 0.0, 1.0);
}

std::size_t EnvironmentMap::pixel(double u, double v) const {
  const int x = std::clamp(static_cast<int>(u * width_), 0, width_ - 1);
  const int y = std::clamp(static_cast<int>(v * height_), 0, height_ - 1);
  return static_cast<std::size_t>(y) * width_ + x;
}

Rgb EnvironmentMap::radiance(const Vec3& dir) const {
  double u = 0.0;
  double v = 0.0;
  coordinates(dir, u, v);
  const std::size_t i = pixel(u, v);
  return scale_ * Rgb(rgb_[3 * i], rgb_[3 * i + 1], rgb_[3 * i + 2]);
}

double EnvironmentMap::pdf(const Vec3& dir) const {
  double u = 0.0;
  double v = 0.0;
  coordinates(dir, u, v);
  const double sin_theta = std::sin(kPi * v);
  if (!(sin_theta > 0.0)) return 0.0;
  return dist_.pdf(u, v) / (2.0 * kPi * kPi * sin_theta);
}

EnvironmentMap::Sample EnvironmentMap::sample(double xi1, double xi2) const {
  Sample s;
  const Distribution2D::Sample uv = dist_.sample(xi1, xi2);
  const double sin_theta = std::sin(kPi * uv.v);
  if (!(uv.pdf > 0.0) || !(sin_theta > 0.0)) return s;
  s.wi = direction(uv.u, uv.v);
  s.pdf = uv.pdf / (2.0 * kPi * kPi * sin_theta);
  const std::size_t i = pixel(uv.u, uv.v);
  s.radiance = scale_ * Rgb(rgb_[3 * i], rgb_[3 * i + 1], rgb_[3 * i + 2]);
  return s;
}

EnvironmentMap load_environment(const std::filesystem::path& path, double scale) {
  if (!std::filesystem::is_regular_file(path))
    fail("environment image '{}' cannot be opened (missing or not a file)", path.string());
  Image im = read_exr(path);
  for (std::size_t i = 0; i < im.rgb.size(); ++i) {
    if (!std::isfinite(im.rgb[i]) || im.rgb[i] < 0.0f)
      fail("environment image '{}': pixel ({}, {}) has value {} (radiance must be finite and >= 0)", path.string(),
           (i / 3) % static_cast<std::size_t>(im.width), (i / 3) / static_cast<std::size_t>(im.width), im.rgb[i]);
  }
  return EnvironmentMap(im.width, im.height, std::move(im.rgb), scale);
}

}  // namespace weft::render
