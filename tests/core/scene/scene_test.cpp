// Scene JSON parser (core/scene/scene.cpp): every user error is a SceneError whose message names
// the file and the JSON path of the offending value plus a phrase that tells the user what is
// wrong (docs/design.md §3-4: unknown keys are errors, n < 1 is an error, nothing is clamped).
// Positive cases: the docs/design.md §3 example, library materials (N-BK7, calcite) and every
// shipped scene.
#include "core/scene/scene.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/core/scene_support.h"

namespace eikon {
namespace {

namespace fs = std::filesystem;

constexpr const char* kOrigin = "scene-under-test.json";

// A minimal valid scene; tests splice one faulty piece into it.
std::string scene(const std::string& materials, const std::string& objects,
                  const std::string& extra = "") {
  return "{" + extra + (extra.empty() ? "" : ",") + "\"materials\": {" + materials +
         "}, \"objects\": [" + objects + "]}";
}
const std::string kGlass = R"("glass": {"n": 1.5})";
const std::string kSphere =
    R"({"shape": "sphere", "center": [0, 0, 0], "radius": 3, "material": "glass"})";

/// Parses `text`, expects a SceneError, returns its message (empty + test failure otherwise).
std::string errorOf(const std::string& text, const fs::path& origin = kOrigin) {
  return test::sceneErrorOf(text, origin);
}

// The message must read "FILE: /json/path: ..." and contain `phrase`.
#define EXPECT_SCENE_ERROR(text, json_path, phrase)                                 \
  do {                                                                              \
    const std::string msg_ = errorOf(text);                                         \
    EXPECT_EQ(msg_.rfind(std::string(kOrigin) + ": ", 0), 0u)                       \
        << "message does not start with the file: " << msg_;                        \
    EXPECT_NE(msg_.find(std::string(": ") + (json_path) + ": "), std::string::npos) \
        << "message lacks the JSON path " << (json_path) << ": " << msg_;           \
    EXPECT_NE(msg_.find(phrase), std::string::npos)                                 \
        << "message lacks '" << (phrase) << "': " << msg_;                          \
  } while (0)

using test::TempDir;

// ------------------------------------------------------------------ syntax and unknown keys

TEST(SceneParse, MalformedJson) {
  const std::string msg = errorOf(R"({"objects": [ {"shape": "sphere", )");
  EXPECT_EQ(msg.rfind(std::string(kOrigin) + ": ", 0), 0u) << msg;
  EXPECT_NE(msg.find("malformed JSON"), std::string::npos) << msg;
}

// JSON has no NaN literal: writing one must give the malformed-JSON error, not a NaN radius.
TEST(SceneParse, NanLiteralIsMalformedJson) {
  const std::string msg =
      errorOf(scene(kGlass, R"({"shape": "sphere", "radius": NaN, "material": "glass"})"));
  EXPECT_NE(msg.find("malformed JSON"), std::string::npos) << msg;
  EXPECT_EQ(msg.rfind(std::string(kOrigin) + ": ", 0), 0u) << msg;
}

// A number too large for a double (1e999 → ∞) must be a SceneError naming file and path (or at
// least the file) — not a raw nlohmann exception escaping the parser.
TEST(SceneParse, OverflowingNumberIsSceneError) {
  const std::string msg =
      errorOf(scene(kGlass, R"({"shape": "sphere", "radius": 1e999, "material": "glass"})"));
  EXPECT_EQ(msg.rfind(std::string(kOrigin) + ": ", 0), 0u) << msg;
}

TEST(SceneParse, UnknownTopLevelKey) {
  EXPECT_SCENE_ERROR(scene(kGlass, kSphere, R"("lamps": [])"), "/lamps", "unknown key");
}

TEST(SceneParse, UnknownCameraKey) {
  EXPECT_SCENE_ERROR(scene(kGlass, kSphere, R"("camera": {"position": [0, 0, -60], "zoom": 2})"),
                     "/camera/zoom", "unknown key");
}

TEST(SceneParse, UnknownVolumeKey) {
  EXPECT_SCENE_ERROR(scene(kGlass, kSphere, R"("volume": {"resolution": 32, "smoothing": 1})"),
                     "/volume/smoothing", "unknown key");
}

TEST(SceneParse, UnknownMaterialKey) {
  EXPECT_SCENE_ERROR(scene(R"("glass": {"n": 1.5, "abbe": 64})", kSphere), "/materials/glass/abbe",
                     "unknown key");
}

// A sphere has a radius, not a size: the message names the key and the shape.
TEST(SceneParse, UnknownKeyForShape) {
  EXPECT_SCENE_ERROR(
      scene(kGlass, R"({"shape": "sphere", "radius": 3, "size": [1, 1, 1], "material": "glass"})"),
      "/objects/0", "unknown key 'size'");
  const std::string msg = errorOf(
      scene(kGlass, R"({"shape": "sphere", "radius": 3, "size": [1, 1, 1], "material": "glass"})"));
  EXPECT_NE(msg.find("sphere"), std::string::npos) << msg;
}

TEST(SceneParse, UnknownShape) {
  EXPECT_SCENE_ERROR(scene(kGlass, R"({"shape": "torus", "radius": 3, "material": "glass"})"),
                     "/objects/0/shape", "unknown shape 'torus'");
}

TEST(SceneParse, MissingObjects) {
  EXPECT_SCENE_ERROR(R"({"materials": {"glass": {"n": 1.5}}})", "/",
                     "missing required key 'objects'");
}

TEST(SceneParse, ObjectsNotAnArray) {
  EXPECT_SCENE_ERROR(R"({"objects": {"shape": "sphere"}})", "/objects", "expected an array");
}

// ------------------------------------------------------------------ refractive indices

TEST(SceneParse, IndexBelowOne) {
  EXPECT_SCENE_ERROR(scene(R"("glass": {"n": 0.9})", kSphere), "/materials/glass/n",
                     "must be >= 1");
}

// n = 0.9 + 0.01/λ² (λ in µm) is 0.969 at 380 nm and 0.916 at 780 nm: below 1 everywhere visible.
TEST(SceneParse, CauchyBelowOneInTheVisible) {
  EXPECT_SCENE_ERROR(scene(R"("glass": {"n": {"cauchy": [0.9, 0.01]}})", kSphere),
                     "/materials/glass/n", "below 1");
}

// Below 1 only at the red end: A = 0.99, B = 0.004 µm² gives n(380 nm) = 1.0177 but
// n(780 nm) = 0.9966 — the whole 380–780 nm window must be checked, not one wavelength.
TEST(SceneParse, CauchyBelowOneOnlyAtTheRedEnd) {
  EXPECT_SCENE_ERROR(scene(R"("glass": {"n": {"cauchy": [0.99, 0.004]}})", kSphere),
                     "/materials/glass/n", "below 1");
}

TEST(SceneParse, CauchyCoefficientCount) {
  EXPECT_SCENE_ERROR(scene(R"("glass": {"n": {"cauchy": []}})", kSphere),
                     "/materials/glass/n/cauchy", "1 to 6 coefficients");
  EXPECT_SCENE_ERROR(scene(R"("glass": {"n": {"cauchy": [1.5, 0, 0, 0, 0, 0, 0]}})", kSphere),
                     "/materials/glass/n/cauchy", "got 7");
}

TEST(SceneParse, SellmeierOddCount) {
  EXPECT_SCENE_ERROR(
      scene(R"("glass": {"n": {"sellmeier": [1.03961212, 0.231792344, 1.01046945, 0.006, 0.02]}})",
            kSphere),
      "/materials/glass/n/sellmeier", "got 5 numbers");
}

// A Sellmeier pole inside the visible window (C = 0.25 µm² ⇒ pole at 500 nm) gives n² < 0 just
// below it: the index is undefined there and must be rejected, the message naming the pole.
TEST(SceneParse, SellmeierPoleInTheVisible) {
  EXPECT_SCENE_ERROR(scene(R"("glass": {"n": {"sellmeier": [1.0, 0.25]}})", kSphere),
                     "/materials/glass/n", "puts a pole at 500 nm");
}

TEST(SceneParse, UnknownMaterialName) {
  EXPECT_SCENE_ERROR(
      scene(kGlass, R"({"shape": "sphere", "radius": 3, "material": "unobtainium"})"),
      "/objects/0/material", "unknown material 'unobtainium'");
}

TEST(SceneParse, UniaxialWithoutOpticAxis) {
  EXPECT_SCENE_ERROR(scene(R"("xtal": {"n_o": 1.6, "n_e": 1.5})",
                           R"({"shape": "sphere", "radius": 3, "material": "xtal"})"),
                     "/objects/0", "needs an optic_axis");
}

TEST(SceneParse, ZeroOpticAxis) {
  EXPECT_SCENE_ERROR(scene(R"("xtal": {"n_o": 1.6, "n_e": 1.5, "optic_axis": [0, 0, 0]})",
                           R"({"shape": "sphere", "radius": 3, "material": "xtal"})"),
                     "/materials/xtal/optic_axis", "non-zero");
  EXPECT_SCENE_ERROR(
      scene(R"("xtal": {"n_o": 1.6, "n_e": 1.5})",
            R"({"shape": "sphere", "radius": 3, "material": "xtal", "optic_axis": [0, 0, 0]})"),
      "/objects/0/optic_axis", "non-zero");
}

TEST(SceneParse, BothNAndNo) {
  EXPECT_SCENE_ERROR(scene(R"("m": {"n": 1.5, "n_o": 1.6, "n_e": 1.5, "optic_axis": [0, 0, 1]})",
                           R"({"shape": "sphere", "radius": 3, "material": "m"})"),
                     "/materials/m", "not both");
}

TEST(SceneParse, MissingNe) {
  EXPECT_SCENE_ERROR(scene(R"("m": {"n_o": 1.6, "optic_axis": [0, 0, 1]})",
                           R"({"shape": "sphere", "radius": 3, "material": "m"})"),
                     "/materials/m", "missing n_e");
}

// A linear GRIN profile is n(x) = n0 + g·(x − origin); inside a 20 mm box with g = 0.2/mm it
// spans 1.5 ± 2 = [−0.5, 3.5]: n < 1 over much of the object. docs/design.md §4: n < 1 is an error,
// never clamped, wherever it occurs — so the parser (or voxeliser) must refuse this scene.
TEST(SceneParse, LinearGrinBelowOneInsideTheObject) {
  const std::string text =
      scene(R"("grin": {"n": {"linear": {"n0": 1.5, "gradient_per_mm": [0, 0.2, 0]}}})",
            R"({"shape": "box", "size": [20, 20, 20], "material": "grin"})");
  bool refused = false;
  try {
    parseScene(text, kOrigin);
  } catch (const SceneError& e) {
    refused = true;
    EXPECT_NE(std::string(e.what()).find("below 1"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(refused) << "a linear GRIN material reaching n = -0.5 inside its object was accepted";
}

// ------------------------------------------------------------------ shapes

TEST(SceneParse, NonPositiveRadius) {
  EXPECT_SCENE_ERROR(scene(kGlass, R"({"shape": "sphere", "radius": -3, "material": "glass"})"),
                     "/objects/0/radius", "must be > 0");
  EXPECT_SCENE_ERROR(scene(kGlass, R"({"shape": "sphere", "radius": 0, "material": "glass"})"),
                     "/objects/0/radius", "must be > 0");
}

TEST(SceneParse, ZeroBoxSize) {
  EXPECT_SCENE_ERROR(scene(kGlass, R"({"shape": "box", "size": [2, 0, 2], "material": "glass"})"),
                     "/objects/0/size", "must be > 0");
}

// apex_deg 0 said "must be in (0, 180]" and 180 "(0, 180)": both say the open range now, and an
// angle so near 0 or 180 that the triangle is a sliver says so instead of "the planes do not
// enclose a bounded solid".
TEST(SceneParse, PrismApexAngleRange) {
  auto prism = [](const std::string& apex) {
    return scene(kGlass, R"({"shape": "prism", "apex_deg": )" + apex +
                             R"(, "side": 10, "height": 10, "material": "glass"})");
  };
  for (const char* apex : {"0", "180", "-1", "200"}) {
    EXPECT_SCENE_ERROR(prism(apex), "/objects/0/apex_deg",
                       "must be in (0, 180), got " + std::string(apex));
    EXPECT_EQ(errorOf(prism(apex)).find('\n'), std::string::npos);
  }
  for (const char* apex : {"1e-300", "179.99999999"})
    EXPECT_SCENE_ERROR(prism(apex), "/objects/0/apex_deg", "the prism's cross-section would be ");
  EXPECT_NO_THROW(parseScene(prism("179.99"), kOrigin));
}

// Three planes cannot bound a solid; four planes that all face +x leave −x open.
TEST(SceneParse, PlanesThatDoNotEncloseASolid) {
  EXPECT_SCENE_ERROR(scene(kGlass, R"({"shape": "planes", "material": "glass",
                                      "planes": [[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1]]})"),
                     "/objects/0", "at least 4 planes");
  EXPECT_SCENE_ERROR(scene(kGlass, R"({"shape": "planes", "material": "glass",
                                      "planes": [[1, 0, 0, 1], [0, 1, 0, 1], [0, -1, 0, 1], [0, 0, 1, 1]]})"),
                     "/objects/0", "do not enclose a bounded solid");
}

TEST(SceneParse, PlanesWithZeroNormal) {
  EXPECT_SCENE_ERROR(scene(kGlass, R"({"shape": "planes", "material": "glass",
                                      "planes": [[0, 0, 0, 1], [1, 0, 0, 1], [-1, 0, 0, 1], [0, 1, 0, 1]]})"),
                     "/objects/0/planes/0", "non-zero");
}

// ------------------------------------------------------------------ volume, camera, environment

TEST(SceneParse, BoundsMaxNotAboveBoundsMin) {
  EXPECT_SCENE_ERROR(
      scene(kGlass, kSphere, R"("volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, -5, 5]})"),
      "/volume", "bounds_max must exceed bounds_min");
  EXPECT_SCENE_ERROR(
      scene(kGlass, kSphere, R"("volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, -6]})"),
      "/volume", "bounds_max must exceed bounds_min");
}

TEST(SceneParse, Resolution) {
  EXPECT_SCENE_ERROR(scene(kGlass, kSphere, R"("volume": {"resolution": 0})"), "/volume/resolution",
                     "got 0");
  EXPECT_SCENE_ERROR(scene(kGlass, kSphere, R"("volume": {"resolution": 32.5})"),
                     "/volume/resolution", "expected an integer");
  EXPECT_SCENE_ERROR(scene(kGlass, kSphere, R"("volume": {"resolution": "64"})"),
                     "/volume/resolution", "expected an integer");
}

TEST(SceneParse, NegativeSmoothing) {
  EXPECT_SCENE_ERROR(scene(kGlass, kSphere, R"("volume": {"smoothing_voxels": -0.5})"),
                     "/volume/smoothing_voxels", "got -0.5");
}

TEST(SceneParse, CameraPositionEqualsLookAt) {
  EXPECT_SCENE_ERROR(
      scene(kGlass, kSphere, R"("camera": {"position": [1, 2, 3], "look_at": [1, 2, 3]})"),
      "/camera", "coincide");
}

TEST(SceneParse, CameraSizeZero) {
  EXPECT_SCENE_ERROR(scene(kGlass, kSphere, R"("camera": {"width": 0})"), "/camera/width", "got 0");
}

TEST(SceneParse, UnknownEnvironmentType) {
  EXPECT_SCENE_ERROR(scene(kGlass, kSphere, R"("environment": {"type": "skybox"})"),
                     "/environment/type", "unknown environment type 'skybox'");
}

TEST(SceneParse, LatlongFileMissing) {
  TempDir dir;
  const fs::path missing = dir.path() / "no_such_sky.exr";
  EXPECT_SCENE_ERROR(
      scene(kGlass, kSphere,
            R"("environment": {"type": "latlong", "file": ")" + missing.string() + "\"}"),
      "/environment/file", missing.string());
}

TEST(SceneParse, LatlongFileNotAnExr) {
  TempDir dir;
  const fs::path text = dir.write("sky.exr", "this is a text file, not an OpenEXR image\n");
  const std::string json = scene(
      kGlass, kSphere, R"("environment": {"type": "latlong", "file": ")" + text.string() + "\"}");
  EXPECT_SCENE_ERROR(json, "/environment/file", text.string());
  EXPECT_SCENE_ERROR(json, "/environment/file", "not an OpenEXR file");
}

// A relative latlong path is resolved against the scene file's directory (here tests/data/scenes,
// which holds not_an_exr.exr, a text file), and the message names the resolved file.
TEST(SceneParse, LatlongRelativePathResolvesAgainstTheSceneFile) {
  const fs::path scene_file = fs::path(EIKON_SOURCE_DIR) / "tests/data/scenes/latlong_not_exr.json";
  try {
    loadScene(scene_file);
    ADD_FAILURE() << "expected a SceneError";
  } catch (const SceneError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(scene_file.string() + ": /environment/file: ", 0), 0u) << msg;
    EXPECT_NE(msg.find((scene_file.parent_path() / "not_an_exr.exr").string()), std::string::npos)
        << msg;
    EXPECT_NE(msg.find("not an OpenEXR file"), std::string::npos) << msg;
  }
}

TEST(SceneParse, MissingSceneFile) {
  try {
    loadScene("/nonexistent/dir/scene.json");
    ADD_FAILURE() << "expected a SceneError";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/scene.json"), std::string::npos)
        << e.what();
  }
}

// ------------------------------------------------------------------ positive cases

// The docs/design.md §3 example verbatim (N-BK7 comes from the material library, my-calcite is
// inline).
TEST(SceneParse, DesignExampleParses) {
  const char* text = R"({
    "camera": {"position": [0, 0, -60], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
               "width": 800, "height": 600},
    "environment": {"type": "checker", "squares": 16},
    "volume": {"bounds_min": [-12, -12, -12], "bounds_max": [12, 12, 12], "resolution": 128,
               "smoothing_voxels": 0.75},
    "materials": {"my-calcite": {"n_o": {"cauchy": [1.638706, 6.71288e-3, 3.1719e-5]},
                                 "n_e": {"cauchy": [1.477117, 3.05897e-3, 2.4129e-5]},
                                 "optic_axis": [0, 0.7071, 0.7071],
                                 "attenuation_o_per_mm": [0, 0, 0],
                                 "attenuation_e_per_mm": [0, 0, 0]}},
    "objects": [
      {"shape": "box", "center": [0, 0, 0], "size": [20, 20, 10], "rotation_deg": [0, 0, 0],
       "material": "my-calcite"},
      {"shape": "sphere", "center": [0, 0, 0], "radius": 8, "material": "N-BK7"}
    ],
    "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 1.0}]
  })";
  Scene s;
  ASSERT_NO_THROW(s = parseScene(text, kOrigin));
  ASSERT_EQ(s.objects.size(), 2u);
  EXPECT_EQ(s.camera.width, 800);
  EXPECT_EQ(s.volume.resolution, 128);
  ASSERT_EQ(s.materials.count("N-BK7"), 1u);
  ASSERT_EQ(s.materials.count("my-calcite"), 1u);
  const Material& bk7 = s.materials.at("N-BK7");
  EXPECT_FALSE(bk7.uniaxial);
  // SCHOTT catalogue: n_d(587.5618 nm) = 1.51680 (5 decimals in the catalogue ⇒ ±5e-6).
  EXPECT_NEAR(bk7.n_o.index(587.5618), 1.51680, 1e-5);
  const Material& cal = s.materials.at("my-calcite");
  EXPECT_TRUE(cal.uniaxial);
  ASSERT_TRUE(cal.optic_axis.has_value());
  EXPECT_NEAR(glm::length(*cal.optic_axis), 1.0, 1e-12);
  EXPECT_NEAR(cal.optic_axis->y, std::sqrt(0.5), 1e-12);
  // Cauchy A + B/λ² + C/λ⁴ at 589.3 nm (λ² = 0.347274 µm²): 1.638706 + 0.019330 + 0.000263.
  const double l2 = 0.5893 * 0.5893;
  EXPECT_NEAR(cal.n_o.index(589.3), 1.638706 + 6.71288e-3 / l2 + 3.1719e-5 / (l2 * l2), 1e-12);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_TRUE(s.anyUniaxial());
  EXPECT_TRUE(s.anyDispersive());
}

// Calcite from the library: uniaxial, its own optic axis of unit length, an object override
// [0, 3, 4] normalised to [0, 0.6, 0.8]. Indices at 589.3 nm are those quoted in the file's notes
// from Ghosh 1999 (n_o = 1.658344, n_e = 1.486130, 6 decimals); 1e-5 allows for the rounding of
// the quoted values and of the 8-digit Sellmeier coefficients, and is still 100x smaller than
// any confusion of o and e or of formula 1 vs 2 would produce.
TEST(SceneParse, CalciteFromTheLibrary) {
  const std::string text = scene("", R"({"shape": "box", "size": [4, 4, 4], "material": "calcite"},
                                        {"shape": "sphere", "center": [8, 0, 0], "radius": 2, "material": "calcite",
                                         "optic_axis": [0, 3, 4]})");
  Scene s;
  ASSERT_NO_THROW(s = parseScene(text, kOrigin));
  ASSERT_EQ(s.materials.count("calcite"), 1u);
  const Material& c = s.materials.at("calcite");
  EXPECT_TRUE(c.uniaxial);
  ASSERT_TRUE(c.optic_axis.has_value());
  EXPECT_NEAR(glm::length(*c.optic_axis), 1.0, 1e-12);
  EXPECT_NEAR(c.n_o.index(589.3), 1.658344, 1e-5);
  EXPECT_NEAR(c.n_e.index(589.3), 1.486130, 1e-5);
  ASSERT_EQ(s.objects.size(), 2u);
  EXPECT_FALSE(s.objects[0].optic_axis.has_value());
  ASSERT_TRUE(s.objects[1].optic_axis.has_value());
  EXPECT_NEAR(s.objects[1].optic_axis->x, 0.0, 1e-15);
  EXPECT_NEAR(s.objects[1].optic_axis->y, 0.6, 1e-15);
  EXPECT_NEAR(s.objects[1].optic_axis->z, 0.8, 1e-15);
  EXPECT_TRUE(s.anyUniaxial());
}

// A material no object uses is left out, and nothing is said (a palette of materials is fine
// under --strict): an unused dispersive, uniaxial or scattering material made the volume
// dispersive (a spectral render, 12 light bands), uniaxial (two modes) or lit where nothing in it
// is. It is still checked: a bad one is an error.
TEST(SceneParse, UnusedMaterialsAreLeftOut) {
  const std::string text = R"({
    "volume": {"bounds_min": [-10, -10, -10], "bounds_max": [10, 10, 10], "resolution": 16},
    "materials": {"plain": {"n": 1.5},
                  "spare": {"n": {"cauchy": [1.5, 0.004]}, "albedo": 0.5, "opacity": 1},
                  "crystal": {"n_o": 1.6, "n_e": 1.5, "optic_axis": [0, 0, 1]}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 3, "material": "plain"}]
  })";
  Scene s;
  ASSERT_NO_THROW(s = parseScene(text, kOrigin));
  EXPECT_EQ(s.materials.count("plain"), 1u);
  EXPECT_EQ(s.materials.count("spare"), 0u);
  EXPECT_EQ(s.materials.count("crystal"), 0u);
  EXPECT_FALSE(s.anyDispersive());
  EXPECT_FALSE(s.anyScattering());
  EXPECT_FALSE(s.anyUniaxial());
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  std::string bad = text;
  const std::string diffuse = "\"albedo\": 0.5, \"opacity\": 1";
  bad.replace(bad.find(diffuse), diffuse.size(), "\"albedo\": 0.5");  // needs an attenuation
  EXPECT_THROW(parseScene(bad, kOrigin), SceneError);
}

// Every material in the library loads (the library lookup must not reject its own files).
TEST(SceneParse, EveryLibraryMaterialLoads) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(fs::path(EIKON_SOURCE_DIR) / "materials")) {
    if (e.path().extension() != ".json") continue;
    ++n;
    EXPECT_NO_THROW(loadMaterialFile(e.path())) << e.path();
  }
  EXPECT_GE(n, 10);
}

TEST(SceneParse, ShippedScenesParse) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(fs::path(EIKON_SOURCE_DIR) / "scenes")) {
    if (e.path().extension() != ".json") continue;
    ++n;
    try {
      Scene s = loadScene(e.path());
      EXPECT_FALSE(s.objects.empty()) << e.path();
    } catch (const std::exception& ex) {
      ADD_FAILURE() << e.path() << ": " << ex.what();
    }
  }
  EXPECT_GE(n, 1);
}

TEST(SceneParse, TestDataScenesParse) {
  const fs::path p = fs::path(EIKON_SOURCE_DIR) / "tests/data/scenes/tiny_sphere.json";
  Scene s;
  ASSERT_NO_THROW(s = loadScene(p));
  EXPECT_EQ(s.camera.width, 32);
  EXPECT_EQ(s.volume.resolution, 32);
  EXPECT_EQ(s.file, p);
}

}  // namespace
}  // namespace eikon

// ------------------------------------------------------------------ lights and scattering (issue
// 6)
namespace eikon {
namespace {

std::string withLight(const std::string& light) {
  return scene(kGlass, kSphere, "\"lights\": [" + light + "]");
}

TEST(SceneParse, LightsParseBeamsSpotsAndSpectra) {
  Scene s =
      parseScene(withLight(R"({"type": "directional", "direction": [0, -2, 0], "irradiance": 3,
                                     "beam_radius": 1.5, "beam_center": [1, 2, 3], "spectrum": "E"},
                                    {"type": "spot", "position": [0, 5, 0], "direction": [0, -1, 0],
                                     "cone_half_angle_deg": 20, "intensity": 2,
                                     "spectrum": {"wavelength_nm": [400, 700], "power": [1, 3]}},
                                    {"type": "point", "position": [0, 5, 0]})"),
                 kOrigin);
  ASSERT_EQ(s.lights.size(), 3u);
  EXPECT_EQ(s.lights[0].direction, glm::dvec3(0, -1, 0));
  EXPECT_EQ(s.lights[0].beam_radius, 1.5);
  EXPECT_EQ(s.lights[0].position, glm::dvec3(1, 2, 3));
  EXPECT_EQ(s.lights[0].spectralPower(555.0), 1.0);  // "E": flat
  EXPECT_EQ(s.lights[1].type, Light::Type::Spot);
  EXPECT_EQ(s.lights[1].cone_half_angle_deg, 20.0);
  EXPECT_DOUBLE_EQ(s.lights[1].spectralPower(550.0), 2.0);  // linear between (400, 1) and (700, 3)
  EXPECT_EQ(s.lights[1].spectralPower(720.0), 0.0);         // nothing outside the table
  EXPECT_DOUBLE_EQ(s.lights[2].spectralPower(560.0), 100.0);  // default D65, 100 at 560 nm
}

TEST(SceneParse, BadLights) {
  EXPECT_SCENE_ERROR(withLight(R"({"type": "laser", "direction": [0, -1, 0]})"), "/lights/0/type",
                     "unknown light type");
  EXPECT_SCENE_ERROR(withLight(R"({"type": "directional", "direction": [0, 0, 0]})"),
                     "/lights/0/direction", "non-zero");
  EXPECT_SCENE_ERROR(
      withLight(R"({"type": "directional", "direction": [0, -1, 0], "beam_radius": -1})"),
      "/lights/0/beam_radius", "must be > 0");
  EXPECT_SCENE_ERROR(
      withLight(R"({"type": "directional", "direction": [0, -1, 0], "beam_center": [0, 0, 0]})"),
      "/lights/0/beam_center", "needs beam_radius");
  EXPECT_SCENE_ERROR(withLight(R"({"type": "point", "position": [0, 0, 0], "beam_radius": 1})"),
                     "/lights/0/beam_radius", "unknown key");
  EXPECT_SCENE_ERROR(
      withLight(
          R"({"type": "spot", "position": [0, 0, 0], "direction": [0, -1, 0], "cone_half_angle_deg": 95})"),
      "/lights/0/cone_half_angle_deg", "must be in");
  EXPECT_SCENE_ERROR(
      withLight(R"({"type": "spot", "position": [0, 0, 0], "direction": [0, -1, 0]})"), "/lights/0",
      "cone_half_angle_deg");
  EXPECT_SCENE_ERROR(withLight(R"({"type": "point", "position": [0, 0, 0], "intensity": -2})"),
                     "/lights/0/intensity", "must be in");
  EXPECT_SCENE_ERROR(
      withLight(R"({"type": "point", "position": [0, 0, 0], "spectrum": "tungsten"})"),
      "/lights/0/spectrum", "unknown spectrum");
  EXPECT_SCENE_ERROR(withLight(R"({"type": "point", "position": [0, 0, 0],
                                   "spectrum": {"wavelength_nm": [500, 400], "power": [1, 1]}})"),
                     "/lights/0/spectrum/wavelength_nm/1", "strictly increasing");
  EXPECT_SCENE_ERROR(withLight(R"({"type": "point", "position": [0, 0, 0],
                                   "spectrum": {"wavelength_nm": [800, 900], "power": [1, 1]}})"),
                     "/lights/0/spectrum", "no power in 380-780 nm");
  EXPECT_SCENE_ERROR(withLight(R"({"type": "point", "position": [0, 0, 0],
                                   "spectrum": {"wavelength_nm": [400, 500], "power": [1, -1]}})"),
                     "/lights/0/spectrum/power/1", ">= 0");
  EXPECT_SCENE_ERROR(withLight(R"({"type": "point", "position": [0, 0, 0],
                                   "spectrum": {"wavelength_nm": [400, 500], "power": [1e308, 1e308]}})"),
                     "/lights/0/spectrum/power/0", "must be at most 1e9");
}

TEST(SceneParse, ScatteringMaterials) {
  Scene s = parseScene(
      scene(
          R"("smoke": {"n": 1, "attenuation_per_mm": 0.1, "albedo": [0.9, 0.8, 0.7], "phase_g": 0.4},
                                 "floor": {"n": 1, "opacity": 1, "albedo": 0.5})",
          R"({"shape": "sphere", "radius": 3, "material": "smoke"},
                                {"shape": "sphere", "center": [5, 0, 0], "radius": 1, "material": "floor"})"),
      kOrigin);
  EXPECT_EQ(s.materials.at("smoke").albedo, glm::dvec3(0.9, 0.8, 0.7));
  EXPECT_EQ(s.materials.at("smoke").phase_g, 0.4);
  EXPECT_EQ(s.materials.at("floor").albedo, glm::dvec3(0.5));
  const std::string obj = R"({"shape": "sphere", "radius": 3, "material": "m"})";
  EXPECT_SCENE_ERROR(scene(R"("m": {"n": 1, "attenuation_per_mm": 0.1, "albedo": 1.2})", obj),
                     "/materials/m/albedo", "[0, 1]");
  EXPECT_SCENE_ERROR(scene(R"("m": {"n": 1, "albedo": 0.5})", obj), "/materials/m/albedo",
                     "attenuation_per_mm > 0");
  EXPECT_SCENE_ERROR(
      scene(R"("m": {"n": 1, "attenuation_per_mm": 0.1, "albedo": 0.5, "phase_g": 1})", obj),
      "/materials/m/phase_g", "(-1, 1)");
  EXPECT_SCENE_ERROR(scene(R"("m": {"n": 1, "opacity": 1, "albedo": 0.5, "phase_g": 0.2})", obj),
                     "/materials/m/phase_g", "diffuse");
}

}  // namespace
}  // namespace eikon
