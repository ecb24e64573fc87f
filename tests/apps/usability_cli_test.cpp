// What a newcomer meets, run through the real `eikon` binary: a misspelt material is answered
// with the closest names and the library's list; `eikon info` lists the library; silent mistakes
// (an unlit diffuse floor, a beam that misses everything) are warned about, and --strict refuses
// them; a scene's "render" sets the render's defaults under the options; the cache folder keeps
// to EIKON_CACHE_MAX_MB.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/apps/cli_support.h"

namespace {

namespace fs = std::filesystem;
using eikon::test::Outcome;
using eikon::test::quote;

class Usability : public ::testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir() / name) << text;
    return (dir() / name).string();
  }
  Outcome run(const std::string& args, const std::string& env = "") const {
    return eikon::test::runEikon(
        args, dir() / "io",
        "EIKON_VALIDATION=1 EIKON_CACHE_DIR=" + quote((dir() / "cache").string()) + " " + env);
  }
  Outcome render(const std::string& scene_text, const std::string& extra,
                 const std::string& env = "") const {
    return run("render " + quote(write("scene.json", scene_text)) + " -o " +
                   quote((dir() / "out" / "r.exr").string()) + " " + extra,
               env);
  }
  const fs::path& dir() const { return tmp_.path(); }
  eikon::test::TempDir tmp_{"eikon_usability"};
};

std::vector<std::string> shippedMaterials() {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(fs::path(EIKON_SOURCE_DIR) / "materials"))
    if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
  return names;
}

std::string sphereOf(const std::string& material, const std::string& top = "") {
  return R"({)" + top +
         R"("camera": {"position": [0, 0, -30], "look_at": [0, 0, 0], "fov_deg": 30, "width": 16, "height": 12},
    "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 16},
    "objects": [{"shape": "sphere", "radius": 3, "material": ")" +
         material + R"("}]})";
}

TEST_F(Usability, AMisspeltMaterialIsAnsweredWithTheClosestAndTheList) {
  const Outcome r = render(sphereOf("N-BK8"), "-q");
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(r.err.rfind("eikon: error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("/objects/0/material: unknown material 'N-BK8'"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("did you mean 'N-BK7'?"), std::string::npos) << r.err;
  for (const std::string& name : shippedMaterials())
    EXPECT_NE(r.err.find(name), std::string::npos) << name << ": " << r.err;
  EXPECT_FALSE(fs::exists(dir() / "out" / "r.exr"));
  // The README's spelling renders.
  const Outcome ok = render(sphereOf("fused silica"), "-q --strict");
  EXPECT_EQ(ok.code, 0) << ok.err;
}

TEST_F(Usability, InfoListsEveryLibraryMaterial) {
  const Outcome r = run("info");
  ASSERT_EQ(r.code, 0) << r.err;
  const size_t at = r.out.find("\nmaterials:");
  ASSERT_NE(at, std::string::npos) << r.out;
  const std::string line = r.out.substr(at + 1, r.out.find('\n', at + 1) - at - 1);
  for (const std::string& name : shippedMaterials())
    EXPECT_TRUE(line.find(" " + name + ",") != std::string::npos ||
                line.find(" " + name + " (") != std::string::npos)
        << name << ": " << line;
  EXPECT_NE(line.find((fs::path(EIKON_SOURCE_DIR) / "materials").string()), std::string::npos)
      << line;
}

// The scene's "render" is the render's default: its spp in the summary, its exposure in the PNG
// (the same bytes as --exposure 2 on the scene without it); options override it.
TEST_F(Usability, TheScenesRenderSettingsAreTheDefaults) {
  const std::string hinted =
      sphereOf("N-BK7", R"("render": {"spp": 3, "wavelengths": 2, "exposure": 2}, )");
  const Outcome r = render(hinted, "-q --reference");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("(16x12, 2 wavelengths, 3 spp)"), std::string::npos) << r.out;
  const std::string png = eikon::test::slurp(dir() / "out" / "r.png");
  const Outcome o = render(hinted, "-q --reference --spp 2 --wavelengths 0 --exposure 0");
  ASSERT_EQ(o.code, 0) << o.err;
  EXPECT_NE(o.out.find("(16x12, RGB, 2 spp)"), std::string::npos) << o.out;
  EXPECT_NE(eikon::test::slurp(dir() / "out" / "r.png"), png);
  const Outcome plain =
      render(sphereOf("N-BK7"), "-q --reference --spp 3 --wavelengths 2 --exposure 2");
  ASSERT_EQ(plain.code, 0) << plain.err;
  EXPECT_EQ(eikon::test::slurp(dir() / "out" / "r.png"), png);
  const Outcome bad = render(sphereOf("N-BK7", R"("render": {"spp": 0}, )"), "-q");
  EXPECT_NE(bad.code, 0);
  EXPECT_NE(bad.err.find("/render/spp: "), std::string::npos) << bad.err;
}

// A diffuse floor under a glass ball (caustic_sphere made small).
std::string floorScene(const std::string& lights) {
  return R"({
    "camera": {"position": [0, 20, -46], "look_at": [0, -5, 0], "fov_deg": 34, "width": 16, "height": 12},
    "volume": {"bounds_min": [-14, -9.5, -14], "bounds_max": [14, 14, 14], "resolution": 20},
    "materials": {"glass": {"n": 1.5168}, "floor": {"n": 1.0, "opacity": 1, "albedo": 0.8}},
    "objects": [{"shape": "box", "center": [0, -8, 0], "size": [26.5, 1.5, 26.5], "material": "floor"},
                {"shape": "sphere", "center": [0, 2, 0], "radius": 6, "material": "glass"}])" +
         lights + "}";
}

TEST_F(Usability, AnUnlitFloorIsWarnedAboutAndRefusedUnderStrict) {
  const Outcome r = render(floorScene(""), "-q --reference");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("eikon: warning: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/objects/0 ('floor'): its material has an albedo"), std::string::npos)
      << r.err;
  const Outcome strict = render(floorScene(""), "-q --reference --strict");
  EXPECT_NE(strict.code, 0);
  EXPECT_NE(strict.err.find("(--strict)"), std::string::npos) << strict.err;
}

// A beam that misses everything is warned about and not simulated; aimed at the ball it is.
TEST_F(Usability, ABeamThatMissesEverythingIsNotSimulated) {
  auto beam = [](double x) {
    return floorScene(
        R"(, "lights": [{"type": "directional", "direction": [0, 0, 1], "beam_center": [)" +
        std::to_string(x) + R"(, 5, 0], "beam_radius": 1}])");
  };
  const std::string light = "-q --reference --light-split 8 --light-step 2 --no-light-cache";
  const Outcome miss = render(beam(20), light);
  ASSERT_EQ(miss.code, 0) << miss.err;
  EXPECT_NE(miss.err.find("/lights/0: the light's beam misses every object"), std::string::npos)
      << miss.err;
  EXPECT_EQ(miss.out.find("simulated"), std::string::npos) << miss.out;
  const Outcome hit = render(beam(3), light);
  ASSERT_EQ(hit.code, 0) << hit.err;
  EXPECT_EQ(hit.err, "");
  EXPECT_NE(hit.out.find("eikon: simulated"), std::string::npos) << hit.out;
  EXPECT_NE(render(beam(20), light + " --strict").code, 0);
}

/// The cache entries in `dir`.
size_t entries(const fs::path& dir) {
  size_t n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    n += e.path().extension() == ".bin" &&
         e.path().filename().string().find(".tmp-") == std::string::npos;
  return n;
}

// EIKON_CACHE_MAX_MB=0 keeps only the entry written last (a GPU render writes specialised
// SPIR-V and the pipeline cache, a lit one its volume and light too); unset, they all stay.
TEST_F(Usability, TheCacheKeepsToItsCap) {
  const std::string scene =
      floorScene(R"(, "lights": [{"type": "directional", "direction": [0.25, -1, 0.15]}])");
  const std::string light = "-q --light-split 8 --light-step 2";
  ASSERT_EQ(render(scene, light).code, 0);
  EXPECT_GE(entries(dir() / "cache"), 3u);
  fs::remove_all(dir() / "cache");
  const Outcome capped = render(scene, light, "EIKON_CACHE_MAX_MB=0");
  ASSERT_EQ(capped.code, 0) << capped.err;
  EXPECT_EQ(entries(dir() / "cache"), 1u);
  const Outcome bad = render(scene, light, "EIKON_CACHE_MAX_MB=lots");
  EXPECT_EQ(bad.code, 2);
  EXPECT_EQ(bad.err,
            "eikon: error: EIKON_CACHE_MAX_MB must be a whole number of MiB in [0, 1073741824], "
            "got 'lots'\n");
}

}  // namespace
