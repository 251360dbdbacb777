#pragma once
/// @file
/// @brief "Did you mean …?" for misspelt names (laws, scene keys, object types).

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace weft {

/// @brief Case-insensitive Levenshtein distance.
[[nodiscard]] std::size_t edit_distance(const std::string& a, const std::string& b);

/// @brief The candidate nearest to `word` by edit_distance, or "" when there are none or the
/// nearest is farther than `max_distance` (so an unrelated word gets no suggestion).
[[nodiscard]] std::string closest_name(const std::string& word, const std::vector<std::string>& candidates,
                                       std::size_t max_distance = std::numeric_limits<std::size_t>::max());

}  // namespace weft
