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

// An empty or blank name is refused before anything is written, not as a failed rename of the
// temporary file (which named '.<stem>.tmp<pid>-<n>' and, for " ", would have made a file " ").
TEST(AtomicFile, EmptyOrBlankTargetIsRefusedFirst) {
  const auto dir = fresh_dir("atomic-blank");
  const fs::path here = fs::current_path();
  fs::current_path(dir);
  for (const char* name : {"", " ", "\t", " \n "}) {
    bool called = false;
    EXPECT_THAT([&] { weft::write_atomically(name, [&](const fs::path&) { called = true; }); },
                ::testing::ThrowsMessage<weft::Error>(::testing::HasSubstr("must name a file, got a")))
        << "'" << name << "'";
    EXPECT_FALSE(called);
  }
  fs::current_path(here);
  EXPECT_EQ(count_files(dir), 0U);
  fs::remove_all(dir);
}

TEST(AtomicFile, OutputNameProblem) {
  EXPECT_EQ(weft::output_name_problem("", true), "must name a folder, got an empty value");
  EXPECT_EQ(weft::output_name_problem(" \t", true), "must name a folder, got a blank value");
  EXPECT_EQ(weft::output_name_problem("\t", false), "must name a file, got a blank value");
  // A name with white space around it is a name: the shell kept it on purpose.
  EXPECT_EQ(weft::output_name_problem(" run ", true), "");
  EXPECT_EQ(weft::output_name_problem("run", false), "");
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
