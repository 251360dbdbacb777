// Checks that a rendered cloth image shows the cloth (CLI tests of `weft render` with no scene
// and of `weft gen` + `weft render <out>/scene.json`). The scene (cloth_scene.h) puts a bright
// backlight behind the patch: without a cloth the centre of the frame is that light (uniform,
// saturated) or empty space (dark). A visible cloth makes a large share of the centre's pixels
// partly transmitting (between 2% and 85% of the backlight's radiance) and textured (the
// weave's gaps and yarns). Exit 0 when both hold, 1 with the measured statistics otherwise.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "weft/core/error.h"
#include "weft/render/image.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: cloth_image_check IMAGE.exr\n");
    return 2;
  }
  try {
    const weft::render::Image im = weft::render::read_exr(argv[1]);
    std::vector<double> all;
    std::vector<double> centre;
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x) {
        const double l = (im.at(x, y, 0) + im.at(x, y, 1) + im.at(x, y, 2)) / 3.0;
        if (!std::isfinite(l)) {
          std::fprintf(stderr, "pixel %d,%d is not finite\n", x, y);
          return 1;
        }
        all.push_back(l);
        if (x >= im.width / 4 && x < 3 * im.width / 4 && y >= im.height / 4 && y < 3 * im.height / 4)
          centre.push_back(l);
      }
    std::sort(all.begin(), all.end());
    const double backlight = all[static_cast<std::size_t>(0.99 * static_cast<double>(all.size() - 1))];
    double sum = 0.0;
    double sum2 = 0.0;
    int partial = 0;
    for (double l : centre) {
      if (l > 0.02 * backlight && l < 0.85 * backlight) ++partial;
      sum += l;
      sum2 += l * l;
    }
    const double n = static_cast<double>(centre.size());
    const double mean = sum / n;
    const double cov = std::sqrt(std::max(0.0, sum2 / n - mean * mean)) / std::max(mean, 1e-300);
    const double share = partial / n;
    std::printf("backlight %.4g, centre mean %.4g, centre CoV %.3f, partly transmitting share %.3f\n", backlight, mean,
                cov, share);
    if (!(backlight > 0.0) || share < 0.25 || cov < 0.1) {
      std::fprintf(stderr, "the cloth is not visible: share %.3f (need >= 0.25), CoV %.3f (need >= 0.1)\n", share, cov);
      return 1;
    }
    return 0;
  } catch (const weft::Error& e) {
    std::fprintf(stderr, "cloth_image_check: %s\n", e.what());
    return 1;
  }
}
