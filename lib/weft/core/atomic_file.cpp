#include "weft/core/atomic_file.h"

#include <atomic>
#include <cerrno>
#include <fstream>
#include <system_error>
#include <utility>

#include <unistd.h>

#include "weft/core/error.h"

namespace weft {
namespace fs = std::filesystem;

namespace {
fs::path temporary_beside(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  fs::path tmp = target;
  // Keep the extension last: some writers (VTK, OpenEXR) choose a format from it.
  tmp.replace_filename(
      fmt::format(".{}.tmp{}-{}{}", target.stem().string(), ::getpid(), counter++, target.extension().string()));
  return tmp;
}
}  // namespace

std::string output_name_problem(std::string_view value, bool folder) {
  const char* what = folder ? "folder" : "file";
  if (value.empty()) return fmt::format("must name a {}, got an empty value", what);
  if (value.find_first_not_of(" \t\n\v\f\r") == std::string_view::npos)
    return fmt::format("must name a {}, got a blank value", what);
  return {};
}

void write_atomically(const fs::path& target, const std::function<void(const fs::path&)>& write) {
  if (const std::string problem = output_name_problem(target.native(), false); !problem.empty())
    fail("output file '{}': {}", target.string(), problem);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) fail("output folder '{}' does not exist", dir.string());
  if (::access(dir.c_str(), W_OK) != 0) fail("output folder '{}' is not writable", dir.string());
  const fs::path tmp = temporary_beside(target);
  try {
    write(tmp);
    if (!fs::exists(tmp, ec)) fail("writing '{}' produced no file", target.string());
    fs::rename(tmp, target, ec);
    if (ec) fail("cannot rename '{}' to '{}': {}", tmp.string(), target.string(), ec.message());
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

void write_text_atomically(const fs::path& target, std::string_view text) {
  write_atomically(target, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) fail("cannot open '{}' for writing", target.string());
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.flush();
    if (!out) fail("cannot write '{}' (disk full?)", target.string());
  });
}

void ensure_directory(const fs::path& dir) {
  std::error_code ec;
  if (fs::is_directory(dir, ec)) return;
  fs::create_directories(dir, ec);
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
  if (!created_.empty()) return;
  for (const auto& entry : fs::directory_iterator(folder_, ec)) before_.insert(entry.path());
}

FolderRollback::~FolderRollback() {
  if (!active_) return;
  std::error_code ec;
  if (!created_.empty()) {
    fs::remove_all(created_, ec);
    return;
  }
  std::set<fs::path> now;
  for (const auto& entry : fs::directory_iterator(folder_, ec)) now.insert(entry.path());
  for (const fs::path& p : now)
    if (!before_.contains(p)) fs::remove_all(p, ec);
}

}  // namespace weft
