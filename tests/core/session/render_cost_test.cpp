// The cost of a render said before it starts (core/session/render_cost.h): the work is counted
// from the settings, the time scaled from a trial of an eighth of each side on the same session,
// and the trial reports no progress of its own (the real render's is the one shown).
#include "core/session/render_cost.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "core/session/session.h"

namespace eikon {
namespace {

const char* kSphere = R"({
  "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
             "width": 160, "height": 120},
  "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 16},
  "materials": {"glass": {"n": 1.5}},
  "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 4, "material": "glass"}]
})";

TEST(RenderCost, WorkIsPixelsTimesSamplesTimesWavelengths) {
  const Scene scene = parseScene(kSphere, "sphere.json");
  RenderSettings rs;
  rs.spp = 3;
  rs.wavelengths = 8;
  RenderCost c = renderWork(scene, rs);
  EXPECT_EQ(c.width, 160);  // the camera's, the settings leaving it 0
  EXPECT_EQ(c.height, 120);
  EXPECT_DOUBLE_EQ(c.samples, 160.0 * 120 * 3 * 8);
  EXPECT_DOUBLE_EQ(c.host_bytes, renderHostBytes(scene, rs));
  EXPECT_DOUBLE_EQ(c.seconds, 0.0);  // no trial, no time
  EXPECT_EQ(describeRenderCost(c).find("about"), std::string::npos);
  rs.wavelengths = 0;  // RGB: one march carries the three channels
  rs.width = 16384;
  rs.height = 16384;
  rs.spp = 1;
  c = renderWork(scene, rs);
  EXPECT_DOUBLE_EQ(c.samples, 16384.0 * 16384.0);
  EXPECT_TRUE(worthATrial(c));
  EXPECT_NE(
      describeRenderCost(c).find("render 16384x16384 px x 1 spp x RGB = 268 M samples, up to"),
      std::string::npos)
      << describeRenderCost(c);
  // Writing 268 M pixels at kWriteSecondsPerPixel: 2 min 22 s, said with the work.
  EXPECT_DOUBLE_EQ(c.write_seconds, 16384.0 * 16384.0 * kWriteSecondsPerPixel);
  EXPECT_NE(describeRenderCost(c).find("about 2 min 22 s to write the EXR and PNG"),
            std::string::npos)
      << describeRenderCost(c);
  rs.width = 64;
  rs.height = 48;
  EXPECT_FALSE(worthATrial(renderWork(scene, rs)));
}

// The trial's time less a render's fixed cost (8×8 pixels) scales with the pixels: 64 times.
TEST(RenderCost, TrialIsAnEighthOfEachSideAndScaledBy64) {
  auto scene = std::make_shared<Scene>(parseScene(kSphere, "sphere.json"));
  Session session(scene);
  std::vector<std::string> stages;
  session.setProgress({[&](const char* what, double) { stages.push_back(what); }, {}});
  session.prepare(false);
  stages.clear();
  RenderSettings rs = renderSettings(*scene, ViewRequest{});
  RenderCost c = renderWork(*scene, rs);
  timeRenderTrial(session, rs, /*gpu=*/false, c);
  EXPECT_EQ(c.trial_width, 20);
  EXPECT_EQ(c.trial_height, 15);
  EXPECT_GT(c.trial_seconds, 0.0);
  EXPECT_GT(c.seconds, 0.0);
  EXPECT_LE(c.seconds, c.trial_seconds * 64.0);
  EXPECT_DOUBLE_EQ(c.low, kRenderCostLow * c.seconds);
  EXPECT_DOUBLE_EQ(c.high, kRenderCostHigh * c.seconds);
  EXPECT_TRUE(stages.empty()) << "the trial reported progress as '" << stages.front() << "'";
  const std::string line = describeRenderCost(c);
  EXPECT_NE(line.find("on the CPU reference, timed on a 20x15 trial"), std::string::npos) << line;
  // The real render afterwards is unchanged by the trial and reports its own progress.
  const RenderImage img = session.render(rs, false);
  EXPECT_EQ(img.width, 160);
  EXPECT_FALSE(stages.empty());
}

// An image too small for an eighth of each side keeps its size and takes 1/64 of the samples:
// the trial never renders as much as the render.
TEST(RenderCost, ATinyImageIsTimedOnFewerSamples) {
  auto scene = std::make_shared<Scene>(parseScene(kSphere, "sphere.json"));
  Session session(scene);
  RenderSettings rs = renderSettings(*scene, ViewRequest{});
  rs.width = 4;
  rs.height = 3;
  rs.spp = 256;
  RenderCost c = renderWork(*scene, rs);
  timeRenderTrial(session, rs, /*gpu=*/false, c);
  EXPECT_EQ(c.trial_width, 4);
  EXPECT_EQ(c.trial_height, 3);
  EXPECT_GT(c.seconds, c.trial_seconds);  // 64 times the trial's samples
}

TEST(RenderCost, DurationsReadAsPeopleSayThem) {
  EXPECT_EQ(formatDuration(4.26), "4.3 s");
  EXPECT_EQ(formatDuration(400), "6 min 40 s");
  EXPECT_EQ(formatDuration(7500), "2 h 05 min");
}

}  // namespace
}  // namespace eikon
