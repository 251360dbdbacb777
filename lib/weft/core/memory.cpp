#include "weft/core/memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "weft/core/error.h"

namespace weft {

std::uint64_t default_memory_budget() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page = ::sysconf(_SC_PAGE_SIZE);
  std::uint64_t usable =
      pages <= 0 || page <= 0 ? 8ULL << 30U : static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page);
  rlimit limit{};
  if (::getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    usable = std::min<std::uint64_t>(usable, limit.rlim_cur);
  return usable / 2U;
}

std::uint64_t memory_budget_bytes(const char* what, double mib) {
  require_non_negative(what, mib);
  if (mib == 0.0) return default_memory_budget();
  // 2^64 as a double: anything at or above it saturates (the cast would be undefined).
  constexpr double kTwo64 = 18446744073709551616.0;
  const double bytes = std::ceil(mib * 1024.0 * 1024.0);
  if (bytes >= kTwo64) return std::numeric_limits<std::uint64_t>::max();
  return std::max<std::uint64_t>(1U, static_cast<std::uint64_t>(bytes));
}

namespace {
// The binary units a byte count is said in, past bytes: a 64-bit count is below 16 EiB, so a huge
// estimate reads "3.05 PiB", never a run of digits in GiB.
struct ByteUnit {
  double size;
  const char* name;
  int decimals;  // format_bytes's: one below a GiB, two from there on
};
constexpr std::array<ByteUnit, 6> kByteUnits{{{0x1p10, "KiB", 1},
                                              {0x1p20, "MiB", 1},
                                              {0x1p30, "GiB", 2},
                                              {0x1p40, "TiB", 2},
                                              {0x1p50, "PiB", 2},
                                              {0x1p60, "EiB", 2}}};

// The largest unit `bytes` (>= 1024) holds at least once.
const ByteUnit& unit_of(std::uint64_t bytes) {
  std::size_t u = 0;
  while (u + 1 < kByteUnits.size() && static_cast<double>(bytes) >= kByteUnits[u + 1].size) ++u;
  return kByteUnits[u];
}
}  // namespace

std::pair<std::string, std::string> format_bytes_apart(std::uint64_t a, std::uint64_t b) {
  std::pair<std::string, std::string> texts{format_bytes(a), format_bytes(b)};
  if (a == b || texts.first != texts.second) return texts;
  // Equal texts: both counts are past 1 KiB. The smaller one's unit keeps its integer part
  // (1023.999999999 GiB against 1024.000000000 GiB, not 1.000000000 TiB twice).
  const ByteUnit& unit = unit_of(std::min(a, b));
  for (int decimals = 2; decimals <= 9; ++decimals) {
    texts = {fmt::format("{:.{}f} {}", static_cast<double>(a) / unit.size, decimals, unit.name),
             fmt::format("{:.{}f} {}", static_cast<double>(b) / unit.size, decimals, unit.name)};
    if (texts.first != texts.second) return texts;
  }
  return {fmt::format("{} bytes", a), fmt::format("{} bytes", b)};
}

std::string format_bytes(std::uint64_t bytes) {
  if (bytes == 1U) return "1 byte";
  if (bytes < 1024U) return fmt::format("{} bytes", bytes);
  const ByteUnit* unit = &unit_of(bytes);
  // A count that rounds up to 1024 of its unit is said in the next one ("1.00 TiB", not "1024.00 GiB").
  const double scale = std::pow(10.0, unit->decimals);
  if (unit != &kByteUnits.back() && std::round(static_cast<double>(bytes) / unit->size * scale) / scale >= 1024.0)
    ++unit;
  return fmt::format("{:.{}f} {}", static_cast<double>(bytes) / unit->size, unit->decimals, unit->name);
}

}  // namespace weft
