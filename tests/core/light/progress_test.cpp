// Progress in pieces: the long pieces of work report how far they are often enough for
// the CLI's progress printer (apps/progress.h) to move at least once a second. The voxeliser
// reports per z slab, the light simulators per time step (CPU) or dispatch (GPU), the view
// renderers per band of rows (GPU) or row (CPU). Every sequence of reports stays in [0, 1], never
// decreases and ends at 1; the counts are lower bounds from the work's size, not timings.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "core/reference/reference_lighting.h"
#include "core/reference/wavefront.h"
#include "core/render/light_simulator.h"
#include "tests/core/light_fixtures.h"
#include "tests/core/test_support.h"

namespace eikon {
namespace {

using test::context;
using test::sceneFromJson;

void expectMonotoneToOne(const std::vector<double>& f, const char* what) {
  ASSERT_FALSE(f.empty()) << what;
  for (size_t i = 0; i < f.size(); ++i) {
    EXPECT_GE(f[i], 0.0) << what << " report " << i;
    EXPECT_LE(f[i], 1.0) << what << " report " << i;
    if (i > 0) {
      EXPECT_GE(f[i], f[i - 1]) << what << " report " << i;
    }
  }
  EXPECT_NEAR(f.back(), 1.0, 1e-9) << what;
}

// The sphere (R = 1 mm) spans 2R/h = 20 z layers of h = 0.1 mm (plus the smoothing margin),
// which the voxeliser takes in slabs of kVoxelBlock (4) layers (core/volume/grid.h): the object
// phase alone reports at least 20 / 4 = 5 times on one thread (it reported once per object).
TEST(Progress, VoxeliserReportsPerSlab) {
  const Scene scene = sceneFromJson(test::kGlassSphereLightScene);
  for (int threads : {1, 4}) {
    std::vector<double> f;
    int object_phase = 0;
    VoxelizeOptions o;
    o.threads = threads;
    o.progress = [&](double x, const char*) {
      f.push_back(x);
      if (x < 0.4) ++object_phase;
    };
    voxelize(scene, o);
    expectMonotoneToOne(f, "voxelize");
    if (threads == 1) {
      EXPECT_GE(object_phase, 20 / kVoxelBlock);
    }
  }
}

// The CPU simulator reports after every step: the beam crosses the 4 mm box in ≥ 4 mm / dt
// (dt = 0.5 h = 0.05 mm) = 80 steps. The last report, after every patch has ended, is 1.
TEST(Progress, CpuLightSimulatorReportsPerStep) {
  const Scene scene = sceneFromJson(test::kGlassSphereLightScene);
  const VolumeSet vol = voxelize(scene);
  VolumeField field(vol);
  for (int threads : {1, 2}) {
    std::vector<double> f;
    WavefrontSettings s;
    s.threads = threads;
    s.split_span_voxels = 4;  // few patches: the steps, not the patches, are counted here
    s.progress = [&](double x) { f.push_back(x); };
    WavefrontSimulator(field, vol.grid, s).run(test::directionalLight({1, 0, 0}, 1.0));
    EXPECT_GE(f.size(), 80u);
    expectMonotoneToOne(f, "CPU wavefront");
  }
}

// The GPU twin reports per dispatch of 16 steps: ≥ 80 / 16 = 5 reports.
TEST(Progress, GpuLightSimulatorReportsPerDispatch) {
  const Scene scene = sceneFromJson(test::kGlassSphereLightScene);
  const VolumeSet vol = voxelize(scene);
  std::vector<double> f;
  WavefrontSettings s;
  s.split_span_voxels = 4;
  s.progress = [&](double x) { f.push_back(x); };
  GpuWavefront(context(), vol, s, 16).run(test::directionalLight({1, 0, 0}, 1.0));
  EXPECT_GE(f.size(), 5u);
  expectMonotoneToOne(f, "GPU wavefront");
  test::expectNoValidationMessages();
}

// The lighting driver passes the runs' steps on as one stage: many more reports than runs + 1
// (what it made before), all under one label.
TEST(Progress, LightingDriverReportsWithinRuns) {
  std::string json = test::kGlassSphereLightScene;
  json.insert(json.rfind('}'),
              R"(, "lights": [{"type": "directional", "direction": [1, 0, 0], "irradiance": 1}])");
  const Scene scene = sceneFromJson(json);
  VolumeSet vol = voxelize(scene);
  std::vector<double> f;
  std::vector<std::string> labels;
  LightingOptions o;
  o.bands = 2;
  o.wave.split_span_voxels = 4;
  o.progress = [&](double x, const std::string& what) {
    f.push_back(x);
    if (labels.empty() || labels.back() != what) labels.push_back(what);
  };
  const LightingSummary sum = simulateLightingReference(scene, vol, o);
  EXPECT_EQ(sum.runs, 2u);
  // A report per time step (straight steps cover several): ten a run is already five times the
  // runs + 1 of before.
  EXPECT_GE(f.size(), 2 * 10u);
  expectMonotoneToOne(f, "lighting");
  EXPECT_EQ(labels.size(), 1u) << labels.back();
}

// A small image is several bands (it was one dispatch, so progress jumped from 0 to 100%): the
// first band is one workgroup row of 8 pixel rows, so 24 rows are at least 2 bands.
TEST(Progress, ViewRenderersReportPerBandAndRow) {
  test::Twins t(test::kGlassSphereLightScene);
  RenderSettings rs;
  rs.width = 32;
  rs.height = 24;
  std::vector<double> gpu, cpu;
  rs.progress = [&](double x) { gpu.push_back(x); };
  t.gpu->render(rs);
  EXPECT_GE(gpu.size(), 2u);
  expectMonotoneToOne(gpu, "GPU view");
  rs.progress = [&](double x) { cpu.push_back(x); };
  t.cpu->render(t.scene.camera, rs, 2);
  EXPECT_GE(cpu.size(), 2u);
  expectMonotoneToOne(cpu, "CPU view");
  test::expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon
