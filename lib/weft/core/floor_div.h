#pragma once
/// @file
/// @brief Integer division rounding towards −∞: voxel and block indices of negative coordinates
/// (C++ `/` truncates towards zero, which would put −1 in block 0).

#include <cstdint>

namespace weft {

/// ⌊a / b⌋ for b ≠ 0 (64-bit, so voxel coordinates and block sizes of any width mix freely).
[[nodiscard]] constexpr std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  std::int64_t q = a / b;
  if ((a % b != 0) && ((a < 0) != (b < 0))) --q;
  return q;
}

static_assert(floor_div(-1, 8) == -1 && floor_div(-8, 8) == -1 && floor_div(7, 8) == 0 && floor_div(-9, 8) == -2);

}  // namespace weft
