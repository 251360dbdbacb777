#pragma once
/// @file
/// @brief Numbers in file and folder names (the study matrix's case folders, `weft sim2d`'s charts
/// per η): one rule, so that distinct values never share a name.

#include <string>

namespace weft {

/// @brief `x` in the fewest decimal digits that read back as the same double (45 → "45",
/// 0.996 → "0.996", 30.00000001 → "30.00000001", 1e-5 → "1e-05"), −0 as "0" (the same value).
/// Distinct values give distinct names: a rounded form (a fixed count of digits) gave 0.996 and
/// 0.999 one name, and the second value's files replaced the first's.
[[nodiscard]] std::string number_name(double x);

/// @brief number_name with its sign always written, "+" for 0 too ("+0.5", "-0.5", "+0"): for
/// names whose convention spells the sign.
[[nodiscard]] std::string signed_number_name(double x);

}  // namespace weft
