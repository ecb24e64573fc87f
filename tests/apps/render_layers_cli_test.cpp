// `eikon render --layers spectral,modes` through the real binary, read back with OpenImageIO's
// tools (Debian openimageio-tools: iinfo, oiiotool), which know nothing of eikon: the file holds
// R, G, B, one channel per wavelength bin named after Fichet et al. 2021 ("S0.<centre>nm", ','
// for the decimal point; bins of 400/N nm from 380 nm), the unit attribute, and the o.* / e.*
// layers. Bad --layers values end the run with one line and no files. (iinfo --stats is
// OpenImageIO's oiiotool --stats.)
#include <gtest/gtest.h>
#include <unistd.h>

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

constexpr const char* kScene = R"({
  "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
             "width": 16, "height": 12},
  "environment": {"type": "constant", "radiance": [0.5, 0.5, 0.5]},
  "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 24},
  "materials": {"glass": {"n": {"sellmeier": [1.03961212, 0.231792344, 1.01046945,
                                               0.00600069867, 0.0200179144, 103.560653]}}},
  "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 5, "material": "glass"}]
})";

/// A temporary folder holding kScene as scene.json.
struct Dir {
  eikon::test::TempDir tmp{"eikon_layers_cli"};
  const fs::path path = tmp.path();
  Dir() { std::ofstream(path / "scene.json") << kScene; }
};

size_t lineCount(const std::string& s) {
  size_t n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

TEST(RenderLayersCli, SpectralAndModeChannelsReadBackWithOpenImageIO) {
  Dir d;
  const fs::path out = d.path / "out.exr";
  const Outcome r =
      eikon::test::runEikon("render " + quote((d.path / "scene.json").string()) + " -o " +
                                quote(out.string()) + " --wavelengths 4 --layers spectral,modes -q",
                            d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  const Outcome info = eikon::test::runProgram("iinfo", "-v " + quote(out.string()), d.path);
  ASSERT_EQ(info.code, 0) << info.err;
  // 3 + 4 + 6 channels; the bins of 100 nm are centred at 430, 530, 630 and 730 nm.
  EXPECT_NE(info.out.find("13 channel"), std::string::npos) << info.out;
  for (const char* name : {"S0.430,000000nm", "S0.530,000000nm", "S0.630,000000nm",
                           "S0.730,000000nm", "o.R", "o.G", "o.B", "e.R", "e.G", "e.B"})
    EXPECT_NE(info.out.find(name), std::string::npos) << name << " missing in\n" << info.out;
  EXPECT_NE(info.out.find("emissiveUnits"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("W.m^-2.sr^-1.nm^-1"), std::string::npos) << info.out;
  // OpenImageIO's statistics, channels in its order R, G, B, the S0 bins, e.*, o.*: nothing is NaN;
  // without a crystal the e-mode carries nothing and the o-mode everything (o = RGB).
  const Outcome stats = eikon::test::runProgram("iinfo", "--stats " + quote(out.string()), d.path);
  ASSERT_EQ(stats.code, 0) << stats.err;
  EXPECT_NE(stats.out.find("NanCount: 0 0 0 0 0 0 0 0 0 0 0 0 0"), std::string::npos) << stats.out;
  const size_t at = stats.out.find("Stats Max:");
  ASSERT_NE(at, std::string::npos) << stats.out;
  std::istringstream in(stats.out.substr(at + 10));
  std::vector<double> max(13);
  for (double& v : max) in >> v;
  ASSERT_TRUE(bool(in)) << stats.out;
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(max[size_t(7 + c)], 0.0) << "e channel " << c;
    EXPECT_NEAR(max[size_t(10 + c)], max[size_t(c)], 1e-5 * max[size_t(c)]) << "o vs RGB " << c;
    EXPECT_GT(max[size_t(c)], 0.4);  // at least the grey sky's 0.5 less rounding
  }
}

TEST(RenderLayersCli, BadLayersAreOneLineAndNoFiles) {
  Dir d;
  const fs::path out = d.path / "out.exr";
  const std::string scene = quote((d.path / "scene.json").string());
  for (const std::string& extra : {std::string("--layers spectral,colour --wavelengths 4"),
                                   std::string("--layers spectral, --wavelengths 4"),
                                   std::string("--layers spectral --wavelengths 0")}) {
    const Outcome r = eikon::test::runEikon(
        "render " + scene + " -o " + quote(out.string()) + " " + extra + " -q", d.path);
    EXPECT_NE(r.code, 0) << extra;
    EXPECT_EQ(lineCount(r.err), 1u) << extra << ": " << r.err;
    EXPECT_NE(r.err.find("layers"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << extra;
    EXPECT_FALSE(fs::exists(d.path / "out.png")) << extra;
  }
}

}  // namespace
