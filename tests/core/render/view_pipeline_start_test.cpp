// The view pipeline started before the volume exists (core/render/view_pipeline_start.h):
// its key is predicted from the scene, so the prediction must give the flags the
// voxelised volume gives, for every shipped scene (a miss would compile a second kernel: correct,
// but the start-up gain lost); and a render that adopts the early pipeline gives the same image,
// bit for bit, as one that builds its own.
#include "core/render/view_pipeline_start.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "core/render/view_renderer.h"
#include "shaders/eikon_shared.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

namespace fs = std::filesystem;

TEST(ViewPipelineStart, PredictedFlagsAreTheVoxelisedVolumesForEveryShippedScene) {
  int scenes = 0;
  for (const auto& e : fs::directory_iterator(fs::path(EIKON_SOURCE_DIR) / "scenes")) {
    if (e.path().extension() != ".json") continue;
    SCOPED_TRACE(e.path().filename().string());
    Scene scene = loadScene(e.path());
    scene.volume.resolution = 20;  // the flags do not depend on it; convex_apart is taken at its h
    const VolumeSet v = voxelize(scene);
    EXPECT_EQ(predictVolumeFeatureFlags(scene, false), volumeFeatureFlags(v));
    VolumeSet lit = v;
    lit.light_fluence.assign(v.grid.count(), glm::vec4(0.0f));
    lit.light_flux.assign(v.grid.count(), glm::vec4(0.0f));
    EXPECT_EQ(predictVolumeFeatureFlags(scene, true), volumeFeatureFlags(lit));
    EXPECT_NE(volumeFeatureFlags(lit) & EIKON_F_LIT, 0);
    ++scenes;
  }
  EXPECT_GE(scenes, 20);
}

// The flags follow the features they name (a smoothed glass sphere has none of them; the sharp
// one is sharp; a uniaxial crystal is uniaxial), so that the comparison above is not of zeros.
TEST(ViewPipelineStart, FlagsNameTheVolumesFeatures) {
  const char* sphere = R"({
    "volume": {"bounds_min": [-2, -2, -2], "bounds_max": [2, 2, 2], "resolution": 8},
    "materials": {"g": {"n": 1.5}},
    "objects": [{"shape": "sphere", "radius": 1, "material": "g"}]})";
  Scene s = sceneFromJson(sphere);
  // A lone sharp sphere takes the crossings on its shape (BoundaryField::exact).
  EXPECT_EQ(predictVolumeFeatureFlags(s, false),
            EIKON_F_SHARP | EIKON_F_EXACT | EIKON_F_SMALL_MEDIA | EIKON_F_SMALL_SHAPES);
  s.interfaces = Scene::Interfaces::Smoothed;
  EXPECT_EQ(predictVolumeFeatureFlags(s, false), 0);
  s.materials.at("g").uniaxial = true;
  s.materials.at("g").n_e = Dispersion::constant(1.6);
  s.materials.at("g").optic_axis = glm::dvec3(0, 1, 0);
  EXPECT_EQ(predictVolumeFeatureFlags(s, false), EIKON_F_UNIAXIAL);
}

// A render whose view pipeline was started early adopts it and renders what a renderer that
// compiles its own renders, bit for bit; an early start of other settings is ignored.
TEST(ViewPipelineStart, AnEarlyPipelineRendersTheSameImage) {
  Scene scene = sceneFromJson(R"({
    "camera": {"position": [0, 0, -30], "look_at": [0, 0, 0], "fov_deg": 20, "width": 12, "height": 9},
    "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": 16},
    "materials": {"g": {"n": 1.5}},
    "objects": [{"shape": "sphere", "radius": 3, "material": "g"}]})");
  const VolumeSet v = voxelize(scene);
  RenderSettings rs;
  RenderImage own;
  {
    ViewRenderer r(context(), scene, v);
    own = r.render(rs);
  }
  for (int other : {0, 1}) {
    RenderSettings early_settings = rs;
    if (other) early_settings.wavelengths = 4;  // another key: not adopted
    std::shared_ptr<void> early = startViewPipeline(context(), scene, false, early_settings);
    ASSERT_NE(early, nullptr);
    RenderImage img;
    {
      ViewRenderer r(context(), scene, v, &rs);
      img = r.render(rs);
    }
    early.reset();
    ASSERT_EQ(img.rgb.size(), own.rgb.size());
    EXPECT_EQ(std::memcmp(img.rgb.data(), own.rgb.data(), own.rgb.size() * sizeof(own.rgb[0])), 0)
        << (other ? "other settings started early" : "the same settings started early");
  }
  // Settings render() refuses start nothing.
  RenderSettings bad = rs;
  bad.spp = 0;
  EXPECT_EQ(startViewPipeline(context(), scene, false, bad), nullptr);
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
