// The resolution floor of a coarsening factor (resolution_floor.h; docs/render.md §6e).
#include "weft/study/resolution_floor.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>

#include <nlohmann/json.hpp>

#include "weft/core/error.h"

namespace weft::study {

using render::Image;

double block_footprint_pixels(const render::CameraDesc& camera, const render::Vec3& centre, double block) {
  if (!(block > 0.0) || !std::isfinite(block)) fail("resolution floor: block size must be > 0, got {}", block);
  const double d = (centre - camera.position).norm();
  if (!(d > 0.0)) fail("resolution floor: the cloth's centre is at the camera");
  const double pitch = 2.0 * d * std::tan(0.5 * camera.fov_deg * std::numbers::pi / 180.0) / camera.height;
  return block / pitch;
}

namespace {

/// The normalised tent at integer offsets −(n−1) … n−1, n = ⌈footprint⌉.
std::vector<double> tent_weights(double footprint) {
  const int n = static_cast<int>(std::ceil(footprint));
  std::vector<double> w;
  double sum = 0.0;
  for (int d = -(n - 1); d <= n - 1; ++d) {
    w.push_back(std::max(0.0, 1.0 - std::abs(d) / footprint));
    sum += w.back();
  }
  for (double& x : w) x /= sum;
  return w;
}

/// One pass of the separable filter along x (dx = 1) or y: values with the weights, variances
/// with their squares (independent pixels), edges clamped.
void convolve(Image& img, const std::vector<double>& w, bool along_x) {
  const int r = static_cast<int>(w.size() / 2);
  const std::vector<float> rgb = img.rgb;
  const std::vector<float> var = img.variance;
  const auto index = [&](int x, int y, int c) { return (static_cast<std::size_t>(y) * img.width + x) * 3 + c; };
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c) {
        double v = 0.0;
        double s = 0.0;
        for (std::size_t j = 0; j < w.size(); ++j) {
          const int k = static_cast<int>(j) - r;
          const int xx = along_x ? std::clamp(x + k, 0, img.width - 1) : x;
          const int yy = along_x ? y : std::clamp(y + k, 0, img.height - 1);
          const double wk = w[j];
          v += wk * rgb[index(xx, yy, c)];
          if (!var.empty()) s += wk * wk * var[index(xx, yy, c)];
        }
        img.rgb[index(x, y, c)] = static_cast<float>(v);
        if (!var.empty()) img.variance[index(x, y, c)] = static_cast<float>(s);
      }
}

}  // namespace

Image smooth_over_footprint(const Image& image, double footprint) {
  if (!std::isfinite(footprint)) fail("resolution floor: footprint must be finite, got {}", footprint);
  Image out = image;
  if (footprint <= 1.0) return out;
  const std::vector<double> w = tent_weights(footprint);
  convolve(out, w, true);
  convolve(out, w, false);
  return out;
}

std::vector<ResolutionFloor> resolution_floors(const Image& a, const Image& b, const Image& reference,
                                               const std::vector<bool>& mask, const render::CameraDesc& camera,
                                               const render::Vec3& centre, double voxel,
                                               const std::vector<int>& factors) {
  std::vector<ResolutionFloor> out;
  for (const int f : factors) {
    ResolutionFloor r;
    r.factor = f;
    r.footprint = block_footprint_pixels(camera, centre, f * voxel);
    r.scales =
        bias_by_scale(smooth_over_footprint(a, r.footprint), smooth_over_footprint(b, r.footprint), reference, mask);
    out.push_back(std::move(r));
  }
  return out;
}

nlohmann::json resolution_floor_json(const ResolutionFloor& f) {
  return {{"factor", f.factor}, {"footprint_px", f.footprint}, {"scales", scale_bias_json(f.scales)}};
}

ResolutionFloor resolution_floor_from_json(const nlohmann::json& j) {
  ResolutionFloor f;
  f.factor = j.at("factor").get<int>();
  f.footprint = j.at("footprint_px").get<double>();
  f.scales = scale_bias_from_json(j.at("scales"));
  return f;
}

}  // namespace weft::study
