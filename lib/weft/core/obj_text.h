#pragma once
/// @file
/// @brief Wavefront OBJ text, read once for every OBJ loader (yarn curves, render meshes): its
/// statements, numbers and vertex references.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace weft {

/// @brief One statement of an OBJ text: its tag ("v", "l", "f", …) and arguments.
struct ObjStatement {
  std::size_t line = 0;  ///< 1-based number of the statement's first physical line
  std::string tag;
  std::vector<std::string> args;
};

/// @brief The statements of an OBJ text in order. As the format allows: a line ending in a
/// backslash continues on the next, `#` starts a comment that runs to the end of the (joined)
/// line, wherever it stands, blank and comment-only lines are skipped, and CRLF ends a line too.
class ObjStatements {
 public:
  explicit ObjStatements(std::string_view text) : text_(text) {}
  /// @brief The next statement into `s`; false at the end of the text.
  bool next(ObjStatement& s);

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_ = 0;
};

/// @brief `token` as a finite number ("0.5", "-3e-7", "+3e-3"; parse_number's rules), or nullopt.
[[nodiscard]] std::optional<double> obj_number(std::string_view token);

/// @brief The vertex a reference ("i", "i/t", "i//n", "i/t/n") names, 0-based, of the `defined`
/// vertices so far: i from 1, or negative counting back from the last (-1). nullopt when the
/// reference is malformed, 0, or out of range; `index` then holds the number it spelled, if any.
[[nodiscard]] std::optional<std::size_t> obj_vertex(std::string_view token, std::size_t defined,
                                                    long long* index = nullptr);

}  // namespace weft
