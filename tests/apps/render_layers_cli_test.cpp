// `eikon render --layers spectral,modes` through the real binary, read back with OpenImageIO's
// tools (Debian openimageio-tools: iinfo, oiiotool), which know nothing of eikon: the file holds
// R, G, B, one channel per wavelength bin named after Fichet et al. 2021 ("S0.<centre>nm", ','
// for the decimal point; bins of 400/N nm from 380 nm), the unit attribute, the o.* / e.* layers
// and the aov layer's channels. Bad --layers values end the run with one line and no files.
// (iinfo --stats is OpenImageIO's oiiotool --stats.)
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
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

// The statistics line `label` of `iinfo --stats` (one number per channel, in the order of the
// `channel list:` line of `iinfo -v`) by channel name.
std::map<std::string, double> statsByChannel(const std::string& verbose, const std::string& stats,
                                             const std::string& label) {
  std::vector<std::string> names;
  const size_t list = verbose.find("channel list:");
  if (list == std::string::npos) return {};
  std::istringstream line(verbose.substr(list + 13, verbose.find('\n', list) - list - 13));
  for (std::string name; std::getline(line, name, ',');)
    names.push_back(name.substr(name.find_first_not_of(' ')));
  const size_t at = stats.find(label);
  if (at == std::string::npos) return {};
  std::istringstream in(stats.substr(at + label.size()));
  std::map<std::string, double> out;
  for (const std::string& n : names) in >> out[n];
  return in ? out : std::map<std::string, double>{};
}

// `--layers aov`: Z, Px Py Pz, Nx Ny Nz, objectId and steps. Closed forms on kScene's sphere
// (radius 5 at the origin, eye at z = −40, sharp interfaces): the four central pixels' rays are
// the nearest to the axis, all at the same angle, so the least Z is theirs, t = −b − √(b² − 1575)
// along d (b = o·d); the sky around has Z = inf (iinfo counts them), objectId −1 there and 0 on
// the sphere; Nz ≤ 0 (normals face the camera); steps ≤ 2 per pixel (enter, leave: the single
// transmitted path, `--transport single`; full transport adds a step per internal reflection).
TEST(RenderLayersCli, AovChannelsReadBackWithOpenImageIO) {
  Dir d;
  const fs::path out = d.path / "out.exr";
  const Outcome r = eikon::test::runEikon("render " + quote((d.path / "scene.json").string()) +
                                              " -o " + quote(out.string()) +
                                              " --wavelengths 0 --layers aov --transport single -q",
                                          d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  const Outcome info = eikon::test::runProgram("iinfo", "-v " + quote(out.string()), d.path);
  ASSERT_EQ(info.code, 0) << info.err;
  EXPECT_NE(info.out.find("12 channel"), std::string::npos) << info.out;
  const Outcome stats = eikon::test::runProgram("iinfo", "--stats " + quote(out.string()), d.path);
  ASSERT_EQ(stats.code, 0) << stats.err;
  const auto lo = statsByChannel(info.out, stats.out, "Stats Min:");
  const auto hi = statsByChannel(info.out, stats.out, "Stats Max:");
  const auto inf = statsByChannel(info.out, stats.out, "Stats InfCount:");
  for (const char* name : {"Z", "Px", "Py", "Pz", "Nx", "Ny", "Nz", "objectId", "steps"})
    ASSERT_EQ(lo.count(name), 1u) << name << " missing in\n" << info.out << stats.out;
  // Pixel (7, 5) of 16 × 12 at fov 30°: u = −(0.5/16·2)·tan 15°·4/3, v = (1/12)·tan 15°.
  const double t15 = std::tan(15.0 * std::numbers::pi / 180.0);
  const double u = 1.0 / 16.0 * t15 * 4.0 / 3.0, v = 1.0 / 12.0 * t15;
  const double dz = 1.0 / std::sqrt(1.0 + u * u + v * v), b = -40.0 * dz;
  const double t = -b - std::sqrt(b * b - (1600.0 - 25.0));
  EXPECT_NEAR(lo.at("Z"), t, 1e-4);
  EXPECT_GT(inf.at("Z"), 0.0);  // the sky
  EXPECT_EQ(lo.at("objectId"), -1.0);
  EXPECT_EQ(hi.at("objectId"), 0.0);
  EXPECT_LE(hi.at("Nz"), 0.0);
  EXPECT_GE(lo.at("Nz"), -1.0 - 1e-6);
  EXPECT_EQ(lo.at("steps"), 0.0);  // a ray through empty space leaves in its first segment
  EXPECT_EQ(hi.at("steps"), 2.0);
}

TEST(RenderLayersCli, BadLayersAreOneLineAndNoFiles) {
  Dir d;
  const fs::path out = d.path / "out.exr";
  const std::string scene = quote((d.path / "scene.json").string());
  for (const std::string& extra :
       {std::string("--layers spectral,colour --wavelengths 4"),
        std::string("--layers spectral, --wavelengths 4"),
        std::string("--layers spectral --wavelengths 0"), std::string("--layers aov,depth")}) {
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
