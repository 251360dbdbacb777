#pragma once
// Test helper: a PNG read back through VTK's reader, with colour counts for assertions.

#include <algorithm>
#include <array>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkSmartPointer.h>

namespace weft::viz::test {

struct Image {
  vtkSmartPointer<vtkImageData> data;
  int width = 0;
  int height = 0;
  int components = 0;

  [[nodiscard]] std::array<int, 3> rgb(int x, int y) const {
    auto* p = static_cast<unsigned char*>(data->GetScalarPointer(x, y, 0));
    return {p[0], p[1], p[2]};
  }
};

inline Image read_png(const std::filesystem::path& path) {
  vtkNew<vtkPNGReader> reader;
  Image image;
  if (reader->CanReadFile(path.c_str()) == 0) return image;
  reader->SetFileName(path.c_str());
  reader->Update();
  image.data = reader->GetOutput();
  int dims[3];
  image.data->GetDimensions(dims);
  image.width = dims[0];
  image.height = dims[1];
  image.components = image.data->GetNumberOfScalarComponents();
  return image;
}

/// Pixels within `tol` of `colour` per channel; their mean row (VTK rows run bottom-up) and column.
struct ColourHits {
  long count = 0;
  double mean_row = 0.0;
  double mean_col = 0.0;
};

inline ColourHits find_colour(const Image& image, std::array<int, 3> colour, int tol = 40) {
  ColourHits hits;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const auto c = image.rgb(x, y);
      if (std::abs(c[0] - colour[0]) <= tol && std::abs(c[1] - colour[1]) <= tol && std::abs(c[2] - colour[2]) <= tol) {
        ++hits.count;
        hits.mean_row += y;
        hits.mean_col += x;
      }
    }
  }
  if (hits.count > 0) {
    hits.mean_row /= static_cast<double>(hits.count);
    hits.mean_col /= static_cast<double>(hits.count);
  }
  return hits;
}

/// A fresh, empty folder for one test's outputs.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("weft_viz_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace weft::viz::test

namespace weft::viz::test {

/// Removes a test's outputs unless it failed or WEFT_KEEP_TEST_OUTPUT is set (to look at them).
inline void cleanup(const std::filesystem::path& dir) {
  if (std::getenv("WEFT_KEEP_TEST_OUTPUT") != nullptr || ::testing::Test::HasFailure()) return;
  std::filesystem::remove_all(dir);
}

}  // namespace weft::viz::test

namespace weft::viz::test {

/// Pixels whose colour satisfies `keep(r, g, b)`.
template <typename Predicate>
long count_pixels(const Image& image, Predicate keep) {
  long n = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const auto c = image.rgb(x, y);
      if (keep(c[0], c[1], c[2])) ++n;
    }
  }
  return n;
}

}  // namespace weft::viz::test

namespace weft::viz::test {

/// A window of an image in fractions of its width and height, measured from the TOP left corner
/// (as one reads a picture; VTK's rows run bottom-up, this converts).
struct Region {
  double left = 0.0;
  double top = 0.0;
  double right = 1.0;
  double bottom = 1.0;
};

/// How much of a series' colour a picture shows: the pixels within `tol` per channel of `colour`
/// in `region`, and how many distinct columns they fall in (a drawn curve spans many columns; a
/// legend sample or a stray antialiased pixel spans few).
struct Coverage {
  long pixels = 0;
  int columns = 0;
  int rows = 0;
};

inline Coverage coverage(const Image& image, std::array<int, 3> colour, int tol = 30, Region region = {}) {
  Coverage cov;
  const int x0 = std::clamp(static_cast<int>(region.left * image.width), 0, image.width);
  const int x1 = std::clamp(static_cast<int>(region.right * image.width), 0, image.width);
  // Top-down fractions to VTK's bottom-up rows.
  const int y0 = std::clamp(static_cast<int>((1.0 - region.bottom) * image.height), 0, image.height);
  const int y1 = std::clamp(static_cast<int>((1.0 - region.top) * image.height), 0, image.height);
  std::vector<char> col_hit(static_cast<std::size_t>(std::max(0, x1 - x0)), 0);
  std::vector<char> row_hit(static_cast<std::size_t>(std::max(0, y1 - y0)), 0);
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const auto c = image.rgb(x, y);
      if (std::abs(c[0] - colour[0]) <= tol && std::abs(c[1] - colour[1]) <= tol && std::abs(c[2] - colour[2]) <= tol) {
        ++cov.pixels;
        col_hit[static_cast<std::size_t>(x - x0)] = 1;
        row_hit[static_cast<std::size_t>(y - y0)] = 1;
      }
    }
  }
  cov.columns = static_cast<int>(std::count(col_hit.begin(), col_hit.end(), 1));
  cov.rows = static_cast<int>(std::count(row_hit.begin(), row_hit.end(), 1));
  return cov;
}

}  // namespace weft::viz::test
