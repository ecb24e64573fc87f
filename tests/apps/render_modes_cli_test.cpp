// `eikon render --modes o|e|both` through the real binary: a bad value is one line and no files;
// `--modes e --layers modes` of a crystal writes the e-mode alone at the whole of the light (the
// o.* layer empty, the e.* layer the RGB), read back with OpenImageIO's iinfo as
// render_layers_cli_test.cpp does. The CPU twin (--reference) keeps the test free of compiles.
#include <gtest/gtest.h>

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

// A calcite block, optic axis at 45° in the x-z plane, in front of a checkerboard.
constexpr const char* kCrystal = R"({
  "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 14,
             "width": 16, "height": 12},
  "environment": {"type": "checker", "squares": 48},
  "volume": {"bounds_min": [-4, -3, -8], "bounds_max": [4, 3, 8], "resolution": 24},
  "objects": [{"shape": "box", "center": [0, 0, 0], "size": [7, 5, 10], "material": "calcite",
               "optic_axis": [1, 0, 1]}]
})";

struct Dir {
  eikon::test::TempDir tmp{"eikon_modes_cli"};
  const fs::path path = tmp.path();
  Dir() { std::ofstream(path / "scene.json") << kCrystal; }
};

TEST(RenderModesCli, BadModesValueIsOneLineAndNoFiles) {
  Dir d;
  const fs::path out = d.path / "out.exr";
  const Outcome r = eikon::test::runEikon("render " + quote((d.path / "scene.json").string()) +
                                              " -o " + quote(out.string()) + " --modes oe -q",
                                          d.path);
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(r.err.find("eikon: error: "), 0u) << r.err;
  EXPECT_NE(r.err.find("--modes"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'oe'"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(d.path / "out.png"));
}

TEST(RenderModesCli, EModeAloneCarriesTheWholeImage) {
  Dir d;
  const fs::path out = d.path / "e.exr";
  const Outcome r =
      eikon::test::runEikon("render " + quote((d.path / "scene.json").string()) + " -o " +
                                quote(out.string()) + " --modes e --layers modes --reference -q",
                            d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  const Outcome stats = eikon::test::runProgram("iinfo", "--stats " + quote(out.string()), d.path);
  ASSERT_EQ(stats.code, 0) << stats.err;
  // Channels in OpenImageIO's order: R, G, B, e.R..B, o.R..B.
  const size_t at = stats.out.find("Stats Max:");
  ASSERT_NE(at, std::string::npos) << stats.out;
  std::istringstream in(stats.out.substr(at + 10));
  std::vector<double> max(9);
  for (double& v : max) in >> v;
  ASSERT_TRUE(bool(in)) << stats.out;
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(max[size_t(6 + c)], 0.0) << "o channel " << c;
    EXPECT_NEAR(max[size_t(3 + c)], max[size_t(c)], 1e-6 * max[size_t(c)]) << "e vs RGB " << c;
    EXPECT_GT(max[size_t(c)], 0.5);  // the checkerboard's light squares through the block
  }
}

}  // namespace
