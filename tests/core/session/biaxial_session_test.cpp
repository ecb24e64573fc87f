// A scene with a biaxial crystal at the door (core/session): its modes are named fast and slow when
// its crystals are all biaxial (light trees, --modes), o and e beside a uniaxial crystal; the
// polarised render and trace say in one line that they are not yet for biaxial crystals.
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

TEST(BiaxialSession, PolarisedRenderAndTraceAreRefusedInOneLine) {
  auto scene = std::make_shared<Scene>(parseScene(sceneWith(kBiaxial), "b.json"));
  RenderSettings rs;
  rs.polarised = true;
  try {
    checkPolarisedScene(*scene, rs);
    ADD_FAILURE() << "a polarised render of a biaxial crystal was not refused";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "b.json: a polarised render (--polarised) is not yet for biaxial crystals");
  }
  Session session(scene);
  try {
    session.tracePolarised({{0, 0, -20}, {0, 0, 1}, 587.5618}, Stokes(1, 0, 0, 0), {}, false);
    ADD_FAILURE() << "a polarised trace of a biaxial crystal was not refused";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "b.json: the polarised trace is not yet for biaxial crystals");
  }
}

}  // namespace
}  // namespace eikon
