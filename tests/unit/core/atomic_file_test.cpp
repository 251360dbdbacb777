#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"

#include <unistd.h>

namespace fs = std::filesystem;

namespace {

fs::path fresh_dir(const char* name) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("weft-test-{}-{}", name, ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::size_t count_files(const fs::path& dir) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}));
}

TEST(AtomicFile, WritesWholeFile) {
  const auto dir = fresh_dir("atomic-ok");
  weft::write_text_atomically(dir / "a.txt", "hello");
  std::ifstream in(dir / "a.txt");
  std::string s;
  in >> s;
  EXPECT_EQ(s, "hello");
  EXPECT_EQ(count_files(dir), 1U);
  fs::remove_all(dir);
}

TEST(AtomicFile, FailedWriteLeavesNothing) {
  const auto dir = fresh_dir("atomic-fail");
  EXPECT_THROW(weft::write_atomically(dir / "b.txt",
                                      [](const fs::path& tmp) {
                                        std::ofstream(tmp) << "half";
                                        throw std::runtime_error("boom");
                                      }),
               std::runtime_error);
  EXPECT_EQ(count_files(dir), 0U);
  fs::remove_all(dir);
}

TEST(AtomicFile, MissingFolderIsAClearError) {
  EXPECT_THAT([] { weft::write_text_atomically("/nonexistent-weft-folder/x.txt", "x"); },
              ::testing::ThrowsMessage<weft::Error>(::testing::HasSubstr("/nonexistent-weft-folder")));
}

TEST(AtomicFile, TemporaryKeepsExtension) {
  const auto dir = fresh_dir("atomic-ext");
  weft::write_atomically(dir / "c.vtp", [](const fs::path& tmp) {
    EXPECT_EQ(tmp.extension(), ".vtp");
    std::ofstream(tmp) << "x";
  });
  EXPECT_TRUE(fs::exists(dir / "c.vtp"));
  fs::remove_all(dir);
}

}  // namespace

namespace {

// A run of many files that fails half-way leaves none of them: a folder the guard made goes
// with everything in it, and in a folder that was there only what the run added goes.
TEST(FolderRollback, FailedRunLeavesNoHalfOutput) {
  const auto dir = fresh_dir("rollback");
  std::ofstream(dir / "kept.txt") << "before";
  const auto run = [&](const fs::path& folder, bool succeed) {
    weft::FolderRollback outputs(folder);
    weft::write_text_atomically(folder / "grid.txt", "one file of the run");
    if (succeed) outputs.keep();
  };
  run(dir / "new" / "study", false);
  EXPECT_FALSE(fs::exists(dir / "new"));  // both levels were made by the run
  run(dir, false);
  EXPECT_TRUE(fs::exists(dir / "kept.txt"));
  EXPECT_FALSE(fs::exists(dir / "grid.txt"));
  run(dir / "new" / "study", true);
  EXPECT_TRUE(fs::exists(dir / "new" / "study" / "grid.txt"));
  fs::remove_all(dir);
}

}  // namespace
