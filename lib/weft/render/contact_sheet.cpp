#include "weft/render/contact_sheet.h"

#include <algorithm>
#include <cstdint>

#include <vtkFreeTypeTools.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkStdString.h>
#include <vtkTextProperty.h>

#include "weft/core/error.h"

namespace weft::render {
namespace {

// A caption rasterised by FreeType (VTK's text renderer without any OpenGL, so sheets need no
// X display): `alpha` is the glyph coverage, row-major from the top-left.
struct Caption {
  int width = 0;
  int height = 0;
  std::vector<unsigned char> alpha;
};

Caption rasterise(const std::string& text, int font_size) {
  Caption c;
  if (text.empty()) return c;
  vtkNew<vtkTextProperty> property;
  property->SetFontFamilyToArial();
  property->SetFontSize(font_size);
  property->SetColor(0.0, 0.0, 0.0);
  property->SetJustificationToLeft();
  property->SetVerticalJustificationToBottom();
  vtkNew<vtkImageData> image;
  int dims[2] = {0, 0};
  // dpi 72: font_size is then in pixels.
  if (!vtkFreeTypeTools::GetInstance()->RenderString(property.GetPointer(), vtkStdString(text), 72, image.GetPointer(),
                                                     dims) ||
      dims[0] <= 0 || dims[1] <= 0)
    fail("contact sheet: cannot draw the label '{}'", text);
  int extent[6];
  image->GetExtent(extent);
  c.width = dims[0];
  c.height = dims[1];
  c.alpha.assign(static_cast<std::size_t>(c.width) * c.height, 0);
  const int components = image->GetNumberOfScalarComponents();
  for (int y = 0; y < c.height; ++y) {
    for (int x = 0; x < c.width; ++x) {
      // VTK images start at the bottom row.
      const auto* p = static_cast<const unsigned char*>(
          image->GetScalarPointer(extent[0] + x, extent[2] + (c.height - 1 - y), extent[4]));
      c.alpha[static_cast<std::size_t>(y) * c.width + x] = p[components - 1];
    }
  }
  return c;
}

}  // namespace

int sheet_zoom(int width, int height, int min_tile_side) {
  if (width <= 0 || height <= 0) fail("contact sheet: empty image ({}x{})", width, height);
  const int side = std::max(width, height);
  return std::max(1, (min_tile_side + side - 1) / side);
}

void write_contact_sheet_png(const std::filesystem::path& path, const std::vector<SheetTile>& tiles,
                             const SheetLayout& layout) {
  if (tiles.empty()) fail("contact sheet '{}': no images", path.string());
  if (layout.columns < 0 || layout.min_tile_side < 1 || layout.gap < 0 || layout.font_size < 4)
    fail("contact sheet '{}': bad layout (columns {}, min side {}, gap {}, font {})", path.string(), layout.columns,
         layout.min_tile_side, layout.gap, layout.font_size);
  const int n = static_cast<int>(tiles.size());
  const int columns = layout.columns == 0 ? n : std::min(layout.columns, n);
  const int rows = (n + columns - 1) / columns;
  std::vector<Caption> captions;
  std::vector<int> zoom;
  int cell_w = 0;
  int image_h = 0;
  int caption_h = 0;
  for (const auto& t : tiles) {
    if (t.image.rgb.size() != static_cast<std::size_t>(t.image.width) * t.image.height * 3 || t.image.width <= 0)
      fail("contact sheet '{}': an image is empty or malformed", path.string());
    zoom.push_back(sheet_zoom(t.image.width, t.image.height, layout.min_tile_side));
    captions.push_back(rasterise(t.label, layout.font_size));
    cell_w = std::max({cell_w, t.image.width * zoom.back(), captions.back().width});
    image_h = std::max(image_h, t.image.height * zoom.back());
    caption_h = std::max(caption_h, captions.back().height);
  }
  const int label_gap = caption_h > 0 ? layout.gap / 2 + 2 : 0;
  const int cell_h = image_h + label_gap + caption_h;
  const int width = columns * cell_w + (columns + 1) * layout.gap;
  const int height = rows * cell_h + (rows + 1) * layout.gap;
  std::vector<unsigned char> rgb(static_cast<std::size_t>(width) * height * 3, 255);
  for (int i = 0; i < n; ++i) {
    const int x0 = layout.gap + (i % columns) * (cell_w + layout.gap);
    const int y0 = layout.gap + (i / columns) * (cell_h + layout.gap);
    const Image& im = tiles[i].image;
    const int z = zoom[i];
    for (int y = 0; y < im.height * z; ++y)
      for (int x = 0; x < im.width * z; ++x)
        for (int c = 0; c < 3; ++c)
          rgb[(static_cast<std::size_t>(y0 + y) * width + x0 + x) * 3 + c] =
              srgb8(im.at(x / z, y / z, c), tiles[i].exposure);
    const Caption& cap = captions[i];
    const int cy = y0 + image_h + label_gap;
    const int cx = x0 + (im.width * z - cap.width) / 2 > x0 ? x0 + (im.width * z - cap.width) / 2 : x0;
    for (int y = 0; y < cap.height; ++y)
      for (int x = 0; x < cap.width; ++x) {
        const unsigned a = cap.alpha[static_cast<std::size_t>(y) * cap.width + x];
        auto* p = &rgb[(static_cast<std::size_t>(cy + y) * width + cx + x) * 3];
        for (int c = 0; c < 3; ++c) p[c] = static_cast<unsigned char>((p[c] * (255U - a) + 127U) / 255U);
      }
  }
  write_rgb8_png(path, width, height, rgb);
}

}  // namespace weft::render
