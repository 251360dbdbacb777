#pragma once
/// @file
/// @brief Linear RGB images with per-pixel standard errors; EXR and PNG files.

#include <filesystem>
#include <vector>

namespace weft::render {

/// A linear RGB image with, per pixel and channel, the variance of the pixel's mean estimate.
struct Image {
  int width = 0;
  int height = 0;
  int spp = 0;
  std::vector<float> rgb;       ///< width·height·3, row-major from the top-left
  std::vector<float> variance;  ///< variance of each mean (s²/n), same layout

  [[nodiscard]] float at(int x, int y, int c) const { return rgb[(static_cast<std::size_t>(y) * width + x) * 3 + c]; }
  [[nodiscard]] float var_at(int x, int y, int c) const {
    return variance[(static_cast<std::size_t>(y) * width + x) * 3 + c];
  }
};

/// Writes a linear 32-bit float RGB OpenEXR file, atomically. Throws weft::Error, writing nothing,
/// when a pixel is not finite (the count in the message: docs/render.md "Image files").
void write_exr(const std::filesystem::path& path, const Image& image);
/// Reads an RGB(A) OpenEXR file (variance left empty). Throws weft::Error naming the file.
[[nodiscard]] Image read_exr(const std::filesystem::path& path);
/// The 8-bit sRGB code of a linear value scaled by `exposure` (clamped to [0, 1]; IEC 61966-2-1).
[[nodiscard]] unsigned char srgb8(float linear, double exposure = 1.0);
/// Writes 8-bit RGB pixels (width·height·3, row-major from the top-left) as a PNG, atomically.
void write_rgb8_png(const std::filesystem::path& path, int width, int height, const std::vector<unsigned char>& rgb);
/// Writes an 8-bit sRGB PNG (clamped, scaled by `exposure`), atomically.
void write_png(const std::filesystem::path& path, const Image& image, double exposure = 1.0);
/// write_exr and write_png of one image at the same time, on two threads when there are: each
/// is a zlib compression (a quarter of a 1-spp 1024×768 render's CPU) that would otherwise run
/// after the parallel render with every other core idle. The PNG's sRGB codes are made first on
/// all threads, and the EXR's 16-row ZIP blocks are compressed on OpenEXR's pool, sized to the
/// TBB thread limit (`--threads`). Same bytes as one after the other, on any thread count.
void write_exr_and_png(const std::filesystem::path& exr, const std::filesystem::path& png, const Image& image,
                       double exposure = 1.0);

/// Root-mean-square difference over all pixels and channels; images must have equal size.
[[nodiscard]] double rmse(const Image& a, const Image& b);

}  // namespace weft::render
