// core/io/atomic_write.h: a set of files replaces its targets all together or not at all, and
// concurrent writers of the same set never leave a mixed set: a failed PNG write keeps
// the render's previous EXR, and two renders to one -o never leave an EXR and a PNG from
// different renders.
#include "core/io/atomic_write.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "tests/core/file_support.h"

namespace eikon {
namespace {

using eikon::test::slurp;

namespace fs = std::filesystem;

FileContent text(const std::string& content) {
  return [content](const fs::path& tmp) { std::ofstream(tmp, std::ios::binary) << content; };
}

class AtomicWrite : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "eikon_atomic_XXXXXX").string();
    ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  void expectNoTemporaries(const fs::path& dir) const {
    for (const auto& e : fs::recursive_directory_iterator(dir))
      EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  }
  fs::path dir_;
};

TEST_F(AtomicWrite, PairReplacesBothTargetsAndCreatesFolders) {
  const fs::path png = dir_ / "a" / "b" / "x.png", exr = dir_ / "a" / "b" / "x.exr";
  writeFilesTogether({{png, text("png 1")}, {exr, text("exr 1")}});
  EXPECT_EQ(slurp(png), "png 1");
  EXPECT_EQ(slurp(exr), "exr 1");
  writeFilesTogether({{png, text("png 2")}, {exr, text("exr 2")}});
  EXPECT_EQ(slurp(png), "png 2");
  EXPECT_EQ(slurp(exr), "exr 2");
  EXPECT_EQ(lockPathFor(png), dir_ / "a" / "b" / ".x.lock");
  expectNoTemporaries(dir_);
}

// Every set written left an empty ".x.lock" behind: the holder removes it as it unlocks.
TEST_F(AtomicWrite, NoLockFileIsLeftBehind) {
  const fs::path png = dir_ / "x.png", exr = dir_ / "x.exr";
  for (int round = 0; round < 2; ++round) {
    writeFilesTogether({{png, text("png")}, {exr, text("exr")}});
    EXPECT_FALSE(fs::exists(fs::symlink_status(lockPathFor(png))));
  }
  // Nor after a failed write (the lock taken, a rename refused).
  EXPECT_THROW(
      writeFilesTogether({{png, text("png 2")},
                          {exr, [](const fs::path&) { throw std::runtime_error("codec"); }}}),
      std::runtime_error);
  EXPECT_FALSE(fs::exists(fs::symlink_status(lockPathFor(png))));
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"x.exr", "x.png"}));
}

// A symbolic link planted at the lock file's name was followed, creating a file at its target
// (anywhere the writer may write). The link is refused with one line naming it; nothing is created
// at its target and both targets stay as they were.
TEST_F(AtomicWrite, LockFileThatIsASymbolicLinkIsRefused) {
  const fs::path png = dir_ / "x.png", exr = dir_ / "x.exr", target = dir_ / "elsewhere";
  writeFilesTogether({{png, text("old png")}, {exr, text("old exr")}});
  fs::create_symlink(target, lockPathFor(png));
  try {
    writeFilesTogether({{png, text("new png")}, {exr, text("new exr")}});
    ADD_FAILURE() << "a symbolic link as the lock file was followed";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("cannot write '" + lockPathFor(png).string() +
                          "': the lock file is a symbolic link",
                      0),
              0u)
        << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
  EXPECT_FALSE(fs::exists(fs::symlink_status(target)));
  EXPECT_TRUE(fs::is_symlink(lockPathFor(png)));  // not ours to remove
  EXPECT_EQ(slurp(png), "old png");
  EXPECT_EQ(slurp(exr), "old exr");
  expectNoTemporaries(dir_);
  // A link to an existing file is refused alike, the file untouched.
  fs::remove(lockPathFor(png));
  std::ofstream(target) << "precious";
  fs::create_symlink(target, lockPathFor(png));
  EXPECT_THROW(writeFilesTogether({{png, text("new png")}, {exr, text("new exr")}}),
               std::runtime_error);
  EXPECT_EQ(slurp(target), "precious");
  EXPECT_EQ(slurp(png), "old png");
}

// The second file's writer fails after the first file's content is complete (a full disk while
// writing the EXR, or the PNG in the old order): neither target changes, no temporary is left,
// and the message names the target whose write failed.
TEST_F(AtomicWrite, FailureOfTheSecondFileLeavesBothTargetsIntact) {
  const fs::path png = dir_ / "x.png", exr = dir_ / "x.exr";
  writeFilesTogether({{png, text("old png")}, {exr, text("old exr")}});
  try {
    writeFilesTogether({{png, text("new png")}, {exr, [](const fs::path& tmp) {
                                                   std::ofstream(tmp) << "half";
                                                   throw std::runtime_error(
                                                       "No space left on device");
                                                 }}});
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "cannot write '" + exr.string() + "': No space left on device");
  }
  EXPECT_EQ(slurp(png), "old png");
  EXPECT_EQ(slurp(exr), "old exr");
  expectNoTemporaries(dir_);
}

// Folders made for a set that then fails are removed again (no partial output, not even an empty
// folder); folders that existed before stay.
TEST_F(AtomicWrite, FoldersCreatedForAFailedSetAreRemoved) {
  fs::create_directory(dir_ / "kept");
  const fs::path a = dir_ / "kept" / "new" / "deeper" / "a.json", b = dir_ / "other" / "b.yml";
  EXPECT_THROW(
      writeFilesTogether(
          {{a, text("a")}, {b, [](const fs::path&) { throw std::runtime_error("disk full"); }}}),
      std::runtime_error);
  EXPECT_TRUE(fs::is_directory(dir_ / "kept"));
  EXPECT_FALSE(fs::exists(dir_ / "kept" / "new"));
  EXPECT_FALSE(fs::exists(dir_ / "other"));
  writeBytesAtomically(b, "bytes");  // and the bytes writer creates them when it succeeds
  EXPECT_EQ(slurp(b), "bytes");
}

TEST_F(AtomicWrite, TargetThatIsAFolderFailsBeforeAnyTargetChanges) {
  const fs::path png = dir_ / "x.png", exr = dir_ / "x.exr";
  std::ofstream(png) << "old png";
  fs::create_directory(exr);
  EXPECT_THROW(writeFilesTogether({{png, text("new png")}, {exr, text("new exr")}}),
               std::runtime_error);
  EXPECT_EQ(slurp(png), "old png");
  EXPECT_TRUE(fs::is_directory(exr));
  expectNoTemporaries(dir_);
}

// A pipe (or device) at a target is refused, not replaced by a file: as root, `-o /dev/null`
// turned /dev/null into a regular file. A symbolic link is written through: the link stays and
// shows the new file.
TEST_F(AtomicWrite, SpecialFilesAreRefusedAndLinksWrittenThrough) {
  const fs::path fifo = dir_ / "pipe.exr", other = dir_ / "x.png";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::ofstream(other) << "old png";
  try {
    writeFilesTogether({{other, text("new png")}, {fifo, text("new exr")}});
    ADD_FAILURE() << "a pipe was replaced";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("it is a pipe, not a regular file"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(fs::status(fifo).type(), fs::file_type::fifo);
  EXPECT_EQ(slurp(other), "old png");
  EXPECT_THROW(checkWritable(fifo), std::runtime_error);
  expectNoTemporaries(dir_);

  const fs::path target = dir_ / "real" / "shown.txt", link = dir_ / "link.txt";
  fs::create_directories(target.parent_path());
  std::ofstream(target) << "old";
  fs::create_symlink(target, link);
  EXPECT_NO_THROW(checkWritable(link));
  writeBytesAtomically(link, "new");
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link)));
  EXPECT_EQ(slurp(target), "new");
  EXPECT_EQ(slurp(link), "new");
}

TEST_F(AtomicWrite, SingleFileAndBytes) {
  const fs::path f = dir_ / "new" / "one.json";
  writeBytesAtomically(f, "{\"a\": 1}\n");
  EXPECT_EQ(slurp(f), "{\"a\": 1}\n");
  EXPECT_THROW(
      writeFileAtomically(f, [](const fs::path&) { throw std::runtime_error("encoder failed"); }),
      std::runtime_error);
  EXPECT_EQ(slurp(f), "{\"a\": 1}\n");
  expectNoTemporaries(dir_);
}

// Writers racing on one pair, each writing its own tag into both files, while a reader that takes
// the same lock checks that the two files always carry the same tag. Without the lock the renames
// of two writers interleave (png from one, exr from the other) within a few hundred rounds here.
TEST_F(AtomicWrite, ConcurrentWritersNeverLeaveAMixedPair) {
  const fs::path png = dir_ / "x.png", exr = dir_ / "x.exr";
  writeFilesTogether({{png, text("w0 r0")}, {exr, text("w0 r0")}});
  std::atomic<bool> stop{false};
  std::atomic<int> mixed{0}, checks{0};
  std::thread reader([&] {
    while (!stop) {
      const OutputSetLock lock(png);  // the writers' protocol: they remove the file as they unlock
      if (slurp(png) != slurp(exr)) ++mixed;
      ++checks;
    }
  });
  std::vector<std::thread> writers;
  for (int w = 1; w <= 3; ++w)
    writers.emplace_back([&, w] {
      for (int r = 0; r < 200; ++r) {
        const std::string tag = "w" + std::to_string(w) + " r" + std::to_string(r);
        writeFilesTogether({{png, text(tag)}, {exr, text(tag)}});
      }
    });
  for (auto& t : writers) t.join();
  stop = true;
  reader.join();
  EXPECT_EQ(mixed.load(), 0) << "of " << checks.load() << " checks";
  EXPECT_GT(checks.load(), 0);
  EXPECT_EQ(slurp(png), slurp(exr));
  EXPECT_FALSE(fs::exists(fs::symlink_status(lockPathFor(png))));
  expectNoTemporaries(dir_);
}

// The removal protocol itself: processes (not threads: flock locks belong to open files, and each
// process opens its own) that each hold the lock in turn while removing it as they unlock never
// find another process inside. Each increments a counter file under the lock, read-modify-write
// with a pause between: a lock lost to the removal (two holders at once) loses an increment.
TEST_F(AtomicWrite, LockRemovalKeepsMutualExclusionAcrossProcesses) {
  const fs::path first = dir_ / "x.png", counter = dir_ / "count";
  std::ofstream(counter) << 0;
  constexpr int kProcesses = 4, kRounds = 150;
  std::vector<pid_t> pids;
  for (int p = 0; p < kProcesses; ++p) {
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      for (int r = 0; r < kRounds; ++r) {
        const OutputSetLock lock(first);
        int n = 0;
        std::ifstream(counter) >> n;
        ::usleep(50);
        std::ofstream(counter) << n + 1;
      }
      ::_exit(0);
    }
    pids.push_back(pid);
  }
  for (const pid_t pid : pids) {
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  }
  int n = 0;
  std::ifstream(counter) >> n;
  EXPECT_EQ(n, kProcesses * kRounds);
  EXPECT_FALSE(fs::exists(fs::symlink_status(lockPathFor(first))));
}

}  // namespace
}  // namespace eikon
