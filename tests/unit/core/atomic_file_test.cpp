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
  try {
    weft::write_text_atomically("/nonexistent-weft-folder/x.txt", "x");
    FAIL() << "expected weft::Error";
  } catch (const weft::Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-weft-folder"), std::string::npos);
  }
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

// A run that fails after making its output folder leaves no empty folder behind (the folders it
// made, parents included, go), but never removes what existed or what holds a file.
TEST(OutputFolder, FailedRunLeavesNoEmptyFolder) {
  const auto dir = fresh_dir("output-folder");
  try {
    const weft::OutputFolder folder(dir / "a" / "b");
    ASSERT_TRUE(fs::is_directory(dir / "a" / "b"));
    throw std::runtime_error("the run failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_FALSE(fs::exists(dir / "a"));
  EXPECT_TRUE(fs::is_directory(dir));
  {
    const weft::OutputFolder folder(dir / "c" / "d");
    weft::write_text_atomically(dir / "c" / "d" / "part.txt", "x");
  }
  EXPECT_TRUE(fs::exists(dir / "c" / "d" / "part.txt"));
  {
    weft::OutputFolder folder(dir / "e");
    folder.keep();
  }
  EXPECT_TRUE(fs::is_directory(dir / "e"));
  { const weft::OutputFolder existing(dir / "e"); }
  EXPECT_TRUE(fs::is_directory(dir / "e"));
  fs::remove_all(dir);
}

}  // namespace
