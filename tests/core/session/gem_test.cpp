// The gem studio's metrics (core/session/gem.h, docs/gem-studio.md) on the shipped round
// brilliant (scenes/faceted_round_brilliant.json) in diamond and in other materials, same cut:
// each test states the optics that orders the metrics. Small images and few tilts keep them cheap.
#include "core/session/gem.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "tests/core/file_support.h"

namespace eikon {
namespace {

const std::filesystem::path kCut =
    std::filesystem::path(EIKON_SOURCE_DIR) / "scenes" / "faceted_round_brilliant.json";

/// The shipped brilliant with its stone's index `n` (a JSON index: a number or a Cauchy fit);
/// null keeps the scene's diamond.
std::shared_ptr<Scene> brilliant(const nlohmann::json& n = nullptr) {
  nlohmann::json j = nlohmann::json::parse(test::slurp(kCut));
  j["environment"] = {{"preset", "dome"}};
  if (!n.is_null()) {
    j["materials"] = {{"stone", {{"n", n}}}};
    j["objects"][0]["material"] = "stone";
  }
  return std::make_shared<Scene>(parseScene(j.dump(), kCut));
}

/// A Cauchy index n = A + B/λ² with n = 2.4175 (diamond's) at 587.56 nm, whatever B.
nlohmann::json cauchyAtDiamondIndex(double b) {
  const double lambda_um = 0.5875618;
  return {{"cauchy", {2.4175 - b / (lambda_um * lambda_um), b}}, {"range_nm", {300, 1000}}};
}

GemRequest smallRequest() {
  GemRequest r;
  r.tilts_deg = {-10, 0, 10};
  r.width = r.height = 64;
  r.spp = 4;
  r.wavelengths = 8;
  return r;
}

// Fire is light split into colours by dispersion. At a fixed index the paths through the stone
// are the same at the index wavelength; the angle between a ray's red and blue ends grows in
// proportion to the Cauchy B (13 times from 0.002 to 0.026), so more pixels see a spot source in
// only part of the spectrum. Without dispersion every wavelength takes the same path through the
// stone (the same Fresnel choices: one seed per pixel sample); what colour remains is sampling's
// at the sources' edges (the wavelengths' passes), which dispersion only adds to.
TEST(Gem, FireRisesWithDispersionAtAFixedIndex) {
  const GemRequest r = smallRequest();
  const double none = analyseGem(brilliant(cauchyAtDiamondIndex(0.0)), r).fire;
  const double low = analyseGem(brilliant(cauchyAtDiamondIndex(0.002)), r).fire;
  const double high = analyseGem(brilliant(cauchyAtDiamondIndex(0.026)), r).fire;
  EXPECT_GT(low, none);
  EXPECT_GT(high, 2.0 * low) << "B = 0.026 against B = 0.002";
}

// Light entering the table at normal incidence meets the pavilion mains (40.75°) at 49.25° and
// then at 3·40.75° − 90° = 32.25°. Diamond (critical angle asin(1/2.4175) = 24.4°) reflects both
// totally and returns the light; glass of n 1.5 (critical 41.8°) lets the second escape through
// the pavilion. So the glass stone is darker under the dome and leaks far more of its table
// (windowing) under the Ideal-scope's backlight, and its dark share (extinction) grows.
TEST(Gem, GlassOfTheSameCutIsDarkerAndWindowsWhereDiamondReturnsTheLight) {
  const GemRequest r = smallRequest();
  const GemReport diamond = analyseGem(brilliant(), r);
  const GemReport glass = analyseGem(brilliant(1.5), r);
  EXPECT_LT(glass.brightness, 0.75 * diamond.brightness);
  EXPECT_GT(glass.windowing, 3.0 * diamond.windowing);
  EXPECT_GT(glass.windowing, 0.1);  // a third of the outline is table; most of it leaks
  EXPECT_GT(glass.extinction, diamond.extinction);
  // The outline face-up is the 16-sided girdle (radius 5 mm, area 8 sin(π/8)·r², 2.6% under the
  // circle) in a frame of 2 · 1.05 · R (R: half the stone's bounding-box diagonal) on a side.
  const auto [lo, hi] = brilliant()->objects[0].shape.bounds();
  const double frame = 2.0 * 1.05 * 0.5 * glm::length(hi - lo);
  const double girdle = 8.0 * std::sin(std::numbers::pi / 8.0) * 25.0;
  EXPECT_NEAR(diamond.per_tilt[1].outline_px / (64.0 * 64.0), girdle / (frame * frame), 0.01);
  for (const GemTilt& t : diamond.per_tilt) {
    EXPECT_GE(t.brightness, 0.0);
    EXPECT_LE(t.windowing, 1.0);
  }
}

// The renders' random choices are seeded by pixel and sample alone: the same request gives the
// same metrics, bit for bit.
TEST(Gem, Deterministic) {
  GemRequest r = smallRequest();
  r.tilts_deg = {0, 5};
  r.width = r.height = 32;
  const GemReport a = analyseGem(brilliant(), r), b = analyseGem(brilliant(), r);
  EXPECT_EQ(a.brightness, b.brightness);
  EXPECT_EQ(a.fire, b.fire);
  EXPECT_EQ(a.scintillation, b.scintillation);
  EXPECT_EQ(a.windowing, b.windowing);
  EXPECT_EQ(a.extinction, b.extinction);
}

TEST(Gem, RequestChecks) {
  EXPECT_EQ(parseGemTilts("-20:20:5").size(), 9u);
  EXPECT_EQ(parseGemTilts("-10,0,10"), (std::vector<double>{-10, 0, 10}));
  for (const char* bad : {"", "1,,2", "0:10", "10:0:5", "0:10:0", "-70,0", "a", "0:10:-1"})
    EXPECT_THROW(parseGemTilts(bad), SettingError) << bad;
  GemRequest r;
  r.width = 0;
  EXPECT_THROW(checkGemRequest(r), SettingError);
  const auto scene = brilliant();
  EXPECT_EQ(gemStone(*scene, std::nullopt), 0u);
  EXPECT_THROW(gemStone(*scene, 3), std::invalid_argument);
}

}  // namespace
}  // namespace eikon
