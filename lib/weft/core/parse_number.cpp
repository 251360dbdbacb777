#include "weft/core/parse_number.h"

#include <charconv>
#include <system_error>

namespace weft {

std::optional<double> parse_number(std::string_view text) {
  // from_chars takes no leading '+'; a user writing "+2" means 2.
  if (!text.empty() && text.front() == '+') {
    text.remove_prefix(1);
    if (!text.empty() && (text.front() == '-' || text.front() == '+')) return std::nullopt;
  }
  if (text.empty()) return std::nullopt;
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

}  // namespace weft
