// core/io/cache_limit.h: the cache folder is held to its cap by removing whole entries, least
// recently used first, never the entry just written, a writer's temporary or a file that is not an
// entry; a reader of a removed entry still reads it whole; EIKON_CACHE_MAX_MB sets the cap.
#include "core/io/cache_limit.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace eikon {
namespace {

namespace fs = std::filesystem;

class CacheLimit : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "eikon_cache_limit_XXXXXX").string();
    ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override {
    ::unsetenv("EIKON_CACHE_MAX_MB");
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  /// A file of `bytes` bytes last modified `age_s` seconds ago.
  fs::path entry(const std::string& name, size_t bytes, int age_s) const {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << std::string(bytes, 'x');
    fs::last_write_time(p, fs::file_time_type::clock::now() - std::chrono::seconds(age_s));
    return p;
  }
  fs::path dir_;
};

TEST_F(CacheLimit, OnlyEntriesAreEntries) {
  for (const char* name : {"light-0123456789abcdef.bin", "volume-0123456789abcdef.bin",
                           "spirv-0123456789abcdef.bin", "pipelines-10005-0000.bin"})
    EXPECT_TRUE(isCacheEntryName(name)) << name;
  for (const char* name : {"light-0123456789abcdef.bin.tmp-AbCd1234", ".trim.lock", "notes.txt",
                           "light-.binx", "volume.bin", ".x.lock", "mine.bin"})
    EXPECT_FALSE(isCacheEntryName(name)) << name;
}

// 4 entries of 100 bytes under a 250-byte cap: the two least recently used go, whatever their
// kind; the temporary, the lock and a foreign file stay and are not counted.
TEST_F(CacheLimit, LeastRecentlyUsedEntriesGoFirst) {
  const fs::path oldest = entry("light-0000000000000001.bin", 100, 400);
  const fs::path old = entry("volume-0000000000000002.bin", 100, 300);
  const fs::path recent = entry("spirv-0000000000000003.bin", 100, 200);
  const fs::path newest = entry("pipelines-10005-0000.bin", 100, 100);
  const fs::path tmp = entry("light-0000000000000009.bin.tmp-AbCd1234", 1000, 1000);
  const fs::path foreign = entry("notes.txt", 1000, 1000);
  EXPECT_EQ(trimCacheDir(dir_, {}, 250), 200u);
  EXPECT_FALSE(fs::exists(oldest));
  EXPECT_FALSE(fs::exists(old));
  EXPECT_TRUE(fs::exists(recent));
  EXPECT_TRUE(fs::exists(newest));
  EXPECT_TRUE(fs::exists(tmp));
  EXPECT_TRUE(fs::exists(foreign));
  EXPECT_EQ(trimCacheDir(dir_, {}, 250), 0u);  // within the cap: nothing more
}

// Using an entry (touchCacheEntry, as every cache does on a hit) makes it the last to go; the
// entry just written is kept even when it alone exceeds the cap.
TEST_F(CacheLimit, UseRefreshesAndTheNewEntryIsKept) {
  const fs::path used = entry("light-0000000000000001.bin", 100, 400);
  const fs::path unused = entry("light-0000000000000002.bin", 100, 300);
  touchCacheEntry(used);
  EXPECT_EQ(trimCacheDir(dir_, {}, 150), 100u);
  EXPECT_TRUE(fs::exists(used));
  EXPECT_FALSE(fs::exists(unused));
  const fs::path big = entry("volume-0000000000000003.bin", 1000, 0);
  EXPECT_EQ(trimCacheDir(dir_, big, 0), 100u);
  EXPECT_TRUE(fs::exists(big));
  EXPECT_FALSE(fs::exists(used));
}

// A process reading an entry when it is removed reads all of it (POSIX keeps an unlinked file's
// data for those who hold it open).
TEST_F(CacheLimit, AReaderOfARemovedEntryReadsItWhole) {
  const fs::path e = entry("light-0000000000000001.bin", 4096, 100);
  std::ifstream reader(e, std::ios::binary);
  ASSERT_TRUE(reader);
  EXPECT_EQ(trimCacheDir(dir_, {}, 0), 4096u);
  EXPECT_FALSE(fs::exists(e));
  const std::string bytes((std::istreambuf_iterator<char>(reader)), {});
  EXPECT_EQ(bytes, std::string(4096, 'x'));
}

// One trimmer at a time: while another process holds the folder's trim lock, nothing is removed.
TEST_F(CacheLimit, AHeldTrimLockLeavesTheTrimmingToItsHolder) {
  const fs::path e = entry("light-0000000000000001.bin", 100, 100);
  const int fd = ::open((dir_ / ".trim.lock").c_str(), O_RDWR | O_CREAT, 0666);
  ASSERT_GE(fd, 0);
  // flock locks are per open file description: a second open in this process competes as another
  // process would.
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  EXPECT_EQ(trimCacheDir(dir_, {}, 0), 0u);
  EXPECT_TRUE(fs::exists(e));
  ::close(fd);
  EXPECT_EQ(trimCacheDir(dir_, {}, 0), 100u);
}

TEST_F(CacheLimit, TheCapComesFromTheEnvironment) {
  ::unsetenv("EIKON_CACHE_MAX_MB");
  EXPECT_EQ(cacheMaxBytes(), kDefaultCacheMaxBytes);
  EXPECT_EQ(kDefaultCacheMaxBytes, uint64_t(1) << 30);
  ::setenv("EIKON_CACHE_MAX_MB", "3", 1);
  EXPECT_EQ(cacheMaxBytes(), 3u << 20);
  ::setenv("EIKON_CACHE_MAX_MB", "0", 1);
  EXPECT_EQ(cacheMaxBytes(), 0u);
  for (const char* bad : {"-1", "1.5", "abc", "1e3", " 5", "99999999999"}) {
    ::setenv("EIKON_CACHE_MAX_MB", bad, 1);
    std::string error;
    EXPECT_FALSE(cacheMaxBytesSetting(&error)) << bad;
    EXPECT_NE(error.find("EIKON_CACHE_MAX_MB must be a whole number of MiB"), std::string::npos)
        << error;
    EXPECT_EQ(cacheMaxBytes(), kDefaultCacheMaxBytes) << bad;
  }
}

}  // namespace
}  // namespace eikon
