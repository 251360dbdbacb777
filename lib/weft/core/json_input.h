#pragma once
/// @file
/// @brief JSON a user wrote (a scene, a cloth spec): parsed once, the same way for every input,
/// with errors at a line and column and no key given twice.

#include <cstddef>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace weft {

/// Line and column (1-based) of byte offset `offset` in `text`.
struct TextPosition {
  std::size_t line = 1;
  std::size_t column = 1;
};
[[nodiscard]] TextPosition position_of(std::string_view text, std::size_t offset);

/// @brief The JSON value of `text` (a UTF-8 byte order mark skipped), or weft::Error naming
/// `source`: at line:column for a syntax error, and naming the key and the object for a key an
/// object gives twice. RFC 8259 §4 leaves duplicate names to the parser; nlohmann keeps the last,
/// so `"spp": 16, "spp": 4` rendered at 4 without a word, although every key of a scene is
/// checked.
[[nodiscard]] nlohmann::json parse_json_input(std::string_view text, const std::string& source);

}  // namespace weft
