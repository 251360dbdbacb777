// A candidate's bias against image scale (bias_scales.h; docs/render.md §6e).
#include "weft/study/bias_scales.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "weft/core/error.h"
#include "weft/study/bias_estimate.h"

namespace weft::study {

using render::Image;

double BlockBias::bias() const { return std::sqrt(std::max(0.0, bias_sq)); }
double BlockBias::z() const { return stderr_sq > 0.0 ? bias_sq / stderr_sq : 0.0; }

nlohmann::json scale_bias_json(const ScaleBias& s) {
  nlohmann::json blocks = nlohmann::json::array();
  for (const BlockBias& b : s.blocks)
    blocks.push_back({{"block", b.block},
                      {"count", b.blocks},
                      {"bias_sq", b.bias_sq},
                      {"bias_sq_stderr", b.stderr_sq},
                      {"bias", b.bias()},
                      {"bias_z", b.z()}});
  return {{"blocks", blocks},
          {"level", {{"difference", s.level.difference}, {"difference_stderr", s.level.stderr_difference}}}};
}

ScaleBias scale_bias_from_json(const nlohmann::json& j) {
  ScaleBias s;
  for (const auto& b : j.at("blocks"))
    s.blocks.push_back({b.at("block").get<int>(), b.at("count").get<int>(), b.at("bias_sq").get<double>(),
                        b.at("bias_sq_stderr").get<double>()});
  s.level.difference = j.at("level").at("difference").get<double>();
  s.level.stderr_difference = j.at("level").at("difference_stderr").get<double>();
  return s;
}

std::string scale_bias_csv_header() {
  std::string h;
  for (const int k : kBiasBlocks)
    if (k > 1) h += fmt::format("cloth_bias_{0}px,cloth_bias_{0}px_z,", k);
  return h + "cloth_level,cloth_level_stderr";
}

std::string scale_bias_csv(const ScaleBias& s) {
  std::string row;
  for (const int k : kBiasBlocks) {
    if (k == 1) continue;
    const auto it = std::find_if(s.blocks.begin(), s.blocks.end(), [&](const BlockBias& b) { return b.block == k; });
    row += it == s.blocks.end() ? std::string(",,") : fmt::format("{:.8g},{:.4g},", it->bias(), it->z());
  }
  return row + (s.blocks.empty() ? std::string(",")
                                 : fmt::format("{:.8g},{:.6g}", s.level.difference, s.level.stderr_difference));
}

Image block_means(const Image& image, int k, const std::vector<bool>& mask, std::vector<bool>& block_mask) {
  if (k < 1) fail("bias by scale: block size must be >= 1 pixel, got {}", k);
  Image out;
  out.width = image.width / k;
  out.height = image.height / k;
  out.spp = image.spp;
  const auto cells = static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height);
  out.rgb.assign(3 * cells, 0.0F);
  if (!image.variance.empty()) out.variance.assign(3 * cells, 0.0F);
  block_mask.assign(cells, true);
  const double inv = 1.0 / (static_cast<double>(k) * k);
  for (int by = 0; by < out.height; ++by) {
    for (int bx = 0; bx < out.width; ++bx) {
      const std::size_t cell = static_cast<std::size_t>(by) * out.width + bx;
      double sum[3] = {0.0, 0.0, 0.0};
      double var[3] = {0.0, 0.0, 0.0};
      for (int y = by * k; y < (by + 1) * k; ++y) {
        for (int x = bx * k; x < (bx + 1) * k; ++x) {
          const std::size_t p = static_cast<std::size_t>(y) * image.width + x;
          if (!mask.empty() && !mask[p]) block_mask[cell] = false;
          for (std::size_t c = 0; c < 3; ++c) {
            sum[c] += image.rgb[3 * p + c];
            if (!image.variance.empty()) var[c] += image.variance[3 * p + c];
          }
        }
      }
      for (std::size_t c = 0; c < 3; ++c) {
        out.rgb[3 * cell + c] = static_cast<float>(sum[c] * inv);
        // Var of a mean of k² independent pixel means: Σ var / k⁴ (bias_scales.h).
        if (!out.variance.empty()) out.variance[3 * cell + c] = static_cast<float>(var[c] * inv * inv);
      }
    }
  }
  return out;
}

namespace {

/// The level over the mask (bias_scales.h). Its variance is Σ_p Var(Σ_c d_pc) / N² over the N
/// values: the three channels of a pixel come from the same paths, so each pixel's channel sum
/// is one term. Var of (A + B)/2's channel sum is estimated without bias by (Σ_c (a − b))²/4 (A
/// and B independent, alike); R's by (Σ_c sd_c)², the bound of fully correlated channels, since
/// R carries per-channel variances only.
LevelBias level_of(const Image& a, const Image& b, const Image& r, const std::vector<bool>& mask) {
  LevelBias level;
  double sum = 0.0;
  double var = 0.0;
  std::size_t n = 0;
  const std::size_t pixels = r.rgb.size() / 3;
  for (std::size_t p = 0; p < pixels; ++p) {
    if (!mask.empty() && !mask[p]) continue;
    double d_ab = 0.0;
    double sd_r = 0.0;
    for (std::size_t c = 0; c < 3; ++c) {
      const std::size_t i = 3 * p + c;
      sum += 0.5 * (static_cast<double>(a.rgb[i]) + b.rgb[i]) - r.rgb[i];
      d_ab += static_cast<double>(a.rgb[i]) - b.rgb[i];
      sd_r += r.variance.empty() ? 0.0 : std::sqrt(std::max(0.0F, r.variance[i]));
    }
    var += d_ab * d_ab / 4.0 + sd_r * sd_r;
    n += 3;
  }
  if (n == 0) return level;
  const auto nn = static_cast<double>(n);
  level.difference = sum / nn;
  level.stderr_difference = std::sqrt(var) / nn;
  return level;
}

}  // namespace

ScaleBias bias_by_scale(const Image& a, const Image& b, const Image& r, const std::vector<bool>& mask,
                        const std::vector<int>& blocks) {
  // estimate_bias checks the sizes of A, B and R; the level needs them first.
  (void)estimate_bias(a, b, r, nullptr);
  if (!mask.empty() && mask.size() != r.rgb.size() / 3)
    fail("bias by scale: mask of {} pixels for a {}x{} image", mask.size(), r.width, r.height);
  ScaleBias out;
  for (const int k : blocks) {
    std::vector<bool> block_mask;
    const Image ak = block_means(a, k, mask, block_mask);
    const Image bk = block_means(b, k, mask, block_mask);
    const Image rk = block_means(r, k, mask, block_mask);
    BlockBias bb;
    bb.block = k;
    bb.blocks = static_cast<int>(std::count(block_mask.begin(), block_mask.end(), true));
    const BiasEstimate e = estimate_bias(ak, bk, rk, &block_mask);
    bb.bias_sq = e.bias_sq;
    bb.stderr_sq = e.stderr_sq;
    out.blocks.push_back(bb);
  }
  out.level = level_of(a, b, r, mask);
  return out;
}

}  // namespace weft::study
