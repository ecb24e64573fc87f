// The `eikon` binary (render, trace, info) run as a user runs it: help texts, a tiny render that
// writes OUT.exr and OUT.png, the JSON of `trace`, GPU vs CPU reference agreement, and bad input
// — one stderr line "eikon: error: ...", non-zero exit, no output file and no leftover temporary.
// GPU runs have EIKON_VALIDATION=1 and must print no "[vulkan validation]" line.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>

#include "core/io/exr.h"
#include "tests/apps/cli_support.h"
#include "tests/sanitizers.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using eikon::test::Outcome;
using eikon::test::slurp;

// A small glass sphere (n = 1.5, r = 3 mm) in a 10 mm volume of 32³ voxels, a 32x24 camera.
std::string tinyScene(const std::string& volume_extra = "",
                      const std::string& material = R"({"n": 1.5})",
                      const std::string& object_extra = "") {
  return R"({
  "camera": {"position": [0, 0, -30], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 20, "width": 32, "height": 24},
  "environment": {"type": "checker", "squares": 8},
  "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "smoothing_voxels": 0.75)" +
         (volume_extra.empty() ? std::string(R"(, "resolution": 32)") : ", " + volume_extra) + R"(},
  "materials": {"glass": )" +
         material + R"(},
  "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 3, "material": "glass")" +
         object_extra + R"(}]
})";
}

/// The same scene marched through smoothed layers (tests of the layer march and of GPU-vs-CPU
/// agreement while the GPU twin marches smoothed).
std::string smoothedScene(const std::string& scene) {
  return R"({"interfaces": "smoothed",)" + scene.substr(1);
}

using eikon::test::quote;

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "eikon_cli_XXXXXX").string();
    ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
    io_ = dir_ / "io";  // captured stdout/stderr live apart from the output directory
    out_ = dir_ / "out";
    fs::create_directories(io_);
    fs::create_directories(out_);
  }
  void TearDown() override {
    std::error_code ec;
    for (auto& p : chmodded_) fs::permissions(p, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(dir_, ec);
  }

  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  /// Run `eikon ARGS` with validation layers on; stdout/stderr captured.
  Outcome run(const std::string& args) const {
    Outcome o = eikon::test::runEikon(args, io_, "EIKON_VALIDATION=1");
    EXPECT_EQ(o.err.find("[vulkan validation]"), std::string::npos) << "validation messages:\n"
                                                                    << o.err;
    return o;
  }
  std::string outPath(const std::string& name = "render.exr") const {
    return (out_ / name).string();
  }

  /// Exactly one stderr line "eikon: error: ..." containing `phrase`, non-zero exit, nothing left
  /// in `dir` (the output directory) but what was there before.
  void expectCleanFailure(const Outcome& r, const std::string& phrase, const fs::path& dir) const {
    EXPECT_NE(r.code, 0);
    EXPECT_EQ(r.err.rfind("eikon: error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(phrase), std::string::npos)
        << "stderr lacks '" << phrase << "': " << r.err;
    std::error_code ec;
    if (fs::is_directory(dir, ec))
      for (auto& e : fs::directory_iterator(dir, ec)) {
        const std::string n = e.path().filename().string();
        EXPECT_EQ(n.find(".tmp-"), std::string::npos) << "temporary file left: " << n;
        EXPECT_NE(e.path().extension(), ".exr") << "output left: " << n;
        EXPECT_NE(e.path().extension(), ".png") << "output left: " << n;
      }
  }
  void expectCleanFailure(const Outcome& r, const std::string& phrase) const {
    expectCleanFailure(r, phrase, out_);
  }

  Outcome render(const std::string& scene_text, const std::string& extra = "") {
    const std::string scene = write("scene.json", scene_text);
    return run("render " + quote(scene) + " -o " + quote(outPath()) + " " + extra);
  }

  fs::path dir_, io_, out_;
  std::vector<fs::path> chmodded_;
};

// ------------------------------------------------------------------ help and info

TEST_F(Cli, TopLevelHelp) {
  const Outcome r = run("--help");
  EXPECT_EQ(r.code, 0) << r.err;
  for (const char* s : {"render", "trace", "info", "fit"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
}

TEST_F(Cli, RenderHelp) {
  const Outcome r = run("render --help");
  EXPECT_EQ(r.code, 0) << r.err;
  for (const char* s : {"--output", "--width", "--height", "--spp", "--wavelengths", "--reference"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
}

TEST_F(Cli, TraceHelp) {
  const Outcome r = run("trace --help");
  EXPECT_EQ(r.code, 0) << r.err;
  for (const char* s : {"--origin", "--dir", "--wavelength", "--json", "--reference"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
}

TEST_F(Cli, Info) {
  const Outcome r = run("info");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("max 3D image side"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("device:"), std::string::npos) << r.out;
}

// Every "label: value" line of `eikon info` has its value in one column, after at least one space
// (it printed "max storage buffer:128 MiB").
TEST_F(Cli, InfoValuesAreAligned) {
  const Outcome r = run("info");
  ASSERT_EQ(r.code, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  size_t column = 0;
  int rows = 0;
  while (std::getline(lines, line)) {
    const size_t colon = line.find(':');
    if (line.rfind("eikon ", 0) == 0 || colon == std::string::npos) continue;
    ASSERT_LT(colon + 1, line.size()) << line;
    EXPECT_EQ(line[colon + 1], ' ') << "no space after the label: " << line;
    const size_t value = line.find_first_not_of(' ', colon + 1);
    ASSERT_NE(value, std::string::npos) << line;
    if (rows++ == 0) column = value;
    EXPECT_EQ(value, column) << "value not in the column of the first row: " << line;
  }
  EXPECT_GE(rows, 6) << r.out;
  EXPECT_NE(r.out.find("max storage buffer: "), std::string::npos) << r.out;
}

// ------------------------------------------------------------------ render

TEST_F(Cli, RenderTinyScene) {
  const Outcome r = render(tinyScene());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(outPath("render.exr")));
  EXPECT_TRUE(fs::is_regular_file(outPath("render.png")));
  EXPECT_NE(r.out.find("eikon: rendered"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("32x24"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(outPath("render.png")), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << "one summary line:\n" << r.out;
  for (auto& e : fs::directory_iterator(out_))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  // The EXR reads back at the camera's size with finite, non-negative radiance, and the image is
  // not blank: the checker environment has radiance ≥ its dark colour everywhere.
  const eikon::RgbaImage img = eikon::readExrRgba(outPath("render.exr"), 64, 64);
  EXPECT_EQ(img.width, 32);
  EXPECT_EQ(img.height, 24);
  double mx = 0;
  for (size_t i = 0; i < img.rgba.size(); ++i) {
    EXPECT_TRUE(std::isfinite(img.rgba[i]) && img.rgba[i] >= 0.0f) << i;
    mx = std::max(mx, double(img.rgba[i]));
  }
  EXPECT_GT(mx, 0.1);
  const std::string png = slurp(outPath("render.png"));
  ASSERT_GE(png.size(), 8u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
}

// At the documented limits (an index of 10, an emission of 1e9, an environment radiance of 1e8
// times an intensity of 10 = 1e9; docs/scene-format.md) both twins render finite pixels: the
// limits are where NaN and Inf stop (n = 1e20, emission or radiance 1e308 rendered them).
TEST_F(Cli, RenderAtTheInputLimitsIsFinite) {
  std::string text = tinyScene("", R"({"n": 10, "emission": 1e9, "attenuation_per_mm": 0.1})");
  const std::string checker = R"({"type": "checker", "squares": 8})";
  text.replace(text.find(checker), checker.size(),
               R"({"type": "constant", "radiance": 1e8, "intensity": 10})");
  for (const char* twin : {"", " --reference"}) {
    SCOPED_TRACE(twin);
    const Outcome r = render(text, std::string("-q") + twin);
    ASSERT_EQ(r.code, 0) << r.err;
    const eikon::RgbaImage img = eikon::readExrRgba(outPath("render.exr"), 64, 64);
    double mx = 0;
    for (size_t i = 0; i < img.rgba.size(); ++i) {
      ASSERT_TRUE(std::isfinite(img.rgba[i])) << i;
      mx = std::max(mx, double(img.rgba[i]));
    }
    EXPECT_GT(mx, 1e8);
  }
}

// Every shipped scene renders clean under --strict (warnings are errors): scenes/diamond_brilliant
// used to warn that diamond is measured over 226-760 nm only. Tiny renders on the CPU twin (no
// shader compilation), 4 wavelengths (or RGB where the scene's own "render" asks for it, as
// biaxial_tanzanite does: its indices are measured over 431-687 nm only), and the light
// simulation as small as the flags allow.
TEST_F(Cli, EveryShippedSceneRendersCleanUnderStrict) {
  std::vector<fs::path> scenes;
  for (const auto& e : fs::directory_iterator(fs::path(EIKON_SOURCE_DIR) / "scenes"))
    if (e.path().extension() == ".json") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  ASSERT_GE(scenes.size(), 9u) << "scenes/ not found under " << EIKON_SOURCE_DIR;
  for (const fs::path& scene : scenes) {
    std::ifstream in(scene);
    const nlohmann::json j = nlohmann::json::parse(in);
    const bool rgb = j.contains("render") && j["render"].value("wavelengths", -1) == 0;
    const Outcome r = run("render " + quote(scene.string()) + " -o " +
                          quote(outPath(scene.stem().string() + ".exr")) +
                          " --strict -q --reference --width 16 --height 12 --spp 1 --wavelengths " +
                          (rgb ? "0" : "4") +
                          " --light-bands 1"
                          " --max-patches 1024 --light-split 8 --light-step 2 --no-light-cache");
    EXPECT_EQ(r.code, 0) << scene << ": " << r.err;
    EXPECT_EQ(r.err, "") << scene;
    EXPECT_TRUE(fs::is_regular_file(outPath(scene.stem().string() + ".exr"))) << scene;
  }
}

// ------------------------------------------------------------------ progress

/// Lines of `err` (progress lines end in '\n' when stderr is not a terminal) that look like
/// "eikon: STAGE  42.0%  1.2 s, ETA ..." for STAGE starting with `stage`.
std::vector<std::string> progressLines(const std::string& err, const std::string& stage) {
  std::vector<std::string> out;
  std::istringstream in(err);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("eikon: " + stage, 0) == 0 && line.find("%  ") != std::string::npos &&
        line.find(", ETA ") != std::string::npos)
      out.push_back(line);
  return out;
}

// stderr is not a terminal here: no progress lines by default, and none with -q even when forced;
// --progress always shows each stage with elapsed time and ETA, its first report and its 100%.
// The lit scene has all three stages: voxelising, light, rendering.
TEST_F(Cli, RenderProgressOnlyWhenAskedOrOnATerminal) {
  // A translucent ball with an albedo: its in-scatter shows the light (without one the lights
  // are not simulated, LightsWithoutAnAlbedoAreNotSimulated); attenuating, it is lit in 3 bands.
  std::string lit = tinyScene("", R"({"n": 1.5, "attenuation_per_mm": 0.1, "albedo": 0.5})");
  lit.insert(lit.rfind('}'),
             R"(, "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 1}])");
  const std::string light = " --reference --light-split 8 --light-step 2 --no-light-cache";
  const Outcome quiet = render(lit, light);
  ASSERT_EQ(quiet.code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "") << "progress without a terminal";
  EXPECT_EQ(std::count(quiet.out.begin(), quiet.out.end(), '\n'), 2) << "the summary lines only:\n"
                                                                     << quiet.out;
  const Outcome never = render(lit, light + " --progress always -q");
  ASSERT_EQ(never.code, 0) << never.err;
  EXPECT_EQ(never.err, "");
  const Outcome forced = render(lit, light + " --progress always");
  ASSERT_EQ(forced.code, 0) << forced.err;
  for (const char* stage : {"voxelising", "light 1 light x 3 bands x 1 mode", "rendering"}) {
    const auto lines = progressLines(forced.err, stage);
    ASSERT_FALSE(lines.empty()) << stage << ":\n" << forced.err;
    EXPECT_NE(lines.back().find("100.0%"), std::string::npos) << lines.back();
    EXPECT_NE(lines.back().find("ETA 0.0 s"), std::string::npos) << lines.back();
  }
  // Nothing else on stderr: every line is a progress line.
  const size_t lines = size_t(std::count(forced.err.begin(), forced.err.end(), '\n'));
  EXPECT_EQ(lines, progressLines(forced.err, "").size()) << forced.err;
  EXPECT_NE(forced.out.find("eikon: rendered"), std::string::npos) << forced.out;
}

TEST_F(Cli, TraceProgressOnlyWhenAsked) {
  const std::string scene = write("scene.json", tinyScene());
  const std::string args = "trace " + quote(scene) + " --origin 0,0,-5 --dir 0,0,1 --reference";
  const Outcome quiet = run(args);
  ASSERT_EQ(quiet.code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");
  const Outcome forced = run(args + " --progress always");
  ASSERT_EQ(forced.code, 0) << forced.err;
  const auto lines = progressLines(forced.err, "voxelising");
  ASSERT_FALSE(lines.empty()) << forced.err;
  EXPECT_NE(lines.back().find("100.0%"), std::string::npos) << lines.back();
  EXPECT_EQ(forced.out, quiet.out);
  EXPECT_EQ(run(args + " --progress always -q").err, "");
  // The GPU twin: building its pipelines and uploading the volume has no fraction. It is a stage of
  // its own, shown with its elapsed time, instead of the voxeliser's "100.0%, ETA 0.0 s" redrawn
  // every second while it runs (seen for 9 s on a 64x48 render).
  const Outcome gpu =
      run("trace " + quote(scene) + " --origin 0,0,-5 --dir 0,0,1 --progress always");
  ASSERT_EQ(gpu.code, 0) << gpu.err;
  std::istringstream in(gpu.err);
  int preparing = 0, voxelDone = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("eikon: preparing the GPU", 0) == 0) ++preparing;
    if (line.rfind("eikon: voxelising", 0) == 0 && line.find("100.0%") != std::string::npos)
      ++voxelDone;
  }
  EXPECT_GE(preparing, 1) << gpu.err;
  EXPECT_EQ(voxelDone, 1) << "a finished stage is drawn once at 100%:\n" << gpu.err;
}

TEST_F(Cli, BadProgressOptionFailsCleanly) {
  expectCleanFailure(render(tinyScene(), "--progress sometimes"),
                     "--progress must be auto, always or never");
  const std::string scene = write("scene.json", tinyScene());
  expectCleanFailure(run("trace " + quote(scene) + " --origin 0,0,-5 --dir 0,0,1 --progress loud"),
                     "--progress must be auto, always or never");
}

// ------------------------------------------------------------------ render: bad input

TEST_F(Cli, RenderMalformedJson) {
  expectCleanFailure(render(R"({"objects": [ {"shape": )"), "malformed JSON");
}

TEST_F(Cli, RenderUnknownKeyNamesThePath) {
  const Outcome r = render(tinyScene(R"("resolution": 32, "smoothing": 1)"));
  expectCleanFailure(r, "/volume/smoothing");
  EXPECT_NE(r.err.find("unknown key"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("scene.json"), std::string::npos) << "the message names the file: " << r.err;
}

TEST_F(Cli, RenderIndexBelowOne) {
  const Outcome r = render(tinyScene("", R"({"n": 0.9})"));
  expectCleanFailure(r, "/materials/glass/n");
  EXPECT_NE(r.err.find(">= 1"), std::string::npos) << r.err;
}

TEST_F(Cli, RenderZeroSize) {
  std::string s = tinyScene();
  const std::string sphere =
      R"({"shape": "sphere", "center": [0, 0, 0], "radius": 3, "material": "glass"})";
  s.replace(s.find(sphere), sphere.size(),
            R"({"shape": "box", "size": [2, 0, 2], "material": "glass"})");
  expectCleanFailure(render(s), "/objects/0/size");
}

// A volume beyond the device's 3D image side limit is refused before voxelising, naming the limit.
TEST_F(Cli, RenderResolutionBeyondTheDeviceLimit) {
  const Outcome info = run("info");
  ASSERT_EQ(info.code, 0) << info.err;
  const auto at = info.out.find("max 3D image side:");
  ASSERT_NE(at, std::string::npos) << info.out;
  const long limit = std::stol(info.out.substr(at + std::string("max 3D image side:").size()));
  ASSERT_GT(limit, 0);
  const long res = std::max(5000L, limit + 1);
  const Outcome r = render(tinyScene(R"("resolution": )" + std::to_string(res)));
  expectCleanFailure(r, "/volume/resolution");
  EXPECT_NE(r.err.find(std::to_string(limit)), std::string::npos)
      << "message should state the limit " << limit << ": " << r.err;
}

// Missing folders of -o are created (the render used to fail: "directory 'out' does not exist"),
// also for a relative path, which is how a user types it.
TEST_F(Cli, RenderCreatesMissingOutputFolders) {
  const std::string scene = write("scene.json", tinyScene());
  const fs::path missing = dir_ / "no_such_dir" / "deeper";
  const Outcome r =
      run("render " + quote(scene) + " -q --reference -o " + quote((missing / "x.exr").string()));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(missing / "x.exr"));
  EXPECT_TRUE(fs::is_regular_file(missing / "x.png"));
  const Outcome rel = run("render " + quote(scene) + " -q --reference -o " +
                          quote(fs::relative(dir_ / "rel" / "y.exr", fs::current_path()).string()));
  ASSERT_EQ(rel.code, 0) << rel.err;
  EXPECT_TRUE(fs::is_regular_file(dir_ / "rel" / "y.exr"));
  EXPECT_TRUE(fs::is_regular_file(dir_ / "rel" / "y.png"));
}

// A file where a folder of -o should be: one error line before any work, nothing created.
TEST_F(Cli, RenderOutputFolderIsAFile) {
  const std::string scene = write("scene.json", tinyScene());
  write("plain", "not a folder");
  const Outcome r =
      run("render " + quote(scene) + " -o " + quote((dir_ / "plain" / "sub" / "x.exr").string()));
  expectCleanFailure(r, "is not a folder", dir_);
  EXPECT_TRUE(fs::is_regular_file(dir_ / "plain"));
}

// An unwritable output directory. As root, permissions do not apply (access(W_OK) succeeds on a
// 0555 directory), so there the test writes under /proc, which refuses new files even for root.
TEST_F(Cli, RenderOutputDirectoryReadOnly) {
  const std::string scene = write("scene.json", tinyScene());
  const fs::path ro = dir_ / "readonly";
  fs::create_directories(ro);
  fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                          fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  chmodded_.push_back(ro);
  if (::access(ro.c_str(), W_OK) != 0) {
    expectCleanFailure(run("render " + quote(scene) + " -o " + quote((ro / "x.exr").string())),
                       "not writable", ro);
    EXPECT_TRUE(fs::is_empty(ro));
  } else {
    const Outcome r = run("render " + quote(scene) + " -o /proc/eikon_cli_test.exr");
    expectCleanFailure(r, "/proc/eikon_cli_test", "/proc");
    EXPECT_FALSE(fs::exists("/proc/eikon_cli_test.exr"));
    EXPECT_FALSE(fs::exists("/proc/eikon_cli_test.png"));
  }
}

// A render that fails while writing (here: files limited to 8 KiB, so the 6 KB PNG preview is
// written and the 22 KB EXR is not, as on a full disk) leaves the previous render's EXR and PNG
// byte for byte, and no temporary. It used to delete the previous EXR when the PNG failed.
TEST_F(Cli, FailedWriteLeavesThePreviousOutputsIntact) {
  const std::string scene = write("scene.json", tinyScene());
  // --transport single: the single path keeps the tiny scene's sphere visible in its constant
  // sky, where full transport makes a non-absorbing object vanish (the white furnace) and the
  // EXR compresses below the limit.
  const std::string common = "render " + quote(scene) +
                             " -q --reference --transport single --width 160 --height 120 -o " +
                             quote(outPath());
  const Outcome first = run(common);
  ASSERT_EQ(first.code, 0) << first.err;
  const std::string exr = slurp(outPath("render.exr")), png = slurp(outPath("render.png"));
  // The sizes the limit is chosen between (a 160x120 render of the tiny scene: ~22 KB, ~6 KB).
  ASSERT_GT(exr.size(), 12000u);
  ASSERT_LT(png.size(), 8192u);
  // A different picture (2 spp, brighter preview): had it replaced anything, the bytes would
  // differ.
  const Outcome r = eikon::test::runProgramWithFileLimit(
      EIKON_BINARY, common + " --spp 2 --exposure 1", io_, 8192);
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(r.err.rfind("eikon: error: cannot write '" + outPath("render.exr") + "'", 0), 0u)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(slurp(outPath("render.exr")), exr);
  EXPECT_EQ(slurp(outPath("render.png")), png);
  for (auto& e : fs::directory_iterator(out_))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  // The same render without the limit does replace both (the test above is not vacuous).
  const Outcome again = run(common + " --spp 2 --exposure 1");
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_NE(slurp(outPath("render.exr")), exr);
  EXPECT_NE(slurp(outPath("render.png")), png);
}

// The progressive preview went to NAME.png itself: a render killed mid-way (SIGKILL: no clean-up
// runs) left the previous render's EXR beside a preview of the new one. The preview has its own
// file, NAME.partial.png, and the pair is replaced only whole: killed after its first preview,
// the render leaves the previous pair byte for byte.
TEST_F(Cli, RenderKilledMidWayLeavesThePreviousPairIntact) {
  const std::string scene = write("scene.json", tinyScene());
  const std::string common =
      "render " + quote(scene) + " -q --width 160 --height 120 -o " + quote(outPath());
  const Outcome first = run(common);
  ASSERT_EQ(first.code, 0) << first.err;
  const std::string exr = slurp(outPath("render.exr")), png = slurp(outPath("render.png"));
  const fs::path partial = outPath("render.partial.png");
  // Many samples: the render takes a minute, and a preview is written a second into it (the
  // progressive preview is the GPU twin's: RenderSettings::on_pass).
  const pid_t pid = eikon::test::startProgram(EIKON_BINARY, common + " --spp 4096", io_);
  ASSERT_GT(pid, 0);
  bool previewed = false;
  for (int i = 0; i < 6000 && !previewed; ++i) {  // up to 120 s
    ::usleep(20000);
    previewed = fs::exists(partial) || slurp(outPath("render.png")) != png;
  }
  ::kill(pid, SIGKILL);
  const Outcome killed = eikon::test::waitProgram(pid, io_);
  EXPECT_EQ(killed.code, -1) << "the render ended before it was killed: " << killed.err;
  EXPECT_TRUE(previewed) << "no preview within 120 s";
  EXPECT_TRUE(slurp(outPath("render.exr")) == exr) << "the EXR changed";
  EXPECT_TRUE(slurp(outPath("render.png")) == png) << "the PNG changed";
  EXPECT_TRUE(fs::exists(partial));  // the preview, under its own name
  // The next render replaces the pair and removes the stale preview.
  const Outcome again = run(common + " --spp 2");
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_TRUE(slurp(outPath("render.png")) != png);
  EXPECT_FALSE(fs::exists(partial));
}

// A render that failed after writing a progressive preview removed NAME.png (the preview had
// replaced it): the previous pair is left byte for byte, and the partial preview removed. Files
// are limited to 8 KiB, so the previews (~6 KB) are written and the final EXR (~22 KB) is not; 1024
// samples take a few seconds (256 took 1.3 s on a quiet machine: too short for a preview, which
// comes at most once a second), a preview a second.
TEST_F(Cli, RenderFailingAfterAPreviewLeavesThePreviousPairIntact) {
  const std::string scene = write("scene.json", tinyScene());
  const std::string common =
      "render " + quote(scene) + " -q --width 160 --height 120 -o " + quote(outPath());
  const Outcome first = run(common);
  ASSERT_EQ(first.code, 0) << first.err;
  const std::string exr = slurp(outPath("render.exr")), png = slurp(outPath("render.png"));
  const fs::path partial = outPath("render.partial.png");
  const pid_t pid = eikon::test::startProgram(EIKON_BINARY, common + " --spp 1024", io_, 8192);
  ASSERT_GT(pid, 0);
  bool previewed = false;
  auto running = [pid] {  // asked without reaping it (WNOWAIT): waitProgram collects it
    siginfo_t info{};
    return ::waitid(P_PID, id_t(pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid == 0;
  };
  while (running()) {
    previewed = previewed || fs::exists(partial) || slurp(outPath("render.png")) != png;
    ::usleep(10000);
  }
  const Outcome r = eikon::test::waitProgram(pid, io_);
  ASSERT_TRUE(previewed) << "the render wrote no preview before it failed; make it longer";
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(r.err.rfind("eikon: error: cannot write '" + outPath("render.exr") + "'", 0), 0u)
      << r.err;
  EXPECT_TRUE(slurp(outPath("render.exr")) == exr) << "the EXR changed";
  EXPECT_TRUE(slurp(outPath("render.png")) == png) << "the PNG changed";
  EXPECT_FALSE(fs::exists(partial));
  for (auto& e : fs::directory_iterator(out_))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
}

// A PNG write error (files limited to 2 KiB: libpng's first 4 KiB write fails) is eikon's one
// line, naming the file and libpng's reason; libpng's own "libpng error: Write Error" line used to
// come first. --transport single keeps the sphere visible in the constant sky (full transport
// makes it vanish there, and the PNG would compress below the limit).
TEST_F(Cli, PngWriteErrorIsOneEikonLine) {
  const std::string scene = write("scene.json", tinyScene());
  const Outcome r = eikon::test::runProgramWithFileLimit(
      EIKON_BINARY,
      "render " + quote(scene) + " -q --reference --transport single --width 160 --height 120 -o " +
          quote(outPath()),
      io_, 2048);
  expectCleanFailure(
      r, "cannot write '" + outPath("render.png") + "': libpng: Write Error (File too large)");
  EXPECT_EQ(r.err.find("libpng error"), std::string::npos) << r.err;
}

// An output that is one of the render's inputs is refused with one line and the input is left as
// it was: -o naming the environment map (directly or through a symbolic link), or a scene file
// whose name is where the PNG preview would go. Both used to be overwritten with exit 0.
TEST_F(Cli, RenderRefusesToOverwriteItsInputs) {
  const std::vector<float> sky(8 * 4 * 3, 0.5f);
  eikon::writeExrRgb(dir_ / "sky.exr", 8, 4, sky);
  const std::string sky_bytes = slurp(dir_ / "sky.exr");
  std::string text = tinyScene();
  const std::string checker = R"({"type": "checker", "squares": 8})";
  text.replace(text.find(checker), checker.size(), R"({"type": "latlong", "file": "sky.exr"})");
  const std::string scene = write("scene.json", text);
  Outcome r =
      run("render " + quote(scene) + " -q --reference -o " + quote((dir_ / "sky.exr").string()));
  expectCleanFailure(r, "is the scene's environment map", fs::path());
  EXPECT_EQ(slurp(dir_ / "sky.exr"), sky_bytes);
  EXPECT_FALSE(fs::exists(dir_ / "sky.png"));
  // The same file under another name.
  fs::create_symlink(dir_ / "sky.exr", dir_ / "link.exr");
  r = run("render " + quote(scene) + " -q --reference -o " + quote((dir_ / "link.exr").string()));
  expectCleanFailure(r, "refusing to overwrite an input", fs::path());
  EXPECT_TRUE(fs::is_symlink(dir_ / "link.exr"));
  EXPECT_EQ(slurp(dir_ / "sky.exr"), sky_bytes);
  // The PNG preview beside -o would replace the scene file.
  const std::string odd = write("odd.png", tinyScene());
  r = run("render " + quote(odd) + " -q --reference -o " + quote((dir_ / "odd.exr").string()));
  expectCleanFailure(r, "is the scene file", fs::path());
  EXPECT_EQ(slurp(dir_ / "odd.png"), tinyScene());
  // A scene beside its outputs is fine when the names differ.
  r = run("render " + quote(scene) + " -q --reference -o " + quote((dir_ / "scene.exr").string()));
  EXPECT_EQ(r.code, 0) << r.err;
}

TEST_F(Cli, RenderOutputMustEndInExr) {
  const std::string scene = write("scene.json", tinyScene());
  expectCleanFailure(run("render " + quote(scene) + " -o " + quote(outPath("render.png"))), ".exr");
}

TEST_F(Cli, RenderSppZero) { expectCleanFailure(render(tinyScene(), "--spp 0"), "--spp"); }

// A given size must be a size: --width 0 used to render at the scene's width with exit 0, and
// --wavelengths -1 at the default. Not given still means the scene's value (RenderTinyScene).
TEST_F(Cli, RenderZeroOrNegativeSizesAreRejected) {
  for (const char* bad :
       {"--width 0", "--height 0", "--width -5", "--height -1", "--spp -2", "--wavelengths -1"}) {
    const std::string flag = std::string(bad).substr(0, std::string(bad).find(' '));
    const Outcome r = render(tinyScene(), bad);
    expectCleanFailure(r, flag + " must be in [");
    EXPECT_NE(r.err.find("got " + std::string(bad).substr(flag.size() + 1)), std::string::npos)
        << r.err;
  }
}

TEST_F(Cli, RenderSceneFileMissing) {
  expectCleanFailure(
      run("render " + quote((dir_ / "nope.json").string()) + " -o " + quote(outPath())),
      "nope.json");
}

// CLI-syntax errors (a missing required option, an unknown flag) are bad input too: docs/design.md
// §4 / the CLI contract say one "eikon: error:" line and a non-zero exit, like every other error.
TEST_F(Cli, RenderMissingOutputOptionIsOneErrorLine) {
  const std::string scene = write("scene.json", tinyScene());
  expectCleanFailure(run("render " + quote(scene)), "--output");
}

TEST_F(Cli, UnknownOptionIsOneErrorLine) {
  const std::string scene = write("scene.json", tinyScene());
  expectCleanFailure(run("render " + quote(scene) + " -o " + quote(outPath()) + " --bogus"),
                     "--bogus");
}

// "eikon bogus" said "A subcommand is required", as if none had been given.
TEST_F(Cli, UnknownCommandIsNamedWithTheCommands) {
  for (const char* args : {"bogus", "bogus render", "Render x.json"}) {
    const Outcome r = run(args);
    const std::string word = std::string(args).substr(0, std::string(args).find(' '));
    expectCleanFailure(
        r, "'" + word +
               "' is not an eikon command (render, trace, info, fit, view, gem, sweep; run "
               "with --help)");
  }
  expectCleanFailure(run(""), "a command is required: render, trace, info, fit, view, gem, sweep");
}

// An empty number (--width "") was converted to 0: "--width must be in [1, 16384], got 0", and
// --exposure "" and --threads "" were taken as 0 without a word.
TEST_F(Cli, EmptyNumberIsSaidToBeEmpty) {
  const std::string scene = write("scene.json", tinyScene());
  for (const char* option : {"--width", "--spp", "--exposure", "--threads"})
    expectCleanFailure(
        run("render " + quote(scene) + " -o " + quote(outPath()) + " " + option + " ''"),
        std::string(option) + ": the value is empty, expected a number");
  expectCleanFailure(run("trace " + quote(scene) + " --origin 0,0,-5 --dir 0,0,1 --wavelength ' '"),
                     "--wavelength: the value is empty, expected a number");
  EXPECT_EQ(render(tinyScene(), "--width 16 -q").code, 0);
}

// A scene of 70 000 objects printed ~22 000 warnings before the error that 65 535 is the most.
TEST_F(Cli, TooManyObjectsIsTheOnlyLine) {
  std::string objects;
  for (int i = 0; i < 70000; ++i)
    objects += std::string(i ? ", " : "") +
               R"({"shape": "sphere", "center": [0, 0, 0], "radius": 50, "material": "glass"})";
  const std::string text = tinyScene();
  const size_t at = text.find(R"("objects": [)");
  ASSERT_NE(at, std::string::npos);
  expectCleanFailure(render(text.substr(0, at) + R"("objects": [)" + objects + "]}"),
                     "/objects: sharp interfaces allow at most 65535 objects, got 70000");
}

// ------------------------------------------------------------------ trace

TEST_F(Cli, TraceZeroDirection) {
  const std::string scene = write("scene.json", tinyScene());
  expectCleanFailure(run("trace " + quote(scene) + " --origin 0,0,-4 --dir 0,0,0"), "--dir");
}

TEST_F(Cli, TraceOriginWithTwoNumbers) {
  const std::string scene = write("scene.json", tinyScene());
  expectCleanFailure(run("trace " + quote(scene) + " --origin 1,2 --dir 0,0,1"), "--origin");
}

TEST_F(Cli, TraceNegativeWavelength) {
  const std::string scene = write("scene.json", tinyScene());
  expectCleanFailure(run("trace " + quote(scene) + " --origin 0,0,-4 --dir 0,0,1 --wavelength -5"),
                     "--wavelength");
}

// Indices are checked over 380–780 nm when the scene is read, but a trace may ask for any
// wavelength in [100, 10000] nm. A Sellmeier term B = 1, C = 0.04 µm² has its pole at 200 nm:
// n² = 1 + λ²/(λ² − 0.04) is −98 at 199 nm (no index) and 102 at 201 nm (n = 10.1), and n = 1.67
// at 300 nm. The first two used to trace (the GPU twin printed an OPL of ~59 m) or fail inside
// Fresnel's laws without naming anything.
TEST_F(Cli, TraceWavelengthWhereAnIndexLeavesItsRangeIsRefused) {
  const std::string scene =
      write("scene.json", tinyScene("", R"({"n": {"sellmeier": [1.0, 0.04]}})"));
  for (const char* nm : {"199", "201"})
    for (const char* twin : {"", " --reference"})
      expectCleanFailure(
          run("trace " + quote(scene) + " --origin 0,0,-4 --dir 0,0,1 --wavelength " + nm + twin),
          "--wavelength leaves the index of material 'glass' outside [1, 10]");
  const Outcome fine =
      run("trace " + quote(scene) + " --origin 0,0,-4 --dir 0,0,1 --wavelength 300 -q");
  EXPECT_EQ(fine.code, 0) << fine.err;
}

// An origin at z = −1e300 printed an exit at −inf and NaN Stokes with exit code 0 (--json: null):
// it is bounded as a scene's positions are, ±1e12 mm.
TEST_F(Cli, TraceOriginBeyondTheCoordinateLimit) {
  const std::string scene = write("scene.json", tinyScene());
  for (const char* asJson : {"", " --json"}) {
    const Outcome r = run("trace " + quote(scene) + " -q --origin 0,2,-1e300 --dir 0,0,1" + asJson);
    expectCleanFailure(r, "--origin must be within ±1e12 mm");
    EXPECT_EQ(r.out, "");
  }
}

// A denormal direction (1e-320 is finite) is refused for being zero, not as "not finite".
TEST_F(Cli, TraceDenormalDirectionIsZeroNotNonFinite) {
  const std::string scene = write("scene.json", tinyScene());
  const Outcome r = run("trace " + quote(scene) + " -q --origin 0,0,-4 --dir 0,0,1e-320");
  expectCleanFailure(r, "--dir must be a non-zero vector");
  EXPECT_EQ(r.err.find("finite"), std::string::npos) << r.err;
}

// --origin and --dir take --stokes's parser (parseNumberList): a trailing comma, an empty field,
// hexadecimal and an empty value were accepted or read in part.
TEST_F(Cli, TraceOriginAndDirAreThreeDecimalNumbersAndNothingElse) {
  const std::string scene = write("scene.json", tinyScene());
  for (const char* bad : {"", "0,0,-4,", "0,,0,-4", "0x0,0,-4", "0,0,-4;", "0,0,-4e"}) {
    expectCleanFailure(
        run("trace " + quote(scene) + " -q --origin " + quote(bad) + " --dir 0,0,1"),
        "--origin must be three finite numbers x,y,z, got '" + std::string(bad) + "'");
    expectCleanFailure(run("trace " + quote(scene) + " -q --origin 0,0,-4 --dir " + quote(bad)),
                       "--dir must be three finite numbers x,y,z, got '" + std::string(bad) + "'");
  }
  EXPECT_EQ(run("trace " + quote(scene) + " -q --origin ' 0, 0,-4.0e0' --dir +0,-0,1.").code, 0);
}

TEST_F(Cli, TraceNonFiniteOrigin) {
  const std::string scene = write("scene.json", tinyScene());
  expectCleanFailure(run("trace " + quote(scene) + " --origin 0,nan,-4 --dir 0,0,1"), "--origin");
}

// A ray parallel to the axis at height y0 = 1.5 mm through a glass sphere (n = 1.5, r = 3 mm)
// starting inside the volume at z = −4.9, wavelength 550 nm.
struct TraceCase {
  std::string args = "--origin 0,1.5,-4.9 --dir 0,0,1 --wavelength 550 --json";
};

json parseTrace(const Outcome& r) {
  json j;
  try {
    j = json::parse(r.out);
  } catch (const std::exception& e) {
    ADD_FAILURE() << "trace --json did not print JSON (" << e.what() << "):\n" << r.out;
  }
  return j;
}

TEST_F(Cli, TraceJsonIsotropic) {
  const std::string scene = write("scene.json", tinyScene());
  const Outcome r = run("trace " + quote(scene) + " " + TraceCase{}.args);
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = parseTrace(r);
  ASSERT_TRUE(j.is_object());
  EXPECT_DOUBLE_EQ(j.at("wavelength_nm").get<double>(), 550.0);
  ASSERT_TRUE(j.at("modes").is_array());
  ASSERT_EQ(j.at("modes").size(), 2u);
  EXPECT_EQ(j["modes"][0].at("mode"), "o");
  EXPECT_EQ(j["modes"][1].at("mode"), "e");
  for (const auto& m : j["modes"]) {
    for (const char* k : {"exit_point", "exit_direction", "wave_normal"}) {
      ASSERT_TRUE(m.at(k).is_array()) << k;
      ASSERT_EQ(m.at(k).size(), 3u) << k;
    }
    ASSERT_TRUE(m.at("optical_path_mm").is_number());
    ASSERT_TRUE(m.at("transmittance").is_number());
    const auto d = m["exit_direction"].get<std::vector<double>>();
    const auto w = m["wave_normal"].get<std::vector<double>>();
    // Unit vectors: the tracer normalises in double (or float: 1 ulp ≈ 6e-8) ⇒ 1e-6.
    EXPECT_NEAR(std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), 1.0, 1e-6);
    EXPECT_NEAR(std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]), 1.0, 1e-6);
    // Isotropic: wave normal = ray direction.
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(d[size_t(i)], w[size_t(i)], 1e-6);
    // A sphere is a converging lens: a ray entering at y = +1.5 leaves heading down (−y) and
    // still forward (+z), out of the volume (|coordinate| = 5 on some face).
    EXPECT_LT(d[1], -0.05);
    EXPECT_GT(d[2], 0.5);
    const auto p = m["exit_point"].get<std::vector<double>>();
    const double face = std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])});
    EXPECT_NEAR(face, 5.0, 0.01) << "exit point should lie on the volume boundary";
    // Fresnel losses at two air-glass faces (normal incidence R = 4% each): 0.85 < T < 1.
    const double T = m["transmittance"];
    EXPECT_GT(T, 0.85);
    EXPECT_LE(T, 1.0);
    // Optical path ≥ geometric path from origin to exit (n ≥ 1 everywhere) and ≥ the straight
    // distance, which is ≥ 9.9 − a little.
    EXPECT_GT(m["optical_path_mm"].get<double>(), 9.0);
  }
  EXPECT_EQ(j["modes"][0]["exit_point"], j["modes"][1]["exit_point"]);
}

// The axial ray from the volume face z = −5 through the sphere's centre, both twins.
//  * Symmetry: the grid is symmetric about the axis, so the ray stays on it: exit (0, 0, 5),
//    direction (0, 0, 1) up to float32 rounding (GPU) ⇒ 1e-5.
//  * Optical path: 4 mm of air + 2r = 6 mm of n = 1.5 ⇒ 13 mm. The voxelised surface is placed
//    within ±h/2 (h = 0.3125 mm) at each crossing ⇒ ±(n − 1)·h = ±0.16 mm, and smoothing with
//    σ = 0.75 h shortens the central chord by 2σ²/r ⇒ −0.018 mm ⇒ tolerance 0.2 mm.
//  * Transmittance: Fresnel at normal incidence, R = ((n − 1)/(n + 1))² = 0.04 per surface,
//    T = 0.96² = 0.9216; ±2e-3 ⇔ R within ±1e-3 per surface ⇔ the index contrast within ±1%.
TEST_F(Cli, TraceAxialRayPhysics) {
  const std::string scene = write("scene.json", tinyScene());
  for (const char* twin : {"", " --reference"}) {
    const Outcome r = run("trace " + quote(scene) + " --origin 0,0,-5 --dir 0,0,1 --json" + twin);
    ASSERT_EQ(r.code, 0) << r.err;
    const json j = parseTrace(r);
    ASSERT_TRUE(j.is_object());
    const json& m = j["modes"][0];
    const auto p = m["exit_point"].get<std::vector<double>>();
    const auto d = m["exit_direction"].get<std::vector<double>>();
    EXPECT_NEAR(p[0], 0.0, 1e-5) << twin;
    EXPECT_NEAR(p[1], 0.0, 1e-5) << twin;
    EXPECT_NEAR(p[2], 5.0, 1e-5) << twin;
    EXPECT_NEAR(d[2], 1.0, 1e-5) << twin;
    const double opl = m["optical_path_mm"], T = m["transmittance"];
    std::printf("[ measured ]%s axial OPL %.6f mm (expected 13), T %.6f (expected 0.9216)\n", twin,
                opl, T);
    EXPECT_NEAR(opl, 13.0, 0.2) << twin;
    EXPECT_NEAR(T, 0.9216, 2e-3) << twin;
  }
}

// The text output carries what --json carries: interfaces crossed, total internal reflections and
// steps. The axial ray through the sphere crosses exactly 2 interfaces (in, out) and is never
// totally reflected (normal incidence). An isotropic scene prints one "o=e" line and says the modes
// coincide; a uniaxial one prints o and e.
TEST_F(Cli, TraceTextShowsCountsAndIsotropicModes) {
  const std::string iso = write("scene.json", smoothedScene(tinyScene()));
  for (const char* twin : {"", " --reference"}) {
    const Outcome r = run("trace " + quote(iso) + " --origin 0,0,-5 --dir 0,0,1" + twin);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("isotropic scene: the o and e modes coincide"), std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("  o=e: exit ("), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("  o: "), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("  e: "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(" 2 interfaces crossed, 0 total internal reflections, "),
              std::string::npos)
        << r.out;
    // Steps: homogeneous runs are crossed in long straight steps, so only a lower bound is sure:
    // the 6 mm inside the sphere's smoothed surface region alone takes well over 10 steps of 0.25
    // h.
    const auto at = r.out.find(" total internal reflections, ");
    ASSERT_NE(at, std::string::npos);
    const int steps =
        std::stoi(r.out.substr(at + std::string(" total internal reflections, ").size()));
    EXPECT_GT(steps, 10) << r.out;
    EXPECT_NE(r.out.find(std::to_string(steps) + " steps\n"), std::string::npos) << r.out;
  }
  // Uniaxial (calcite-like, optic axis across the ray): two mode lines, each with its counts.
  const std::string uni =
      write("uni.json", tinyScene("", R"({"n_o": 1.658, "n_e": 1.486, "optic_axis": [0, 1, 0]})"));
  const Outcome r = run("trace " + quote(uni) + " --origin 0,0,-5 --dir 0,0,1 --reference");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.find("coincide"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  o: exit ("), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  e: exit ("), std::string::npos) << r.out;
  size_t count = 0;
  for (size_t p = r.out.find(" 2 interfaces crossed, 0 total internal reflections, ");
       p != std::string::npos;
       p = r.out.find(" 2 interfaces crossed, 0 total internal reflections, ", p + 1))
    ++count;
  EXPECT_EQ(count, 2u) << r.out;
}

// GPU (float32) vs CPU reference (double) on the same voxel field and the same step size.
// Tolerance 1e-4 mm on the exit point: the two differ by float32 rounding only. Positions of
// |x| ≤ 5 mm carry 3e-7 mm per step; ≈ 200 steps add up to ≤ 6e-5 mm if every rounding had the
// same sign, and the refraction at the sphere turns a direction error δ (≈ 1e-6 rad) into
// ≤ 1e-5 mm over the 10 mm path ⇒ 1e-4 mm. The directions are compared to 1e-4 likewise.
TEST_F(Cli, TraceGpuAgreesWithReference) {
  const std::string scene = write("scene.json", smoothedScene(tinyScene()));
  const Outcome gpu = run("trace " + quote(scene) + " " + TraceCase{}.args);
  ASSERT_EQ(gpu.code, 0) << gpu.err;
  const Outcome cpu = run("trace " + quote(scene) + " " + TraceCase{}.args + " --reference");
  ASSERT_EQ(cpu.code, 0) << cpu.err;
  const json g = parseTrace(gpu), c = parseTrace(cpu);
  ASSERT_TRUE(g.is_object() && c.is_object());
  const auto pg = g["modes"][0]["exit_point"].get<std::vector<double>>();
  const auto pc = c["modes"][0]["exit_point"].get<std::vector<double>>();
  const auto dg = g["modes"][0]["exit_direction"].get<std::vector<double>>();
  const auto dc = c["modes"][0]["exit_direction"].get<std::vector<double>>();
  double dp = 0, dd = 0;
  for (size_t i = 0; i < 3; ++i) {
    dp = std::max(dp, std::abs(pg[i] - pc[i]));
    dd = std::max(dd, std::abs(dg[i] - dc[i]));
  }
  std::printf(
      "[ measured ] GPU vs reference: exit point %.2e mm, direction %.2e; OPL %.9f vs %.9f\n", dp,
      dd, g["modes"][0]["optical_path_mm"].get<double>(),
      c["modes"][0]["optical_path_mm"].get<double>());
  EXPECT_LT(dp, 1e-4);
  EXPECT_LT(dd, 1e-4);
  // The ray was actually bent (the comparison is not trivially between two straight lines).
  EXPECT_GT(std::abs(pc[1] - 1.5), 0.1);
}

// ------------------------------------------------------------------ lights

// Sharp interfaces: the light follows the scene's "interfaces" on both twins, and its Fresnel
// reflections as reflected wavefronts up to LightingOptions::max_reflection_generations. The
// summary reports the reflected flux not followed, as a share of the emitted flux: less than the
// least the light would lose without reflected wavefronts, the normal-incidence loss of the lit
// disc's two passes, 1 − (1 − R₀)² = 0.0784 times the disc's share πR²/(10 mm)² = 0.196 of the
// light over the box (what is dropped is the reflection of the last generation followed inside the
// ball, (1 − R₀)R₀⁵ of a ray at normal incidence, and the loss of patches the rim tears); a
// smoothed scene reflects nothing.
TEST_F(Cli, LightSummaryReportsTheFluxReflectedAtSharpInterfaces) {
  const std::string scene = R"({
  "camera": {"position": [0, 20, -20], "look_at": [0, -2, 0], "up": [0, 1, 0], "fov_deg": 30, "width": 16, "height": 12},
  "environment": {"type": "constant", "radiance": 0.1},
  "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": 24},
  INTERFACES
  "materials": {"glass": {"n": 1.5}, "floor": {"n": 1, "opacity": 1, "albedo": 0.8}},
  "objects": [{"shape": "box", "center": [0, -3.5, 0], "size": [8, 1, 8], "material": "floor"},
              {"shape": "sphere", "center": [0, 0.5, 0], "radius": 2.5, "material": "glass"}],
  "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 2}]
})";
  auto reflected = [&](const std::string& interfaces, const std::string& device) {
    std::string text = scene;
    text.replace(text.find("INTERFACES"), 10, "\"interfaces\": \"" + interfaces + "\",");
    const Outcome o = render(text, "-q --caustics kill --no-light-cache --light-device " + device);
    EXPECT_EQ(o.code, 0) << o.err;
    const size_t at = o.out.find("reflected ");
    EXPECT_NE(at, std::string::npos) << o.out;
    return at == std::string::npos ? -1.0 : std::strtod(o.out.c_str() + at + 10, nullptr);
  };
  const double disc = std::numbers::pi * 2.5 * 2.5 / 100.0;
  for (const char* device : {"cpu", "gpu"}) {
    const double r = reflected("sharp", device);
    EXPECT_LT(r, 0.0784 * disc) << device;
  }
  EXPECT_EQ(reflected("smoothed", "cpu"), 0.0);
}

// --light-reflections N follows N generations of reflected wavefronts at sharp interfaces: with
// none, every Fresnel reflection of the sphere's two crossings is dropped into flux_reflected;
// with the default 4 the first ones go on as patches, so less is dropped (docs/light-simulator.md
// "Reflected wavefronts"). The sphere reflects at least R(0) = 4% of what reaches it at the top.
TEST_F(Cli, LightReflectionsZeroDropsMoreReflectedFlux) {
  const std::string scene = R"({
  "camera": {"position": [0, 20, -20], "look_at": [0, -2, 0], "up": [0, 1, 0], "fov_deg": 30, "width": 16, "height": 12},
  "environment": {"type": "constant", "radiance": 0.1},
  "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": 24},
  "interfaces": "sharp",
  "materials": {"glass": {"n": 1.5}, "floor": {"n": 1, "opacity": 1, "albedo": 0.8}},
  "objects": [{"shape": "box", "center": [0, -3.5, 0], "size": [8, 1, 8], "material": "floor"},
              {"shape": "sphere", "center": [0, 0.5, 0], "radius": 2.5, "material": "glass"}],
  "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 2}]
})";
  auto reflected = [&](const std::string& options) {
    const Outcome o =
        render(scene, "-q --caustics kill --no-light-cache --light-device cpu " + options);
    EXPECT_EQ(o.code, 0) << o.err;
    const size_t at = o.out.find("reflected ");
    EXPECT_NE(at, std::string::npos) << o.out;
    return at == std::string::npos ? -1.0 : std::strtod(o.out.c_str() + at + 10, nullptr);
  };
  const double disc = std::numbers::pi * 2.5 * 2.5 / 100.0;  // the sphere's share of the flux
  const double none = reflected("--light-reflections 0"), four = reflected("");
  EXPECT_GT(none, 0.04 * disc);
  EXPECT_GT(none, four);
  EXPECT_EQ(reflected("--light-reflections 4"), four);
  const Outcome bad = render(scene, "-q --light-reflections 65");
  EXPECT_NE(bad.code, 0);
  EXPECT_NE(bad.err.find("--light-reflections must be in [0, 64]"), std::string::npos) << bad.err;
}

// A lit floor under the tiny glass sphere: the light is simulated once and then read back from
// the cache (keyed by the medium, the lights and the simulator settings, never the camera), and
// the cached render is the same picture. The sphere sits a little off the light's seed lattice,
// so that no seed corner runs exactly tangent to it, a contact float and double decide
// differently (tests/core/render/sharp_wavefront_twins_test.cpp, GlassSphereIrradianceAgrees).
TEST_F(Cli, RenderSimulatesLightOnceThenUsesTheCache) {
  const std::string scene = R"({
  "camera": {"position": [0, 20, -20], "look_at": [0, -2, 0], "up": [0, 1, 0], "fov_deg": 30, "width": 32, "height": 24},
  "environment": {"type": "constant", "radiance": 0.1},
  "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": 24},
  "materials": {"glass": {"n": 1.5}, "floor": {"n": 1, "opacity": 1, "albedo": 0.8}},
  "objects": [{"shape": "box", "center": [0, -3.5, 0], "size": [8, 1, 8], "material": "floor"},
              {"shape": "sphere", "center": [0.0123, 0.5, -0.0071], "radius": 2.5, "material": "glass"}],
  "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 2}]
})";
  const std::string cache = (dir_ / "cache").string();
  const Outcome first = render(scene, "-q --caustics kill --light-cache " + quote(cache));
  ASSERT_EQ(first.code, 0) << first.err;
  EXPECT_NE(first.out.find("simulated 1 light runs"), std::string::npos) << first.out;
  EXPECT_NE(first.out.find("flux balance"), std::string::npos) << first.out;
  const std::vector<float> a = eikon::readExrRgba(outPath(), 64, 64).rgba;
  // A different camera: the light is not simulated again.
  std::string moved = scene;
  moved.replace(moved.find("[0, 20, -20]"), 12, "[0, 21, -20]");
  const Outcome second = render(moved, "-q --caustics kill --light-cache " + quote(cache));
  ASSERT_EQ(second.code, 0) << second.err;
  EXPECT_NE(second.out.find("light volumes from the cache"), std::string::npos) << second.out;
  // Same camera, cached light: the same picture as the first, simulated, render.
  const Outcome third = render(scene, "-q --caustics kill --light-cache " + quote(cache));
  ASSERT_EQ(third.code, 0) << third.err;
  const std::vector<float> c = eikon::readExrRgba(outPath(), 64, 64).rgba;
  ASSERT_EQ(a.size(), c.size());
  EXPECT_EQ(a, c);
  // A moved light is simulated anew.
  std::string relit = scene;
  relit.replace(relit.find("[0, -1, 0]"), 10, "[0.1, -1, 0]");
  const Outcome fourth = render(relit, "-q --caustics kill --light-cache " + quote(cache));
  ASSERT_EQ(fourth.code, 0) << fourth.err;
  EXPECT_NE(fourth.out.find("simulated 1 light runs"), std::string::npos) << fourth.out;
  // The lit floor is brighter than the unlit one (environment only).
  const Outcome dark = render(scene, "-q --no-light");
  ASSERT_EQ(dark.code, 0) << dark.err;
  const std::vector<float> d = eikon::readExrRgba(outPath(), 64, 64).rgba;
  double lit_sum = 0, dark_sum = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (i % 4 == 3) continue;  // RGBA: alpha is 1 everywhere
    lit_sum += a[i];
    dark_sum += d[i];
  }
  // The floor fills about a third of the view and shows 0.8·2/π = 0.51 when lit, 0 when not; the
  // environment (0.1) is the same in both.
  EXPECT_GT(lit_sum, 1.3 * dark_sum);
  // The GPU simulator gives the same picture as the CPU reference (the default on lavapipe): the
  // twins' light volumes agree to ~1e-5 (tests/core/render/wavefront_gpu_test.cpp); allow 1e-3 of
  // the sum.
  const Outcome gpu = render(scene, "-q --caustics kill --no-light-cache --light-device gpu");
  ASSERT_EQ(gpu.code, 0) << gpu.err;
  EXPECT_NE(gpu.out.find("simulated 1 light runs on llvmpipe"), std::string::npos) << gpu.out;
  const std::vector<float> g = eikon::readExrRgba(outPath(), 64, 64).rgba;
  double diff = 0;
  for (size_t i = 0; i < a.size(); ++i) diff += std::abs(double(g[i]) - a[i]);
  EXPECT_LT(diff, 1e-3 * lit_sum);
}

// The light volumes show only where a material has an albedo (in-scatter, a diffuse surface):
// without one the lights are not simulated (a lit faceted gem took an hour for no pixel), the
// user is told why, and the picture is the unlit one.
TEST_F(Cli, LightsWithoutAnAlbedoAreNotSimulated) {
  const std::string scene = R"({
  "camera": {"position": [0, 20, -20], "look_at": [0, -2, 0], "up": [0, 1, 0], "fov_deg": 30, "width": 32, "height": 24},
  "environment": {"type": "constant", "radiance": 0.1},
  "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": 24},
  "materials": {"glass": {"n": 1.5}, "floor": {"n": 1, "opacity": 1}},
  "objects": [{"shape": "box", "center": [0, -3.5, 0], "size": [8, 1, 8], "material": "floor"},
              {"shape": "sphere", "center": [0, 0.5, 0], "radius": 2.5, "material": "glass"}],
  "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 2}]
})";
  const Outcome lit = render(scene, "-q --no-light-cache");
  ASSERT_EQ(lit.code, 0) << lit.err;
  EXPECT_NE(lit.err.find("the lights are not simulated: no material has an albedo"),
            std::string::npos)
      << lit.err;
  EXPECT_EQ(lit.out.find("simulated"), std::string::npos) << lit.out;
  const std::vector<float> a = eikon::readExrRgba(outPath(), 64, 64).rgba;
  const Outcome dark = render(scene, "-q --no-light");
  ASSERT_EQ(dark.code, 0) << dark.err;
  EXPECT_EQ(dark.err.find("not simulated"), std::string::npos) << dark.err;
  EXPECT_EQ(a, eikon::readExrRgba(outPath(), 64, 64).rgba);
}

// The GPU twin's accumulation volume takes 36 bytes a voxel (EIKON_SPLAT_ACC_WORDS + 1 words) in
// one storage buffer: a grid larger than the device's limit (`eikon info`) is refused before any
// work with one line that names the remedy, and `--light-device auto` takes the CPU twin there.
TEST_F(Cli, LightVolumeLargerThanTheGpuHoldsIsRefusedOrSimulatedOnTheCpu) {
  const Outcome info = run("info");
  ASSERT_EQ(info.code, 0) << info.err;
  const size_t at = info.out.find("max storage buffer:");
  ASSERT_NE(at, std::string::npos) << info.out;
  const double mib = std::stod(info.out.substr(at + 19));
  // A cube of n³ voxels with 36·n³ bytes just over the limit.
  const int n = int(std::ceil(std::cbrt(mib * 1048576.0 / 36.0))) + 1;
  if (n > 400) GTEST_SKIP() << "the device holds " << mib << " MiB: a test grid would be too large";
  const std::string scene = R"({
  "camera": {"position": [0, 20, -20], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30, "width": 8, "height": 6},
  "environment": {"type": "constant", "radiance": 0.1},
  "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": )" +
                            std::to_string(n) + R"(},
  "materials": {"floor": {"n": 1, "opacity": 1, "albedo": 0.8}},
  "objects": [{"shape": "box", "center": [0, -4.5, 0], "size": [10, 1, 10], "material": "floor"}],
  "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 1}]
})";
  const std::string args = "-q --no-light-cache --light-split 8 --light-step 2 --max-patches 1024 ";
  expectCleanFailure(render(scene, args + "--light-device gpu"),
                     "voxels needs " + std::to_string(int64_t(36.0 * n * n * n) >> 20) +
                         " MiB of one storage buffer");
  const Outcome cpu = render(scene, args + "--light-device auto");
  ASSERT_EQ(cpu.code, 0) << cpu.err;
  EXPECT_NE(cpu.out.find("on the CPU reference"), std::string::npos) << cpu.out;
}

TEST_F(Cli, BadLightOptionsFailCleanly) {
  expectCleanFailure(render(tinyScene(), "--light-bands 100"), "--light-bands");
  expectCleanFailure(render(tinyScene(), "--light-splat brightest"),
                     "--light-splat must be accumulate or highest");
  expectCleanFailure(render(tinyScene(), "--max-patches 10"), "--max-patches");
  expectCleanFailure(render(tinyScene(), "--light-split 0.1"), "--light-split");
  expectCleanFailure(render(tinyScene(), "--light-device tpu"),
                     "--light-device must be auto, gpu or cpu");
  expectCleanFailure(render(tinyScene(), "--caustics ignore"), "--caustics must be pass or kill");
  expectCleanFailure(render(tinyScene(), "--threads -7 --no-light"),
                     "--threads must be in [1, 1024], or 0 for all cores");
  expectCleanFailure(render(tinyScene(), "--light-step -1"),
                     "--light-step must be in (0, 2] voxels, or 0 for the default (0.5)");
}

// Values that used to pass unchecked: a NaN exposure (a black PNG), a bad --progress beside -q
// (the word was never read).
TEST_F(Cli, ExposureAndProgressAreCheckedEvenWhenUnused) {
  expectCleanFailure(render(tinyScene(), "--exposure nan"), "--exposure must be in [-64, 64]");
  expectCleanFailure(render(tinyScene(), "--exposure 1e6"), "--exposure must be in [-64, 64]");
  expectCleanFailure(render(tinyScene(), "-q --progress sometimes"),
                     "--progress must be auto, always or never");
  // The value as it was given, not std::to_string's 301 digits of 1e300.
  const Outcome huge = render(tinyScene(), "--exposure 1e300");
  expectCleanFailure(huge, "--exposure must be in [-64, 64] stops, got 1e+300");
  EXPECT_LT(huge.err.size(), 80u) << huge.err;
  EXPECT_EQ(render(tinyScene(), "-q --exposure -64").code, 0);
}

// An image the host cannot hold is refused before anything is voxelised, with the numbers, where
// it used to end in a bare "std::bad_alloc": under a 1 GiB address-space limit a 16384² image
// (3 channels, about 12 bytes each measured: 9.7 GB) cannot fit.
TEST_F(Cli, ImageLargerThanTheHostHoldsIsRefusedWithTheNumbers) {
  if (eikon::test::kAddressSanitizer) GTEST_SKIP() << eikon::test::kNoAddressSpaceLimitUnderAsan;
  const std::string scene = write("scene.json", tinyScene());
  const Outcome limited = eikon::test::runProgram(
      "ulimit -v 1048576; " + std::string(EIKON_BINARY),
      "render " + quote(scene) + " -o " + quote(outPath()) + " --width 16384 --height 16384", io_);
  expectCleanFailure(limited, "a 16384x16384 image of 3 channels a pixel needs about");
  EXPECT_NE(limited.err.find("of host memory"), std::string::npos) << limited.err;
}

// A march cut short (here by a step so small that no ray gets through the object's layer within
// the march's 20000 steps) is counted and warned about, and --strict makes it an error that
// leaves no output.
TEST_F(Cli, MarchesAndLightCutShortAreSaid) {
  std::string smoothed = tinyScene();
  smoothed.insert(1, R"("interfaces": "smoothed",)");  // a layer marched step by step
  const Outcome warned = render(smoothed, "--step 1e-30 --no-light");
  ASSERT_EQ(warned.code, 0) << warned.err;
  EXPECT_NE(warned.err.find("pixel samples were cut short and lack the light"), std::string::npos)
      << warned.err;
  fs::remove(outPath("render.exr"));
  fs::remove(outPath("render.png"));
  expectCleanFailure(render(smoothed, "--step 1e-30 --no-light --strict"),
                     "pixel samples were cut short");
  const Outcome clean = render(smoothed, "--no-light");
  ASSERT_EQ(clean.code, 0) << clean.err;
  EXPECT_EQ(clean.err.find("cut short"), std::string::npos) << clean.err;
}

}  // namespace
