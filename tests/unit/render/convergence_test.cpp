// Convergence-study helpers (docs/render.md §6): log–log fits recover known power laws, the
// reference-noise correction removes exactly the reference's variance.
#include "weft/render/convergence.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "error_matchers.h"
#include "weft/core/error.h"
#include "weft/core/rng.h"

namespace weft::render {
namespace {

Image constant_image(int w, int h, float value, float variance = 0.0F) {
  Image im;
  im.width = w;
  im.height = h;
  im.rgb.assign(static_cast<std::size_t>(w) * h * 3, value);
  im.variance.assign(im.rgb.size(), variance);
  return im;
}

TEST(LogLogFit, RecoversAnExactPowerLaw) {
  const std::vector<double> x{2, 8, 64, 128, 512};
  std::vector<double> y;
  for (const double v : x) y.push_back(3.0 * std::pow(v, -0.5));
  const LogLogFit fit = fit_log_log(x, y);
  EXPECT_NEAR(fit.slope, -0.5, 1e-12);
  EXPECT_NEAR(std::exp(fit.intercept), 3.0, 1e-12);
  EXPECT_NEAR(fit.slope_stderr, 0.0, 1e-12);
  EXPECT_EQ(fit.points, 5);
}

// Noisy y: the fitted slope lies within 5 standard errors of the true one.
TEST(LogLogFit, NoisySlopeWithinFiveStandardErrors) {
  Pcg32 rng = stream_for(3, 0);
  std::vector<double> x;
  std::vector<double> y;
  for (int i = 0; i < 40; ++i) {
    x.push_back(std::pow(2.0, 1 + i % 10));
    y.push_back(std::pow(x.back(), -0.5) * std::exp(0.1 * (rng.uniform() - 0.5)));
  }
  const LogLogFit fit = fit_log_log(x, y);
  EXPECT_GT(fit.slope_stderr, 0.0);
  EXPECT_NEAR(fit.slope, -0.5, 5.0 * fit.slope_stderr);
}

TEST(LogLogFit, SkipsNonPositivePointsAndRefusesTooFew) {
  const LogLogFit fit = fit_log_log({0.0, 1.0, 4.0, -2.0}, {5.0, 1.0, 0.25, 1.0});
  EXPECT_EQ(fit.points, 2);
  EXPECT_NEAR(fit.slope, -1.0, 1e-12);
  EXPECT_THROW((void)fit_log_log({1.0, 2.0}, {1.0, 0.0}), Error);
  EXPECT_THROW((void)fit_log_log({2.0, 2.0}, {1.0, 3.0}), Error);
  EXPECT_THROW((void)fit_log_log({1.0}, {1.0, 2.0}), Error);
}

TEST(Convergence, ReferenceNoiseIsRemovedFromTheRmse) {
  const Image image = constant_image(4, 3, 1.5F);
  const Image reference = constant_image(4, 3, 1.0F, 0.09F);  // rmse² = 0.25, minus 0.09 → 0.16
  EXPECT_NEAR(rmse(image, reference), 0.5, 1e-7);
  EXPECT_NEAR(rmse_against_noisy_reference(image, reference), 0.4, 1e-6);
  EXPECT_NEAR(mean_variance(reference), 0.09, 1e-7);
  // Never below 0 when the reference is noisier than the difference.
  EXPECT_EQ(rmse_against_noisy_reference(reference, constant_image(4, 3, 1.0F, 1.0F)), 0.0);
}

// A reference is a radiance image: the first negative or non-finite value is named; zeros are
// fine (a black background).
TEST(Convergence, AReferenceWithANegativeOrNonFiniteValueIsRefused) {
  Image reference = constant_image(4, 3, 0.0F);
  EXPECT_NO_THROW(check_reference(reference, "ref.exr"));
  reference.rgb[3 * (4 * 2 + 1) + 1] = -0.25F;
  EXPECT_THAT([&] { check_reference(reference, "ref.exr"); },
              weft::test::throws_one_line_error_with({"ref.exr", "pixel (x 1, y 2) channel G is -0.25"}));
  reference.rgb[3 * (4 * 2 + 1) + 1] = std::nanf("");
  EXPECT_THAT([&] { check_reference(reference, "ref.exr"); }, weft::test::throws_one_line_error_with({"channel G"}));
}

}  // namespace
}  // namespace weft::render
