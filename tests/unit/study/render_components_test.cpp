// The component split of a study's images (render_components.h) on synthetic renders whose
// components are known: a candidate biased in its single scattering only shows that bias there,
// transmission and multiple scattering stay unbiased, and the three levels add up to the full one.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "weft/core/error.h"
#include "weft/render/builtin_scenes.h"
#include "weft/render/scene.h"
#include "weft/study/render_components.h"

namespace weft::study {
using render::Image;
namespace {

constexpr int kW = 96;
constexpr int kH = 64;

Image blank(bool with_variance) {
  Image im;
  im.width = kW;
  im.height = kH;
  im.rgb.assign(static_cast<std::size_t>(kW) * kH * 3, 0.0F);
  if (with_variance) im.variance.assign(im.rgb.size(), 0.0F);
  return im;
}

/// One "image" and its two component renders: truth t, s, m per value, every render with its
/// own noise (σ), `single_shift` added to the single scattering of every render of the image.
struct Renders {
  Image full;
  ComponentRenders parts;
};

Renders render_like(double sigma, double single_shift, bool with_variance, std::uint64_t seed) {
  std::mt19937_64 truth_rng(99);  // the same truth for every image
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.1, 0.4);
  std::normal_distribution<double> n(0.0, sigma);
  Renders r{blank(with_variance), {blank(with_variance), blank(with_variance)}};
  const auto var = static_cast<float>(sigma * sigma);
  for (std::size_t i = 0; i < r.full.rgb.size(); ++i) {
    const double t = u(truth_rng);
    const double s = u(truth_rng) + single_shift;
    const double m = u(truth_rng);
    r.parts.transmission.rgb[i] = static_cast<float>(t + n(rng));
    r.parts.upto_single.rgb[i] = static_cast<float>(t + s + n(rng));
    r.full.rgb[i] = static_cast<float>(t + s + m + n(rng));
    if (with_variance) r.full.variance[i] = r.parts.transmission.variance[i] = r.parts.upto_single.variance[i] = var;
  }
  return r;
}

TEST(StudyComponents, ABiasInSingleScatteringShowsThereOnly) {
  const double delta = 0.04;
  const Renders a = render_like(0.08, delta, false, 1);
  const Renders b = render_like(0.08, delta, false, 2);
  const Renders r = render_like(0.02, 0.0, true, 3);
  const std::vector<ComponentBias> c = component_biases(a.full, b.full, r.full, a.parts, b.parts, r.parts, {});
  ASSERT_EQ(c.size(), 3U);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(c[i].name, kComponentNames[i]);
    const BlockBias& k = c[i].bias.blocks.at(0);
    const LevelBias& l = c[i].bias.level;
    if (c[i].name == "single") {
      EXPECT_LT(std::abs(k.bias_sq - delta * delta), 5.0 * k.stderr_sq);
      EXPECT_GT(k.z(), 5.0);
      EXPECT_LT(std::abs(l.difference - delta), 5.0 * l.stderr_difference);
    } else {
      EXPECT_LT(std::abs(k.z()), 5.0) << c[i].name;
      EXPECT_LT(std::abs(l.difference), 5.0 * l.stderr_difference) << c[i].name;
    }
  }
  // T + (L≤1 − T) + (L − L≤1) = L value by value: the levels add up to the full one.
  const ScaleBias full = bias_by_scale(a.full, b.full, r.full, {}, {1});
  EXPECT_NEAR(c[0].bias.level.difference + c[1].bias.level.difference + c[2].bias.level.difference,
              full.level.difference, 1e-6);
}

TEST(StudyComponents, ADifferenceCarriesBothVariances) {
  const Renders r = render_like(0.1, 0.0, true, 4);
  const Image d = difference_image(r.full, r.parts.upto_single);
  EXPECT_FLOAT_EQ(d.variance[7], r.full.variance[7] + r.parts.upto_single.variance[7]);
  EXPECT_FLOAT_EQ(d.rgb[7], r.full.rgb[7] - r.parts.upto_single.rgb[7]);
  Image small = r.full;
  small.width = 10;
  EXPECT_THROW((void)difference_image(small, r.full), Error);
}

TEST(StudyComponents, OnlyTheAskedFamiliesAreSplit) {
  const std::vector<std::string> asked{"exponential", "local-gamma-segment"};
  EXPECT_TRUE(splits_components(asked, "fine"));
  EXPECT_TRUE(splits_components(asked, "exponential-4x"));
  EXPECT_TRUE(splits_components(asked, "local-gamma-segment-16x"));
  EXPECT_FALSE(splits_components(asked, "local-gamma-4x"));
  EXPECT_FALSE(splits_components(asked, "shadow-corrected-4x"));
  EXPECT_FALSE(splits_components(asked, "slab-gamma"));
  EXPECT_FALSE(splits_components({}, "fine"));
  EXPECT_TRUE(splits_components({"slab-gamma"}, "slab-gamma"));
  EXPECT_TRUE(splits_components({"all"}, "shadow-corrected-8x"));
}

TEST(StudyComponents, AReflectingSurfaceIsRefused) {
  // max_depth 1 would cut the walls' bounces too: the single-scattering image would be wrong.
  const render::SceneDesc cornell =
      render::parse_scene(render::builtin_scene("cornell_media"), "built-in scene", std::filesystem::current_path());
  EXPECT_THROW(check_component_scene(cornell), Error);
}

}  // namespace
}  // namespace weft::study
