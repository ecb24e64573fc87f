// `eikon trace --stokes S0,S1,S2,S3` (docs/polarisation.md): the Stokes vector of the
// light leaving along the traced path, "stokes_out" in --json and in the text, from both twins
// (the GPU's by default, the CPU's with --reference), against closed forms:
//  - Malus: sheets at 0° and 60° pass ½cos²60° = 0.125 of unpolarised light, linear at 60°
//    (S1 = 0.125 cos 120°, S2 = 0.125 sin 120°);
//  - a quartz quarter-wave plate (31¼ waves) with its axis at 45° turns light linear along x̂
//    (--stokes 1,1,0,0) left circular: S3/S0 ≤ −0.999;
// and bad --stokes values (count, S0 ≤ 0, degree of polarisation > 1, not numbers) or --stokes on a
// smoothed scene are one error line.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "tests/apps/cli_support.h"

namespace {

namespace fs = std::filesystem;
using eikon::test::Outcome;
using eikon::test::quote;

class TraceStokesCli : public ::testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  Outcome run(const std::string& args) const {
    Outcome o = eikon::test::runEikon(args, dir_ / "io", "EIKON_VALIDATION=1");
    EXPECT_EQ(o.err.find("[vulkan validation]"), std::string::npos) << o.err;
    return o;
  }
  void expectCleanFailure(const Outcome& r, const std::string& phrase) const {
    EXPECT_NE(r.code, 0);
    EXPECT_EQ(r.err.rfind("eikon: error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(phrase), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;  // no partial output
  }
  eikon::test::TempDir tmp_{"eikon_stokes_cli"};
  const fs::path dir_ = tmp_.path();
};

std::string sheetJson(double z, double deg) {
  const double r = deg * std::numbers::pi / 180.0;
  return R"({"shape": "polarizer", "center": [0, 0, )" + std::to_string(z) +
         R"(], "normal": [0, 0, 1], "transmission_axis": [)" + std::to_string(std::cos(r)) + ", " +
         std::to_string(std::sin(r)) + R"(, 0], "size": [20, 20]})";
}

std::string sceneJson(const std::string& objects, const std::string& extra = "") {
  return R"({)" + extra + R"("environment": {"type": "constant", "radiance": 1},
  "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": 32},
  "materials": {"glass": {"n": 1.5}},
  "objects": [)" +
         objects + "]}";
}

const char* kAside =
    R"({"shape": "sphere", "center": [3, 3, 3], "radius": 1, "material": "glass"})";

std::vector<double> stokesOut(const Outcome& r) {
  const nlohmann::json j = nlohmann::json::parse(r.out);
  return j.at("stokes_out").get<std::vector<double>>();
}

TEST_F(TraceStokesCli, MalusOnBothTwins) {
  const std::string scene =
      write("malus.json", sceneJson(sheetJson(-8, 0) + ", " + sheetJson(8, 60) + ", " + kAside));
  for (const char* twin : {"", " --reference"}) {
    const Outcome r = run("trace " + quote(scene) +
                          " --origin 0,0,-20 --dir 0,0,1 --wavelength 550 --json" + twin);
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<double> s = stokesOut(r);
    ASSERT_EQ(s.size(), 4u);
    // Sheet axes written with 6 digits: 1e-6; the GPU's float32 sums: 1e-5.
    EXPECT_NEAR(s[0], 0.125, 1e-5) << twin;
    EXPECT_NEAR(s[1], 0.125 * std::cos(2.0944), 1e-5) << twin;
    EXPECT_NEAR(s[2], 0.125 * std::sin(2.0944), 1e-5) << twin;
    EXPECT_NEAR(s[3], 0.0, 1e-5) << twin;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("stokes_in").get<std::vector<double>>(), (std::vector<double>{1, 0, 0, 0}));
    ASSERT_EQ(j.at("polarised_beams").size(), 1u);
  }
  const Outcome text = run("trace " + quote(scene) + " --origin 0,0,-20 --dir 0,0,1 --reference");
  ASSERT_EQ(text.code, 0) << text.err;
  const size_t at = text.out.find("stokes_out (");
  ASSERT_NE(at, std::string::npos) << text.out;
  EXPECT_NEAR(std::stod(text.out.substr(at + 12)), 0.125, 1e-5) << text.out;
}

TEST_F(TraceStokesCli, QuarterWaveQuartzPlateMakesLeftCircularLight) {
  // quartz at 589.2938 nm: n_e − n_o = 1.553306033 − 1.544205989 = 0.009100044 (Ghosh's Sellmeier
  // terms of materials/quartz.json); 31.25 waves.
  const double t = 31.25 * 589.2938e-6 / 0.009100044;
  const std::string scene =
      write("qwp.json", sceneJson(R"({"shape": "box", "center": [0, 0, 0], "size": [9, 9, )" +
                                  std::to_string(t) +
                                  R"(], "material": "quartz", "optic_axis": [0.7071067811865476,
                                   0.7071067811865476, 0]})"));
  for (const char* twin : {"", " --reference"}) {
    const Outcome r = run(
        "trace " + quote(scene) +
        " --origin 0.3,0.2,-20 --dir 0,0,1 --wavelength 589.2938 --stokes 1,1,0,0 --json" + twin);
    ASSERT_EQ(r.code, 0) << r.err;
    const std::vector<double> s = stokesOut(r);
    std::printf("[ measured ] quarter-wave plate%s: S3/S0 = %.6f\n", twin, s[3] / s[0]);
    // The plate's t is written with 6 digits (δt ≤ 5e-7 mm: 5e-4 rad; n_e − n_o above to 1e-9:
    // 2e-5 rad) and the GPU's float32 indices add 2e-3 rad: |S3|/S0 ≥ cos(3e-3) > 0.999.
    EXPECT_LE(s[3] / s[0], -0.999) << twin;
  }
}

TEST_F(TraceStokesCli, BadStokesIsOneErrorLine) {
  const std::string scene = write("aside.json", sceneJson(kAside));
  const std::string base = "trace " + quote(scene) + " --origin 0,0,-20 --dir 0,0,1 --stokes ";
  expectCleanFailure(run(base + "1,0,0"), "--stokes must be four finite numbers");
  expectCleanFailure(run(base + "0,0,0,0"), "--stokes needs S0 > 0");
  expectCleanFailure(run(base + "-1,0,0,0"), "--stokes needs S0 > 0");
  expectCleanFailure(run(base + "1,1,1,0"), "degree of polarisation");
  expectCleanFailure(run(base + "1,x,0,0"), "--stokes must be four finite numbers");
  expectCleanFailure(run(base + "1,nan,0,0"), "--stokes must be four finite numbers");
}

// An empty --stokes was silently the default 1,0,0,0, and a trailing comma and hexadecimal were
// accepted, while '1,,0,0' was refused: exactly four finite decimal numbers, or one error line.
TEST_F(TraceStokesCli, StokesIsFourDecimalNumbersAndNothingElse) {
  const std::string scene = write("aside.json", sceneJson(kAside));
  const std::string base = "trace " + quote(scene) + " --origin 0,0,-20 --dir 0,0,1 -q --stokes ";
  for (const char* bad : {"", "1,0,0,0,", ",1,0,0,0", "1,,0,0", "0x1,0,0,0", "1,0,0,0x0",
                          "1,0,0,inf", "1,0,0,1e999", "1,0,0,0 x", "1,0,0,.", "1,0,0,1e"})
    expectCleanFailure(run(base + quote(bad)),
                       "--stokes must be four finite numbers S0,S1,S2,S3, "
                       "got '" +
                           std::string(bad) + "'");
  // Decimal forms and blanks around a number are numbers.
  const Outcome r = run(base + quote(" +1.0, 0, -0.5e-0 ,.5") + " --json --reference");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out).at("stokes_in").get<std::vector<double>>(),
            (std::vector<double>{1, 0, -0.5, 0.5}));
}

TEST_F(TraceStokesCli, StokesOnASmoothedSceneIsOneErrorLine) {
  const std::string scene =
      write("smoothed.json", sceneJson(kAside, R"("interfaces": "smoothed", )"));
  expectCleanFailure(
      run("trace " + quote(scene) + " --origin 0,0,-20 --dir 0,0,1 --stokes 1,0,0,0 --reference"),
      "--stokes: the polarised trace needs");
  // Without --stokes the trace runs and says why there is no stokes_out.
  const Outcome r =
      run("trace " + quote(scene) + " --origin 0,0,-20 --dir 0,0,1 --reference --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j.at("stokes_out").is_null());
}

}  // namespace
