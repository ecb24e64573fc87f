// Hostile input through the real `eikon` binary: what reaches the terminal is one
// "eikon: error: ..." line of printable text whatever bytes the input held, directories given as
// files say so, and (further down) host memory and the light cache.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/io/exr.h"
#include "tests/apps/cli_support.h"
#include "tests/sanitizers.h"

namespace {

namespace fs = std::filesystem;
using eikon::test::Outcome;

using eikon::test::quote;

class InputCli : public ::testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    return (dir_ / name).string();
  }
  Outcome run(const std::string& args, const std::string& env = "") const {
    return eikon::test::runEikon(args, dir_ / "io", env);
  }
  /// `eikon trace --reference SCENE` along +z through the centre.
  Outcome trace(const std::string& scene, const std::string& env = "") const {
    return run("trace --reference " + quote(scene) + " --origin 0,0,-20 --dir 0,0,1", env);
  }
  /// One line "eikon: error: ..." of printable ASCII/UTF-8 (no control bytes, no NUL), exit ≠ 0.
  static void expectOneCleanLine(const Outcome& r, const std::string& phrase) {
    EXPECT_NE(r.code, 0);
    EXPECT_EQ(r.err.rfind("eikon: error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.back(), '\n');
    for (size_t i = 0; i + 1 < r.err.size(); ++i) {
      const unsigned char c = static_cast<unsigned char>(r.err[i]);
      EXPECT_TRUE(c >= 0x20 && c != 0x7f)
          << "control byte " << int(c) << " at " << i << " in: " << r.err;
    }
    EXPECT_NE(r.err.find(phrase), std::string::npos)
        << "stderr lacks '" << phrase << "': " << r.err;
  }
  eikon::test::TempDir tmp_{"eikon_input_cli"};
  const fs::path dir_ = tmp_.path();
};

TEST_F(InputCli, BinaryFileGivesOnePrintableLine) {
  std::string bytes = "{\"objects\": [\"";
  for (int b = 1; b < 256; ++b) bytes += char(b);
  bytes += std::string(50000, 'x');
  const Outcome r = trace(write("binary.json", bytes));
  expectOneCleanLine(r, "malformed JSON");
  EXPECT_LT(r.err.size(), 600u);
  for (unsigned char c : r.err) EXPECT_LT(c, 0x80) << r.err;  // no valid UTF-8 in there either
  // With a NUL among them the file is refused as text holding one, before it is parsed.
  bytes.insert(14, 1, '\0');
  expectOneCleanLine(trace(write("binary.json", bytes)),
                     "binary.json: holds a NUL byte at offset 14 (line 1)");
}

// The NUL in the key is shown as \x00 and the rest of the message follows it.
TEST_F(InputCli, NulInAKeyDoesNotCutTheMessage) {
  const Outcome r = trace(write("nul.json", R"({"objects": [], "cam\u0000era": {}})"));
  expectOneCleanLine(r, "/cam\\x00era: unknown key (allowed here:");
}

TEST_F(InputCli, DirectoryAsSceneSaysSo) {
  fs::create_directory(dir_ / "scene.json");
  expectOneCleanLine(trace((dir_ / "scene.json").string()),
                     "scene.json: is a directory, expected a scene file");
}

// `eikon render /dev/zero` read without end, its memory growing ~300 MB/s; a link to it, and a
// library material linked to it, the same. Nothing is rendered and nothing written.
TEST_F(InputCli, DevZeroIsRefusedAsNotARegularFile) {
  const std::string out = " -o " + quote((dir_ / "out" / "o.exr").string()) + " -q";
  expectOneCleanLine(
      run("render /dev/zero" + out),
      "/dev/zero: is not a regular file (a character device), expected a scene file");
  fs::create_symlink("/dev/zero", dir_ / "z.json");
  expectOneCleanLine(run("render " + quote((dir_ / "z.json").string()) + out),
                     "z.json: is not a regular file (a character device)");
  fs::create_directory(dir_ / "lib");
  fs::create_symlink("/dev/zero", dir_ / "lib" / "zz.json");
  const std::string scene = write("mat.json", R"({"objects": [{"shape": "sphere", "radius": 3,
      "material": "zz"}]})");
  expectOneCleanLine(
      run("render " + quote(scene) + out, "EIKON_MATERIALS_PATH=" + quote((dir_ / "lib").string())),
      "zz.json: is not a regular file (a character device), expected a material file");
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

// A scene followed by "\0garbage" rendered, everything after the NUL ignored.
TEST_F(InputCli, NulAfterTheSceneIsRefused) {
  const std::string scene = R"({"materials": {"g": {"n": 1.5}},
      "objects": [{"shape": "sphere", "radius": 3, "material": "g"}]})";
  const std::string file = write("nul.json", scene + std::string("\0garbage {{{ \xff", 14));
  const Outcome r =
      run("render " + quote(file) + " -o " + quote((dir_ / "o.exr").string()) + " -q");
  expectOneCleanLine(r, "nul.json: holds a NUL byte at offset " + std::to_string(scene.size()) +
                            " (line 2), expected a scene file (text)");
  EXPECT_FALSE(fs::exists(dir_ / "o.exr"));
}

// A sphere of 7e8 mm about the volume filled it silently (the traced optical path changed, no
// message): trace now prints the scene's warning, once, and still traces.
TEST_F(InputCli, TraceWarnsAboutAnObjectCoveringTheVolume) {
  const Outcome r = trace(write("huge.json", R"({"materials": {"g": {"n": 1.5}},
      "objects": [{"shape": "sphere", "radius": 7e8, "material": "g"}]})"));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("eikon: warning: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("huge.json: /objects/0: the object covers the whole volume"),
            std::string::npos)
      << r.err;
  // --strict makes it an error, as for render: one line, non-zero exit, nothing on stdout.
  const Outcome strict = run("trace --reference " + quote((dir_ / "huge.json").string()) +
                             " --origin 0,0,-5 --dir 0,0,1 --strict");
  EXPECT_NE(strict.code, 0);
  EXPECT_EQ(strict.out, "");
  EXPECT_EQ(std::count(strict.err.begin(), strict.err.end(), '\n'), 1) << strict.err;
  EXPECT_NE(strict.err.find("covers the whole volume"), std::string::npos) << strict.err;
  EXPECT_NE(strict.err.find("(--strict)"), std::string::npos) << strict.err;
}

// ------------------------------------------------------------------ host memory

// Under `prlimit --as` (1.5 GB of address space) a 256³ volume (≈ 3.9 GB for the voxeliser) is
// refused with the numbers and the limit, not with std::bad_alloc.
TEST_F(InputCli, HostMemoryIsCheckedBeforeVoxelising) {
  if (eikon::test::kAddressSanitizer) GTEST_SKIP() << eikon::test::kNoAddressSpaceLimitUnderAsan;
  const std::string scene =
      write("big.json", R"({"volume": {"bounds_min": [-12, -12, -12], "bounds_max": [12, 12, 12],
      "resolution": 256}, "materials": {"glass": {"n": 1.5}},
      "objects": [{"shape": "sphere", "radius": 5, "material": "glass"}]})");
  const Outcome r = trace(scene, "prlimit --as=1500000000");
  expectOneCleanLine(r, "/volume/resolution: voxelising 256x256x256 voxels needs ");
  EXPECT_NE(r.err.find(" GiB of host memory, "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("available (RLIMIT_AS)"), std::string::npos) << r.err;
}

// ------------------------------------------------------------------ light cache

// A cached light file whose payload is overwritten at the same size (NaN, huge values and random
// bytes) fails its checksum: the light is simulated again with a one-line warning, and the
// picture is the first one exactly (the simulation is deterministic), so finite. The rewritten
// entry is then used.
TEST_F(InputCli, CorruptedLightCacheIsSimulatedAgain) {
  const std::string scene = write("lit.json", R"({
  "camera": {"position": [0, 20, -20], "look_at": [0, -2, 0], "up": [0, 1, 0], "fov_deg": 30, "width": 24, "height": 16},
  "environment": {"type": "constant", "radiance": 0.1},
  "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": 24},
  "materials": {"glass": {"n": 1.5}, "floor": {"n": 1, "opacity": 1, "albedo": 0.8}},
  "objects": [{"shape": "box", "center": [0, -3.5, 0], "size": [8, 1, 8], "material": "floor"},
              {"shape": "sphere", "center": [0, 0.5, 0], "radius": 2.5, "material": "glass"}],
  "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 2}]
})");
  const fs::path cache = dir_ / "cache", exr = dir_ / "out.exr";
  const std::string args = "render --reference -q --caustics kill --light-cache " +
                           quote(cache.string()) + " " + quote(scene) + " -o " +
                           quote(exr.string());
  const Outcome first = run(args);
  ASSERT_EQ(first.code, 0) << first.err;
  ASSERT_NE(first.out.find("simulated 1 light runs"), std::string::npos) << first.out;
  const std::vector<float> a = eikon::readExrRgba(exr, 64, 64).rgba;
  // The light cache's entry: the folder's largest file (beside it may lie the folder's lock).
  fs::path entry;
  for (const auto& e : fs::directory_iterator(cache))
    if (e.is_regular_file() && (entry.empty() || e.file_size() > fs::file_size(entry)))
      entry = e.path();
  ASSERT_FALSE(entry.empty());
  const auto size = fs::file_size(entry);
  ASSERT_GT(size, 1024u);
  {
    std::fstream f(entry, std::ios::in | std::ios::out | std::ios::binary);
    const float bad[4] = {std::nanf(""), 3e38f, -1e30f, 1e-40f};
    f.seekp(std::streamoff(size / 2));
    for (int k = 0; k < 64; ++k) f.write(reinterpret_cast<const char*>(bad), sizeof bad);
    f.seekp(std::streamoff(size - 100));
    for (int k = 0; k < 50; ++k) f.put(char(37 * k + 11));
  }
  ASSERT_EQ(fs::file_size(entry), size);
  const Outcome second = run(args);
  ASSERT_EQ(second.code, 0) << second.err;
  EXPECT_EQ(std::count(second.err.begin(), second.err.end(), '\n'), 1) << second.err;
  EXPECT_NE(second.err.find("eikon: warning: light cache: "), std::string::npos) << second.err;
  EXPECT_NE(second.err.find("is corrupted (checksum mismatch); simulating the light again"),
            std::string::npos)
      << second.err;
  EXPECT_NE(second.out.find("simulated 1 light runs"), std::string::npos) << second.out;
  EXPECT_EQ(second.out.find("from the cache"), std::string::npos) << second.out;
  const std::vector<float> b = eikon::readExrRgba(exr, 64, 64).rgba;
  for (float v : b) ASSERT_TRUE(std::isfinite(v));
  EXPECT_EQ(a, b);
  const Outcome third = run(args);
  ASSERT_EQ(third.code, 0) << third.err;
  EXPECT_TRUE(third.err.empty()) << third.err;
  EXPECT_NE(third.out.find("from the cache"), std::string::npos) << third.out;
  EXPECT_EQ(eikon::readExrRgba(exr, 64, 64).rgba, a);
}

}  // namespace
