// `eikon trace` through the table facet of a stone given as a faceting diagram (shape "faceted"):
// a plate cut on the machine — 8 girdle facets, a table and a flat culet — of
// n = 2. A ray at 30° from the table's normal refracts to θt with sin θt = sin 30° / 2 (Snell),
// crosses the 2 mm plate, leaves the parallel culet at 30° again and reaches the volume's floor:
// its exit point there is displaced by 2·tan θt against the straight line, which fixes θt.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "tests/apps/cli_support.h"

namespace {

namespace fs = std::filesystem;
using eikon::test::Outcome;
using eikon::test::quote;

TEST(FacetedCli, TraceThroughTheTableRefractsAsSnellSays) {
  const eikon::test::TempDir tmp("eikon_faceted_cli");  // removed at the end, unlike before
  const fs::path& dir = tmp.path();
  const fs::path scene = dir / "plate.json";
  std::ofstream(scene) << R"({
  "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": 64,
             "smoothing_voxels": 0.75},
  "materials": {"n2": {"n": 2.0}},
  "objects": [{"shape": "faceted", "material": "n2", "gear": 96,
    "girdle": {"outline": "round", "diameter": 8, "thickness": 2},
    "tiers": [{"name": "G", "side": "girdle", "symmetry": 8, "first_index": 6, "meet": "girdle"},
              {"name": "T", "side": "table", "distance": 1},
              {"name": "K", "side": "culet", "distance": 1}]}]
})";
  const double kDeg = std::numbers::pi / 180.0;
  const double c30 = std::cos(30 * kDeg), s30 = std::sin(30 * kDeg);
  // From the volume's top face y = 5 to the table at (0, 1, −1): 4 mm down, 4 tan 30° along z.
  const double z0 = -1.0 - 4.0 * std::tan(30 * kDeg);
  std::ostringstream args;
  args.precision(17);
  args << "trace " << quote(scene.string()) << " --origin 0,5," << z0 << " --dir 0," << -c30 << ","
       << s30 << " --json --reference";
  const Outcome r = eikon::test::runEikon(args.str(), dir / "io");
  fs::remove_all(dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const auto p = j["modes"][0]["exit_point"].get<std::vector<double>>();
  const auto d = j["modes"][0]["exit_direction"].get<std::vector<double>>();
  const double sin_t = s30 / 2.0, tan_t = sin_t / std::sqrt(1.0 - sin_t * sin_t);
  // Table (y = 1) to culet (y = −1): z grows by 2 tan θt; culet to the floor y = −5: 4 tan 30°.
  const double z_exit = -1.0 + 2.0 * tan_t + 4.0 * std::tan(30 * kDeg);
  std::printf("[ measured ] exit z %.6f mm (Snell: %.6f; straight through: %.6f)\n", p[2], z_exit,
              -1.0 + 6.0 * std::tan(30 * kDeg));
  EXPECT_NEAR(p[0], 0.0, 1e-6);
  EXPECT_NEAR(p[1], -5.0, 1e-6);
  // 1e-3 mm in z is 0.03° in θt (n = 1.9 would move the exit by 0.029 mm).
  EXPECT_NEAR(p[2], z_exit, 1e-3);
  EXPECT_NEAR(d[1], -c30, 1e-6);
  EXPECT_NEAR(d[2], s30, 1e-6);
  EXPECT_EQ(j["modes"][0]["interfaces"].get<int>(), 2);
}

}  // namespace
