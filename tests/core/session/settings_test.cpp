// The settings table (core/session/settings.h) that the CLI's options, Python's keywords and the
// session's range checks are made from: every row complete, every default inside its own range,
// and every bound enforced with the setting's own name, both by checkSettingValue and by the
// path a command line takes (fillSettings).
#include "core/session/settings.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>

#include "core/render/render_defaults.h"
#include "core/session/session.h"

namespace eikon {
namespace {

constexpr unsigned kFronts[] = {SettingFront::RenderCli, SettingFront::TraceCli,
                                SettingFront::ViewCli,   SettingFront::PyRender,
                                SettingFront::PyLight,   SettingFront::PyTrace};

bool ranged(const Setting& s) {
  return s.kind == SettingKind::Integer || s.kind == SettingKind::Number;
}

/// The name of the setting a check refuses, or "" when it accepts.
template <class F>
std::string refusedName(F&& check) {
  try {
    check();
  } catch (const SettingError& e) {
    return e.setting();
  }
  return "";
}

/// The given value of one setting through fillSettings, as `eikon render --NAME VALUE` gives it.
std::string refusedByFill(const Setting& s, double v, unsigned front) {
  std::map<std::string, SettingValue, std::less<>> values;
  SettingValue& value = values[s.name];
  value.given = true;
  value.integer = int(v);
  value.number = v;
  SettingRequests requests;
  return refusedName([&] { fillSettings(values, front, requests); });
}

TEST(Settings, EveryRowIsComplete) {
  std::set<std::string> names;
  for (const Setting& s : settings()) {
    SCOPED_TRACE(s.name);
    EXPECT_TRUE(names.insert(s.name).second) << "named twice";
    EXPECT_GT(std::string(s.help).size(), 10u);
    EXPECT_GT(std::string(s.field).size(), 3u);
    EXPECT_NE(s.fill, nullptr);
    EXPECT_NE(s.fronts, 0u);
    // Neutral words: the CLI option without its dashes, lower case and hyphens.
    EXPECT_EQ(std::string(s.name).find_first_not_of("abcdefghijklmnopqrstuvwxyz-"),
              std::string::npos);
    if (ranged(s)) {
      EXPECT_LT(s.min, s.max);
    }
    if (s.kind == SettingKind::Choice || s.kind == SettingKind::Text) {
      EXPECT_GE(s.choices.size(), 2u);
    }
    for (const SettingChoice& c : s.choices) EXPECT_GT(std::string(c.means).size(), 3u) << c.name;
    // An unset default says what it means.
    for (unsigned front : kFronts)
      if ((s.fronts & front) && s.kind != SettingKind::Flag && !*settingDefault(s, front).value) {
        EXPECT_GT(std::string(settingDefault(s, front).means).size(), 3u);
      }
  }
  // One keyword per setting on each Python front end.
  for (unsigned front : {SettingFront::PyRender, SettingFront::PyLight, SettingFront::PyTrace}) {
    std::set<std::string> keywords;
    for (const Setting& s : settings())
      if (s.fronts & front) {
        EXPECT_TRUE(keywords.insert(settingKeyword(s)).second) << s.name;
      }
  }
}

TEST(Settings, EveryDefaultIsInsideItsRange) {
  for (const Setting& s : settings())
    for (unsigned front : kFronts) {
      if (!(s.fronts & front)) continue;
      const SettingDefault d = settingDefault(s, front);
      SCOPED_TRACE(std::string(s.name) + " on front " + std::to_string(front) + ": '" + d.value +
                   "'");
      if (!*d.value) continue;  // unset: `means` says what it is
      if (ranged(s)) {
        const double v = std::stod(d.value);
        // A value standing for "unset" (Python's width=0) must not be one the range takes.
        EXPECT_EQ(settingInRange(s, v), !d.unset);
        if (!d.unset) {
          EXPECT_EQ(refusedByFill(s, v, front), "");
        }
      } else if (s.kind == SettingKind::Choice) {
        EXPECT_NO_THROW(checkSettingChoice(s, d.value));
      }
    }
}

TEST(Settings, EveryBoundRefusesItsNeighbourNamingTheSetting) {
  for (const Setting& s : settings()) {
    if (!ranged(s)) continue;
    SCOPED_TRACE(s.name);
    const bool integer = s.kind == SettingKind::Integer;
    const double inf = std::numeric_limits<double>::infinity();
    double below = s.min_open ? s.min : integer ? s.min - 1 : std::nextafter(s.min, -inf);
    if (s.special && *s.special == below) {  // "or 0 for all cores": taken, and the next refused
      EXPECT_EQ(refusedName([&] { checkSettingValue(s, below); }), "");
      below = integer ? below - 1 : std::nextafter(below, -inf);
    }
    const double above = integer ? s.max + 1 : std::nextafter(s.max, inf);
    for (double bad : {below, above}) {
      SCOPED_TRACE(bad);
      EXPECT_EQ(refusedName([&] { checkSettingValue(s, bad); }), s.name);
      const unsigned cli = s.fronts & SettingFront::RenderCli  ? SettingFront::RenderCli
                           : s.fronts & SettingFront::TraceCli ? SettingFront::TraceCli
                                                               : SettingFront::ViewCli;
      if (s.fronts & SettingFront::Cli) {
        EXPECT_EQ(refusedByFill(s, bad, cli), s.name);
      }
    }
    if (!integer) {
      EXPECT_EQ(refusedName([&] { checkSettingValue(s, std::nan("")); }), s.name);
    }
    // The bounds themselves are taken (an open one is not, unless it is the special value).
    const bool min_taken = !s.min_open || (s.special && *s.special == s.min);
    EXPECT_EQ(refusedName([&] { checkSettingValue(s, s.min); }), min_taken ? "" : s.name);
    EXPECT_EQ(refusedName([&] { checkSettingValue(s, s.max); }), "");
  }
}

TEST(Settings, ChoicesAreRefusedWithTheirList) {
  const Setting& splat = setting("light-splat");
  EXPECT_EQ(refusedName([&] { checkSettingChoice(splat, "max"); }), "light-splat");
  EXPECT_EQ(settingChoiceList(splat), "accumulate or highest");
  EXPECT_THROW(setting("no-such-setting"), std::logic_error);
}

TEST(Settings, HelpSaysTheRangeAndTheDefault) {
  EXPECT_EQ(settingHelp(setting("width"), SettingFront::RenderCli),
            "Image width in [1, 16384]. Default: the scene camera's");
  EXPECT_EQ(settingHelp(setting("step"), SettingFront::RenderCli),
            "Integration step in (0, 4] voxels. Default: 0.5");
  EXPECT_EQ(settingHelp(setting("step"), SettingFront::TraceCli),
            "Integration step in (0, 4] voxels. Default: 0.25");
  EXPECT_EQ(settingRange(setting("light-step")), "in (0, 2] voxels, or 0 for the default (0.5)");
  EXPECT_EQ(settingNumber(16777216), "16777216");
  EXPECT_EQ(settingNumber(587.5618), "587.5618");
}

// The command line's path: the table's defaults fill the requests as the session's own defaults
// (a render with no options is the render of `eikon render` before the table existed).
TEST(Settings, DefaultsFillTheRequestsAsTheSessionsDefaults) {
  std::map<std::string, SettingValue, std::less<>> values;
  for (const Setting& s : settings()) {
    if (!(s.fronts & SettingFront::RenderCli)) continue;
    SettingValue& v = values[s.name];
    const std::string d = s.value;
    v.integer = d.empty() || s.kind != SettingKind::Integer ? 0 : std::stoi(d);
    v.number = d.empty() || s.kind != SettingKind::Number ? 0 : std::stod(d);
    v.text = d;
  }
  SettingRequests r;
  fillSettings(values, SettingFront::RenderCli, r);
  const LightRequest light;
  EXPECT_FALSE(r.view.width || r.view.height || r.view.spp || r.view.wavelengths);
  EXPECT_EQ(r.march.step_voxels, 0.5);
  EXPECT_EQ(r.march.integrator, Integrator::RK4);
  EXPECT_TRUE(r.march.skip_empty && r.march.fresnel);
  EXPECT_EQ(r.view.wavelength_nm, ViewRequest{}.wavelength_nm);
  EXPECT_EQ(r.light.bands, light.bands);
  EXPECT_EQ(r.light.splat, light.splat);
  EXPECT_EQ(r.light.step_voxels, light.step_voxels);
  EXPECT_EQ(r.light.split_voxels, light.split_voxels);
  EXPECT_EQ(r.light.max_patches, light.max_patches);
  EXPECT_EQ(r.light.reflections, light.reflections);
  EXPECT_EQ(light.reflections, defaultLightingOptions().max_reflection_generations);
  EXPECT_EQ(r.light.caustics, light.caustics);
  EXPECT_EQ(r.light.smoothing_voxels, light.smoothing_voxels);
  EXPECT_EQ(r.light.device, light.device);
  EXPECT_EQ(r.light.threads, light.threads);
  EXPECT_EQ(r.device, "auto");
}

}  // namespace
}  // namespace eikon
