#include "weft/viz/volume_view.h"

#include <gtest/gtest.h>

#include "image_probe.h"
#include "weft/core/error.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::viz {
namespace {

// A 40x40x10 slab of concentration 0.6 with a denser band: a stand-in for a cloth sample.
volume::Grid slab() {
  volume::Grid grid(0.05, "concentration");
  for (int k = 0; k < 10; ++k) {
    for (int j = 0; j < 40; ++j) {
      for (int i = 0; i < 40; ++i) grid.set_value(i, j, k, (j / 5) % 2 == 0 ? 0.9f : 0.3f);
    }
  }
  return grid;
}

bool is_white(int r, int g, int b) { return r > 245 && g > 245 && b > 245; }

TEST(VolumeView, RendersTheVolumeWhereTheCameraLooks) {
  const auto dir = test::scratch_dir("volume");
  VolumeView view;
  view.title = "slab";
  view.width = 400;
  view.height = 320;
  const auto png = dir / "volume.png";
  const RenderOutcome out = save_volume_png(slab(), view, png);
  ASSERT_TRUE(out.written) << out.reason;
  const test::Image image = test::read_png(png);
  ASSERT_TRUE(image.data);
  EXPECT_EQ(image.width, 400);
  EXPECT_EQ(image.height, 320);
  // The volume's warm colours (red > green > blue) cover a good part of the picture...
  const long warm = test::count_pixels(image, [](int r, int g, int b) { return !is_white(r, g, b) && r > g && g > b; });
  EXPECT_GT(warm, image.width * image.height / 20);
  // ...and the centre, where the camera looks.
  const auto centre = image.rgb(image.width / 2, image.height / 2);
  EXPECT_FALSE(is_white(centre[0], centre[1], centre[2]));
  test::cleanup(dir);
}

TEST(VolumeView, DrawsEachArrowInItsColour) {
  const auto dir = test::scratch_dir("volume_arrows");
  VolumeView view;
  view.width = 400;
  view.height = 320;
  view.arrows = {{{1, 0, 0}, {0, 200, 0}, "x"}, {{0, 0, -1}, {0, 0, 230}, "z"}};
  const auto png = dir / "arrows.png";
  ASSERT_TRUE(save_volume_png(slab(), view, png).written);
  const test::Image image = test::read_png(png);
  ASSERT_TRUE(image.data);
  // Shading changes the brightness, not the hue: the dominant channel tells the arrows apart.
  const long green = test::count_pixels(image, [](int r, int g, int b) { return g > 80 && g > 2 * r && g > 2 * b; });
  const long blue = test::count_pixels(image, [](int r, int g, int b) { return b > 80 && b > 2 * r && b > 2 * g; });
  EXPECT_GT(green, 200);
  EXPECT_GT(blue, 200);
  test::cleanup(dir);
}

TEST(VolumeView, LargeBoxIsDownsampledForDisplay) {
  const auto dir = test::scratch_dir("volume_large");
  volume::Grid grid(0.01, "density");
  // A 600x60x30 box: above the 256-per-axis display budget, so it is averaged down.
  grid.impl().grid->tree().fill(openvdb::CoordBBox(openvdb::Coord(0, 0, 0), openvdb::Coord(599, 59, 29)), 0.5f, true);
  VolumeView view;
  view.width = 320;
  view.height = 240;
  const auto png = dir / "large.png";
  ASSERT_TRUE(save_volume_png(grid, view, png).written);
  const test::Image image = test::read_png(png);
  const long warm = test::count_pixels(image, [](int r, int g, int b) { return !is_white(r, g, b) && r > g && g > b; });
  EXPECT_GT(warm, image.width * image.height / 20);
  test::cleanup(dir);
}

TEST(VolumeView, BadInputIsAnErrorWithoutAFile) {
  const auto dir = test::scratch_dir("volume_bad");
  VolumeView view;
  EXPECT_THROW(save_volume_png(volume::Grid(1.0), view, dir / "empty.png"), weft::Error);
  view.arrows = {{{0, 0, 0}, {255, 0, 0}, "nowhere"}};
  EXPECT_THROW(save_volume_png(slab(), view, dir / "arrow.png"), weft::Error);
  view.arrows.clear();
  EXPECT_THROW(save_volume_png(slab(), view, dir / "missing" / "v.png"), weft::Error);
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  test::cleanup(dir);
}

}  // namespace
}  // namespace weft::viz
