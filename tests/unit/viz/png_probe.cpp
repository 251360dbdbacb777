// png_probe: a CLI test's view of a picture. Counts the pixels of one colour (a series' colour)
// in a region of a PNG and fails unless there are enough of them, so a cmake-driven CLI test can
// check that each series was drawn.
//
//   png_probe FILE R,G,B [--tol N] [--region LEFT,TOP,RIGHT,BOTTOM] [--min-pixels N]
//             [--min-columns N] [--max-pixels N]
//
// Region fractions are measured from the top left. Prints "pixels P columns C rows R width W
// height H"; exit 0 when every bound holds, 1 when one does not, 2 on a usage error or an
// unreadable file.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "image_probe.h"

namespace {

bool parse_numbers(const std::string& text, double* out, int n) {
  std::size_t pos = 0;
  for (int i = 0; i < n; ++i) {
    std::size_t used = 0;
    try {
      out[i] = std::stod(text.substr(pos), &used);
    } catch (...) {
      return false;
    }
    pos += used;
    if (i + 1 < n) {
      if (pos >= text.size() || text[pos] != ',') return false;
      ++pos;
    }
  }
  return pos == text.size();
}

int usage() {
  std::fprintf(stderr,
               "usage: png_probe FILE R,G,B [--tol N] [--region L,T,R,B] [--min-pixels N] [--min-columns N] "
               "[--max-pixels N]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return usage();
  double rgb[3];
  if (!parse_numbers(argv[2], rgb, 3)) return usage();
  int tol = 30;
  weft::viz::test::Region region;
  long min_pixels = 1;
  long max_pixels = -1;
  int min_columns = 0;
  for (int i = 3; i < argc; ++i) {
    const std::string opt = argv[i];
    if (i + 1 >= argc) return usage();
    const std::string value = argv[++i];
    if (opt == "--tol") {
      tol = std::atoi(value.c_str());
    } else if (opt == "--region") {
      double r[4];
      if (!parse_numbers(value, r, 4)) return usage();
      region = {r[0], r[1], r[2], r[3]};
    } else if (opt == "--min-pixels") {
      min_pixels = std::atol(value.c_str());
    } else if (opt == "--max-pixels") {
      max_pixels = std::atol(value.c_str());
    } else if (opt == "--min-columns") {
      min_columns = std::atoi(value.c_str());
    } else {
      return usage();
    }
  }
  const weft::viz::test::Image image = weft::viz::test::read_png(argv[1]);
  if (!image.data) {
    std::fprintf(stderr, "png_probe: %s is not a readable PNG\n", argv[1]);
    return 2;
  }
  const auto cov = weft::viz::test::coverage(
      image, {static_cast<int>(rgb[0]), static_cast<int>(rgb[1]), static_cast<int>(rgb[2])}, tol, region);
  std::printf("pixels %ld columns %d rows %d width %d height %d\n", cov.pixels, cov.columns, cov.rows, image.width,
              image.height);
  const bool ok =
      cov.pixels >= min_pixels && cov.columns >= min_columns && (max_pixels < 0 || cov.pixels <= max_pixels);
  return ok ? 0 : 1;
}
