#pragma once
/// @file
/// @brief The one exception type weft throws for bad input and impossible requests.

#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace weft {

/// @brief Thrown for invalid parameters, malformed files and requests that cannot be met.
///
/// The message names the input and the problem in one line ("gamma law: alpha must be > 0,
/// got -1"); apps print it as `weft: error: <message>` and exit non-zero.
class Error : public std::runtime_error {
 public:
  /// The message is kept to one line whatever it quotes (one_line).
  explicit Error(const std::string& message) : std::runtime_error(one_line(message)) {}

  /// `text` with its control characters written out: a newline as \n, a carriage return as \r,
  /// NUL as \0, the others as \xHH (a tab stays). A path or scene key that holds them then
  /// prints as one line, and NUL no longer cuts the message short (what() is a C string).
  static std::string one_line(const std::string& text);
};

/// @brief Throws weft::Error with a fmt-formatted message.
template <typename... Args>
[[noreturn]] void fail(fmt::format_string<Args...> format, Args&&... args) {
  throw Error(fmt::format(format, std::forward<Args>(args)...));
}

/// @brief Checks that `value` is finite and > 0; `what` names it in the error.
double require_positive(const char* what, double value);
/// @brief Checks that `value` is finite and >= 0.
double require_non_negative(const char* what, double value);
/// @brief Checks that `value` is finite.
double require_finite(const char* what, double value);

}  // namespace weft
