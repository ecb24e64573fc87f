// The benchmark programs parse their options like the `eikon` CLI (CLI11): --help prints a usage
// line and exits 0 (it used to end in an uncaught exception), and a bad option is one error line
// and a non-zero exit. Skipped when the benchmarks are not built (EIKON_BUILD_BENCHMARKS=OFF).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/apps/cli_support.h"

namespace {

namespace fs = std::filesystem;

struct Bench {
  const char* name;
  const char* binary;
};

class BenchHelp : public ::testing::TestWithParam<Bench> {
 protected:
  /// Run the benchmark with `args`; skips the test when it was not built.
  eikon::test::Outcome run(const std::string& args) {
    const std::string bin = GetParam().binary;
    if (bin.empty() || !fs::exists(bin)) return {-2, "", ""};
    return eikon::test::runProgram(bin, args, dir_);
  }
  eikon::test::TempDir tmp_{"eikon_bench_cli"};
  const fs::path dir_ = tmp_.path();
};

TEST_P(BenchHelp, HelpPrintsUsageAndExitsZero) {
  if (std::string(GetParam().binary).empty() || !fs::exists(GetParam().binary))
    GTEST_SKIP() << GetParam().name << " is not built (EIKON_BUILD_BENCHMARKS=OFF)";
  const eikon::test::Outcome r = run("--help");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("Usage:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(GetParam().name), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--help"), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("terminate"), std::string::npos) << r.err;
}

TEST_P(BenchHelp, UnknownOptionFailsWithOneLine) {
  if (std::string(GetParam().binary).empty() || !fs::exists(GetParam().binary))
    GTEST_SKIP() << GetParam().name << " is not built (EIKON_BUILD_BENCHMARKS=OFF)";
  const eikon::test::Outcome r = run("--no-such-option");
  EXPECT_NE(r.code, 0);
  EXPECT_LT(r.code, 128) << "killed by a signal (an uncaught exception aborts): " << r.err;
  EXPECT_NE(r.err.find("--no-such-option"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("terminate"), std::string::npos) << r.err;
}

INSTANTIATE_TEST_SUITE_P(Benchmarks, BenchHelp,
                         ::testing::Values(Bench{"view_bench", EIKON_VIEW_BENCH},
                                           Bench{"fit_bench", EIKON_FIT_BENCH},
                                           Bench{"spectral_bench", EIKON_SPECTRAL_BENCH},
                                           Bench{"light_bench", EIKON_LIGHT_BENCH}),
                         [](const auto& param_info) { return std::string(param_info.param.name); });

// bench/baseline_ratio.sh (docs/performance.md): its arguments are checked before anything runs,
// each mistake one line naming the argument and a non-zero exit.
class BaselineRatio : public ::testing::Test {
 protected:
  eikon::test::Outcome run(const std::string& args, const std::string& env = "") {
    return eikon::test::runProgram(std::string(EIKON_SOURCE_DIR) + "/bench/baseline_ratio.sh", args,
                                   dir_, env);
  }
  static int lines(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }
  eikon::test::TempDir tmp_{"eikon_baseline_ratio"};
  const fs::path dir_ = tmp_.path();
};

TEST_F(BaselineRatio, MissingBaselineBinaryIsOneErrorLine) {
  const auto r = run("--baseline " + (dir_ / "no_such_program").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--baseline"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no_such_program"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST_F(BaselineRatio, BaselineFromTheEnvironmentIsCheckedToo) {
  const auto r = run("", "EIKON_BASELINE=" + (dir_ / "absent").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("absent"), std::string::npos) << r.err;
}

TEST_F(BaselineRatio, BadArgumentsAreOneErrorLine) {
  for (const char* args : {"--reps 0", "--reps x", "--no-such-option"}) {
    const auto r = run(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(lines(r.err), 1) << args << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << args << ": " << r.out;
  }
}

TEST_F(BaselineRatio, MissingBuildIsOneErrorLine) {
  const auto r = run("--build " + (dir_ / "no_build").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("not built"), std::string::npos) << r.err;
}

// bench/startup.sh (docs/performance.md "Start-up"): the same for its arguments, checked before
// any render runs (so nothing is printed on stdout).
TEST_F(BaselineRatio, StartupBenchBadArgumentsAreOneErrorLine) {
  const std::string script = std::string(EIKON_SOURCE_DIR) + "/bench/startup.sh";
  for (const std::string& args :
       {std::string("--reps 0"), std::string("--reps x"), std::string("--no-such-option"),
        "--eikon " + (dir_ / "no_eikon").string(), (dir_ / "no_scene.json").string()}) {
    const auto r = eikon::test::runProgram(script, args, dir_, "");
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(lines(r.err), 1) << args << ": " << r.err;
    EXPECT_NE(r.err.find("startup.sh: error:"), std::string::npos) << args << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << args << ": " << r.out;
  }
}

}  // namespace
