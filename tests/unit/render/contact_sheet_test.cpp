// Labelled contact sheets (docs/render.md §6c: never four unlabelled 48 px images): small
// images are enlarged by an integer factor, each keeps its own pixels, and each gets a caption.
#include "weft/render/contact_sheet.h"

#include <filesystem>
#include <vector>

#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include "weft/core/error.h"

namespace weft::render {
namespace {

Image checker(int w, int h, float a, float b) {
  Image im;
  im.width = w;
  im.height = h;
  im.rgb.resize(static_cast<std::size_t>(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) im.rgb[(static_cast<std::size_t>(y) * w + x) * 3 + c] = ((x + y) % 2) ? a : b;
  return im;
}

struct Png {
  int width = 0;
  int height = 0;
  vtkNew<vtkImageData> data;
  // Red channel at (x, y), y from the top.
  [[nodiscard]] int red(int x, int y) const {
    return static_cast<const unsigned char*>(data->GetScalarPointer(x, height - 1 - y, 0))[0];
  }
};

void read_png(const std::filesystem::path& path, Png& png) {
  vtkNew<vtkPNGReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  png.data->DeepCopy(reader->GetOutput());
  int dims[3];
  png.data->GetDimensions(dims);
  png.width = dims[0];
  png.height = dims[1];
}

// Dark pixels (red < 128) in the rectangle [x0, x1) x [y0, y1).
int dark_pixels(const Png& png, int x0, int x1, int y0, int y1) {
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) n += png.red(x, y) < 128 ? 1 : 0;
  return n;
}

TEST(ContactSheet, ZoomIsTheSmallestIntegerFactorReachingTheMinimumSide) {
  EXPECT_EQ(sheet_zoom(48, 36, 192), 4);
  EXPECT_EQ(sheet_zoom(50, 20, 192), 4);  // 200 >= 192, 150 < 192
  EXPECT_EQ(sheet_zoom(320, 240, 192), 1);
  EXPECT_EQ(sheet_zoom(1, 1, 192), 192);
  EXPECT_THROW((void)sheet_zoom(0, 5, 192), Error);
}

TEST(ContactSheet, EnlargesEveryImageAndCaptionsIt) {
  const auto dir = std::filesystem::path(::testing::TempDir()) / "weft_contact_sheet";
  std::filesystem::create_directories(dir);
  const auto path = dir / "sheet.png";
  // Two 8x6 checkerboards (white/black and white/grey) labelled, a third unlabelled.
  const std::vector<SheetTile> tiles{{checker(8, 6, 1.0F, 0.0F), "2 spp", 1.0},
                                     {checker(8, 6, 1.0F, 0.2F), "512 spp", 1.0},
                                     {checker(8, 6, 1.0F, 1.0F), "", 1.0}};
  SheetLayout layout;
  layout.min_tile_side = 64;  // zoom 8: 64 x 48 px per image
  layout.gap = 8;
  write_contact_sheet_png(path, tiles, layout);
  Png png;
  read_png(path, png);
  const int tile_w = 64;
  ASSERT_EQ(png.width, 3 * tile_w + 4 * layout.gap);
  ASSERT_GT(png.height, 48 + 2 * layout.gap);  // room for the captions
  for (int i = 0; i < 3; ++i) {
    const int x0 = layout.gap + i * (tile_w + layout.gap);
    const int y0 = layout.gap;
    // Each source pixel became an 8x8 block: the block's corners carry the source value.
    const int black = i == 0 ? 0 : (i == 1 ? srgb8(0.2F) : 255);
    EXPECT_EQ(png.red(x0, y0), black) << i;
    EXPECT_EQ(png.red(x0 + 7, y0 + 7), black) << i;
    EXPECT_EQ(png.red(x0 + 8, y0), 255) << i;
    EXPECT_EQ(png.red(x0 + 15, y0 + 7), 255) << i;
    // The caption strip under the image: text for labelled tiles, blank for the unlabelled one.
    const int dark = dark_pixels(png, x0, x0 + tile_w, y0 + 48, png.height - layout.gap);
    if (i < 2) {
      EXPECT_GT(dark, 10) << "tile " << i << " has no visible caption";
    } else {
      EXPECT_EQ(dark, 0);
    }
  }
  // The longer label is wider: "512 spp" covers more columns than "2 spp".
  auto inked_columns = [&](int x0) {
    int n = 0;
    for (int x = x0; x < x0 + tile_w; ++x) n += dark_pixels(png, x, x + 1, layout.gap + 48, png.height) > 0 ? 1 : 0;
    return n;
  };
  EXPECT_GT(inked_columns(layout.gap + tile_w + layout.gap), inked_columns(layout.gap));
}

TEST(ContactSheet, RefusesNoTilesAndBadLayouts) {
  const auto path = std::filesystem::path(::testing::TempDir()) / "weft_contact_sheet_bad.png";
  EXPECT_THROW(write_contact_sheet_png(path, {}), Error);
  SheetLayout bad;
  bad.columns = -1;
  EXPECT_THROW(write_contact_sheet_png(path, {{checker(2, 2, 0.F, 1.F), "x", 1.0}}, bad), Error);
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace weft::render
