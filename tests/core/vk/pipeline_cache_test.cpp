// The persistent pipeline cache (core/vk/pipeline_cache.h): a context saves
// the driver's cache after building pipelines and the next context loads it; a corrupt, truncated,
// foreign or oversized file is ignored with one note and replaced, never handed to the driver,
// never a crash. Whether the cache makes the build faster is measured in docs/performance.md, not
// here (tests are not timed).
#include "core/vk/pipeline_cache.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "core/vk/context.h"
#include "core/vk/resources.h"
#include "shaders/eikon_shared.h"
#include "shaders/scan.spv.h"
#include "tests/core/file_support.h"

namespace eikon::vk {
namespace {

using eikon::test::put;
using eikon::test::slurp;

namespace fs = std::filesystem;

class PipelineCache : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "eikon_pipeline_cache_XXXXXX").string();
    ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
    file_ = dir_ / "sub" / "pipelines.bin";  // a missing folder is created by the save
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::unique_ptr<Context> context() const {
    ContextOptions o;
    o.pipeline_cache = file_;
    o.echo_messages = false;
    return Context::create(o);
  }
  /// Build the scan kernel (the smallest of eikon's pipelines) through the context's cache.
  static void buildPipeline(Context& ctx) {
    ComputePipeline p(ctx, std::span<const uint32_t>(k_scan_spv, sizeof(k_scan_spv) / 4),
                      {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}, sizeof(gpu::ScanPush), "scan");
  }
  /// A valid file made by this device, from a context that built the pipeline.
  std::string validFile() const {
    auto ctx = context();
    buildPipeline(*ctx);
    EXPECT_EQ(ctx->savePipelineCache(), "");
    return slurp(file_);
  }
  /// The context made over the file now in place ignored it with exactly one note naming `why`,
  /// builds pipelines anyway, and writes a valid file over it.
  void expectIgnored(const std::string& why) const {
    auto ctx = context();
    EXPECT_EQ(ctx->pipelineCacheLoadedBytes(), 0u);
    const auto notes = ctx->pipelineCacheNotes();
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_NE(notes[0].find("ignored"), std::string::npos) << notes[0];
    EXPECT_NE(notes[0].find(why), std::string::npos) << notes[0];
    EXPECT_EQ(notes[0].find('\n'), std::string::npos) << notes[0];
    buildPipeline(*ctx);
    EXPECT_EQ(ctx->savePipelineCache(), "");
    std::string w;
    EXPECT_TRUE(unpackPipelineCache(slurp(file_), ctx->properties(), &w)) << w;
  }
  fs::path dir_, file_;
};

// Saved after a build: the file holds the driver's data (at least the spec's 32-byte header,
// naming this device), and a second context hands exactly that data back to the driver.
TEST_F(PipelineCache, SavedAfterABuildAndLoadedByTheNextContext) {
  size_t saved = 0;
  {
    auto ctx = context();
    EXPECT_EQ(ctx->pipelineCacheLoadedBytes(), 0u);  // no file yet, and no note for that
    EXPECT_TRUE(ctx->pipelineCacheNotes().empty());
    buildPipeline(*ctx);
    EXPECT_EQ(ctx->savePipelineCache(), "");
    ASSERT_TRUE(fs::is_regular_file(file_));
    size_t size = 0;
    ASSERT_EQ(vkGetPipelineCacheData(ctx->device(), ctx->pipelineCache(), &size, nullptr),
              VK_SUCCESS);
    EXPECT_GE(size, 32u);
    std::string why;
    const auto payload = unpackPipelineCache(slurp(file_), ctx->properties(), &why);
    ASSERT_TRUE(payload) << why;
    EXPECT_EQ(payload->size(), size);
    EXPECT_EQ(checkPipelineCacheHeader(*payload, ctx->properties()), "");
    saved = payload->size();
  }
  auto again = context();
  EXPECT_EQ(again->pipelineCacheLoadedBytes(), saved);
  EXPECT_TRUE(again->pipelineCacheNotes().empty());
  // The same pipeline again: what the driver then holds is what it was given (nothing new to
  // compile), and the file is left as it was.
  const auto before = fs::last_write_time(file_);
  const std::string bytes = slurp(file_);
  buildPipeline(*again);
  size_t size = 0;
  ASSERT_EQ(vkGetPipelineCacheData(again->device(), again->pipelineCache(), &size, nullptr),
            VK_SUCCESS);
  EXPECT_EQ(size, saved);
  EXPECT_EQ(again->savePipelineCache(), "");
  EXPECT_EQ(slurp(file_), bytes);
  EXPECT_EQ(fs::last_write_time(file_), before);
}

// The destructor saves what was built when nobody called savePipelineCache().
TEST_F(PipelineCache, SavedOnDestructionToo) {
  {
    auto ctx = context();
    buildPipeline(*ctx);
  }
  ASSERT_TRUE(fs::is_regular_file(file_));
  EXPECT_GT(context()->pipelineCacheLoadedBytes(), 0u);
}

TEST_F(PipelineCache, RandomBytesAreIgnored) {
  validFile();
  put(file_, std::string(4096, '\x5a'));
  expectIgnored("not an eikon pipeline cache");
}

TEST_F(PipelineCache, TruncatedFileIsIgnored) {
  const std::string good = validFile();
  ASSERT_GT(good.size(), kPipelineCacheFileHeader + 16);
  put(file_, good.substr(0, kPipelineCacheFileHeader + 16));
  expectIgnored("truncated");
  put(file_, good.substr(0, 10));  // not even the eikon header
  expectIgnored("not an eikon pipeline cache");
}

// A flipped byte in the driver's data: the checksum catches it before the driver sees it.
TEST_F(PipelineCache, CorruptedPayloadIsIgnored) {
  std::string bad = validFile();
  bad[bad.size() - 1] = char(bad.back() ^ 0x40);
  put(file_, bad);
  expectIgnored("checksum mismatch");
}

// Whole and well-formed, but made by another device or driver build (the spec's header check:
// vendorID, deviceID, pipelineCacheUUID), or with a header the spec does not allow.
TEST_F(PipelineCache, ForeignOrMalformedDriverHeaderIsIgnored) {
  const std::string good = validFile();
  std::string why;
  auto ctx = context();
  const auto payload = unpackPipelineCache(good, ctx->properties(), &why);
  ASSERT_TRUE(payload) << why;
  ctx.reset();
  struct Case {
    size_t offset;
    const char* why;
  };
  for (const Case& c : {Case{8, "another device"}, Case{12, "another device"},
                        Case{16 + 5, "another device"}, Case{4, "version"}, Case{0, "size"}}) {
    std::string foreign = *payload;
    foreign[c.offset] = char(foreign[c.offset] ^ 0x11);
    put(file_, packPipelineCache(foreign));
    SCOPED_TRACE(c.offset);
    expectIgnored(c.why);
  }
}

// A file beyond the cap is not read at all.
TEST_F(PipelineCache, OversizedFileIsIgnored) {
  fs::create_directories(file_.parent_path());
  {
    std::ofstream out(file_, std::ios::binary);
    out.seekp(std::streamoff(kMaxPipelineCacheBytes + kPipelineCacheFileHeader + 1));
    out.put('\0');
  }
  expectIgnored("larger than");
}

// An empty path: an in-memory cache, nothing read or written.
TEST_F(PipelineCache, NoFileMeansNoSave) {
  ContextOptions o;
  o.pipeline_cache = fs::path();
  o.echo_messages = false;
  auto ctx = Context::create(o);
  EXPECT_NE(ctx->pipelineCache(), VK_NULL_HANDLE);
  buildPipeline(*ctx);
  EXPECT_EQ(ctx->savePipelineCache(), "");
  EXPECT_TRUE(fs::is_empty(dir_));
}

// A folder that cannot be written: the save says why (one note), nothing is thrown.
TEST_F(PipelineCache, UnwritableFolderIsANoteNotAFailure) {
  put(dir_ / "sub", "a file where the folder should be");
  auto ctx = context();
  buildPipeline(*ctx);
  const std::string err = ctx->savePipelineCache();
  EXPECT_NE(err, "");
  ASSERT_EQ(ctx->pipelineCacheNotes().size(), 1u);
  EXPECT_NE(ctx->pipelineCacheNotes()[0].find("not saved"), std::string::npos);
}

// The default file lives in the cache folder, one per device.
TEST(PipelineCacheFile, FollowsTheCacheFolder) {
  VkPhysicalDeviceProperties props{};
  props.vendorID = 0x10005;
  props.deviceID = 0xab;
  const char* old = std::getenv("EIKON_CACHE_DIR");
  const std::string saved = old ? old : "";
  ::setenv("EIKON_CACHE_DIR", "/some/where", 1);
  EXPECT_EQ(defaultPipelineCacheFile(props), fs::path("/some/where/pipelines-10005-00ab.bin"));
  if (old)
    ::setenv("EIKON_CACHE_DIR", saved.c_str(), 1);
  else
    ::unsetenv("EIKON_CACHE_DIR");
}

}  // namespace
}  // namespace eikon::vk
