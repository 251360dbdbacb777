#pragma once
/// @file
/// @brief Outputs appear whole or not at all: write to a temporary name, then rename.

#include <filesystem>
#include <functional>
#include <string_view>
#include <vector>

namespace weft {

/// @brief Calls `write(tmp)` with a temporary path beside `target`, then renames it to `target`.
///
/// If `write` throws, the temporary file is removed and the exception propagates, so a failed
/// run never leaves a half-written output. The target's folder must exist; an unwritable folder
/// gives a weft::Error naming it.
void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path& tmp)>& write);

/// @brief Writes `text` to `target` atomically.
void write_text_atomically(const std::filesystem::path& target, std::string_view text);

/// @brief Creates `dir` (and parents) or throws a weft::Error naming it.
void ensure_directory(const std::filesystem::path& dir);

/// @brief An output folder made before a run (so a bad path fails before any work) that does not
/// outlive a failed run empty: unless kept, the destructor removes the folders the constructor
/// created (deepest first) that are still empty. A folder that existed before, or holds a file,
/// stays (docs/robustness.md: no half-written output, no empty folder).
class OutputFolder {
 public:
  explicit OutputFolder(const std::filesystem::path& dir);
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;
  /// The run succeeded: the folder stays even if empty.
  void keep() { created_.clear(); }

 private:
  void remove_empty() noexcept;
  std::vector<std::filesystem::path> created_;  // deepest first
};

}  // namespace weft
