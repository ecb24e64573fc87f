// A biaxial crystal through the real binary, on the CPU twin (--reference): `eikon trace --json`
// names its modes fast and slow and prints the polarised trace's stokes_out (an input polarised
// along a principal plane's mode leaves with at most its power); `render --layers modes` writes
// fast.R … slow.B (read back with OpenImageIO's iinfo), `--modes fast` and `--modes slow` render;
// `--polarised --layers stokes` writes the Stokes layers.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/apps/cli_support.h"

namespace {

namespace fs = std::filesystem;
using eikon::test::Outcome;
using eikon::test::quote;

constexpr const char* kScene = R"({
  "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
             "width": 16, "height": 12},
  "environment": {"type": "checker", "squares": 8},
  "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 24},
  "materials": {"x": {"n_alpha": 1.53, "n_beta": 1.56, "n_gamma": 1.685,
                      "alpha_axis": [1, 0, 0], "gamma_axis": [0, 0, 1]}},
  "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 5, "material": "x",
               "alpha_axis": [0, 1, 0], "gamma_axis": [1, 0, 1]}]
})";

struct Dir {
  eikon::test::TempDir tmp{"eikon_biaxial_cli"};
  const fs::path path = tmp.path();
  const std::string scene = quote((path / "scene.json").string());
  Dir() { std::ofstream(path / "scene.json") << kScene; }
  Outcome run(const std::string& args) const { return eikon::test::runEikon(args, path); }
};

TEST(BiaxialCli, TraceNamesFastAndSlowAndTracesStokes) {
  Dir d;
  const Outcome r =
      d.run("trace " + d.scene + " --reference --json --origin 0.5,0.3,-20 --dir 0,0,1");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("modes").size(), 2u);
  EXPECT_EQ(j["modes"][0]["mode"], "fast");
  EXPECT_EQ(j["modes"][1]["mode"], "slow");
  ASSERT_TRUE(j["stokes_out"].is_array()) << r.out;
  // The fast and slow beams leave the sphere in two directions; together they carry what the
  // sphere's two faces transmit (n = 1.53–1.685 near normal incidence: 8–13% reflected).
  double total = 0.0;
  for (const auto& b : j.at("polarised_beams")) total += b.at("stokes")[0].get<double>();
  EXPECT_GT(total, 0.85) << r.out;
  EXPECT_LT(total, 0.93) << r.out;
  // The two modes refract differently (the sphere is a lens for each of its indices).
  EXPECT_NE(j["modes"][0]["exit_point"], j["modes"][1]["exit_point"]);
  const Outcome s =
      d.run("trace " + d.scene + " --reference --origin 0.5,0.3,-20 --dir 0,0,1 --stokes 1,1,0,0");
  EXPECT_EQ(s.code, 0) << s.err;
  EXPECT_NE(s.out.find("stokes_out"), std::string::npos) << s.out;
}

TEST(BiaxialCli, RenderLayersAreFastAndSlowAndPolarisedRenders) {
  Dir d;
  const fs::path out = d.path / "out.exr";
  const Outcome r =
      d.run("render " + d.scene + " -o " + quote(out.string()) + " --reference --layers modes -q");
  ASSERT_EQ(r.code, 0) << r.err;
  const Outcome info = eikon::test::runProgram("iinfo", "-v " + quote(out.string()), d.path);
  ASSERT_EQ(info.code, 0) << info.err;
  for (const char* name : {"fast.R", "fast.G", "fast.B", "slow.R", "slow.G", "slow.B"})
    EXPECT_NE(info.out.find(name), std::string::npos) << name << " missing in\n" << info.out;
  EXPECT_EQ(info.out.find("o.R"), std::string::npos) << info.out;
  for (const char* m : {"fast", "slow"}) {
    const Outcome one = d.run("render " + d.scene + " -o " + quote((d.path / m).string() + ".exr") +
                              " --reference --modes " + m + " -q");
    EXPECT_EQ(one.code, 0) << one.err;
  }
  const fs::path pol = d.path / "pol.exr";
  const Outcome p = d.run("render " + d.scene + " -o " + quote(pol.string()) +
                          " --reference --polarised --layers stokes -q");
  ASSERT_EQ(p.code, 0) << p.err;
  const Outcome pinfo = eikon::test::runProgram("iinfo", "-v " + quote(pol.string()), d.path);
  ASSERT_EQ(pinfo.code, 0) << pinfo.err;
  EXPECT_NE(pinfo.out.find("S1"), std::string::npos) << pinfo.out;
}

}  // namespace
