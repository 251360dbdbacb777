#include "weft/core/atomic_file.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <mutex>
#include <system_error>
#include <utility>

#include <unistd.h>

#include "weft/core/error.h"
#include "weft/core/progress.h"

namespace weft {
namespace fs = std::filesystem;

namespace {
// `tag` tells a run's temporaries ("tmp") from the earlier versions a FolderRollback keeps ("weft-old").
fs::path temporary_beside(const fs::path& target, const char* tag = "tmp") {
  static std::atomic<unsigned> counter{0};
  fs::path tmp = target;
  // Keep the extension last: some writers (VTK, OpenEXR) choose a format from it.
  tmp.replace_filename(
      fmt::format(".{}.{}{}-{}{}", target.stem().string(), tag, ::getpid(), counter++, target.extension().string()));
  return tmp;
}

constexpr const char* kKeptTag = "weft-old";

bool is_kept_version(const fs::path& p) {
  const std::string name = p.filename().string();
  return name.starts_with('.') && name.find(std::string(".") + kKeptTag) != std::string::npos;
}

// `p` absolute, without symbolic links where it exists: the one spelling both sides of under() use.
fs::path resolved(const fs::path& p) {
  std::error_code ec;
  fs::path a = fs::absolute(p, ec);
  if (ec) return p;
  fs::path r = fs::weakly_canonical(a, ec);
  return ec ? a.lexically_normal() : r;
}

bool under(const fs::path& folder, const fs::path& p) {
  const auto f = std::mismatch(folder.begin(), folder.end(), p.begin(), p.end()).first;
  // A trailing separator of `folder` is an empty last element.
  return f == folder.end() || (std::next(f) == folder.end() && f->empty());
}

// The live guards: write_atomically and ensure_directory may run on several threads at once.
std::mutex g_guards_mutex;
std::vector<FolderRollback*> g_guards;
}  // namespace

std::string output_name_problem(std::string_view value, bool folder) {
  const char* what = folder ? "folder" : "file";
  if (value.empty()) return fmt::format("must name a {}, got an empty value", what);
  if (value.find_first_not_of(" \t\n\v\f\r") == std::string_view::npos)
    return fmt::format("must name a {}, got a blank value", what);
  return {};
}

fs::path through_links(const fs::path& path) {
  fs::path p = path;
  std::error_code ec;
  // 40: the kernel's own limit on the links one lookup follows (ELOOP).
  for (int followed = 0; fs::is_symlink(fs::symlink_status(p, ec)); ++followed) {
    if (followed == 40) fail("output file '{}': too many levels of symbolic links", path.string());
    const fs::path to = fs::read_symlink(p, ec);
    if (ec) fail("output file '{}': cannot read its symbolic link: {}", path.string(), ec.message());
    p = to.is_absolute() ? to : p.parent_path() / to;
  }
  return p;
}

std::string output_file_problem(const fs::path& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(through_links(path), ec);
  if (!fs::exists(st) || fs::is_regular_file(st)) return {};
  if (fs::is_directory(st)) return "is a folder, not a file";
  const char* kind = fs::is_character_file(st) ? "a character device"
                     : fs::is_block_file(st)   ? "a block device"
                     : fs::is_fifo(st)         ? "a named pipe"
                     : fs::is_socket(st)       ? "a socket"
                                               : "not a regular file";
  // An output is written whole under a temporary name and renamed over the old file (above): over
  // a device or a pipe that would replace the node itself, not write into it.
  return fmt::format("is {}, not a regular file (weft writes a file whole and renames it into place)", kind);
}

void write_atomically(const fs::path& requested, const std::function<void(const fs::path&)>& write) {
  if (const std::string problem = output_name_problem(requested.native(), false); !problem.empty())
    fail("output file '{}': {}", requested.string(), problem);
  if (const std::string problem = output_file_problem(requested); !problem.empty())
    fail("output file '{}' {}", requested.string(), problem);
  // A symbolic link names the file it points at: that file is replaced, not the link (as a shell's
  // `>` writes through it).
  const fs::path target = through_links(requested);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    // "file.vdb/x" or a path ending in "/" after a file's name: the folder is a file.
    if (fs::exists(dir, ec)) fail("output folder '{}' is a file, not a folder", dir.string());
    fail("output folder '{}' does not exist", dir.string());
  }
  if (::access(dir.c_str(), W_OK) != 0) fail("output folder '{}' is not writable", dir.string());
  // A folder under the output's name: the rename would fail after the work, and a guard would take
  // the name for one the run wrote and remove what is the user's.
  if (fs::is_directory(target, ec)) fail("output file '{}' is a folder, not a file", target.string());
  const fs::path tmp = temporary_beside(target);
  try {
    write(tmp);
    if (!fs::exists(tmp, ec)) fail("writing '{}' produced no file", target.string());
    stop_if_requested();
    FolderRollback::before_replacing(requested, target);
    fs::rename(tmp, target, ec);
    if (ec) fail("cannot rename '{}' to '{}': {}", tmp.string(), target.string(), ec.message());
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

void write_stream_atomically(const fs::path& target, const std::function<void(std::ostream&)>& write) {
  write_atomically(target, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) fail("cannot open '{}' for writing", target.string());
    errno = 0;
    write(out);
    out.flush();
    const int error = errno;
    out.close();
    // The stream keeps only a failbit; errno still holds the write(2) that failed (ENOSPC, EFBIG).
    if (!out) fail("cannot write '{}': {}", target.string(), error != 0 ? std::strerror(error) : "the write failed");
  });
}

void write_text_atomically(const fs::path& target, std::string_view text) {
  write_stream_atomically(
      target, [&](std::ostream& out) { out.write(text.data(), static_cast<std::streamsize>(text.size())); });
}

void ensure_directory(const fs::path& dir) {
  std::error_code ec;
  if (fs::is_directory(dir, ec)) return;
  fs::path outermost;  // the first folder of `dir` that is not there yet
  for (fs::path p = fs::absolute(dir, ec); !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    outermost = p;
    if (p == p.parent_path()) break;
  }
  fs::create_directories(dir, ec);
  std::error_code made;
  if (!outermost.empty() && fs::exists(outermost, made)) FolderRollback::after_creating(outermost);
  if (ec) fail("cannot create output folder '{}': {}", dir.string(), ec.message());
}

void check_writable_folder(const fs::path& dir) {
  std::error_code ec;
  fs::path at = fs::absolute(dir.empty() ? fs::path(".") : dir, ec);
  if (ec) fail("output folder '{}': {}", dir.string(), ec.message());
  while (!fs::exists(at, ec) && at.has_parent_path() && at != at.parent_path()) at = at.parent_path();
  if (!fs::is_directory(at, ec)) fail("output folder '{}': '{}' is not a folder", dir.string(), at.string());
  const fs::path probe = temporary_beside(at / "weft-write-check");
  {
    std::ofstream f(probe, std::ios::binary);
    if (!f) {
      // ENOENT for a folder that exists is a file system that makes no new files (/proc, /sys):
      // the C library's "No such file or directory" would read as if the folder were missing.
      const int error = errno;
      const std::string reason = error == ENOENT ? std::string("this file system takes no new files")
                                                 : std::error_code(error, std::generic_category()).message();
      fail("output folder '{}' cannot be written{}: {}", dir.string(),
           at == fs::absolute(dir, ec) ? std::string() : fmt::format(" (nothing can be created in '{}')", at.string()),
           reason);
    }
  }
  fs::remove(probe, ec);
}

FolderRollback::FolderRollback(fs::path folder, bool active) : folder_(std::move(folder)), active_(active) {
  if (!active_) return;
  // Its users make the guard before their work: a folder no file can be written to is refused
  // then, not when the first file is (and before anything is created).
  check_writable_folder(folder_);
  std::error_code ec;
  for (fs::path p = fs::absolute(folder_, ec); !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    created_ = p;
    if (p == p.parent_path()) break;
  }
  try {
    ensure_directory(folder_);
  } catch (...) {
    // create_directories may have stopped half way, and no destructor runs for this guard.
    if (!created_.empty()) fs::remove_all(created_, ec);
    throw;
  }
  root_ = resolved(folder_);
  if (created_.empty())
    for (const auto& entry : fs::directory_iterator(folder_, ec)) before_.insert(entry.path());
  const std::lock_guard lock(g_guards_mutex);
  g_guards.push_back(this);
}

void FolderRollback::stop_watching() {
  const std::lock_guard lock(g_guards_mutex);
  g_guards.erase(std::remove(g_guards.begin(), g_guards.end(), this), g_guards.end());
}

void FolderRollback::before_replacing(const fs::path& named, const fs::path& target) {
  const std::lock_guard lock(g_guards_mutex);
  if (g_guards.empty()) return;
  // The guard is chosen by the name the run wrote to (its folder resolved, not its last
  // component: a link in the guarded folder is the run's output there); the file kept and put
  // back is the one the name leads to, wherever it is.
  const fs::path name = resolved(named.has_parent_path() ? named.parent_path() : fs::path(".")) / named.filename();
  const fs::path file = resolved(target);
  std::error_code ec;
  for (FolderRollback* guard : g_guards) {
    // In a folder the guard created everything is new; a file the run wrote before has no
    // earlier version to keep (a report rewritten after its plots).
    if (!guard->created_.empty() || !(under(guard->root_, name) || under(guard->root_, file)) ||
        guard->written_.contains(file))
      continue;
    if (fs::is_regular_file(file, ec)) {
      // A second name for the earlier file: the rename that follows replaces the name, not the
      // bytes. Where the file system has no hard links, a copy.
      const fs::path old = temporary_beside(file, kKeptTag);
      fs::create_hard_link(file, old, ec);
      if (ec) {
        ec.clear();
        fs::copy_file(file, old, ec);
      }
      if (ec) {
        fs::remove(old, ec);
        fail("cannot keep the earlier '{}' to put it back if the run fails: {}", target.string(), ec.message());
      }
      guard->kept_.emplace_back(file, old);
    }
    guard->written_.insert(file);
  }
}

void FolderRollback::after_creating(const fs::path& made) {
  const std::lock_guard lock(g_guards_mutex);
  const fs::path folder = resolved(made);
  for (FolderRollback* guard : g_guards)
    if (guard->created_.empty() && folder != guard->root_ && under(guard->root_, folder))
      guard->made_.push_back(folder);
}

void FolderRollback::keep() {
  if (!active_) return;
  // A stop request that came while nothing reported progress (a plot being drawn) still undoes the
  // run: the destructor puts the folder back (docs/robustness.md "Output folders of failed runs").
  stop_if_requested();
  stop_watching();
  active_ = false;
  std::error_code ec;
  for (const auto& kept : kept_) fs::remove(kept.second, ec);
}

FolderRollback::~FolderRollback() {
  if (!active_) return;
  stop_watching();
  std::error_code ec;
  if (!created_.empty()) {
    fs::remove_all(created_, ec);
    return;
  }
  // The earlier versions back, the last kept first; then what the run added goes.
  std::set<fs::path> restored;
  for (auto it = kept_.rbegin(); it != kept_.rend(); ++it) {
    fs::create_directories(it->first.parent_path(), ec);
    fs::rename(it->second, it->first, ec);
    // Two names of one file (an inner guard put the same earlier version back first): rename
    // does nothing then, and the second name must still go.
    fs::remove(it->second, ec);
    restored.insert(it->first);
  }
  for (const fs::path& file : written_)
    if (!restored.contains(file)) fs::remove(file, ec);
  for (auto it = made_.rbegin(); it != made_.rend(); ++it) fs::remove_all(*it, ec);
  std::set<fs::path> now;
  for (const auto& entry : fs::directory_iterator(folder_, ec)) now.insert(entry.path());
  // An enclosing guard's earlier versions stay for it to put back.
  for (const fs::path& p : now)
    if (!before_.contains(p) && !is_kept_version(p)) fs::remove_all(p, ec);
}

}  // namespace weft
