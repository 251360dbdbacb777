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

TEST(VolumeView, RendersTheCloth) {
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
  // The surface's warm colour (red > green > blue) covers a good part of the picture...
  const long warm = test::count_pixels(image, [](int r, int g, int b) { return !is_white(r, g, b) && r > g && g > b; });
  EXPECT_GT(warm, image.width * image.height / 20);
  // ...and the centre of the oblique view (left 58 %), where the camera looks.
  const auto centre = image.rgb(static_cast<int>(0.29 * image.width), image.height / 2);
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

// Labels go in a key, in a strip below the view that the framing keeps free of geometry: without
// labels the strip is blank, with them it holds each label in its arrow's colour. (A label in the
// scene, beside its arrow's tail, was covered by that tail.)
TEST(VolumeView, LabelsNeverCoverGeometry) {
  const auto dir = test::scratch_dir("volume_labels");
  VolumeView view;
  view.title = "slab";
  view.width = 600;
  view.height = 400;
  view.arrows = {{{1, 0, 0}, {220, 30, 30}, "beam +x"},
                 {{0, 1, 0}, {30, 160, 40}, "beam +y"},
                 {{0, 0, 1}, {30, 60, 220}, "beam +z"}};
  VolumeView bare = view;
  for (Arrow& a : bare.arrows) a.label.clear();
  ASSERT_TRUE(save_volume_png(slab(), view, dir / "labelled.png").written);
  ASSERT_TRUE(save_volume_png(slab(), bare, dir / "bare.png").written);
  const test::Image labelled = test::read_png(dir / "labelled.png");
  const test::Image plain = test::read_png(dir / "bare.png");
  // The key strip: the bottom 8 % of the oblique (left) panel.
  const test::Region strip{0.0, 0.92, 0.58, 1.0};
  const long strip_px = static_cast<long>(0.08 * plain.height) * static_cast<long>(0.58 * plain.width);
  EXPECT_GE(test::coverage(plain, {255, 255, 255}, 0, strip).pixels, strip_px - 2 * plain.width)
      << "geometry reaches into the key strip";
  long label_px = 0;
  for (const Arrow& a : view.arrows) {
    const auto in_strip = test::coverage(labelled, {a.color[0], a.color[1], a.color[2]}, 40, strip);
    EXPECT_GT(in_strip.pixels, 40) << a.label;
    label_px += in_strip.pixels;
  }
  // Above the strip the labels add nothing: the arrow colours cover as much there as without them.
  for (const Arrow& a : view.arrows) {
    const test::Region scene{0.0, 0.0, 0.58, 0.92};
    const auto with = test::coverage(labelled, {a.color[0], a.color[1], a.color[2]}, 40, scene);
    const auto without = test::coverage(plain, {a.color[0], a.color[1], a.color[2]}, 40, scene);
    EXPECT_NEAR(static_cast<double>(with.pixels), static_cast<double>(without.pixels), 0.05 * without.pixels + 10)
        << a.label;
  }
  EXPECT_GT(label_px, 200);
  test::cleanup(dir);
}

// A cloth with a hole: the top view (right panel, straight down z) shows background through it.
TEST(VolumeView, TopViewShowsHoles) {
  const auto dir = test::scratch_dir("volume_hole");
  volume::Grid grid(0.05, "concentration");
  for (int k = 0; k < 4; ++k) {
    for (int j = 0; j < 40; ++j) {
      for (int i = 0; i < 40; ++i) {
        const bool hole = i >= 14 && i < 26 && j >= 14 && j < 26;
        if (!hole) grid.set_value(i, j, k, 0.8f);
      }
    }
  }
  VolumeView view;
  view.width = 600;
  view.height = 400;
  const auto png = dir / "hole.png";
  ASSERT_TRUE(save_volume_png(grid, view, png).written);
  const test::Image image = test::read_png(png);
  // The right panel spans x in [0.58, 1] of the width; the slab is centred in it.
  const int cx = static_cast<int>(0.79 * image.width);
  const int cy = image.height / 2;
  const int slab_px = static_cast<int>(0.9 * 0.42 * image.width);  // fills ~90 % of the panel
  long white_centre = 0;
  long centre = 0;
  for (int y = cy - 8; y <= cy + 8; ++y) {
    for (int x = cx - 8; x <= cx + 8; ++x) {
      const auto c = image.rgb(x, y);
      ++centre;
      if (is_white(c[0], c[1], c[2])) ++white_centre;
    }
  }
  EXPECT_EQ(white_centre, centre) << "the hole is not seen through";
  // Material on both sides of the hole, a third of the slab from the centre.
  for (const int dx : {-slab_px / 3, slab_px / 3}) {
    const auto c = image.rgb(cx + dx, cy);
    EXPECT_FALSE(is_white(c[0], c[1], c[2])) << "no cloth at dx = " << dx;
  }
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
