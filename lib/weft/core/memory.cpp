#include "weft/core/memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
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

std::pair<std::string, std::string> format_bytes_apart(std::uint64_t a, std::uint64_t b) {
  std::pair<std::string, std::string> texts{format_bytes(a), format_bytes(b)};
  if (a == b || texts.first != texts.second) return texts;
  const std::uint64_t larger = std::max(a, b);
  const auto [unit, name] = larger < 1024ULL * 1024U           ? std::pair{1024.0, "KiB"}
                            : larger < 1024ULL * 1024U * 1024U ? std::pair{1024.0 * 1024.0, "MiB"}
                                                               : std::pair{1024.0 * 1024.0 * 1024.0, "GiB"};
  for (int decimals = 2; decimals <= 9; ++decimals) {
    texts = {fmt::format("{:.{}f} {}", static_cast<double>(a) / unit, decimals, name),
             fmt::format("{:.{}f} {}", static_cast<double>(b) / unit, decimals, name)};
    if (texts.first != texts.second) return texts;
  }
  return {fmt::format("{} bytes", a), fmt::format("{} bytes", b)};
}

std::string format_bytes(std::uint64_t bytes) {
  if (bytes == 1U) return "1 byte";
  if (bytes < 1024U) return fmt::format("{} bytes", bytes);
  const double kib = static_cast<double>(bytes) / 1024.0;
  if (kib < 1024.0) return fmt::format("{:.1f} KiB", kib);
  const double mebi = kib / 1024.0;
  if (mebi < 1024.0) return fmt::format("{:.1f} MiB", mebi);
  return fmt::format("{:.2f} GiB", mebi / 1024.0);
}

}  // namespace weft
