#pragma once
/// @file
/// @brief Outputs appear whole or not at all: write to a temporary name, then rename.

#include <filesystem>
#include <functional>
#include <iosfwd>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace weft {

/// @brief What is wrong with `value` given as the name of an output, a folder when `folder` else a
/// file: "must name a folder, got an empty value", "... got a blank value" (only white space), or
/// "" when nothing is. The one rule for every output name a user gives (docs/robustness.md, the
/// empty-argument cases): an empty name would read as the option left out and a command would
/// write to its default path or the working folder; a blank one makes a file or folder named
/// " " there. The CLI's check_output_options, the Python calls' `out=` / `path=` and
/// write_atomically use it; the caller prefixes the option or argument it names.
[[nodiscard]] std::string output_name_problem(std::string_view value, bool folder);

/// @brief `path` with every symbolic link of its last component followed (a chain of them, relative
/// ones against the link's folder), as far as the links exist: the file an output under `path`
/// replaces. A loop is a weft::Error.
[[nodiscard]] std::filesystem::path through_links(const std::filesystem::path& path);

/// @brief What stops `path` (through its links) from taking an output file: "is a folder, not a
/// file", "is a character device, not a regular file (...)" (a device, a pipe, a socket), or ""
/// when nothing does (a regular file, or nothing yet). The CLI checks it before a run, and
/// write_atomically again.
[[nodiscard]] std::string output_file_problem(const std::filesystem::path& path);

/// @brief Calls `write(tmp)` with a temporary path beside `target`, then renames it to `target`.
/// A `target` that is a symbolic link is followed (through_links): the file it names is replaced.
/// One that is a device, a pipe or a socket is refused (output_file_problem), not replaced by a
/// regular file.
///
/// If `write` throws, the temporary file is removed and the exception propagates, so a failed
/// run never leaves a half-written output. A stop request (stop_if_requested, core/progress.h) that
/// arrived while `write` ran stops the run here, before anything is replaced. The target's folder must exist; an
/// unwritable folder gives a weft::Error naming it, and an empty or blank `target` one saying so (output_name_problem),
/// not a failed rename of the temporary file.
void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::filesystem::path& tmp)>& write);

/// @brief Calls `write(out)` with a binary stream on a temporary file beside `target`, then renames
/// it to `target` (write_atomically). A short write (a full disk, a file size limit) is an error
/// naming `target` ("cannot write '<target>': <reason>"), raised before the rename: a writer that
/// does not check its stream (OpenVDB's, for one) cannot leave a truncated file under the name.
void write_stream_atomically(const std::filesystem::path& target, const std::function<void(std::ostream& out)>& write);

/// @brief Writes `text` to `target` atomically (write_stream_atomically).
void write_text_atomically(const std::filesystem::path& target, std::string_view text);

/// @brief Creates `dir` (and parents) or throws a weft::Error naming it.
void ensure_directory(const std::filesystem::path& dir);

/// @brief Refuses, before a run spends anything, an output folder its files could not be written
/// to: `dir`, or where it does not exist yet its nearest existing ancestor (the run creates the
/// rest), must be a folder in which this process can create a file. The test is a file made and
/// removed there, not the permission bits: they do not see read-only mounts, /proc or root's
/// rights. Leaves nothing behind; throws a weft::Error naming `dir` and the reason.
void check_writable_folder(const std::filesystem::path& dir);

/// @brief The files a run writes into one folder appear whole or not at all, for a run of many
/// files (each written atomically) that can fail between them: a run either completes (every file
/// it wrote is new) or leaves the folder as it was (docs/robustness.md "Output folders of failed
/// runs").
///
/// Made before the run's first file: refuses a folder that cannot be written
/// (check_writable_folder), creates `folder` (and missing parents) and remembers what was there.
/// While it lives, write_atomically keeps the earlier version of every file it replaces inside
/// `folder` (a hard link beside it, a copy where the file system has none), and ensure_directory
/// the folders it creates there. Unless keep() is called, the destructor (a failed run unwinding)
/// puts the earlier versions back, removes the files and folders the run added (a folder it created
/// with everything in it, at any depth) and, in `folder`, the entries that were not there before.
/// keep() drops the earlier versions. Guards nest (a study's work folder inside its --out): each
/// keeps its own earlier versions. An inactive guard (an MPI rank that writes nothing) does nothing.
class FolderRollback {
 public:
  explicit FolderRollback(std::filesystem::path folder, bool active = true);
  ~FolderRollback();
  FolderRollback(const FolderRollback&) = delete;
  FolderRollback& operator=(const FolderRollback&) = delete;
  /// The run succeeded: its files stay. Throws Cancelled instead, keeping nothing, when a stop was
  /// requested (stop_if_requested): a run stopped during its last, unreported stretch is undone.
  void keep();

  /// Called by write_atomically before it renames a finished file onto `target`, the file the
  /// output's `named` path leads to (through_links), and by ensure_directory after it created
  /// `made`: every live guard whose folder holds the name (or the target) records the target, so a
  /// link in the folder to a file outside it is put back too. Throws a weft::Error (before
  /// anything is replaced) if an earlier version cannot be kept.
  static void before_replacing(const std::filesystem::path& named, const std::filesystem::path& target);
  static void after_creating(const std::filesystem::path& made);

 private:
  void stop_watching();
  std::filesystem::path folder_;
  std::filesystem::path root_;     ///< folder_, absolute and without symbolic links: what it holds is under it
  std::filesystem::path created_;  ///< the outermost folder this guard created (empty: none)
  std::set<std::filesystem::path> before_;
  std::set<std::filesystem::path> written_;                                    ///< files the run wrote
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> kept_;  ///< (file, its earlier version)
  std::vector<std::filesystem::path> made_;                                    ///< folders the run created
  bool active_;
};

}  // namespace weft
