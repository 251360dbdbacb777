#pragma once
/// @file
/// @brief Numbers from option values, metadata and file headers: the whole text or nothing.

#include <optional>
#include <string>
#include <string_view>

namespace weft {

/// @brief The number `text` spells as a whole ("0.5", "-3e-7", "+2", "inf", "nan"), or nullopt
/// when it is empty, has anything before or after the number (white space included), or is out
/// of double's range. Read by std::from_chars: the same in every locale (std::stod follows
/// LC_NUMERIC, where "0.5" can fail) and exact for the 17 significant digits weft writes.
[[nodiscard]] std::optional<double> parse_number(std::string_view text);

/// @brief A number a user typed as an option's value (or an item of its list): parse_number of
/// `text` without the blanks (spaces, tabs) around it, so "--t ' 5'" and "--sigma '2 '" read as
/// every other spelling of 5 and 2. The options' one rule (apps/usage.h check_number_options).
[[nodiscard]] std::optional<double> parse_option_number(std::string_view text);

/// @brief Why parse_option_number refuses `text`, in words that follow "got '…'" or stand alone:
/// "a hexadecimal number (write it in decimal)", "past double's range", "not a number"; empty
/// when it is a number.
[[nodiscard]] std::string number_problem(std::string_view text);

/// @brief number_problem's words for a text that is no number at all (a caller that also takes
/// names, as --window does, tells this case apart by it).
inline constexpr std::string_view kNotANumber = "not a number";

/// @brief `text` without the blanks (spaces, tabs) around it.
[[nodiscard]] std::string_view trim_blanks(std::string_view text);

}  // namespace weft
