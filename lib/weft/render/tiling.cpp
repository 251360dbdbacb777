#include "weft/render/tiling.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <numeric>

namespace weft::render {

Tiling::Tiling(int width, int height, int spp_per_pass) {
  for (;; side /= 2) {
    tiles_x = (width + side - 1) / side;
    tiles_y = (height + side - 1) / side;
    const long next_samples = static_cast<long>(side / 2) * (side / 2) * spp_per_pass;
    if (side == 1 || count() >= kMinTiles || next_samples < kMinSamples) break;
  }
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
