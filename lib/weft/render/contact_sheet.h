#pragma once
/// @file
/// @brief Labelled contact sheets: images side by side (or in a grid), each enlarged to a size
/// where its noise can be seen and captioned (e.g. "64 spp"), written as one PNG (no VTK here).

#include <filesystem>
#include <string>
#include <vector>

#include "weft/render/image.h"

namespace weft::render {

/// One image of a sheet and its caption.
struct SheetTile {
  Image image;
  std::string label;      ///< drawn under the image; may be empty
  double exposure = 1.0;  ///< linear scale before the sRGB curve (error maps may use their own)
};

struct SheetLayout {
  int columns = 0;          ///< tiles per row; 0: all in one row
  int min_tile_side = 192;  ///< images are enlarged by an integer factor until their longest side is >= this
  int gap = 8;              ///< white pixels between tiles and around the sheet
  int font_size = 14;       ///< caption size in pixels
};

/// The integer factor (>= 1) by which an image of `width` x `height` is enlarged (nearest
/// neighbour, so every rendered pixel stays a visible square of its own noise).
[[nodiscard]] int sheet_zoom(int width, int height, int min_tile_side);

/// Writes `tiles` as one 8-bit sRGB PNG, atomically: row by row in `layout.columns` columns,
/// each image enlarged by sheet_zoom and its label drawn in black under it. Throws weft::Error
/// for no tiles, an empty image, a bad layout or an unwritable target. Needs no display.
void write_contact_sheet_png(const std::filesystem::path& path, const std::vector<SheetTile>& tiles,
                             const SheetLayout& layout = {});

}  // namespace weft::render
