// Start-up of `eikon render`: the --timings lines that show where
// the time before the first dispatch goes. Only what the lines say and their order are tested,
// never how long a stage took (timings vary ±30% on shared machines).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/apps/cli_support.h"

namespace {

namespace fs = std::filesystem;
using eikon::test::Outcome;
using eikon::test::quote;

// A glass sphere in a 24³ volume and a 16x12 camera: a GPU render that starts in seconds.
constexpr const char* kScene = R"({
  "camera": {"position": [0, 0, -30], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 20, "width": 16, "height": 12},
  "environment": {"type": "checker", "squares": 8},
  "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": 24},
  "materials": {"glass": {"n": 1.5}},
  "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 3, "material": "glass"}]
})";

struct Mark {
  double seconds = 0.0, delta = 0.0;
  std::string stage;
};

/// The "eikon: timing: T s  +D s  STAGE" lines of `err`, in order.
std::vector<Mark> timingLines(const std::string& err) {
  std::vector<Mark> marks;
  std::istringstream in(err);
  std::string line;
  const std::string prefix = "eikon: timing: ";
  while (std::getline(in, line)) {
    if (line.rfind(prefix, 0) != 0) continue;
    std::istringstream f(line.substr(prefix.size()));
    Mark m;
    std::string s_unit, d_unit;
    char plus = 0;
    f >> m.seconds >> s_unit >> plus >> m.delta >> d_unit;
    std::getline(f >> std::ws, m.stage);
    EXPECT_FALSE(m.stage.empty()) << line;
    EXPECT_EQ(s_unit, "s") << line;
    EXPECT_EQ(plus, '+') << line;
    EXPECT_EQ(d_unit, "s") << line;
    marks.push_back(m);
  }
  return marks;
}

class StartupCli : public ::testing::Test {
 protected:
  void SetUp() override { std::ofstream(dir_ / "scene.json") << kScene; }
  /// `eikon render` of the scene, with validation and the caches in the test's own folder.
  Outcome render(const std::string& extra, const std::string& env = "") const {
    const std::string e = "EIKON_VALIDATION=1 EIKON_CACHE_DIR=" + quote((dir_ / "cache").string()) +
                          (env.empty() ? "" : " " + env);
    const Outcome o =
        eikon::test::runEikon("render " + quote((dir_ / "scene.json").string()) + " -o " +
                                  quote((dir_ / "out.exr").string()) + " " + extra,
                              dir_ / "io", e);
    EXPECT_EQ(o.err.find("[vulkan validation]"), std::string::npos) << o.err;
    return o;
  }
  eikon::test::TempDir tmp_{"eikon_startup_cli"};
  const fs::path dir_ = tmp_.path();
};

// Every stage up to the written output, once each, in the order they run, with the seconds since
// the process started non-decreasing and each "+delta" the difference to the line before.
TEST_F(StartupCli, TimingsListEveryStageInOrder) {
  const Outcome r = render("--timings");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<Mark> marks = timingLines(r.err);
  const std::vector<std::string> expected = {"command line",   "scene parsed",    "device created",
                                             "voxelised",      "volume uploaded", "pipelines built",
                                             "first dispatch", "rendered",        "written"};
  std::vector<std::string> stages;
  for (const Mark& m : marks) stages.push_back(m.stage);
  EXPECT_EQ(stages, expected) << r.err;
  for (size_t i = 0; i < marks.size(); ++i) {
    EXPECT_GE(marks[i].seconds, 0.0) << marks[i].stage;
    // The process has run for at least as long as the stages it reports.
    EXPECT_LT(marks[i].seconds, 600.0) << marks[i].stage;
    if (i == 0) continue;
    EXPECT_GE(marks[i].seconds, marks[i - 1].seconds) << marks[i].stage;
    // Printed to the millisecond: the delta is the difference of the rounded times ± 1 ms.
    EXPECT_NEAR(marks[i].delta, marks[i].seconds - marks[i - 1].seconds, 1.5e-3) << marks[i].stage;
  }
  // The render's own summary still goes to stdout, untouched.
  EXPECT_NE(r.out.find("eikon: rendered"), std::string::npos) << r.out;
}

// The view pipeline compiled during the upload (ViewRenderer's `expected` settings) is the one the
// render uses: with settings other than the defaults (spectral, Euler, no Fresnel, no skipping:
// other specialisation constants) exactly one pipeline is built, after the upload and before the
// first dispatch. A second one would mean the render compiled its own beside the prefetched one.
TEST_F(StartupCli, TheRendersPipelineIsBuiltOnceWithNonDefaultSettings) {
  const Outcome r =
      render("--timings -q --wavelengths 4 --integrator euler --no-fresnel --no-skip --spp 2");
  ASSERT_EQ(r.code, 0) << r.err;
  std::vector<std::string> stages;
  for (const Mark& m : timingLines(r.err)) stages.push_back(m.stage);
  EXPECT_EQ(std::count(stages.begin(), stages.end(), "pipelines built"), 1) << r.err;
  const auto at = [&](const char* stage) {
    return std::find(stages.begin(), stages.end(), stage) - stages.begin();
  };
  EXPECT_LT(at("volume uploaded"), at("pipelines built")) << r.err;
  EXPECT_LT(at("pipelines built"), at("first dispatch")) << r.err;
  EXPECT_LT(at("first dispatch"), std::ptrdiff_t(stages.size())) << r.err;
}

// EIKON_TIMINGS=1 does what --timings does (for the Python module and the benchmarks); neither
// given, stderr stays empty.
TEST_F(StartupCli, TimingsFromTheEnvironmentAndOffByDefault) {
  const Outcome env = render("-q", "EIKON_TIMINGS=1");
  ASSERT_EQ(env.code, 0) << env.err;
  EXPECT_EQ(timingLines(env.err).size(), 9u) << env.err;
  const Outcome off = render("-q");
  ASSERT_EQ(off.code, 0) << off.err;
  EXPECT_EQ(off.err, "");
}

// The CPU twin has no device and no pipelines: only its own stages are listed.
TEST_F(StartupCli, TimingsOfTheCpuTwin) {
  const Outcome r = render("--reference --timings");
  ASSERT_EQ(r.code, 0) << r.err;
  std::vector<std::string> stages;
  for (const Mark& m : timingLines(r.err)) stages.push_back(m.stage);
  const std::vector<std::string> expected = {"command line", "scene parsed", "voxelised",
                                             "rendered", "written"};
  EXPECT_EQ(stages, expected) << r.err;
}

// The pipeline cache (core/vk/pipeline_cache.h) is written to EIKON_CACHE_DIR by a GPU render; a
// corrupt one there is ignored with one "eikon: note:" line, the render succeeds and replaces it.
TEST_F(StartupCli, PipelineCacheIsWrittenAndACorruptOneIgnored) {
  const Outcome first = render("-q");
  ASSERT_EQ(first.code, 0) << first.err;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir_ / "cache"))
    if (e.path().filename().string().rfind("pipelines-", 0) == 0) files.push_back(e.path());
  ASSERT_EQ(files.size(), 1u);
  const std::string good = eikon::test::slurp(files[0]);
  EXPECT_EQ(good.substr(0, 8), "EIKPIPE1");
  EXPECT_GE(good.size(), 24u + 32u);  // our header and at least the driver's (Vulkan spec)
  std::ofstream(files[0], std::ios::binary | std::ios::trunc) << good.substr(0, good.size() / 2);
  const Outcome second = render("-q");
  ASSERT_EQ(second.code, 0) << second.err;
  EXPECT_EQ(second.err.rfind("eikon: note: pipeline cache '", 0), 0u) << second.err;
  EXPECT_NE(second.err.find("ignored: truncated"), std::string::npos) << second.err;
  EXPECT_EQ(std::count(second.err.begin(), second.err.end(), '\n'), 1) << second.err;
  // Replaced by a whole one (the driver's data may differ from run to run on some drivers).
  const std::string replaced = eikon::test::slurp(files[0]);
  EXPECT_EQ(replaced.substr(0, 8), "EIKPIPE1");
  EXPECT_GE(replaced.size(), 24u + 32u);
  const Outcome third = render("-q");
  ASSERT_EQ(third.code, 0) << third.err;
  EXPECT_EQ(third.err, "");
}

/// The volume cache's entries (core/volume/volume_cache.h) in the test's cache folder.
std::vector<fs::path> volumeEntries(const fs::path& cache) {
  std::vector<fs::path> files;
  if (!fs::exists(cache)) return files;
  for (const auto& e : fs::directory_iterator(cache))
    if (e.path().filename().string().rfind("volume-", 0) == 0) files.push_back(e.path());
  return files;
}

/// The scene with smoothed interfaces: its render reads the voxelised fields (a sharp one without
/// light volumes voxelises only its interfaces and uses no volume cache).
void writeSmoothedScene(const fs::path& file) {
  std::string text = kScene;
  text.insert(text.rfind('}'), R"(, "interfaces": "smoothed")");
  std::ofstream(file) << text;
}

// A GPU render of sharp interfaces without light volumes voxelises only the interfaces
// (Session::prepareGpuRender): no volume-cache entry is read or written.
TEST_F(StartupCli, SharpRenderWithoutLightKeepsNoVolume) {
  const Outcome r = render("-q");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_TRUE(volumeEntries(dir_ / "cache").empty());
}

// A GPU render stores its voxelised volume in EIKON_CACHE_DIR; the next render of the scene reads
// it back and writes the same EXR, byte for byte, as the first and as a render that voxelises
// (--no-volume-cache, which neither reads nor writes an entry).
TEST_F(StartupCli, VolumeCacheGivesTheSameRender) {
  writeSmoothedScene(dir_ / "scene.json");
  const Outcome plain = render("-q --no-volume-cache");
  ASSERT_EQ(plain.code, 0) << plain.err;
  EXPECT_TRUE(volumeEntries(dir_ / "cache").empty());
  const std::string voxelised = eikon::test::slurp(dir_ / "out.exr");
  const Outcome first = render("-q");
  ASSERT_EQ(first.code, 0) << first.err;
  EXPECT_EQ(first.err, "");
  ASSERT_EQ(volumeEntries(dir_ / "cache").size(), 1u);
  EXPECT_EQ(eikon::test::slurp(volumeEntries(dir_ / "cache")[0]).substr(0, 8), "EIKVOXEL");
  EXPECT_EQ(eikon::test::slurp(dir_ / "out.exr"), voxelised);
  const Outcome second = render("-q");
  ASSERT_EQ(second.code, 0) << second.err;
  EXPECT_EQ(second.err, "");
  EXPECT_EQ(volumeEntries(dir_ / "cache").size(), 1u);
  EXPECT_EQ(eikon::test::slurp(dir_ / "out.exr"), voxelised);
}

// A damaged entry is ignored with one "eikon: note:" line, the scene voxelised again (the same
// render), and the entry replaced: the next render is silent.
TEST_F(StartupCli, ACorruptVolumeCacheIsIgnoredWithOneNote) {
  writeSmoothedScene(dir_ / "scene.json");
  ASSERT_EQ(render("-q").code, 0);
  const std::string good_render = eikon::test::slurp(dir_ / "out.exr");
  const std::vector<fs::path> files = volumeEntries(dir_ / "cache");
  ASSERT_EQ(files.size(), 1u);
  const std::string good = eikon::test::slurp(files[0]);
  std::string flipped = good;
  flipped[flipped.size() / 2] ^= 0x20;
  for (const std::string& bad : {good.substr(0, good.size() / 3), flipped}) {
    std::ofstream(files[0], std::ios::binary | std::ios::trunc) << bad;
    const Outcome r = render("-q");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err.rfind("eikon: note: volume cache '", 0), 0u) << r.err;
    // A flipped byte is found by the checksum in an array's data, by the records' check in an
    // array's record (a small volume's entry is mostly records: its constant arrays are stored
    // as one zero flag).
    if (bad.size() < good.size())
      EXPECT_NE(r.err.find("ignored: truncated"), std::string::npos) << r.err;
    else
      EXPECT_TRUE(r.err.find("ignored: checksum mismatch") != std::string::npos ||
                  r.err.find("ignored: its arrays do not match its header") != std::string::npos)
          << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(eikon::test::slurp(dir_ / "out.exr"), good_render);
    EXPECT_EQ(eikon::test::slurp(files[0]), good);  // replaced by a whole entry
  }
  const Outcome after = render("-q");
  ASSERT_EQ(after.code, 0) << after.err;
  EXPECT_EQ(after.err, "");
}

}  // namespace
