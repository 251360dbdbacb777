#pragma once
/// @file
/// @brief The work units of a render pass: the film cut into square tiles, and the order they run in.

#include <cstddef>
#include <vector>

namespace weft::render {

/// The work units of a pass: square tiles of 16, 8, 4, 2 or 1 pixels a side, the largest side
/// that still gives kMinTiles tiles, but no tile under kMinSamples samples per pass (a 64×64 film
/// at 1024 spp: 1024 tiles of 2×2 pixels; 256×256: 1024 of 8×8; 1024×768: 3072 of 16×16; a 48×48
/// film in passes of 1 spp keeps 16×16, as smaller units would cost more to schedule than to
/// render). A few large tiles of very unequal cost (background vs medium) leave threads idle at
/// the end of a pass; with ≥ 1024 units, dynamic scheduling leaves at most about one unit per
/// thread. One tiling serves every pass of a render (a rank keeps its tiles' running sums between
/// passes), and each pixel's samples are still summed by one unit in sample order, so the image
/// does not depend on it (docs/render.md §1).
///
/// Units run in a scrambled order of the tiles (their indices sorted by bit-reversed value, a
/// van der Corput sequence over the film): in row order the first tenth of a cloth render's units
/// is the background above it, about a third of a tenth of the work, and the progress bar's ETA
/// was three times too short; scrambled, every share of the units samples the whole film.
struct Tiling {
  static constexpr int kMaxSide = 16;
  static constexpr std::size_t kMinTiles = 1024;
  static constexpr long kMinSamples = 256;
  /// The most samples one unit renders in a pass. A unit is where a render reports progress and
  /// stops on a Ctrl-C, so it must stay short at any spp: 16 384 samples are 10–20 ms of a
  /// homogeneous medium and ≈ 0.2 s of the cloth grid on one thread.
  static constexpr long kMaxUnitSamples = 16384;
  int side = kMaxSide;
  int tiles_x = 1;
  int tiles_y = 1;

  Tiling(int width, int height, int spp_per_pass);
  /// The side of the tiles of Tiling(width, height, spp_per_pass), without their order.
  [[nodiscard]] static int side_for(int width, int height, int spp_per_pass);
  /// The samples per pixel of a pass of a render of `spp` in as few passes as keep every unit
  /// within kMaxUnitSamples: `spp` itself when its tiles stay within it, else fewer (1 at
  /// least). Passes run one after another and every pixel sums its samples in sample order
  /// across them, so the image does not depend on this split (docs/render.md §1).
  [[nodiscard]] static int bounded_pass_spp(int width, int height, int spp);
  /// The tile that unit u renders (tile t covers pixels from x = (t mod tiles_x)·side,
  /// y = (t div tiles_x)·side).
  [[nodiscard]] std::size_t tile(std::size_t u) const { return order_[u]; }
  [[nodiscard]] std::size_t count() const {
    return static_cast<std::size_t>(tiles_x) * static_cast<std::size_t>(tiles_y);
  }

 private:
  std::vector<std::size_t> order_;
};

}  // namespace weft::render
