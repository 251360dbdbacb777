#include "weft/core/number_name.h"

#include <fmt/format.h>

namespace weft {

// fmt's {} is the shortest round-trip form; + 0.0 turns −0 into 0.
std::string number_name(double x) { return fmt::format("{}", x + 0.0); }

std::string signed_number_name(double x) { return fmt::format("{}{}", x + 0.0 < 0.0 ? "" : "+", number_name(x)); }

}  // namespace weft
