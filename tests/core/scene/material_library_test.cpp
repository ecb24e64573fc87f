// The material library's lookup (core/scene/material_library.h): forgiving in the safe ways
// (letter case, spaces and underscores as hyphens), and an unknown name answered with the closest
// names and the library's folder and names, every materials/*.json among them.
#include "core/scene/material_library.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "core/scene/scene.h"
#include "tests/core/scene_support.h"

namespace eikon {
namespace {

namespace fs = std::filesystem;

std::string withMaterial(const std::string& name) {
  return R"({"objects": [{"shape": "sphere", "radius": 3, "material": ")" + name + "\"}]}";
}

/// The stems of the shipped materials/*.json.
std::vector<std::string> shippedMaterials() {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(fs::path(EIKON_SOURCE_DIR) / "materials"))
    if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());  // as the library lists them
  return names;
}

TEST(MaterialLibrary, EditDistanceIsLevenshtein) {
  EXPECT_EQ(editDistance("", ""), 0u);
  EXPECT_EQ(editDistance("n-bk8", "n-bk7"), 1u);
  EXPECT_EQ(editDistance("kitten", "sitting"), 3u);
  EXPECT_EQ(editDistance("abc", ""), 3u);
  EXPECT_EQ(editDistance("saphire", "sapphire"), 1u);
}

TEST(MaterialLibrary, NamesAreNormalisedForCaseSpacesAndUnderscores) {
  EXPECT_EQ(normalisedMaterialName("Fused Silica"), "fused-silica");
  EXPECT_EQ(normalisedMaterialName("Fused_Silica"), "fused-silica");
  EXPECT_EQ(normalisedMaterialName("N-BK7"), "n-bk7");
}

// "fused silica" (as the README spells it), "Fused_Silica", "FUSED-SILICA" and "Diamond" are the
// library's fused-silica and diamond: the same indices as the exact names.
TEST(MaterialLibrary, ForgivingSpellingsFindTheSameMaterial) {
  const Scene exact = parseScene(withMaterial("fused-silica"), "m.json");
  const double n_d = exact.materials.at("fused-silica").n_o.index(587.5618);
  EXPECT_NEAR(n_d, 1.4585, 1e-3);  // fused silica's n_d (Malitson 1965)
  for (const std::string name : {"fused silica", "Fused_Silica", "FUSED-SILICA", "Fused Silica"}) {
    const Scene s = parseScene(withMaterial(name), "m.json");
    ASSERT_TRUE(s.materials.count(name)) << name;
    EXPECT_EQ(s.materials.at(name).n_o.index(587.5618), n_d) << name;
    EXPECT_TRUE(s.warnings.empty()) << name << ": " << s.warnings.front();
  }
  const Scene diamond = parseScene(withMaterial("Diamond"), "m.json");
  EXPECT_NEAR(diamond.materials.at("Diamond").n_o.index(587.5618), 2.4175, 2e-3);
  ASSERT_TRUE(findLibraryMaterial("ruby"));
  EXPECT_EQ(findLibraryMaterial("RUBY")->filename(), "ruby.json");
}

// "N-BK8": the closest name, then the folder and every library material, in one line.
TEST(MaterialLibrary, UnknownNameSaysTheClosestAndListsTheLibrary) {
  const std::string e = test::sceneErrorOf(withMaterial("N-BK8"), "m.json");
  EXPECT_TRUE(
      test::isOneLineSceneError(e, "m.json", "/objects/0/material", "unknown material 'N-BK8'"))
      << e;
  EXPECT_NE(e.find("did you mean 'N-BK7'?"), std::string::npos) << e;
  EXPECT_NE(e.find((fs::path(EIKON_SOURCE_DIR) / "materials").string()), std::string::npos) << e;
  const std::vector<std::string> shipped = shippedMaterials();
  ASSERT_GE(shipped.size(), 11u);
  for (const std::string& name : shipped)
    EXPECT_NE(e.find(" " + name + (name == shipped.back() ? ")" : ",")), std::string::npos)
        << name << " not listed: " << e;
  // Several close names, closest first; none close: no guess, still the list.
  const std::string q = test::sceneErrorOf(withMaterial("quarts"), "m.json");
  EXPECT_NE(q.find("did you mean 'quartz'?"), std::string::npos) << q;
  const std::string far = test::sceneErrorOf(withMaterial("unobtainium"), "m.json");
  EXPECT_EQ(far.find("did you mean"), std::string::npos) << far;
  EXPECT_NE(far.find("ruby"), std::string::npos) << far;
}

// A scene's own material misspelt is suggested too (it is no library name).
TEST(MaterialLibrary, SceneMaterialsAreSuggested) {
  const std::string e = test::sceneErrorOf(
      R"({"materials": {"crown": {"n": 1.52}}, "objects": [{"shape": "sphere", "radius": 3, "material": "Crown"}]})",
      "m.json");
  EXPECT_NE(e.find("did you mean 'crown'?"), std::string::npos) << e;
}

// Every library material is found by its own name, and listed.
TEST(MaterialLibrary, EveryShippedFileIsListed) {
  const std::vector<std::string> names = libraryMaterialNames();
  for (const std::string& name : shippedMaterials()) {
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
    EXPECT_TRUE(findLibraryMaterial(name)) << name;
  }
}

}  // namespace
}  // namespace eikon
