#pragma once
/// @file
/// @brief Numbers from option values, metadata and file headers: the whole text or nothing.

#include <optional>
#include <string_view>

namespace weft {

/// @brief The number `text` spells as a whole ("0.5", "-3e-7", "+2", "inf", "nan"), or nullopt
/// when it is empty, has anything before or after the number (white space included), or is out
/// of double's range. Read by std::from_chars: the same in every locale (std::stod follows
/// LC_NUMERIC, where "0.5" can fail) and exact for the 17 significant digits weft writes.
[[nodiscard]] std::optional<double> parse_number(std::string_view text);

}  // namespace weft
