// `eikon gem` as a user runs it (docs/gem-studio.md): the JSON it prints, the report folder it
// writes, and bad input refused in one line with a non-zero exit and nothing written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/apps/cli_support.h"

namespace {

namespace fs = std::filesystem;
using eikon::test::Outcome;
using eikon::test::quote;

const std::string kCut =
    quote((fs::path(EIKON_SOURCE_DIR) / "scenes" / "faceted_round_brilliant.json").string());
const std::string kSmall = " --tilts -5,5 --width 24 --height 24 --spp 1 --wavelengths 4";

bool oneLine(const std::string& s) { return !s.empty() && s.find('\n') == s.size() - 1; }

// The metrics' keys at the top level, a row per tilt, and -o's files.
TEST(GemCli, JsonKeysAndReport) {
  const eikon::test::TempDir tmp("eikon_gem_cli");
  const fs::path out = tmp.path() / "report";
  const Outcome r = eikon::test::runEikon(
      "gem " + kCut + kSmall + " --json -o " + quote(out.string()), tmp.path() / "io");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  for (const char* key : {"brightness", "fire", "scintillation", "windowing", "extinction"}) {
    ASSERT_TRUE(j.contains(key)) << key;
    EXPECT_TRUE(j[key].is_number()) << key;
  }
  ASSERT_EQ(j["per_tilt"].size(), 2u);
  EXPECT_EQ(j["per_tilt"][0]["tilt_deg"].get<double>(), -5.0);
  EXPECT_TRUE(j["per_tilt"][1].contains("brightness"));
  for (const char* f : {"report.json", "dome_tilts.png", "dome_tilts.exr", "fire_tilts.png",
                        "aset.png", "idealscope.png", "lightbox.png"})
    EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
}

// Each bad input: one line on stderr, a non-zero exit, no report folder.
TEST(GemCli, BadInputIsOneLineAndWritesNothing) {
  const eikon::test::TempDir tmp("eikon_gem_cli_bad");
  const fs::path out = tmp.path() / "report";
  const fs::path opaque = tmp.path() / "opaque.json";
  std::ofstream(opaque) << R"({"materials": {"clay": {"n": 1.5, "opacity": 1}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 2, "material": "clay"}]})";
  const fs::path file = tmp.path() / "a_file";
  std::ofstream(file) << "x";
  const std::string o = " -o " + quote(out.string());
  const std::pair<std::string, std::string> cases[] = {
      {"gem " + kCut + " --tilts 0:10" + o, "--tilts"},
      {"gem " + kCut + " --tilts 90" + o, "[-60, 60]"},
      {"gem " + kCut + " --width 0" + o, "--width"},
      {"gem " + kCut + " --object 4" + o, "object 4"},
      {"gem " + quote(opaque.string()) + o, "no transparent object"},
      {"gem " + quote((tmp.path() / "missing.json").string()) + o, "missing.json"},
      {"gem " + kCut + kSmall + " -o " + quote(file.string()), "a file"},
      {"gem " + kCut + kSmall + " --seed -1" + o, "--seed"},
      {"gem " + kCut + kSmall + " --seed 4294967296" + o, "--seed"},
      {"gem " + kCut + kSmall + " --seed x" + o, "--seed"},
      {"gem " + kCut + kSmall + " --seed 99999999999999999999" + o, "got 99999999999999999999"},
      {"gem " + kCut + kSmall + " --progress sometimes" + o, "--progress"},
  };
  for (const auto& [args, phrase] : cases) {
    const Outcome r = eikon::test::runEikon(args, tmp.path() / "io");
    EXPECT_NE(r.code, 0) << args;
    EXPECT_TRUE(oneLine(r.err)) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(phrase), std::string::npos) << args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(out)) << args;
  }
}

// stderr is not a terminal here: --progress always prints the tilt series' progress, with its
// 100%; -q silences it even when forced; the default prints nothing for a short run.
TEST(GemCli, ProgressOverTheTiltsAndQuiet) {
  const eikon::test::TempDir tmp("eikon_gem_cli_progress");
  const Outcome shown = eikon::test::runEikon("gem " + kCut + kSmall + " --json --progress always",
                                              tmp.path() / "io");
  ASSERT_EQ(shown.code, 0) << shown.err;
  EXPECT_NE(shown.err.find("eikon: tilts"), std::string::npos) << shown.err;
  EXPECT_NE(shown.err.find("100"), std::string::npos) << shown.err;
  EXPECT_TRUE(nlohmann::json::accept(shown.out));  // stdout holds the JSON alone
  const Outcome quiet = eikon::test::runEikon(
      "gem " + kCut + kSmall + " --json --progress always -q", tmp.path() / "io");
  ASSERT_EQ(quiet.code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");
  const Outcome plain =
      eikon::test::runEikon("gem " + kCut + kSmall + " --json", tmp.path() / "io");
  EXPECT_EQ(plain.err, "");
}

// --seed N shifts the pixel grid: the same seed gives the same figures, another seed others.
TEST(GemCli, SeedIsDeterministicAndChangesTheDraw) {
  const eikon::test::TempDir tmp("eikon_gem_cli_seed");
  const auto run = [&](const std::string& seed) {
    const Outcome r =
        eikon::test::runEikon("gem " + kCut + kSmall + " --json" + seed, tmp.path() / "io");
    EXPECT_EQ(r.code, 0) << r.err;
    return nlohmann::json::parse(r.out);
  };
  const nlohmann::json a = run(" --seed 7"), b = run(" --seed 7"), c = run(" --seed 8");
  EXPECT_EQ(a["brightness"], b["brightness"]);
  EXPECT_EQ(a["per_tilt"], b["per_tilt"]);
  EXPECT_NE(a["brightness"], c["brightness"]);
}

}  // namespace
