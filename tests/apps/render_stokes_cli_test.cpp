// `eikon render --layers stokes` (a polarised render, docs/polarisation.md "Polarised renders")
// through the real binary, read back with OpenImageIO's iinfo: R, G, B and the Stokes channels
// S0.R … S3.B (Mitsuba 3's names) with the frame in the string attribute stokesFrame. The scene:
// a polariser sheet along x in front of a constant grey sky of 0.5, so every pixel holds S0 = ¼,
// S1 = ¼ (x̂ of stokesBasis(−v) is +x for a camera looking along +z), S2 = S3 = 0. Stokes layers
// with spectral or mode layers, smoothed interfaces and a polarised environment end the run with
// one line (naming the JSON path) and no files. A render of scenes/polariscope_quartz_wedge.json's
// wedge whose middle column and row of pixels look along the planes of its side faces has no NaN
// in any channel on either twin (those rays were NaN: the interface solve divided by their zero
// normal flux).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "tests/apps/cli_support.h"

namespace {

namespace fs = std::filesystem;
using eikon::test::Outcome;
using eikon::test::quote;

constexpr const char* kScene = R"({
  "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 0.5,
             "width": 8, "height": 6},
  "environment": {"type": "constant", "radiance": [0.5, 0.5, 0.5]},
  "interfaces": "sharp",
  "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 24},
  "materials": {"glass": {"n": 1.5}},
  "objects": [{"shape": "sphere", "center": [4, 4, 4], "radius": 1, "material": "glass"},
              {"shape": "polarizer", "center": [0, 0, 20], "normal": [0, 0, 1],
               "transmission_axis": [1, 0, 0], "size": [40, 40]}]
})";

struct Dir {
  eikon::test::TempDir tmp{"eikon_stokes_cli"};
  const fs::path path = tmp.path();
  Dir() { std::ofstream(path / "scene.json") << kScene; }
};

std::vector<double> statsRow(const std::string& out, const std::string& label, size_t n) {
  std::vector<double> v(n, -1e30);
  const size_t at = out.find(label);
  if (at == std::string::npos) return {};
  std::istringstream in(out.substr(at + label.size()));
  for (double& x : v) in >> x;
  return in ? v : std::vector<double>{};
}

TEST(RenderStokesCli, StokesChannelsAndFrameReadBackWithOpenImageIO) {
  Dir d;
  const fs::path out = d.path / "out.exr";
  const Outcome r = eikon::test::runEikon("render " + quote((d.path / "scene.json").string()) +
                                              " -o " + quote(out.string()) + " --layers stokes -q",
                                          d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("polarised"), std::string::npos) << r.out;
  const Outcome info = eikon::test::runProgram("iinfo", "-v " + quote(out.string()), d.path);
  ASSERT_EQ(info.code, 0) << info.err;
  EXPECT_NE(info.out.find("15 channel"), std::string::npos) << info.out;
  for (const char* name :
       {"S0.R", "S0.G", "S0.B", "S1.R", "S2.G", "S3.B", "stokesFrame", "stokes_basis(-v)"})
    EXPECT_NE(info.out.find(name), std::string::npos) << name << " missing in\n" << info.out;
  const Outcome stats = eikon::test::runProgram("iinfo", "--stats " + quote(out.string()), d.path);
  ASSERT_EQ(stats.code, 0) << stats.err;
  // OpenImageIO's order: R, G, B, then S0.R S0.G S0.B, S1.*, S2.*, S3.*.
  const std::vector<double> lo = statsRow(stats.out, "Stats Min:", 15),
                            hi = statsRow(stats.out, "Stats Max:", 15);
  ASSERT_FALSE(lo.empty() || hi.empty()) << stats.out;
  const double want[5] = {0.25, 0.25, 0.25, 0.0, 0.0};  // RGB, S0, S1, S2, S3
  for (size_t c = 0; c < 15; ++c) {
    EXPECT_NEAR(lo[c], want[c / 3], 1e-5) << "channel " << c;
    EXPECT_NEAR(hi[c], want[c / 3], 1e-5) << "channel " << c;
  }
}

TEST(RenderStokesCli, StokesWithOtherLayersIsOneLineAndNoFiles) {
  Dir d;
  const fs::path out = d.path / "out.exr";
  for (const std::string& extra :
       {std::string("--layers stokes,modes"), std::string("--layers spectral --wavelengths 4")}) {
    const Outcome r = eikon::test::runEikon("render " + quote((d.path / "scene.json").string()) +
                                                " -o " + quote(out.string()) + " " + extra + " -q",
                                            d.path);
    EXPECT_NE(r.code, 0) << extra;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << extra << ": " << r.err;
    EXPECT_NE(r.err.find("polarised"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << extra;
    EXPECT_FALSE(fs::exists(d.path / "out.png")) << extra;
  }
}

TEST(RenderStokesCli, ScenesAPolarisedRenderCannotTakeAreOneLineAndNoFiles) {
  Dir d;
  const fs::path out = d.path / "out.exr";
  const std::string base = kScene;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"\"interfaces\": \"smoothed\"", "/interfaces"},
      {"\"interfaces\": \"sharp\", \"environment\": {\"type\": \"constant\", \"radiance\": 1, "
       "\"polarization\": {\"stokes\": [1, 1, 0, 0]}}",
       "/environment/polarization"}};
  for (const auto& [replacement, path] : cases) {
    std::string text = base;
    text.replace(text.find("\"interfaces\": \"sharp\""),
                 std::string("\"interfaces\": \"sharp\"").size(), replacement);
    if (path == "/environment/polarization") {  // drop the scene's own environment line
      const size_t at = text.find("  \"environment\": {\"type\": \"constant\", \"radiance\": [0.5");
      text.erase(at, text.find('\n', at) + 1 - at);
    }
    std::ofstream(d.path / "bad.json") << text;
    const Outcome r = eikon::test::runEikon(
        "render " + quote((d.path / "bad.json").string()) + " -o " + quote(out.string()) + " -q",
        d.path);
    EXPECT_NE(r.code, 0) << path;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << path << ": " << r.err;
    EXPECT_NE(
        r.err.find("bad.json: " + path + ": a polarised render (the scene's polariser sheets)"),
        std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(out)) << path;
    EXPECT_FALSE(fs::exists(d.path / "out.png")) << path;
  }
}

// The wedge and plate of scenes/polariscope_quartz_wedge.json with the camera over the corner
// x = 20, y = −15: with an odd image size the middle column's rays lie in the plane x = 20 and the
// middle row's in y = −15 (u, v = 0 exactly), both side faces of both pieces.
constexpr const char* kWedgeCorner = R"({
  "camera": {"position": [20, -15, -250], "look_at": [20, -15, 0], "up": [0, 1, 0],
             "fov_deg": 0.1, "width": 5, "height": 5},
  "environment": {"type": "constant", "radiance": 1},
  "volume": {"bounds_min": [-21, -16, -2.4], "bounds_max": [21, 16, 2], "resolution": 224},
  "objects": [
    {"shape": "polarizer", "center": [0, 0, 10], "normal": [0, 0, 1],
     "transmission_axis": [1, 0, 0], "size": [80, 80]},
    {"shape": "polarizer", "center": [0, 0, -10], "normal": [0, 0, 1],
     "transmission_axis": [0, 1, 0], "size": [80, 80]},
    {"shape": "box", "center": [0, 0, -1.1], "size": [40, 30, 1.0], "material": "quartz",
     "optic_axis": [1, -1, 0]},
    {"shape": "planes", "material": "quartz", "optic_axis": [1, 1, 0],
     "planes": [[1, 0, 0, 20], [-1, 0, 0, 20], [0, 1, 0, 15], [0, -1, 0, 15], [0, 0, -1, 0],
                [0.005, 0, 1, 1.1]]}]
})";

TEST(RenderStokesCli, WedgeRenderedAlongItsSideFacesHasNoNan) {
  Dir d;
  std::ofstream(d.path / "wedge.json") << kWedgeCorner;
  for (const std::string& twin : {std::string("--reference"), std::string("")})
    for (const std::string& spectrum :
         {std::string("--wavelengths 0"), std::string("--wavelengths 4")}) {
      const fs::path out = d.path / "wedge.exr";
      const Outcome r = eikon::test::runEikon("render " + quote((d.path / "wedge.json").string()) +
                                                  " -o " + quote(out.string()) +
                                                  " --layers stokes -q " + twin + " " + spectrum,
                                              d.path);
      ASSERT_EQ(r.code, 0) << twin << " " << spectrum << ": " << r.err;
      const Outcome stats =
          eikon::test::runProgram("iinfo", "--stats " + quote(out.string()), d.path);
      ASSERT_EQ(stats.code, 0) << stats.err;
      const std::vector<double> nan = statsRow(stats.out, "Stats NanCount:", 15),
                                inf = statsRow(stats.out, "Stats InfCount:", 15),
                                lo = statsRow(stats.out, "Stats Min:", 15),
                                hi = statsRow(stats.out, "Stats Max:", 15);
      ASSERT_FALSE(nan.empty() || inf.empty() || lo.empty() || hi.empty()) << stats.out;
      for (size_t c = 0; c < 15; ++c) {
        EXPECT_EQ(nan[c], 0.0) << twin << " " << spectrum << ": channel " << c;
        EXPECT_EQ(inf[c], 0.0) << twin << " " << spectrum << ": channel " << c;
      }
      // RGB mode (one wavelength, white light box of 1): unpolarised light through a polariser
      // keeps at most half its power, so 0 <= S0 <= 1/2 in every channel. (A spectral render's
      // linear sRGB channels of a spectrum may overshoot.)
      if (spectrum == "--wavelengths 0") {
        for (size_t c = 3; c < 6; ++c) {
          EXPECT_GE(lo[c], 0.0) << twin;
          EXPECT_LE(hi[c], 0.5 + 1e-5) << twin;
        }
      }
      fs::remove(out);
      fs::remove(d.path / "wedge.png");
    }
}

// The GPU's polarised render and trace take at most 8 polariser sheets (EIKON_POL_MAX_SHEETS);
// a scene with more loaded, then failed after the voxelising with a message naming neither the file
// nor the sheet. Now the 9th sheet (/objects/9: a sphere comes first) is named with the file and
// the CPU reference as the remedy, before any work: with --progress always the error is the only
// line (it followed "preparing the GPU (pipelines, volume upload)"), and nothing lands in the cache
// folder. The reference renders and traces the scene.
TEST(RenderStokesCli, MoreSheetsThanTheGpuTakesNamesTheNinthBeforeVoxelising) {
  Dir d;
  std::string text = kScene;
  const std::string sheet = R"({"shape": "polarizer", "center": [0, 0, 20], "normal": [0, 0, 1],
               "transmission_axis": [1, 0, 0], "size": [40, 40]})";
  std::string more;
  for (int k = 0; k < 8; ++k) more += ",\n" + sheet;  // 9 sheets in all, /objects/1 to /objects/9
  text.insert(text.rfind("}]") + 1, more);            // after the last object
  std::ofstream(d.path / "many.json") << text;
  const std::string scene = quote((d.path / "many.json").string());
  const fs::path out = d.path / "out.exr", cache = d.path / "cache";
  const std::string env = "EIKON_CACHE_DIR=" + quote(cache.string());
  auto expectRefused = [&](const Outcome& r, const std::string& what) {
    EXPECT_NE(r.code, 0) << what;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << what << ": " << r.err;
    EXPECT_EQ(r.err.rfind("eikon: error: " + (d.path / "many.json").string() + ": /objects/9: ", 0),
              0u)
        << what << ": " << r.err;
    EXPECT_NE(r.err.find("at most 8 polariser sheets; this is sheet 9 of 9"), std::string::npos)
        << what << ": " << r.err;
    EXPECT_NE(r.err.find("--reference"), std::string::npos) << what << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << what << ": " << r.out;
    EXPECT_FALSE(fs::exists(out)) << what;
    EXPECT_FALSE(fs::exists(d.path / "out.png")) << what;
    EXPECT_FALSE(fs::exists(cache)) << what;
  };
  expectRefused(
      eikon::test::runEikon("render " + scene + " -o " + quote(out.string()) + " --progress always",
                            d.path, env),
      "render");
  expectRefused(
      eikon::test::runEikon(
          "trace " + scene + " --origin 0,0,-20 --dir 0,0,1 --stokes 1,0,0,0 --progress always",
          d.path, env),
      "trace --stokes");
  const Outcome trace = eikon::test::runEikon(
      "trace " + scene + " --origin 0,0,-20 --dir 0,0,1 --stokes 1,0,0,0 -q --reference", d.path,
      env);
  EXPECT_EQ(trace.code, 0) << trace.err;
  EXPECT_NE(trace.out.find("stokes_out ("), std::string::npos) << trace.out;
  const Outcome render = eikon::test::runEikon(
      "render " + scene + " -o " + quote(out.string()) + " -q --reference", d.path, env);
  EXPECT_EQ(render.code, 0) << render.err;
  EXPECT_TRUE(fs::exists(out));
}

}  // namespace
