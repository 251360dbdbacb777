#include "weft/core/parse_number.h"

#include <charconv>
#include <string>
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

std::string_view trim_blanks(std::string_view text) {
  const std::size_t first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t") - first + 1);
}

std::optional<double> parse_option_number(std::string_view text) { return parse_number(trim_blanks(text)); }

std::string number_problem(std::string_view text) {
  const std::string_view t = trim_blanks(text);
  if (parse_number(t)) return {};
  std::string_view digits = t;
  if (!digits.empty() && (digits.front() == '+' || digits.front() == '-')) digits.remove_prefix(1);
  if (digits.size() > 1 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X'))
    return "a hexadecimal number (write it in decimal)";
  double value = 0.0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec == std::errc::result_out_of_range && end == digits.data() + digits.size()) return "past double's range";
  return std::string(kNotANumber);
}

}  // namespace weft
