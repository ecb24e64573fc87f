// A scene with a biaxial crystal at the door (core/session): its modes are named fast and slow when
// its crystals are all biaxial (light trees, --modes, the polarised beams' f and s), o and e
// beside a uniaxial crystal; the polarised render is accepted and the polarised trace runs on
// both twins alike.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "core/contract/polarised_render.h"
#include "core/session/light_tree_json.h"
#include "core/session/session.h"

namespace eikon {
namespace {

std::string sceneWith(const std::string& objects) {
  return R"({"environment": {"type": "constant", "radiance": 1},
    "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 32},
    "materials": {"x": {"n_alpha": 1.53, "n_beta": 1.56, "n_gamma": 1.685,
                        "alpha_axis": [1, 0, 0], "gamma_axis": [0, 0, 1]},
                  "q": {"n_o": 1.544, "n_e": 1.553, "optic_axis": [0, 1, 0]}},
    "objects": [)" +
         objects + "]}";
}
const char* kBiaxial = R"({"shape": "sphere", "center": [0, 0, 0], "radius": 3, "material": "x"})";
const char* kUniaxial = R"({"shape": "sphere", "center": [0, 5, 0], "radius": 2, "material": "q"})";

std::vector<std::string> treeModes(const std::string& objects) {
  Session session(std::make_shared<Scene>(parseScene(sceneWith(objects), "b.json")));
  const TraceRequest ray{{0.5, 0.2, -20}, {0, 0, 1}, 587.5618};
  const std::vector<LightTree> trees = session.lightTrees(ray, MarchSettings{}, {});
  const nlohmann::json j = lightTreesJson(ray, {}, trees, "cpu");
  std::vector<std::string> out;
  for (const auto& t : j.at("trees")) out.push_back(t.at("mode").get<std::string>());
  return out;
}

TEST(BiaxialSession, ModesAreFastAndSlowWhereTheCrystalsAreAllBiaxial) {
  EXPECT_EQ(treeModes(kBiaxial), (std::vector<std::string>{"fast", "slow"}));
  EXPECT_EQ(treeModes(std::string(kBiaxial) + ", " + kUniaxial),
            (std::vector<std::string>{"o", "e"}));
  EXPECT_EQ(parseModes("fast"), Modes::O);
  EXPECT_EQ(parseModes("slow"), Modes::E);
}

TEST(BiaxialSession, PolarisedRenderAndTraceRunOnBothTwins) {
  auto scene = std::make_shared<Scene>(parseScene(sceneWith(kBiaxial), "b.json"));
  RenderSettings rs;
  rs.polarised = true;
  EXPECT_NO_THROW(checkPolarisedScene(*scene, rs));
  Session session(scene);
  const TraceRequest ray{{0.4, 0.3, -20}, {0, 0, 1}, 587.5618};
  const PolarisedTrace cpu = session.tracePolarised(ray, Stokes(1, 0, 0, 0), {}, false);
  const PolarisedTrace gpu = session.tracePolarised(ray, Stokes(1, 0, 0, 0), {}, true);
  // Two faces of n ≈ 1.5–1.7 at near-normal incidence: 8–13% reflected, the rest leaves.
  EXPECT_GT(cpu.totalPower(), 0.85);
  EXPECT_LT(cpu.totalPower(), 0.93);
  EXPECT_NEAR(gpu.totalPower(), cpu.totalPower(), 3e-2);  // the GPU's D-projection at its faces
  // The beams' mode letters are fast and slow (f, s), as the scene's modes are named; beside a
  // uniaxial crystal they stay o and e.
  for (const PolarisedTrace* t : {&cpu, &gpu}) {
    std::string letters;
    for (const PolarisedBeam& b : t->beams) letters += b.modes;
    EXPECT_NE(letters.find('f'), std::string::npos) << letters;
    EXPECT_NE(letters.find('s'), std::string::npos) << letters;
    EXPECT_EQ(letters.find_first_of("oe"), std::string::npos) << letters;
  }
  auto mixed = std::make_shared<Scene>(
      parseScene(sceneWith(std::string(kBiaxial) + ", " + kUniaxial), "b.json"));
  std::string letters;
  for (const PolarisedBeam& b :
       Session(mixed).tracePolarised(ray, Stokes(1, 0, 0, 0), {}, false).beams)
    letters += b.modes;
  EXPECT_NE(letters.find_first_of("oe"), std::string::npos) << letters;
  EXPECT_EQ(letters.find_first_of("fs"), std::string::npos) << letters;
}

}  // namespace
}  // namespace eikon
