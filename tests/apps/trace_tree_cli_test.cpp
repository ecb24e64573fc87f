// `eikon trace --tree` (docs/design.md §3): the light tree of one ray as JSON, on the CPU twin.
//  - a non-absorbing slab (n = 1.5) at normal incidence: the exit leaves on the incident side sum
//    to the total reflectance 2R/(1 + R) within the weight cut below --tree-min-weight, and
//    exit + absorbed + cut = 1; the nodes form a tree (ids in order, parents before children);
//  - a calcite plate: one tree per mode, "o" and "e", each of weight 1;
//  - bad --tree-min-weight, --tree-max-depth, the tree options without --tree, and --tree with
//    --stokes are one error line, no output.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/apps/cli_support.h"

namespace {

namespace fs = std::filesystem;
using eikon::test::Outcome;
using eikon::test::quote;

class TraceTreeCli : public ::testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& objects) const {
    std::ofstream(dir_ / name) << R"({"environment": {"type": "constant", "radiance": 1},
      "interfaces": "sharp",
      "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": 32},
      "materials": {"glass": {"n": 1.5}}, "objects": [)" +
                                      objects + "]}";
    return (dir_ / name).string();
  }
  Outcome run(const std::string& args) const {
    return eikon::test::runEikon(args, dir_ / "io", "EIKON_VALIDATION=1");
  }
  void expectCleanFailure(const Outcome& r, const std::string& phrase) const {
    EXPECT_NE(r.code, 0);
    EXPECT_EQ(r.err.rfind("eikon: error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(phrase), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  eikon::test::TempDir tmp_{"eikon_tree_cli"};
  const fs::path dir_ = tmp_.path();
};

const char* kSlab =
    R"({"shape": "box", "center": [0, 0, 0], "size": [6, 6, 4], "material": "glass"})";

TEST_F(TraceTreeCli, SlabTreeBalancesAndReflectsTheClosedForm) {
  const std::string scene = write("slab.json", kSlab);
  const Outcome r = run("trace " + quote(scene) + " --origin 0.3,0.2,-20 --dir 0,0,1 --tree -q");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("trees").size(), 1u);
  const nlohmann::json& t = j["trees"][0];
  EXPECT_EQ(t.at("mode"), "isotropic");
  EXPECT_EQ(j.at("limits").at("min_weight").get<double>(), 1e-6);
  EXPECT_EQ(j.at("limits").at("max_depth").get<int>(), 64);
  const nlohmann::json& nodes = t.at("nodes");
  ASSERT_GT(nodes.size(), 5u);
  EXPECT_EQ(nodes[0].at("event"), "enter");
  EXPECT_TRUE(nodes[0].at("parent").is_null());
  double front = 0.0;
  for (size_t k = 0; k < nodes.size(); ++k) {
    EXPECT_EQ(nodes[k].at("id").get<size_t>(), k);
    if (k > 0) {
      EXPECT_LT(nodes[k].at("parent").get<size_t>(), k);
    }
    if (nodes[k].at("event") == "exit" && nodes[k].at("direction")[2].get<double>() < 0)
      front += nodes[k].at("weight").get<double>();
  }
  for (const nlohmann::json& id : t.at("exits"))
    EXPECT_EQ(nodes[id.get<size_t>()].at("event"), "exit");
  const nlohmann::json& tot = t.at("totals");
  const double cut = tot.at("cut").get<double>();
  EXPECT_NEAR(tot.at("exit").get<double>() + tot.at("absorbed").get<double>() +
                  tot.at("stopped").get<double>() + cut,
              1.0, 1e-12);
  const double R = 0.04;
  EXPECT_LT(cut, 1e-5);  // a few branches just below 1e-6
  EXPECT_NEAR(front, 2.0 * R / (1.0 + R), cut + 1e-12);
}

TEST_F(TraceTreeCli, CrystalGivesATreePerMode) {
  const std::string scene =
      write("calcite.json",
            R"({"shape": "box", "center": [0, 0, 0], "size": [6, 6, 4], "material": "calcite",
          "optic_axis": [0.7071067811865476, 0, 0.7071067811865476]})");
  const Outcome r = run("trace " + quote(scene) +
                        " --origin 0.3,0.2,-20 --dir 0,0,1 --tree --tree-min-weight 1e-9 -q");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("trees").size(), 2u);
  EXPECT_EQ(j["trees"][0].at("mode"), "o");
  EXPECT_EQ(j["trees"][1].at("mode"), "e");
  for (const nlohmann::json& t : j["trees"]) {
    const nlohmann::json& tot = t.at("totals");
    EXPECT_NEAR(tot.at("exit").get<double>() + tot.at("absorbed").get<double>() +
                    tot.at("stopped").get<double>() + tot.at("cut").get<double>(),
                1.0, 1e-12);
    EXPECT_EQ(t.at("nodes")[1].at("object"), 0);  // inside the plate after its first crossing
  }
}

TEST_F(TraceTreeCli, BadTreeOptionsAreOneLine) {
  const std::string scene = write("slab.json", kSlab);
  const std::string ray = " --origin 0,0,-20 --dir 0,0,1 -q";
  expectCleanFailure(run("trace " + quote(scene) + ray + " --tree --tree-min-weight 0"),
                     "tree-min-weight must be in [1e-15, 1]");
  expectCleanFailure(run("trace " + quote(scene) + ray + " --tree --tree-min-weight 2"),
                     "tree-min-weight must be in [1e-15, 1]");
  expectCleanFailure(run("trace " + quote(scene) + ray + " --tree --tree-max-depth 0"),
                     "tree-max-depth must be in [1, 1024]");
  expectCleanFailure(run("trace " + quote(scene) + ray + " --tree-max-depth 3"), "need --tree");
  expectCleanFailure(run("trace " + quote(scene) + ray + " --tree --stokes 1,0,0,0"),
                     "one at a time");
}

}  // namespace
