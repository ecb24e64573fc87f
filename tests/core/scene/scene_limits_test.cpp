// Limits of what a scene may ask for: every quantity derived from the volume and the
// objects must be representable (finite extents, a voxel edge whose inverse is finite in float,
// a grid the GPU's single-precision positions resolve), and objects that the volume would cut
// away entirely, or that fill it entirely, are never a silent change: an error or a warning
// naming the JSON path. Refractive indices lie in [1, 10] and radiances (colours, environment
// maps) at most 1e9 (docs/scene-format.md), so that no accepted value overflows in a render.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "core/io/exr.h"
#include "core/scene/scene.h"
#include "tests/core/scene_support.h"

namespace eikon {
namespace {

constexpr const char* kOrigin = "limits.json";

std::string sceneWith(const std::string& volume, const std::string& object) {
  return R"({"volume": )" + volume +
         R"(, "materials": {"glass": {"n": 1.5}, "haze": {"n": 1, "attenuation_per_mm": 0.01}},
             "objects": [)" +
         object + "]}";
}
const std::string kVolume =
    R"({"bounds_min": [-12, -12, -12], "bounds_max": [12, 12, 12], "resolution": 32})";
const std::string kSphere = R"({"shape": "sphere", "radius": 3, "material": "glass"})";

std::string errorOf(const std::string& text) { return test::sceneErrorOf(text, kOrigin); }

#define EXPECT_LIMIT_ERROR(text, json_path, phrase) \
  EXPECT_TRUE(test::isOneLineSceneError(errorOf(text), kOrigin, json_path, phrase))

// ±1e308 bounds: the extent overflows to inf and the GPU's float grid to NaN (trace printed NaN
// with exit code 0). Every position is limited to ±1e12 mm.
TEST(SceneLimits, AbsurdVolumeBoundsAreRefused) {
  EXPECT_LIMIT_ERROR(
      sceneWith(R"({"bounds_min": [-1e308, -12, -12], "bounds_max": [1e308, 12, 12]})", kSphere),
      "/volume/bounds_min/0", "must be within");
  EXPECT_LIMIT_ERROR(
      sceneWith(R"({"bounds_min": [-12, -12, -12], "bounds_max": [12, 1e13, 12]})", kSphere),
      "/volume/bounds_max/1", "must be within");
}

// A voxel edge of 1e-300 mm has an inverse that is infinite in float.
TEST(SceneLimits, VoxelEdgeTooSmall) {
  EXPECT_LIMIT_ERROR(
      sceneWith(
          R"({"bounds_min": [0, 0, 0], "bounds_max": [1e-300, 1e-300, 1e-300], "resolution": 8})",
          R"({"shape": "sphere", "center": [0, 0, 0], "radius": 1, "material": "glass"})"),
      "/volume/resolution", "voxel edge");
  // 1 µm side / 1024 voxels = 0.98 nm < 1 nm.
  EXPECT_LIMIT_ERROR(
      sceneWith(
          R"({"bounds_min": [0, 0, 0], "bounds_max": [0.001, 0.001, 0.001], "resolution": 1024})",
          R"({"shape": "sphere", "center": [0, 0, 0], "radius": 1, "material": "glass"})"),
      "/volume/resolution", "voxel edge");
  // 1 µm / 512 = 1.95 nm: allowed.
  EXPECT_NO_THROW(parseScene(
      sceneWith(
          R"({"bounds_min": [-0.0005, -0.0005, -0.0005], "bounds_max": [0.0005, 0.0005, 0.0005],
                                           "resolution": 512})",
          R"({"shape": "sphere", "radius": 0.0002, "material": "glass"})"),
      kOrigin));
}

// A 24 mm volume 1e6 mm from the origin at 128 voxels: |x|/h = 5.3e6 voxels; float positions there
// have a spacing of 0.0625 mm = 1/3 voxel. The rule allows |x|/h ≤ 65536 (spacing ≤ 2^-7 voxel).
TEST(SceneLimits, VolumeTooFarFromTheOriginForFloat) {
  EXPECT_LIMIT_ERROR(
      sceneWith(
          R"({"bounds_min": [1000000, -12, -12], "bounds_max": [1000024, 12, 12], "resolution": 128})",
          R"({"shape": "sphere", "center": [1000012, 0, 0], "radius": 3, "material": "glass"})"),
      "/volume/bounds_max", "single-precision");
  // 1000 mm away at h = 24/128 mm: 5340 voxels, fine.
  EXPECT_NO_THROW(parseScene(
      sceneWith(
          R"({"bounds_min": [1000, -12, -12], "bounds_max": [1024, 12, 12], "resolution": 128})",
          R"({"shape": "sphere", "center": [1012, 0, 0], "radius": 3, "material": "glass"})"),
      kOrigin));
}

TEST(SceneLimits, AbsurdObjectCoordinatesAreRefused) {
  EXPECT_LIMIT_ERROR(
      sceneWith(
          kVolume,
          R"({"shape": "sphere", "center": [1e300, 0, 0], "radius": 3, "material": "glass"})"),
      "/objects/0/center/0", "must be within");
  EXPECT_LIMIT_ERROR(
      sceneWith(kVolume, R"({"shape": "sphere", "radius": 1e300, "material": "glass"})"),
      "/objects/0/radius", "at most");
  EXPECT_LIMIT_ERROR(
      sceneWith(kVolume, R"({"shape": "box", "size": [1, 1e13, 1], "material": "glass"})"),
      "/objects/0/size/1", "must be within");
}

// Centre 4294967296 mm (2^32): representable, but nowhere near the volume.
TEST(SceneLimits, ObjectOutsideTheVolumeIsAnError) {
  EXPECT_LIMIT_ERROR(
      sceneWith(
          kVolume,
          R"({"shape": "sphere", "center": [4294967296, 0, 0], "radius": 3, "material": "glass"})"),
      "/objects/0", "entirely outside the volume");
  // Exact for spheres: the sphere's box overlaps the volume's corner region but the sphere does
  // not (distance from (15, 15, 15) to the corner (12, 12, 12) is 5.196 > 5).
  EXPECT_LIMIT_ERROR(
      sceneWith(kVolume,
                R"({"shape": "sphere", "center": [15, 15, 15], "radius": 5, "material": "glass"})"),
      "/objects/0", "entirely outside the volume");
  // Radius 5.2 > 5.196: it reaches into the corner; a warning about the face, no error.
  const Scene s = parseScene(
      sceneWith(
          kVolume,
          R"({"shape": "sphere", "center": [15, 15, 15], "radius": 5.2, "material": "glass"})"),
      kOrigin);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0].find("covers"), std::string::npos) << s.warnings[0];
}

// A sphere of radius 7e8 mm about the volume (the audit's case) covers every voxel: a warning
// that says so, not the boundary warning and not silence; for a haze too.
TEST(SceneLimits, ObjectCoveringTheVolumeIsReported) {
  for (const char* mat : {"glass", "haze"}) {
    const Scene s = parseScene(
        sceneWith(kVolume,
                  std::string(R"({"shape": "sphere", "radius": 7e8, "material": ")") + mat + "\"}"),
        kOrigin);
    ASSERT_EQ(s.warnings.size(), 1u) << mat;
    EXPECT_EQ(s.warnings[0].rfind(std::string(kOrigin) + ": /objects/0: ", 0), 0u) << s.warnings[0];
    EXPECT_NE(s.warnings[0].find("covers the whole volume"), std::string::npos) << s.warnings[0];
  }
  // The corners of the ±12 box are 20.78 mm from the centre: radius 20.7 leaves them out.
  const Scene s = parseScene(
      sceneWith(kVolume, R"({"shape": "sphere", "radius": 20.7, "material": "glass"})"), kOrigin);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0].find("covers"), std::string::npos) << s.warnings[0];
  const Scene s2 = parseScene(
      sceneWith(kVolume, R"({"shape": "sphere", "radius": 20.8, "material": "glass"})"), kOrigin);
  ASSERT_EQ(s2.warnings.size(), 1u);
  EXPECT_NE(s2.warnings[0].find("covers the whole volume"), std::string::npos) << s2.warnings[0];
}

// The shipped scenes are within every limit, and none of their objects covers the volume.
TEST(SceneLimits, ShippedScenesAreWithinTheLimits) {
  int n = 0;
  for (const auto& e :
       std::filesystem::directory_iterator(std::filesystem::path(EIKON_SOURCE_DIR) / "scenes")) {
    if (e.path().extension() != ".json") continue;
    const Scene s = loadScene(e.path());
    for (const auto& w : s.warnings)
      EXPECT_EQ(w.find("covers the whole volume"), std::string::npos) << w;
    ++n;
  }
  EXPECT_GE(n, 5);
}

// ------------------------------------------------------------------ refractive indices in [1, 10]

std::string withMaterial(const std::string& material, const std::string& extra = "") {
  return R"({)" + extra + R"("volume": )" + kVolume + R"(, "materials": {"m": )" + material +
         R"(}, "objects": [{"shape": "sphere", "radius": 3, "material": "m"}]})";
}

// Every index must be finite and in [1, 10] over 380–780 nm, as ambient_index and n0 are: n = 1e20
// rendered NaN pixels, Cauchy [1.5, 1e300, 1e300] too, and a Sellmeier index that overflows to
// infinity passed the old "n >= 1" check.
TEST(SceneLimits, RefractiveIndicesAboveTenAreRefused) {
  EXPECT_LIMIT_ERROR(withMaterial(R"({"n": 1e20})"), "/materials/m/n", "must be <= 10");
  EXPECT_LIMIT_ERROR(withMaterial(R"({"n": 10.5})"), "/materials/m/n", "got 10.5");
  EXPECT_LIMIT_ERROR(withMaterial(R"({"n": {"cauchy": [1.5, 1e300, 1e300]}})"), "/materials/m/n",
                     "above 10");
  // The message names the wavelength and the value: Cauchy 9.9 + 0.1/λ² is 10.59 at 380 nm.
  EXPECT_LIMIT_ERROR(withMaterial(R"({"n": {"cauchy": [9.9, 0.1]}})"), "/materials/m/n",
                     "at 380 nm is above 10");
  EXPECT_LIMIT_ERROR(withMaterial(R"({"n": {"sellmeier": [1e308, 1e308, 1e-308, 1e-308]}})"),
                     "/materials/m/n", "infinite");
  EXPECT_LIMIT_ERROR(withMaterial(R"({"n": {"conrady": [12, 0, 0]}})"), "/materials/m/n",
                     "above 10");
  EXPECT_LIMIT_ERROR(withMaterial(R"({"n_o": 1.6, "n_e": 11, "optic_axis": [0, 0, 1]})"),
                     "/materials/m/n_e", "must be <= 10");
  EXPECT_LIMIT_ERROR(
      withMaterial(R"({"n_o": {"cauchy": [1.6, 1e300]}, "n_e": 1.5, "optic_axis": [0, 0, 1]})"),
      "/materials/m/n_o", "above 10");
  // The limits themselves are allowed.
  EXPECT_NO_THROW(parseScene(withMaterial(R"({"n": 10})"), kOrigin));
  EXPECT_NO_THROW(parseScene(withMaterial(R"({"n": 1})", R"("ambient_index": 1,)"), kOrigin));
}

// A linear profile n0 + g·(x − origin) with n0 = 9 and g = 0.5/mm reaches 10.5 at y = 3 mm inside
// the sphere (radius 3): above 10 inside the object.
TEST(SceneLimits, GradientIndexAboveTenInsideTheObjectIsRefused) {
  EXPECT_LIMIT_ERROR(
      withMaterial(R"({"n": {"linear": {"n0": 9, "gradient_per_mm": [0, 0.5, 0]}}})"),
      "/objects/0/material", "above 10");
  EXPECT_LIMIT_ERROR(
      withMaterial(R"({"n": {"linear": {"n0": 1.5, "gradient_per_mm": [0, 1e300, 0]}}})"),
      "/objects/0/material", "indices must be in [1, 10]");
}

// A library material file is checked as a scene's material, and its error names the file.
TEST(SceneLimits, LibraryMaterialWithAnInfiniteIndexIsRefused) {
  test::TempDir lib;
  const auto file = lib.write(
      "inf.json", R"({"name": "inf", "n": {"sellmeier": [1e308, 1e308, 1e-308, 1e-308]}})");
  const char* old = std::getenv("EIKON_MATERIALS_PATH");
  const std::string saved = old ? old : "";
  ::setenv("EIKON_MATERIALS_PATH", lib.path().c_str(), 1);
  const std::string m =
      errorOf(R"({"volume": )" + kVolume +
              R"(, "objects": [{"shape": "sphere", "radius": 3, "material": "inf"}]})");
  if (old)
    ::setenv("EIKON_MATERIALS_PATH", saved.c_str(), 1);
  else
    ::unsetenv("EIKON_MATERIALS_PATH");
  EXPECT_TRUE(test::isOneLineSceneError(m, file.string(), "/n", "infinite"));
}

// A negative Sellmeier B can make n² ≤ 0: the message says so and names the coefficient, not
// "refractive index undefined ... is below 1". n² = 1 − 5·λ²/(λ² − 0.01) is −4.37 at 380 nm.
TEST(SceneLimits, NegativeSellmeierBIsNamed) {
  const std::string m = errorOf(withMaterial(R"({"n": {"sellmeier": [-5, 0.01]}})"));
  EXPECT_TRUE(test::isOneLineSceneError(m, kOrigin, "/materials/m/n", "B1 = -5 is negative"));
  EXPECT_NE(m.find("at 380 nm"), std::string::npos) << m;
  EXPECT_EQ(m.find("below 1"), std::string::npos) << m;
}

// ------------------------------------------------------------------ radiances at most 1e9

// Emission 1e308 rendered Inf pixels, an environment radiance of 1e308 an all-Inf image: colours
// are capped at 1e9 (as the environment's intensity), and an environment colour times its
// intensity as well.
TEST(SceneLimits, HugeColoursAreRefused) {
  EXPECT_LIMIT_ERROR(withMaterial(R"({"n": 1.5, "emission": 1e308})"), "/materials/m/emission",
                     "at most 1e9");
  EXPECT_LIMIT_ERROR(withMaterial(R"({"n": 1.5, "emission": [1, 2e9, 0]})"),
                     "/materials/m/emission/1", "at most 1e9");
  EXPECT_LIMIT_ERROR(withMaterial(R"({"n": 1.5, "attenuation_per_mm": [0, 0, 1e300]})"),
                     "/materials/m/attenuation_per_mm/2", "at most 1e9");
  EXPECT_LIMIT_ERROR(withMaterial(R"({"n": 1.5, "attenuation_per_mm": {"wavelength_nm": [400, 700],
                                                         "per_mm": [1, 1e300]}})"),
                     "/materials/m/attenuation_per_mm/per_mm/1", "at most 1e9");
  EXPECT_LIMIT_ERROR(
      withMaterial(R"({"n": 1.5})", R"("environment": {"type": "constant", "radiance": 1e308},)"),
      "/environment/radiance", "at most 1e9");
  EXPECT_LIMIT_ERROR(withMaterial(R"({"n": 1.5})", R"("environment": {"type": "checker",
                         "color_a": [1, 1, 2e8], "intensity": 10},)"),
                     "/environment/color_a/2", "times the intensity 10");
  // At the limits: emission 1e9, radiance 1e8 × intensity 10 = 1e9.
  EXPECT_NO_THROW(parseScene(withMaterial(R"({"n": 1.5, "emission": 1e9})"), kOrigin));
  EXPECT_NO_THROW(parseScene(
      withMaterial(R"({"n": 1.5})",
                   R"("environment": {"type": "constant", "radiance": 1e8, "intensity": 10},)"),
      kOrigin));
}

// An environment map's pixels are radiances as a JSON colour is: a negative pixel was accepted,
// and pixels of 3e38 (finite in float) with intensity 10 rendered an all-Inf image. The error
// names the pixel (x, y from the top left) and the channel.
TEST(SceneLimits, EnvironmentMapPixelsAreChecked) {
  test::TempDir d;
  const int w = 4, h = 2;
  auto envScene = [&](float value, int x, int y, int channel, const std::string& intensity) {
    std::vector<float> rgb(size_t(3 * w * h), 0.5f);
    rgb[size_t(3 * (y * w + x) + channel)] = value;
    writeExrRgb(d.path() / "env.exr", w, h, rgb);
    return withMaterial(R"({"n": 1.5})", R"("environment": {"type": "latlong", "file": "env.exr")" +
                                             intensity + "},");
  };
  const auto origin = (d.path() / "s.json").string();
  auto errorIn = [&](const std::string& text) { return test::sceneErrorOf(text, origin); };
  EXPECT_TRUE(test::isOneLineSceneError(errorIn(envScene(-1.0f, 2, 1, 1, "")), origin,
                                        "/environment/file", "pixel (2, 1) channel G is -1"));
  const std::string huge = errorIn(envScene(3e38f, 3, 0, 0, R"(, "intensity": 10)"));
  EXPECT_TRUE(
      test::isOneLineSceneError(huge, origin, "/environment/file", "pixel (3, 0) channel R is "));
  EXPECT_NE(huge.find(": times the intensity 10, above the largest"), std::string::npos) << huge;
  // 2e8 × 10 = 2e9 > 1e9; 1e8 × 10 = 1e9 is the limit, allowed.
  EXPECT_TRUE(test::isOneLineSceneError(errorIn(envScene(2e8f, 0, 0, 2, R"(, "intensity": 10)")),
                                        origin, "/environment/file", "channel B is 200000000"));
  EXPECT_NO_THROW(parseScene(envScene(1e8f, 0, 0, 2, R"(, "intensity": 10)"), origin));
}

}  // namespace
}  // namespace eikon
