#pragma once
// Test helper: a GoogleMock matcher for the errors weft throws, shared by every unit test (the
// folder is on their include path, cmake/WeftTargets.cmake).

#include <initializer_list>
#include <string>
#include <vector>

#include <gmock/gmock.h>

#include "weft/core/error.h"

namespace weft::test {

/// Matches a callable that throws weft::Error (or a subclass) whose message is one line holding
/// every one of `words`: the errors' contract (docs/architecture.md §5 "Errors and exit codes").
/// A mismatch prints the message, or says that nothing or another type was thrown.
///   EXPECT_THAT([&] { (void)parse(text); }, weft::test::throws_one_line_error_with({"in.json", "warp_count"}));
inline auto throws_one_line_error_with(std::initializer_list<std::string> words) {
  std::vector<::testing::Matcher<std::string>> parts{::testing::Not(::testing::HasSubstr("\n"))};
  for (const std::string& word : words) parts.push_back(::testing::HasSubstr(word));
  return ::testing::ThrowsMessage<Error>(::testing::AllOfArray(parts));
}

}  // namespace weft::test
