// The CLI's progress printer (apps/progress.h) where stderr is not a terminal (a file, a pipe, a
// CI log): plain lines at a modest rate, after a quiet time in auto mode or at once after a note
// announcing long work; never carriage returns. Times are shortened through ProgressPacing; the
// rates are the pacing's, counted from the reports, not measured.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "apps/progress.h"

namespace eikon::cli {
namespace {

/// Everything written to `f` so far.
std::string contents(std::FILE* f) {
  std::fflush(f);
  const long end = std::ftell(f);
  std::string s(size_t(std::max(0L, end)), '\0');
  std::rewind(f);
  if (!s.empty()) s.resize(std::fread(s.data(), 1, s.size(), f));
  std::fseek(f, 0, SEEK_END);
  return s;
}

std::vector<std::string> lines(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

ProgressPacing fast() {
  ProgressPacing p;
  p.quiet_for = std::chrono::milliseconds(200);
  p.line_every = std::chrono::milliseconds(300);
  p.line_gap = std::chrono::milliseconds(0);
  return p;
}

// Auto without a terminal: nothing during the quiet time (a short command prints only its
// summary), then plain lines: one per 10% passed, not one per report.
TEST(ProgressPrinter, AutoWithoutATerminalPrintsPlainLinesAfterItsQuietTime) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    Progress p(ProgressMode::Auto, fast(), f, /*tty=*/false);
    p.update("rendering", 0.01);
    p.update("rendering", 0.02);
    EXPECT_EQ(contents(f), "") << "printed during the quiet time";
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    for (int i = 3; i <= 100; ++i) p.update("rendering", i / 100.0);  // 98 reports
    p.finish();
  }
  const std::string out = contents(f);
  EXPECT_EQ(out.find('\r'), std::string::npos) << out;
  const auto ls = lines(out);
  // The first line once awake, one per 10% step passed (10%..90%: 9), and the 100%; the ticker
  // adds at most one more in the milliseconds the loop takes.
  ASSERT_GE(ls.size(), 10u) << out;
  EXPECT_LE(ls.size(), 12u) << out;
  for (const std::string& l : ls) EXPECT_EQ(l.rfind("eikon: rendering ", 0), 0u) << l;
  EXPECT_NE(ls.back().find("100.0%"), std::string::npos) << out;
  std::fclose(f);
}

// Without reports a line still comes after line_every: the work is alive.
TEST(ProgressPrinter, AQuietStageGetsALineAfterLineEvery) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    Progress p(ProgressMode::Always, fast(), f, /*tty=*/false);
    p.update("light", 0.5);
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  }
  const auto ls = lines(contents(f));
  EXPECT_GE(ls.size(), 3u) << "the first report and lines every 0.3 s";
  EXPECT_LE(ls.size(), 8u);
  std::fclose(f);
}

// A note announcing long work (the render's cost line) is printed at once and wakes the lines;
// -q (never) prints neither.
TEST(ProgressPrinter, ALongWorkNoteStartsTheLinesAtOnce) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  ProgressPacing slow = fast();
  slow.quiet_for = std::chrono::hours(1);
  {
    Progress p(ProgressMode::Auto, slow, f, /*tty=*/false);
    p.note("cost: about 6 min", /*long_work=*/false);
    p.update("rendering", 0.0);
    EXPECT_EQ(contents(f), "") << "not long: auto stays quiet";
    p.note("cost: about 6 min", /*long_work=*/true);
    p.update("rendering", 0.05);
    p.finish();
  }
  const auto ls = lines(contents(f));
  ASSERT_EQ(ls.size(), 2u);
  EXPECT_EQ(ls[0], "eikon: cost: about 6 min");
  EXPECT_EQ(ls[1].rfind("eikon: rendering   5.0%", 0), 0u) << ls[1];
  std::FILE* g = std::tmpfile();
  {
    Progress p(ProgressMode::Never, fast(), g, /*tty=*/false);
    p.note("cost: about 6 min", true);
    p.update("rendering", 0.5);
    std::this_thread::sleep_for(std::chrono::milliseconds(400));
  }
  EXPECT_EQ(contents(g), "");
  std::fclose(f);
  std::fclose(g);
}

}  // namespace
}  // namespace eikon::cli
