#include "weft/volume/pass_budget.h"

#include <cmath>
#include <limits>

#include "weft/core/error.h"
#include "weft/core/memory.h"

namespace weft::volume {

void check_pass_cost(std::string_view what, std::string_view subject, const PassCost& cost) {
  const std::uint64_t budget = default_memory_budget();
  // Compared in double: a sparse grid's box can make the estimate larger than any integer.
  if (!(cost.bytes <= static_cast<double>(budget))) {
    const bool fits = cost.bytes < 0x1p63;
    const auto [need, limit] = fits ? format_bytes_apart(static_cast<std::uint64_t>(cost.bytes), budget)
                                    : std::pair{fmt::format("{:.3g} bytes", cost.bytes), format_bytes(budget)};
    fail("{} over {} would take {}, over the memory budget of {} (half the RAM or of ulimit -v)", what, subject, need,
         limit);
  }
  if (!(cost.steps <= kMaxPassSteps)) {
    fail(
        "{} over {} would take {:.3g} steps (voxels read, cells crossed, depths profiled), over the limit of "
        "{:.3g}",
        what, subject, cost.steps, kMaxPassSteps);
  }
}

void check_pass_cost(std::string_view what, const Grid& grid, const PassCost& cost) {
  check_pass_cost(what, fmt::format("grid '{}'", grid.name()), cost);
}

}  // namespace weft::volume
