// The cache of specialised kernels (core/vk/spirv_cache.h): it gives the
// words specialiseSpirv gives, an entry is what is read back (not a fresh specialisation), and a
// random, truncated, bit-flipped, foreign or non-SPIR-V file is ignored with one note on stderr,
// never handed on, and replaced.
#include "core/vk/spirv_cache.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "core/io/build_id.h"
#include "core/vk/specialise.h"
#include "shaders/eikon_shared.h"
#include "shaders/view.spv.h"
#include "tests/core/file_support.h"
#include "tests/core/scene_support.h"

namespace eikon::vk {
namespace {

using eikon::test::put;
using eikon::test::slurp;

namespace fs = std::filesystem;

std::span<const uint32_t> viewSpirv() {
  return std::span<const uint32_t>(k_view_spv, sizeof(k_view_spv) / 4);
}

class SpirvCache : public ::testing::Test {
 protected:
  void SetUp() override {
    if (codeBuildId().empty()) GTEST_SKIP() << "this test binary has no build id";
  }
  eikon::test::TempDir dir_;
  const std::vector<uint32_t> sharp_{1, EIKON_F_SHARP, 2, 0};
  const std::vector<uint32_t> smoothed_{0, 0, 2, 0};
};

TEST_F(SpirvCache, GivesTheSpecialisedWordsAndStoresThem) {
  const std::vector<uint32_t> fresh = specialiseSpirv(viewSpirv(), sharp_);
  const fs::path file = spirvCachePath(viewSpirv(), sharp_, dir_.path());
  ASSERT_FALSE(file.empty());
  EXPECT_EQ(file.parent_path(), dir_.path());
  EXPECT_NE(spirvCachePath(viewSpirv(), smoothed_, dir_.path()), file);  // the constants key it
  EXPECT_EQ(specialiseSpirvCached(viewSpirv(), sharp_, dir_.path()), fresh);
  ASSERT_TRUE(fs::exists(file));
  EXPECT_EQ(slurp(file).substr(0, 8), "EIKSPIRV");
  EXPECT_EQ(slurp(file).size(), 32 + fresh.size() * 4);
  EXPECT_EQ(specialiseSpirvCached(viewSpirv(), sharp_, dir_.path()), fresh);
  // No folder: nothing cached, the same words.
  EXPECT_TRUE(spirvCachePath(viewSpirv(), sharp_, "").empty());
  EXPECT_EQ(specialiseSpirvCached(viewSpirv(), sharp_, ""), fresh);
}

// The entry's words are what comes back: an entry holding the smoothed kernel under the sharp
// key (a valid file, checksum and all) is returned as it is.
TEST_F(SpirvCache, AnEntryIsReadBack) {
  const fs::path file = spirvCachePath(viewSpirv(), sharp_, dir_.path());
  specialiseSpirvCached(viewSpirv(), sharp_, dir_.path());
  std::string bytes = slurp(file);
  const std::vector<uint32_t> other = specialiseSpirv(viewSpirv(), smoothed_);
  ASSERT_NE(other, specialiseSpirv(viewSpirv(), sharp_));
  const uint64_t words = other.size();
  const uint64_t checksum = std::hash<std::string_view>{}(
      std::string_view(reinterpret_cast<const char*>(other.data()), other.size() * 4));
  bytes.resize(32);
  std::memcpy(bytes.data() + 16, &words, 8);
  std::memcpy(bytes.data() + 24, &checksum, 8);
  bytes.append(reinterpret_cast<const char*>(other.data()), other.size() * 4);
  put(file, bytes);
  EXPECT_EQ(specialiseSpirvCached(viewSpirv(), sharp_, dir_.path()), other);
}

TEST_F(SpirvCache, DamagedFilesAreIgnoredWithOneNoteAndReplaced) {
  const std::vector<uint32_t> fresh = specialiseSpirv(viewSpirv(), sharp_);
  const fs::path file = spirvCachePath(viewSpirv(), sharp_, dir_.path());
  specialiseSpirvCached(viewSpirv(), sharp_, dir_.path());
  const std::string good = slurp(file);
  std::mt19937 rng(3);
  std::string random(good.size(), '\0');
  for (char& c : random) c = char(rng());
  std::string flipped = good, key_flipped = good, foreign = good, not_spirv = good;
  flipped[good.size() / 2] ^= 0x08;
  key_flipped[9] ^= 0x01;
  std::memcpy(foreign.data(), "EIKVOXEL", 8);
  const std::vector<std::pair<std::string, std::string>> damaged = {
      {"random bytes", random},
      {"empty", ""},
      {"truncated header", good.substr(0, 20)},
      {"truncated", good.substr(0, good.size() - 4)},
      {"a byte too many", good + "x"},
      {"bit flip in the words", flipped},
      {"bit flip in the key", key_flipped},
      {"foreign magic", foreign}};
  for (const auto& [what, content] : damaged) {
    SCOPED_TRACE(what);
    put(file, content);
    ::testing::internal::CaptureStderr();
    EXPECT_EQ(specialiseSpirvCached(viewSpirv(), sharp_, dir_.path()), fresh);
    const std::string err = ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(err.rfind("eikon: note: SPIR-V cache '" + file.string() + "' ignored: ", 0), 0u)
        << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_EQ(slurp(file), good);
  }
  // A valid file whose words are not SPIR-V is not handed on either.
  std::string words(32 + 5 * 4, '\0');
  std::memcpy(words.data(), good.data(), 16);
  const uint64_t n = 5,
                 checksum = std::hash<std::string_view>{}(std::string_view(words).substr(32));
  std::memcpy(words.data() + 16, &n, 8);
  std::memcpy(words.data() + 24, &checksum, 8);
  put(file, words);
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(specialiseSpirvCached(viewSpirv(), sharp_, dir_.path()), fresh);
  EXPECT_NE(::testing::internal::GetCapturedStderr().find("ignored: not SPIR-V"),
            std::string::npos);
}

// An entry was read whole before any check: a sparse 50 GB file took 68 s and 4 GB. Its size
// is taken first, and an entry larger than any eikon writes is ignored unread, at once.
TEST_F(SpirvCache, AnOversizedEntryIsIgnoredByItsSizeUnread) {
  const std::vector<uint32_t> fresh = specialiseSpirv(viewSpirv(), sharp_);
  const fs::path file = spirvCachePath(viewSpirv(), sharp_, dir_.path());
  specialiseSpirvCached(viewSpirv(), sharp_, dir_.path());
  const std::string good = slurp(file);
  const off_t huge = off_t(50) << 30;
  {
    put(file, good.substr(0, 32));  // a valid header, then 50 GB of holes
    const int fd = ::open(file.c_str(), O_WRONLY | O_CLOEXEC);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::ftruncate(fd, huge), 0) << "this file system holds no 50 GB sparse file";
    ::close(fd);
  }
  ASSERT_EQ(fs::file_size(file), uintmax_t(huge));
  std::string why;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(readSpirvCacheEntry(file, 1, why).empty());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("50 GB sparse SPIR-V cache entry refused in %.6f s\n", seconds);
  EXPECT_LT(seconds, 0.5);
  EXPECT_EQ(why, "larger than any entry (53687091200 bytes)");
  // The cache ignores it with its note, specialises afresh and replaces it.
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(specialiseSpirvCached(viewSpirv(), sharp_, dir_.path()), fresh);
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("ignored: larger than any entry (53687091200 bytes)"), std::string::npos)
      << err;
  EXPECT_EQ(slurp(file), good);
}

}  // namespace
}  // namespace eikon::vk
