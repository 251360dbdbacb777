#pragma once
/// @file
/// @brief A candidate's converged bias against image scale (docs/render.md §6e, "Bias against
/// image scale"): the estimator of bias_estimate.h on images box-filtered over k × k pixel
/// blocks, and over the whole mask (the level: the mean difference with its standard error).

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "weft/render/image.h"

namespace weft::study {

/// The block sizes every study reports (pixels per block side; the level is reported apart).
inline const std::vector<int> kBiasBlocks{1, 2, 4, 8};

/// A block size with fewer blocks on the cloth than this has no usable standard error (the
/// spread of a handful of values whose channels are correlated): it is reported, not judged
/// (matrix.md shows "–", the tests skip it).
constexpr int kMinBiasBlocks = 10;

/// The bias at one block size k: estimate_bias on the k × k block means of A, B and R.
struct BlockBias {
  int block = 1;                      ///< k, pixels per block side
  int blocks = 0;                     ///< blocks wholly inside the mask
  double bias_sq = 0.0;               ///< may be < 0 by noise
  double stderr_sq = 0.0;             ///< its standard error
  [[nodiscard]] double bias() const;  ///< sqrt(max(0, bias_sq))
  [[nodiscard]] double z() const;     ///< bias_sq in standard errors (0 when the error is 0)
};

/// The level: the mean over the mask's values of (A + B)/2 − R, and its standard error from the
/// images' own noise (docs/render.md §6e).
struct LevelBias {
  double difference = 0.0;
  double stderr_difference = 0.0;
};

struct ScaleBias {
  std::vector<BlockBias> blocks;  ///< one per requested k, in order
  LevelBias level;
};

/// @brief The k × k block means of `image` (blocks aligned to the top-left pixel; a partial block
/// at the right or bottom edge is dropped) with the variance of each block mean Σ var / k⁴ (the
/// block's k² pixel means are independent: every pixel draws from its own streams, so
/// Var(Σ x_i / k²) = Σ Var x_i / k⁴). `mask` (one flag per pixel, may be empty: all) becomes
/// `block_mask`: a block is in it when all its pixels are. Throws weft::Error for k < 1.
[[nodiscard]] render::Image block_means(const render::Image& image, int k, const std::vector<bool>& mask,
                                        std::vector<bool>& block_mask);

/// @brief The bias of A, B (same spp, independent seeds) against the reference R at every k of
/// `blocks`, and the level, over the pixels of `mask` (empty: every pixel). k = 1 is
/// estimate_bias itself. Throws weft::Error for images of different sizes or k < 1.
[[nodiscard]] ScaleBias bias_by_scale(const render::Image& a, const render::Image& b, const render::Image& reference,
                                      const std::vector<bool>& mask, const std::vector<int>& blocks = kBiasBlocks);

/// The JSON of a ScaleBias, the one format of the study's reports and of the matrix's stored
/// cases: {"blocks": [{"block", "count", "bias_sq", "bias_sq_stderr", "bias", "bias_z"}, …],
/// "level": {"difference", "difference_stderr"}}; and back (derived keys ignored).
[[nodiscard]] nlohmann::json scale_bias_json(const ScaleBias& s);
[[nodiscard]] ScaleBias scale_bias_from_json(const nlohmann::json& j);

/// CSV columns of a ScaleBias at kBiasBlocks beyond 1 px (1 px is the study's cloth_bias) and the
/// level: "cloth_bias_2px,cloth_bias_2px_z,…,cloth_level,cloth_level_stderr"; and one row's
/// fields (empty when `s` has none).
[[nodiscard]] std::string scale_bias_csv_header();
[[nodiscard]] std::string scale_bias_csv(const ScaleBias& s);

}  // namespace weft::study
