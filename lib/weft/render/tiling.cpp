#include "weft/render/tiling.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <numeric>

namespace weft::render {

int Tiling::side_for(int width, int height, int spp_per_pass) {
  for (int s = kMaxSide;; s /= 2) {
    const auto tiles = static_cast<std::size_t>((width + s - 1) / s) * static_cast<std::size_t>((height + s - 1) / s);
    const long next_samples = static_cast<long>(s / 2) * (s / 2) * spp_per_pass;
    if (s == 1 || tiles >= kMinTiles || next_samples < kMinSamples) return s;
  }
}

int Tiling::bounded_pass_spp(int width, int height, int spp) {
  // Fewer samples per pass can only keep the tiles as large or make them larger, so each step
  // lowers the pass below the last one's bound M / side², and the loop ends.
  int pass = std::max(1, spp);
  for (;;) {
    const long side = side_for(width, height, pass);
    if (pass == 1 || side * side * pass <= kMaxUnitSamples) return pass;
    pass = static_cast<int>(std::max(1L, kMaxUnitSamples / (side * side)));
  }
}

Tiling::Tiling(int width, int height, int spp_per_pass) : side(side_for(width, height, spp_per_pass)) {
  tiles_x = (width + side - 1) / side;
  tiles_y = (height + side - 1) / side;
  // The key of tile (tx, ty): the bits of tx and ty interleaved from their least significant
  // up, so that sorting by it is a bit-reversed (van der Corput) sequence in each coordinate at
  // once: the first 4 units fall in the 4 quadrants of the film, the first 16 in its 16 sixteenths,
  // and so on. Distinct tiles have distinct keys, so the sort permutes them.
  const int bits =
      std::max(std::bit_width(static_cast<unsigned>(tiles_x - 1)), std::bit_width(static_cast<unsigned>(tiles_y - 1)));
  const auto key = [&](std::size_t t) {
    const auto tx = static_cast<std::uint64_t>(t % static_cast<std::size_t>(tiles_x));
    const auto ty = static_cast<std::uint64_t>(t / static_cast<std::size_t>(tiles_x));
    std::uint64_t k = 0;
    for (int b = 0; b < bits; ++b) {
      const auto shift = static_cast<unsigned>(2 * (bits - 1 - b));
      k |= (((tx >> static_cast<unsigned>(b)) & 1U) << (shift + 1U)) |
           (((ty >> static_cast<unsigned>(b)) & 1U) << shift);
    }
    return k;
  };
  order_.resize(count());
  std::iota(order_.begin(), order_.end(), std::size_t{0});
  std::sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
}

}  // namespace weft::render
