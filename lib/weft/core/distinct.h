#pragma once
/// @file
/// @brief Lists of cases (beam directions, correlations, angles) whose items must differ: a
/// repeated item would compute the same numbers again under another index, so it is refused
/// rather than traced twice or silently dropped (docs/robustness.md "Options that would do nothing").

#include <algorithm>
#include <cstddef>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "weft/core/error.h"

namespace weft {

/// @brief Throws weft::Error "<what>: <label(i)> is given twice" for the first item i whose
/// key(items[i]) equals an earlier item's (key: what makes two items the same case, e.g. the unit
/// vector of a direction). O(n log n); the keys must be ordered by < (no NaN: refuse it first).
template <typename T, typename Label, typename Key>
void require_distinct(std::string_view what, const std::vector<T>& items, Label&& label, Key&& key) {
  using K = std::decay_t<std::invoke_result_t<Key&, const T&>>;
  std::vector<std::pair<K, std::size_t>> keyed;
  keyed.reserve(items.size());
  for (std::size_t i = 0; i < items.size(); ++i) keyed.emplace_back(key(items[i]), i);
  std::sort(keyed.begin(), keyed.end());  // equal keys by index: the later one second
  std::size_t repeat = items.size();
  for (std::size_t i = 1; i < keyed.size(); ++i) {
    if (keyed[i].first == keyed[i - 1].first) repeat = std::min(repeat, keyed[i].second);
  }
  if (repeat < items.size()) fail("{}: {} is given twice", what, label(repeat));
}

/// @brief require_distinct of items that are their own key and label (numbers).
template <typename T>
void require_distinct(std::string_view what, const std::vector<T>& items) {
  require_distinct(
      what, items, [&](std::size_t i) { return fmt::format("{}", items[i]); }, [](const T& x) { return x; });
}

}  // namespace weft
