// Scenes that parse but cannot show what they were written for are warned about
// (core/scene/scene_warnings.h): an albedo without lights, an object smaller than a voxel or a
// pixel, a light whose beam or cone misses every object.
#include <gtest/gtest.h>

#include <string>

#include "core/scene/scene.h"
#include "core/scene/scene_warnings.h"

namespace eikon {
namespace {

/// Warnings that contain `phrase`.
size_t count(const Scene& s, const std::string& phrase) {
  size_t n = 0;
  for (const std::string& w : s.warnings) n += w.find(phrase) != std::string::npos;
  return n;
}

std::string allWarnings(const Scene& s) {
  std::string all;
  for (const std::string& w : s.warnings) all += w + "\n";
  return all;
}

// A glass ball over a diffuse floor (caustic_sphere made small); `lights` is the lights array.
Scene floorScene(const std::string& lights) {
  return parseScene(R"({
    "camera": {"position": [0, 20, -46], "look_at": [0, -5, 0], "fov_deg": 34, "width": 32, "height": 24},
    "volume": {"bounds_min": [-14, -9.5, -14], "bounds_max": [14, 14, 14], "resolution": 28},
    "materials": {"glass": {"n": 1.5168}, "floor": {"n": 1.0, "opacity": 1, "albedo": 0.8}},
    "objects": [{"shape": "box", "center": [0, -8, 0], "size": [26.5, 1.5, 26.5], "material": "floor"},
                {"shape": "sphere", "center": [0, 2, 0], "radius": 6, "material": "glass"}])" +
                        lights + "}",
                    "floor.json");
}

TEST(SceneUnseen, AnAlbedoWithoutLightsIsWarnedAbout) {
  const Scene dark = floorScene("");
  ASSERT_EQ(dark.warnings.size(), 1u) << allWarnings(dark);
  EXPECT_EQ(dark.warnings[0].rfind("floor.json: /objects/0 ('floor'): ", 0), 0u)
      << dark.warnings[0];
  EXPECT_NE(dark.warnings[0].find("renders black"), std::string::npos) << dark.warnings[0];
  const Scene lit =
      floorScene(R"(, "lights": [{"type": "directional", "direction": [0.25, -1, 0.15]}])");
  EXPECT_TRUE(lit.warnings.empty()) << allWarnings(lit);
  // A glowing floor shows its emission: no warning.
  const Scene glowing = parseScene(
      R"({"materials": {"lamp": {"n": 1.0, "opacity": 1, "albedo": 0.8, "emission": 0.5}},
          "objects": [{"shape": "box", "size": [10, 1, 10], "material": "lamp"}]})",
      "glow.json");
  EXPECT_TRUE(glowing.warnings.empty()) << allWarnings(glowing);
}

// 0.009 mm typed for 9 mm: 0.018 mm across against 24/128 = 0.1875 mm voxels.
TEST(SceneUnseen, AnObjectSmallerThanAVoxelIsWarnedAbout) {
  auto sphere = [](double r) {
    return parseScene(
        R"({"volume": {"bounds_min": [-12, -12, -12], "bounds_max": [12, 12, 12], "resolution": 128},
      "objects": [{"shape": "sphere", "radius": 9, "material": "N-BK7"},
                  {"shape": "sphere", "radius": )" +
            std::to_string(r) + R"(, "material": "N-BK7"}]})",
        "tiny.json");
  };
  const Scene tiny = sphere(0.009);
  ASSERT_EQ(tiny.warnings.size(), 1u) << allWarnings(tiny);
  EXPECT_EQ(
      tiny.warnings[0].rfind("tiny.json: /objects/1 ('N-BK7'): the object is at most 0.018 mm "
                             "across, smaller than a voxel of the volume (0.1875 mm)",
                             0),
      0u)
      << tiny.warnings[0];
  EXPECT_TRUE(sphere(0.1).warnings.empty()) << allWarnings(sphere(0.1));  // 0.2 mm > a voxel
}

// A 0.1 mm bead 600 mm away: a pixel of a 30° field over 300 rows spans 600·(π/6)/300 = 1.047 mm
// there (0.052 mm at 30 mm).
TEST(SceneUnseen, AnObjectSmallerThanAPixelIsWarnedAbout) {
  auto bead = [](double z) {
    return parseScene(R"({"camera": {"position": [0, 0, )" + std::to_string(z) +
                          R"(], "look_at": [0, 0, 0], "fov_deg": 30, "width": 400, "height": 300},
      "volume": {"bounds_min": [-1, -1, -1], "bounds_max": [1, 1, 1], "resolution": 128},
      "objects": [{"shape": "sphere", "radius": 0.05, "material": "N-BK7"}]})",
                      "bead.json");
  };
  const Scene far = bead(-600);
  EXPECT_EQ(count(far,
                  "/objects/0 ('N-BK7'): the object is at most 0.1 mm across, smaller than a "
                  "pixel of the camera at its distance (1.047"),
            1u)
      << allWarnings(far);
  EXPECT_TRUE(bead(-30).warnings.empty()) << allWarnings(bead(-30));  // 0.052 mm pixels
}

// A beam 1 mm in radius along z at x = 20 passes the 6 mm ball (bounding sphere 6 + 1 < 20):
// warned about, and no light reaches an object; aimed at x = 5 it meets it.
TEST(SceneUnseen, ABeamThatMissesEveryObjectIsWarnedAbout) {
  auto beam = [](double x) {
    return floorScene(
        R"(, "lights": [{"type": "directional", "direction": [0, 0, 1], "beam_center": [)" +
        std::to_string(x) + R"(, 5, 0], "beam_radius": 1}])");
  };
  const Scene miss = beam(20);
  EXPECT_EQ(count(miss, "floor.json: /lights/0: the light's beam misses every object"), 1u)
      << allWarnings(miss);
  EXPECT_EQ(miss.warnings.size(), 1u) << allWarnings(miss);
  EXPECT_FALSE(anyLightReachesAnObject(miss));
  const Scene hit = beam(5);
  EXPECT_TRUE(hit.warnings.empty()) << allWarnings(hit);
  EXPECT_TRUE(anyLightReachesAnObject(hit));
}

// A spot light 40 mm above the scene pointing up misses it (the floor's bounding sphere, 18.8 mm
// in radius about its centre 48 mm below, subtends 23°); pointing down it meets the floor. A
// point light always reaches the objects.
TEST(SceneUnseen, ASpotThatMissesEveryObjectIsWarnedAbout) {
  auto spot = [](double dir_y) {
    return floorScene(R"(, "lights": [{"type": "spot", "position": [0, 40, 0], "direction": [0, )" +
                      std::to_string(dir_y) +
                      R"(, 0], "cone_half_angle_deg": 10, "intensity": 5}])");
  };
  const Scene up = spot(1);
  EXPECT_EQ(count(up, "/lights/0: the light's cone misses every object"), 1u) << allWarnings(up);
  EXPECT_TRUE(spot(-1).warnings.empty()) << allWarnings(spot(-1));
  const Scene point =
      floorScene(R"(, "lights": [{"type": "point", "position": [0, 8.5, 0], "intensity": 5}])");
  EXPECT_TRUE(point.warnings.empty()) << allWarnings(point);
}

}  // namespace
}  // namespace eikon
