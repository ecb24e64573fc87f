// Limits of what a scene may ask for (issue 11): every quantity derived from the volume and the
// objects must be representable (finite extents, a voxel edge whose inverse is finite in float,
// a grid the GPU's single-precision positions resolve), and objects that the volume would cut
// away entirely, or that fill it entirely, are never a silent change: an error or a warning
// naming the JSON path.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

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

}  // namespace
}  // namespace eikon
