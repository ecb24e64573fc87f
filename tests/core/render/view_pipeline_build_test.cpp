// The view pipeline compiled on a thread of its own while the scene is voxelised
// (startViewPipelineBuild, issue 14 start-up): a renderer given it renders exactly what a
// renderer that compiles its own pipeline renders; one started for the other march (sharp vs
// smoothed) is not used; nothing the validation layer can see goes wrong across the threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "core/render/view_renderer.h"
#include "tests/core/test_support.h"

namespace eikon {
namespace {

std::string sphereScene(const std::string& interfaces) {
  return R"({"interfaces": ")" + interfaces + R"(",
  "camera": {"position": [0, 0, -30], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 20, "width": 24, "height": 16},
  "environment": {"type": "checker", "squares": 8},
  "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": 24},
  "materials": {"glass": {"n": 1.5}},
  "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 3, "material": "glass"}]
})";
}

RenderImage renderWith(const Scene& scene, const VolumeSet& vs,
                       std::shared_ptr<ViewPipelineBuild> build) {
  ViewRenderer r(test::context(), scene, vs, std::move(build));
  RenderSettings rs;
  rs.march.step_voxels = 0.5;
  return r.render(rs);
}

// Each march compiled ahead and given to the renderer, or compiled by it: the same pixels. And a
// build for the sharp march given to a smoothed scene's renderer is not used: it compiles the
// smoothed march itself.
TEST(ViewPipelineBuild, RendersWhatALazilyBuiltPipelineRenders) {
  for (const char* interfaces : {"sharp", "smoothed"}) {
    SCOPED_TRACE(interfaces);
    const Scene scene = test::sceneFromJson(sphereScene(interfaces));
    // Started before voxelising, as Session::startViewPipeline does.
    auto build = startViewPipelineBuild(test::context(), scene);
    const VolumeSet vs = voxelize(scene);
    const RenderImage a = renderWith(scene, vs, build);
    const RenderImage b = renderWith(scene, vs, nullptr);
    ASSERT_EQ(a.rgb.size(), size_t(24 * 16 * 3));
    EXPECT_EQ(a.rgb, b.rgb);
    // The sphere is in the picture: not every pixel is the environment's.
    double lo = 1e9, hi = -1e9;
    for (float v : a.rgb) lo = std::min(lo, double(v)), hi = std::max(hi, double(v));
    EXPECT_GT(hi - lo, 0.1);
    if (std::string(interfaces) == "smoothed") {
      const Scene other = test::sceneFromJson(sphereScene("sharp"));
      EXPECT_EQ(renderWith(scene, vs, startViewPipelineBuild(test::context(), other)).rgb, b.rgb);
    }
    test::expectNoValidationMessages();
  }
}

// Dropped unused (a render that failed before drawing): destroying it waits for the compilation
// to end, and the context has nothing to complain about.
TEST(ViewPipelineBuild, DroppedUnusedIsHarmless) {
  const Scene scene = test::sceneFromJson(sphereScene("sharp"));
  auto build = startViewPipelineBuild(test::context(), scene);
  build.reset();
  EXPECT_FALSE(build);
  test::expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon
