#pragma once
/// @file
/// @brief Numbers written to be read back: in file and folder names (the study matrix's case
/// folders, `weft sim2d`'s charts per η), one rule so that distinct values never share a name;
/// and the bounds error messages give, which a user copies into the option they refused.

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

/// @brief Which side of a bound the value a message prints must fall on.
enum class BoundSide { at_least, at_most };

/// @brief A bound in 4 significant digits (more when needed), rounded to its accepted side: a
/// lower bound up, an upper bound down, so that the printed number, given back, is accepted
/// (the smallest voxel, 1.44225e-05, as "1.443e-05", not "1.442e-05" that is refused).
[[nodiscard]] std::string bound_text(double bound, BoundSide side);

}  // namespace weft
