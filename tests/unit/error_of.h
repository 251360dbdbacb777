#pragma once
// The message of the weft::Error a call throws, shared by the unit tests that check messages.
#include <string>

#include "weft/core/error.h"

namespace weft::test {

/// The message of the weft::Error `f` throws ("" when it returns; other exceptions propagate).
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace weft::test
