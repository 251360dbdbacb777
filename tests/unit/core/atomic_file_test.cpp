#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <stdexcept>
#include <string>

#include "file_size_limit.h"
#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/progress.h"

#include <sys/stat.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

fs::path fresh_dir(const char* name) {
  fs::path dir = fs::temp_directory_path() / fmt::format("weft-test-{}-{}", name, ::getpid());
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

// A short write is an error naming the output, and the earlier file stays whole under its name.
TEST(AtomicFile, ShortWriteIsAnErrorNamingTheFile) {
  const auto dir = fresh_dir("atomic-short");
  std::ofstream(dir / "big.txt") << "earlier";
  {
    const weft::test::FileSizeLimit limit(4096);
    EXPECT_THAT(
        [&] { weft::write_text_atomically(dir / "big.txt", std::string(1 << 20, 'x')); },
        ::testing::ThrowsMessage<weft::Error>(::testing::HasSubstr("cannot write '" + (dir / "big.txt").string())));
  }
  EXPECT_EQ(count_files(dir), 1U);
  std::ifstream in(dir / "big.txt");
  std::string s;
  in >> s;
  EXPECT_EQ(s, "earlier");
  fs::remove_all(dir);
}

// A stop request (Ctrl-C in the app) that came while nothing reported progress stops the run where
// it commits: no file is replaced, and a guarded folder is put back instead of kept.
TEST(AtomicFile, StopRequestStopsBeforeReplacing) {
  const auto dir = fresh_dir("atomic-stop");
  std::ofstream(dir / "a.txt") << "earlier";
  std::atomic<int> flag{0};
  weft::set_stop_request(&flag);
  {
    weft::FolderRollback outputs(dir);
    weft::write_text_atomically(dir / "b.txt", "written before the request");
    flag = 2;
    EXPECT_THROW(weft::write_text_atomically(dir / "a.txt", "new"), weft::Cancelled);
    EXPECT_THROW(outputs.keep(), weft::Cancelled);
  }
  weft::set_stop_request(nullptr);
  EXPECT_EQ(count_files(dir), 1U);  // b.txt removed with the run, a.txt as it was
  std::ifstream in(dir / "a.txt");
  std::string s;
  in >> s;
  EXPECT_EQ(s, "earlier");
  weft::write_text_atomically(dir / "a.txt", "new");  // no flag registered: writes go on
  fs::remove_all(dir);
}

TEST(AtomicFile, MissingFolderIsAClearError) {
  EXPECT_THAT([] { weft::write_text_atomically("/nonexistent-weft-folder/x.txt", "x"); },
              ::testing::ThrowsMessage<weft::Error>(::testing::HasSubstr("/nonexistent-weft-folder")));
}

// A folder under the output's name is refused before the write, and stays, also in a guarded
// folder (the guard had taken it for the run's file and removed it).
TEST(AtomicFile, AFolderUnderTheOutputsNameIsRefusedAndKept) {
  const auto dir = fresh_dir("atomic-folder-name");
  fs::create_directories(dir / "img.exr");
  {
    weft::FolderRollback outputs(dir);
    bool wrote = false;
    EXPECT_THAT([&] { weft::write_atomically(dir / "img.exr", [&](const fs::path&) { wrote = true; }); },
                ::testing::ThrowsMessage<weft::Error>(::testing::HasSubstr("is a folder, not a file")));
    EXPECT_FALSE(wrote);
  }
  EXPECT_TRUE(fs::is_directory(dir / "img.exr"));
  fs::remove_all(dir);
}

TEST(AtomicFile, AFileGivenAsTheFolderIsSaidSo) {
  const auto dir = fresh_dir("atomic-file-folder");
  std::ofstream(dir / "grid.vdb") << "a file";
  EXPECT_THAT([&] { weft::write_text_atomically(dir / "grid.vdb" / "x.txt", "x"); },
              ::testing::ThrowsMessage<weft::Error>(
                  ::testing::HasSubstr("'" + (dir / "grid.vdb").string() + "' is a file, not a folder")));
  fs::remove_all(dir);
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

namespace {

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Every file and folder under `dir` with the bytes of each file: a folder "as it was" has the same.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    files[fs::relative(e.path(), dir).string()] = e.is_regular_file() ? read_all(e.path()) : std::string("<dir>");
  return files;
}

// A folder that holds an earlier run's files: a failed run rewrites some of them, adds others
// (beside them, in their subfolder, in a new subfolder) and fails. The folder is then as it was,
// byte for byte; a run that succeeds leaves every file it wrote new and nothing else added.
TEST(FolderRollback, FailedRunPutsBackTheFilesItReplaced) {
  const auto dir = fresh_dir("rollback-replace");
  const auto prefill = [&] {
    fs::remove_all(dir);
    fs::create_directories(dir / "mitsuba");
    std::ofstream(dir / "report.json") << "earlier report";
    std::ofstream(dir / "mitsuba" / "cloth.xml") << "earlier scene";
    std::ofstream(dir / "notes.txt") << "the user's";
  };
  const auto run = [&](bool succeed) {
    weft::FolderRollback outputs(dir);
    weft::write_text_atomically(dir / "report.json", "new report, first pass");
    weft::write_text_atomically(dir / "mitsuba" / "cloth.xml", "new scene");
    weft::write_text_atomically(dir / "mitsuba" / "cloth.vol", "new grid");
    weft::ensure_directory(dir / "pbrt" / "deep");
    weft::write_text_atomically(dir / "pbrt" / "deep" / "cloth.pbrt", "new pbrt");
    weft::write_text_atomically(dir / "report.json", "new report, after the plots");
    if (succeed) outputs.keep();
  };
  prefill();
  const auto before = snapshot(dir);
  run(false);
  EXPECT_EQ(snapshot(dir), before);
  run(true);
  auto after = before;
  after["report.json"] = "new report, after the plots";
  after["mitsuba/cloth.xml"] = "new scene";
  after["mitsuba/cloth.vol"] = "new grid";
  after["pbrt"] = after["pbrt/deep"] = "<dir>";
  after["pbrt/deep/cloth.pbrt"] = "new pbrt";
  EXPECT_EQ(snapshot(dir), after);  // and no earlier version left beside them
  fs::remove_all(dir);
}

// Guards nest (a study's work folder inside its --out): whichever fails, the folder it guards is
// as it was, though the inner one kept its files or put them back first.
TEST(FolderRollback, NestedGuardsEachPutBackTheirFolder) {
  const auto dir = fresh_dir("rollback-nested");
  fs::create_directories(dir / "scene.study");
  std::ofstream(dir / "scene.exr") << "earlier image";
  std::ofstream(dir / "scene.study" / "coarse.vdb") << "earlier grid";
  const auto before = snapshot(dir);
  for (const bool inner_keeps : {true, false}) {
    {
      weft::FolderRollback out(dir);
      {
        weft::FolderRollback work(dir / "scene.study");
        weft::write_text_atomically(dir / "scene.study" / "coarse.vdb", "new grid");
        weft::write_text_atomically(dir / "scene.study" / "fields.vdb", "new fields");
        if (inner_keeps) work.keep();
      }
      weft::write_text_atomically(dir / "scene.exr", "new image");
    }
    EXPECT_EQ(snapshot(dir), before) << "inner guard kept: " << inner_keeps;
  }
  fs::remove_all(dir);
}

}  // namespace

// A symbolic link names the file it points at: the file is replaced and the link stays a link,
// through a chain of links, relative ones against their own folder.
TEST(AtomicFile, ASymbolicLinkIsWrittenThroughNotReplaced) {
  const auto dir = fresh_dir("atomic-link");
  fs::create_directories(dir / "real");
  weft::write_text_atomically(dir / "real" / "a.txt", "old");
  fs::create_symlink("real/a.txt", dir / "link1.txt");
  fs::create_symlink(dir / "link1.txt", dir / "link2.txt");
  weft::write_text_atomically(dir / "link2.txt", "new");
  EXPECT_TRUE(fs::is_symlink(dir / "link1.txt"));
  EXPECT_TRUE(fs::is_symlink(dir / "link2.txt"));
  std::ifstream in(dir / "real" / "a.txt");
  std::string s;
  std::getline(in, s);
  EXPECT_EQ(s, "new");
  // A link to nothing yet makes its target, as a shell's > does.
  fs::create_symlink("made.txt", dir / "dangling.txt");
  weft::write_text_atomically(dir / "dangling.txt", "x");
  EXPECT_TRUE(fs::is_symlink(dir / "dangling.txt"));
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(dir / "made.txt")));
  // A loop is an error naming the path, not a hang.
  fs::create_symlink("loop_b", dir / "loop_a");
  fs::create_symlink("loop_a", dir / "loop_b");
  EXPECT_THAT([&] { weft::write_text_atomically(dir / "loop_a", "x"); },
              ::testing::ThrowsMessage<weft::Error>(::testing::HasSubstr("too many levels of symbolic links")));
  fs::remove_all(dir);
}

// A link in a guarded folder to a file outside it: the run writes through it, and a failed run
// puts that file back as it was; a link to nothing yet has its new target removed.
TEST(AtomicFile, AFailedRunPutsBackTheFileALinkInItsFolderLeadsTo) {
  const auto dir = fresh_dir("atomic-link-rollback");
  fs::create_directories(dir / "out");
  fs::create_directories(dir / "elsewhere");
  weft::write_text_atomically(dir / "elsewhere" / "orig.vdb", "ORIGINAL");
  fs::create_symlink("../elsewhere/orig.vdb", dir / "out" / "cloth.vdb");
  fs::create_symlink("../elsewhere/new.vdb", dir / "out" / "other.vdb");
  {
    weft::FolderRollback outputs(dir / "out");
    weft::write_text_atomically(dir / "out" / "cloth.vdb", "NEW");
    weft::write_text_atomically(dir / "out" / "other.vdb", "NEW");
    std::ifstream in(dir / "elsewhere" / "orig.vdb");
    std::string s;
    std::getline(in, s);
    EXPECT_EQ(s, "NEW");
    EXPECT_TRUE(fs::exists(dir / "elsewhere" / "new.vdb"));
  }  // not kept: the run failed
  std::ifstream in(dir / "elsewhere" / "orig.vdb");
  std::string s;
  std::getline(in, s);
  EXPECT_EQ(s, "ORIGINAL");
  EXPECT_FALSE(fs::exists(dir / "elsewhere" / "new.vdb"));
  EXPECT_TRUE(fs::is_symlink(dir / "out" / "cloth.vdb"));
  EXPECT_TRUE(fs::is_symlink(dir / "out" / "other.vdb"));
  fs::remove_all(dir);
}

// A named pipe (and so a device or a socket: one check) under the output's name, or behind a link,
// is refused before the write and stays what it was: a rename would replace the node itself.
TEST(AtomicFile, ANodeThatIsNotARegularFileIsRefusedAndKept) {
  const auto dir = fresh_dir("atomic-fifo");
  ASSERT_EQ(::mkfifo((dir / "pipe.exr").c_str(), 0600), 0);
  fs::create_symlink("pipe.exr", dir / "link.exr");
  for (const char* name : {"pipe.exr", "link.exr"}) {
    bool wrote = false;
    EXPECT_THAT([&] { weft::write_atomically(dir / name, [&](const fs::path&) { wrote = true; }); },
                ::testing::ThrowsMessage<weft::Error>(::testing::HasSubstr("is a named pipe, not a regular file")))
        << name;
    EXPECT_FALSE(wrote) << name;
  }
  EXPECT_TRUE(fs::is_fifo(dir / "pipe.exr"));
  EXPECT_TRUE(fs::is_symlink(dir / "link.exr"));
  EXPECT_EQ(weft::output_file_problem("/dev/null"),
            "is a character device, not a regular file (weft writes a file whole and renames it into place)");
  EXPECT_EQ(weft::output_file_problem(dir / "none.exr"), "");
  fs::remove_all(dir);
}
