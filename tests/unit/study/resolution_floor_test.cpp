// The resolution floor (resolution_floor.h) on images whose answer is known by construction: a
// single-pixel checkerboard is what a 2-pixel block cannot hold (its floor is the pattern's
// amplitude at 1 px and nothing over 2 × 2 blocks), a linear ramp is kept by the symmetric tent,
// and the footprint follows the pinhole's pixel pitch.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <nlohmann/json.hpp>

#include "weft/core/error.h"
#include "weft/study/resolution_floor.h"

namespace weft::study {
using render::Image;
namespace {

constexpr int kW = 64;
constexpr int kH = 48;

Image filled(double (*f)(int, int)) {
  Image im;
  im.width = kW;
  im.height = kH;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      for (int c = 0; c < 3; ++c) im.rgb.push_back(static_cast<float>(f(x, y) + 0.1 * c));
  im.variance.assign(im.rgb.size(), 0.0F);
  return im;
}

double checker(int x, int y) { return 0.5 + ((x + y) % 2 == 0 ? 0.25 : -0.25); }
double ramp(int x, int y) { return 0.01 * x + 0.02 * y; }

/// Pixels at least `margin` from every edge (where the clamped tent is symmetric).
std::vector<bool> interior(int margin) {
  std::vector<bool> m(static_cast<std::size_t>(kW) * kH, false);
  for (int y = margin; y < kH - margin; ++y)
    for (int x = margin; x < kW - margin; ++x) m[static_cast<std::size_t>(y) * kW + x] = true;
  return m;
}

TEST(ResolutionFloor, FootprintOfOnePixelOrLessIsTheIdentity) {
  const Image im = filled(checker);
  for (const double f : {0.5, 1.0}) {
    const Image s = smooth_over_footprint(im, f);
    EXPECT_EQ(s.rgb, im.rgb);
  }
  EXPECT_THROW((void)smooth_over_footprint(im, std::nan("")), Error);
}

TEST(ResolutionFloor, TwoPixelTentAveragesACheckerboardAndKeepsARamp) {
  const Image c = smooth_over_footprint(filled(checker), 2.0);
  const Image r = smooth_over_footprint(filled(ramp), 4.0);
  const Image r0 = filled(ramp);
  const std::vector<bool> inner = interior(4);
  for (std::size_t i = 0; i < c.rgb.size(); ++i) {
    if (!inner[i / 3]) continue;
    EXPECT_NEAR(c.rgb[i], 0.5 + 0.1 * static_cast<double>(i % 3), 1e-6);
    EXPECT_NEAR(r.rgb[i], r0.rgb[i], 1e-5);
  }
}

TEST(ResolutionFloor, VariancesFollowTheSquaredWeights) {
  Image im = filled(ramp);
  im.variance.assign(im.rgb.size(), 1.0F);
  const Image s = smooth_over_footprint(im, 2.0);  // weights 1/4, 1/2, 1/4 per axis
  const double per_axis = 2.0 / 16.0 + 1.0 / 4.0;
  const std::vector<bool> inner = interior(2);
  for (std::size_t i = 0; i < s.variance.size(); ++i) {
    if (inner[i / 3]) {
      EXPECT_NEAR(s.variance[i], per_axis * per_axis, 1e-7);
    }
  }
}

TEST(ResolutionFloor, CheckerboardIsTheFloorAtOnePixelAndNothingOverBlocks) {
  // The truth has structure at one pixel; the fine images reproduce it without noise, so the
  // floor of a 2-pixel block is the structure itself at 1 px and 0 over aligned 2 × 2 blocks.
  const Image truth = filled(checker);
  render::CameraDesc cam;
  cam.position = {0, 0, 5};
  cam.fov_deg = 90.0;
  cam.height = kH;
  cam.width = kW;
  const double pitch = 2.0 * 5.0 / kH;
  const auto floors = resolution_floors(truth, truth, truth, interior(4), cam, {0, 0, 0}, pitch, {1, 2});
  ASSERT_EQ(floors.size(), 2U);
  EXPECT_NEAR(floors[0].footprint, 1.0, 1e-12);
  EXPECT_NEAR(floors[0].scales.blocks.front().bias(), 0.0, 1e-9);
  EXPECT_NEAR(floors[1].footprint, 2.0, 1e-12);
  EXPECT_NEAR(floors[1].scales.blocks.front().bias(), 0.25, 1e-6);
  ASSERT_GE(floors[1].scales.blocks.size(), 2U);
  EXPECT_EQ(floors[1].scales.blocks[1].block, 2);
  EXPECT_NEAR(floors[1].scales.blocks[1].bias(), 0.0, 1e-6);
  EXPECT_NEAR(floors[1].scales.level.difference, 0.0, 1e-6);
}

TEST(ResolutionFloor, FootprintIsTheBlockOverThePixelPitch) {
  render::CameraDesc cam;
  cam.position = {0, 0, 5};
  cam.fov_deg = 60.0;
  cam.height = 200;
  const double pitch = 2.0 * 5.0 * std::tan(std::numbers::pi / 6.0) / 200.0;
  EXPECT_NEAR(block_footprint_pixels(cam, {0, 0, 0}, 3.0 * pitch), 3.0, 1e-12);
  EXPECT_NEAR(block_footprint_pixels(cam, {3, 0, 1}, 1.0), 1.0 / (2.0 * 5.0 * std::tan(std::numbers::pi / 6.0) / 200.0),
              1e-9);  // distance 5 from the camera again
  EXPECT_THROW((void)block_footprint_pixels(cam, {0, 0, 0}, 0.0), Error);
  EXPECT_THROW((void)block_footprint_pixels(cam, {0, 0, 5}, 1.0), Error);
}

TEST(ResolutionFloor, JsonRoundTrip) {
  const Image truth = filled(checker);
  render::CameraDesc cam;
  cam.height = kH;
  const auto f = resolution_floors(truth, truth, truth, {}, cam, {0, 0, 0}, 0.05, {4}).front();
  const ResolutionFloor back = resolution_floor_from_json(nlohmann::json::parse(resolution_floor_json(f).dump()));
  EXPECT_EQ(back.factor, 4);
  EXPECT_DOUBLE_EQ(back.footprint, f.footprint);
  ASSERT_EQ(back.scales.blocks.size(), f.scales.blocks.size());
  EXPECT_DOUBLE_EQ(back.scales.blocks[0].bias_sq, f.scales.blocks[0].bias_sq);
}

}  // namespace
}  // namespace weft::study
