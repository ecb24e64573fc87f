// A march that runs out of MarchSettings::max_steps lacks the light it would have reached; both
// twins count such pixel samples in RenderImage::cut_samples (march.glsl / sharp.glsl R.cut,
// reference_marcher.cpp MarchResult::ran_out), so `eikon render` warns instead of showing the
// shortfall as darkness.
//
// Closed form: a gradient-index medium fills the whole volume and the camera's frame lies inside
// the volume's face, so every camera ray marches (no straight steps in a varying index) through
// at least the volume's depth D = 16 mm = 16 voxels. With a step of s voxels it needs at least
// D/s steps: s = 1e-4 needs 160 000 > max_steps = 20 000 on every pixel, s = 0.5 at most
// √3·16/0.5 ≈ 56 steps (the longest chord of the volume) on any. So the count is every pixel
// sample, or none, on each twin. On lavapipe the GPU twin's march is cut before its 20 000 steps,
// by the driver's loop budget (about 8192 steps of this march: docs/view-renderer.md); it used to
// end there silently and add the environment as if the ray had left. Either cut is counted.
#include <gtest/gtest.h>

#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

TEST(StepLimit, SamplesThatRunOutOfStepsAreCountedOnBothTwins) {
  Twins t(R"({
    "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "fov_deg": 10, "width": 12, "height": 9},
    "environment": {"type": "checker", "squares": 8},
    "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 16},
    "materials": {"grin": {"n": {"linear": {"n0": 1.5, "gradient_per_mm": [0, 0.002, 0], "origin": [0, 0, 0]}}}},
    "objects": [{"shape": "box", "center": [0, 0, 0], "size": [16, 16, 16], "material": "grin"}]
  })");
  // The frame at the volume's front face (z = -8, 32 mm from the eye): half-height
  // 32·tan 5° = 2.8 mm, well inside the face's 8 mm.
  const long long pixels = 12 * 9;
  for (const auto& [step, expected] : {std::pair{1e-4, pixels}, std::pair{0.5, 0LL}}) {
    RenderSettings rs;
    rs.march.step_voxels = step;
    rs.spp = 2;
    const RenderImage g = t.gpu->render(rs), c = t.cpu->render(t.scene.camera, rs);
    std::printf(
        "[ measured ] step %g voxels: samples cut GPU %lld, CPU %lld (of %lld); steps %g %g\n",
        step, g.cut_samples, c.cut_samples, 2 * pixels, g.mean_steps, c.mean_steps);
    EXPECT_EQ(g.cut_samples, 2 * expected) << step;
    EXPECT_EQ(c.cut_samples, 2 * expected) << step;
  }
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
