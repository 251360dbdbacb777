// The study's labelled contact sheet (study.h). Text comes from VTK's FreeType tools, which
// rasterise a string into an image without any display (unlike VTK's charts).
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <vtkFreeTypeTools.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkStdString.h>
#include <vtkTextProperty.h>

#include "weft/core/error.h"
#include "weft/render/study.h"

namespace weft::render {
namespace {

constexpr int kFontPx = 13;
constexpr int kLineHeight = kFontPx + 5;
constexpr int kGap = 6;
constexpr int kMinTileWidth = 180;  ///< small films are enlarged (nearest neighbour) to this width

/// Draws `text` in black with its top-left corner at (x, y) of `canvas` (linear, white 1).
/// Returns false when FreeType could not render it (the tile then stays unlabelled).
bool draw_text(Image& canvas, int x, int y, const std::string& text) {
  if (text.empty()) return true;
  vtkFreeTypeTools* tools = vtkFreeTypeTools::GetInstance();
  tools->ScaleToPowerTwoOff();
  vtkNew<vtkTextProperty> prop;
  prop->SetFontFamilyToArial();
  prop->SetFontSize(kFontPx);
  prop->SetColor(1.0, 1.0, 1.0);
  prop->SetJustificationToLeft();
  prop->SetVerticalJustificationToBottom();
  vtkNew<vtkImageData> data;
  int dims_text[2] = {0, 0};
  if (!tools->RenderString(prop, vtkStdString(text), 72, data, dims_text)) return false;
  int dims[3];
  data->GetDimensions(dims);
  if (data->GetNumberOfScalarComponents() < 4) return false;
  const auto* px = static_cast<const unsigned char*>(data->GetScalarPointer());
  for (int row = 0; row < dims[1]; ++row) {
    const int cy = y + (dims[1] - 1 - row);  // VTK images start at the bottom row
    if (cy < 0 || cy >= canvas.height) continue;
    for (int col = 0; col < dims[0]; ++col) {
      const int cx = x + col;
      if (cx < 0 || cx >= canvas.width) continue;
      const float a = static_cast<float>(px[(static_cast<std::size_t>(row) * dims[0] + col) * 4 + 3]) / 255.0F;
      for (int c = 0; c < 3; ++c) {
        float& v = canvas.rgb[(static_cast<std::size_t>(cy) * canvas.width + cx) * 3 + c];
        v *= 1.0F - a;
      }
    }
  }
  return true;
}

/// Copies `im` scaled by `k` (nearest neighbour) with each value times `gain` to (x0, y0).
void blit(Image& canvas, const Image& im, int x0, int y0, int k, float gain) {
  for (int y = 0; y < im.height * k; ++y)
    for (int x = 0; x < im.width * k; ++x)
      for (int c = 0; c < 3; ++c)
        canvas.rgb[(static_cast<std::size_t>(y0 + y) * canvas.width + x0 + x) * 3 + c] = gain * im.at(x / k, y / k, c);
}

struct Tile {
  const Image* top = nullptr;
  const Image* bottom = nullptr;
  std::vector<std::string> lines;
};

}  // namespace

Image study_contact_sheet(const StudyResult& result, double error_white) {
  const Image& ref = result.reference;
  if (ref.width <= 0 || ref.height <= 0) fail("study contact sheet: no reference image");
  if (!(error_white > 0.0) || !std::isfinite(error_white))
    fail("study contact sheet: error scale must be finite and > 0, got {}", error_white);
  // Rows by model: {reference, fine, slab}, {exponential-Nx}, {local-gamma-Nx}.
  std::vector<std::vector<Tile>> grid(3);
  grid[0].push_back({&ref, nullptr, {"reference: fine grid", fmt::format("{} spp", ref.spp), "below: its std. error"}});
  for (const auto& c : result.candidates) {
    Tile t{&c.image,
           &c.error_map,
           {c.name, fmt::format("{} spp, {:.3g} s", c.spp, c.seconds),
            fmt::format("RMSE {:.3g} bias {:.3g}", c.rmse, c.bias)}};
    const std::size_t row = c.model == "exponential" ? 1 : c.model == "local-gamma" ? 2 : 0;
    grid[row].push_back(std::move(t));
  }
  std::erase_if(grid, [](const std::vector<Tile>& r) { return r.empty(); });
  const int k = std::max(1, (kMinTileWidth + ref.width - 1) / ref.width);
  const int label_h = 3 * kLineHeight;
  const int tile_w = k * ref.width;
  const int tile_h = label_h + 2 * k * ref.height + kGap;
  std::size_t most = 0;
  for (const auto& r : grid) most = std::max(most, r.size());
  const int cols = static_cast<int>(most);
  const int rows = static_cast<int>(grid.size());
  Image sheet;
  sheet.width = kGap + cols * (tile_w + kGap);
  sheet.height = kGap + rows * (tile_h + kGap);
  sheet.rgb.assign(static_cast<std::size_t>(sheet.width) * sheet.height * 3, 1.0F);
  const auto gain = static_cast<float>(1.0 / error_white);
  for (std::size_t row = 0; row < grid.size(); ++row) {
    for (std::size_t col = 0; col < grid[row].size(); ++col) {
      const int x0 = kGap + static_cast<int>(col) * (tile_w + kGap);
      const int y0 = kGap + static_cast<int>(row) * (tile_h + kGap);
      const Tile& t = grid[row][col];
      for (std::size_t l = 0; l < t.lines.size(); ++l)
        (void)draw_text(sheet, x0, y0 + static_cast<int>(l) * kLineHeight, t.lines[l]);
      blit(sheet, *t.top, x0, y0 + label_h, k, 1.0F);
      if (t.bottom != nullptr) {
        blit(sheet, *t.bottom, x0, y0 + label_h + k * ref.height + kGap, k, gain);
      } else {
        // The reference's tile: its per-pixel standard error on the error maps' scale, the noise
        // floor every RMSE is corrected for.
        Image sd = ref;
        for (std::size_t j = 0; j < sd.rgb.size(); ++j)
          sd.rgb[j] = sd.variance.empty() ? 0.0F : std::sqrt(std::max(0.0F, sd.variance[j]));
        blit(sheet, sd, x0, y0 + label_h + k * ref.height + kGap, k, gain);
      }
    }
  }
  return sheet;
}

}  // namespace weft::render
