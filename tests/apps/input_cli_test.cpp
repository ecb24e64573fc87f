// Hostile input through the real `eikon` binary (issue 11): what reaches the terminal is one
// "eikon: error: ..." line of printable text whatever bytes the input held, directories given as
// files say so, and (further down) host memory and the light cache.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/apps/cli_support.h"

namespace {

namespace fs = std::filesystem;
using eikon::test::Outcome;

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

class InputCli : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "eikon_input_cli_XXXXXX").string();
    ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
    fs::create_directories(dir_ / "io");
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
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
      EXPECT_TRUE(c >= 0x20 && c != 0x7f) << "control byte " << int(c) << " at " << i << " in: " << r.err;
    }
    EXPECT_NE(r.err.find(phrase), std::string::npos) << "stderr lacks '" << phrase << "': " << r.err;
  }
  fs::path dir_;
};

TEST_F(InputCli, BinaryFileGivesOnePrintableLine) {
  std::string bytes = "{\"objects\": [\"";
  for (int b = 0; b < 256; ++b) bytes += char(b);
  bytes += std::string(50000, 'x');
  const Outcome r = trace(write("binary.json", bytes));
  expectOneCleanLine(r, "malformed JSON");
  EXPECT_LT(r.err.size(), 600u);
  for (unsigned char c : r.err) EXPECT_LT(c, 0x80) << r.err;  // no valid UTF-8 in there either
}

// The NUL in the key is shown as \x00 and the rest of the message follows it.
TEST_F(InputCli, NulInAKeyDoesNotCutTheMessage) {
  const Outcome r = trace(write("nul.json", R"({"objects": [], "cam\u0000era": {}})"));
  expectOneCleanLine(r, "/cam\\x00era: unknown key (allowed here:");
}

TEST_F(InputCli, DirectoryAsSceneSaysSo) {
  fs::create_directory(dir_ / "scene.json");
  expectOneCleanLine(trace((dir_ / "scene.json").string()), "scene.json: is a directory, expected a scene file");
}

// ------------------------------------------------------------------ host memory

// Under `prlimit --as` (1.5 GB of address space) a 256³ volume (≈ 3.9 GB for the voxeliser) is
// refused with the numbers and the limit, not with std::bad_alloc.
TEST_F(InputCli, HostMemoryIsCheckedBeforeVoxelising) {
  const std::string scene = write("big.json", R"({"volume": {"bounds_min": [-12, -12, -12], "bounds_max": [12, 12, 12],
      "resolution": 256}, "materials": {"glass": {"n": 1.5}},
      "objects": [{"shape": "sphere", "radius": 5, "material": "glass"}]})");
  const Outcome r = trace(scene, "prlimit --as=1500000000");
  expectOneCleanLine(r, "/volume/resolution: voxelising 256x256x256 voxels needs ");
  EXPECT_NE(r.err.find(" GiB of host memory, "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("available (RLIMIT_AS)"), std::string::npos) << r.err;
}

}  // namespace
