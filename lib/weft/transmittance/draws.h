#pragma once
/// @file
/// @brief Many free-flight distances from one seed, drawn chunk by chunk with progress reports, so
/// that a caller can stop a long run (`weft model --sample N`, Python `Law.sample`;
/// docs/architecture.md "Progress and cancellation").

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "weft/core/progress.h"
#include "weft/core/rng.h"

namespace weft::transmittance {

/// The most distances one run or call draws: more is a typo, and would take minutes (draw with
/// several seeds instead).
inline constexpr std::uint64_t kMaxDraws = 1'000'000'000;

/// Distances per chunk, i.e. per progress report (docs/python.md "Interrupting a call": reports per
/// bounded amount of work): 0.2 ms of gamma draws (~5e-8 s each), 36 ms of the slowest measured,
/// a numerically derived partner (`weft model --law gamma-path --k 4 --theta 0.25 --given S`,
/// ~8.7e-6 s each), so a stop request is seen within that.
inline constexpr std::size_t kDrawChunk = std::size_t{1} << 12U;

/// Draws `count` distances with `draw(rng)`, all from the one stream stream_for(seed, 0) in order
/// (so the numbers do not depend on the chunking), and hands them to `take(std::span<const
/// double>)` in chunks of at most kDrawChunk. Each chunk is a report of stage "sampling" to
/// `progress`, whose Cancelled stops the draws there (no later chunk is drawn or taken).
template <typename Draw, typename Take>
void draw_in_chunks(std::uint64_t count, std::uint64_t seed, ProgressSink& progress, Draw&& draw, Take&& take) {
  ProgressTask task(progress, "sampling", count);
  Pcg32 rng = stream_for(seed, 0);
  std::vector<double> chunk(static_cast<std::size_t>(std::min<std::uint64_t>(kDrawChunk, count)));
  for (std::uint64_t done = 0; done < count;) {
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(kDrawChunk, count - done));
    for (std::size_t i = 0; i < n; ++i) chunk[i] = draw(rng);
    take(std::span<const double>(chunk.data(), n));
    done += n;
    task.step(n);
  }
}

}  // namespace weft::transmittance
