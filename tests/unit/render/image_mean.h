#pragma once
/// @file
/// @brief The mean of an image's first channel with its standard error from the per-pixel
/// sample variances (grey media: the three channels are one estimate, not three).

#include <cmath>

#include "weft/render/image.h"

namespace weft::render::test {

struct Estimate {
  double mean = 0.0;
  double stderr_ = 0.0;
};

inline Estimate image_mean(const Image& im) {
  double sum = 0.0;
  double var = 0.0;
  int n = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      sum += im.at(x, y, 0);
      var += im.var_at(x, y, 0);
      ++n;
    }
  return {sum / n, std::sqrt(var) / n};
}

}  // namespace weft::render::test
