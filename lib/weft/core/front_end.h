#pragma once
/// @file
/// @brief Which front end asked, so that a check shared by the CLI and the Python module names the
/// option in the caller's words ("--rays 4" or "rays_per_column=4"; docs/python.md "One set of
/// checks").

#include <string>

namespace weft {

enum class FrontEnd { cli, python };

/// @brief An option (with its value) as each front end writes it.
struct Spelling {
  std::string cli;
  std::string python;
  [[nodiscard]] const std::string& in(FrontEnd f) const { return f == FrontEnd::cli ? cli : python; }
};

}  // namespace weft
