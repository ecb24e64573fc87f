// The sharp march's order in a gradient-index region with sharp faces (CPU twin): RK4 is fourth
// order, and so is the march through a linear-GRIN slab entered obliquely, if the step that meets
// a face ends on the integrator's own path (sharpLand) and the optical path is integrated by the
// same stages (sharpRk4). Held to the closed form of tests/core/grin_slab_closed_form.h at steps
// of 1, 0.5 and 0.25 mm (32³ voxels of 0.5 mm; steps of 2, 1 and 0.5 voxels): the errors of the
// exit point and of the optical path fall as h⁴, so the order observed over the 4× range is ≥ 3.5
// (measured: exit point 16.3× and 16.4× per halving, 4.0 over the range; optical path 29× and
// 25×, 4.7). A crossing placed on the step's straight chord instead (off the curved path by its
// sagitta κh²/8), or the optical path summed by the trapezoid rule, is second order: ≈ 4× per
// halving, order ≈ 2. The errors at 0.25 mm (~1e-6 mm) are far above double rounding (~1e-14).
// Both crossing searches of the view march are run: the planes of a lone convex shape
// (convex_apart) and the shapes' clips (exact: a small box beside the slab keeps them from being
// apart).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/reference/reference_marcher.h"
#include "core/scene/scene.h"
#include "core/volume/field.h"
#include "core/volume/volume_set.h"
#include "tests/core/grin_slab_closed_form.h"

namespace eikon {
namespace {

using test::GrinSlab;
using test::observedOrder;

struct Errors {
  double point = 0.0, path = 0.0;
};

void expectFourthOrder(const std::string& extra, bool exact) {
  const GrinSlab slab;
  const Scene scene = parseScene(slab.sceneJson(32, extra), "grin_slab.json");
  const VolumeSet volume = voxelize(scene);
  ASSERT_EQ(volume.boundary.exact, exact);
  ASSERT_EQ(volume.boundary.convex_apart, !exact);
  const VolumeField field(volume);
  const ReferenceMarcher ref(field, scene.environment);
  const double steps[] = {2.0, 1.0, 0.5};  // voxels of 0.5 mm
  Errors e[3];
  for (int i = 0; i < 3; ++i) {
    MarchSettings ms;
    ms.step_voxels = steps[i];
    const TraceOutcome t = ref.trace({slab.origin(), slab.direction(), 550.0}, ms);
    ASSERT_TRUE(t.left_volume);
    ASSERT_EQ(t.interfaces, 2);
    e[i] = {glm::length(t.exit_point - slab.exitPoint()),
            std::abs(t.optical_path_mm - slab.opticalPath())};
    std::printf("[ measured ] %s, h = %.2f mm: exit point error %.3e mm, optical path %.3e mm\n",
                exact ? "exact" : "convex", 0.5 * steps[i], e[i].point, e[i].path);
  }
  const double point = observedOrder(e[0].point, e[2].point, 4.0);
  const double path = observedOrder(e[0].path, e[2].path, 4.0);
  std::printf(
      "[ measured ] %s: ratios per halving exit point %.1f, %.1f; optical path %.1f, "
      "%.1f; order over 4x: %.2f, %.2f\n",
      exact ? "exact" : "convex", e[0].point / e[1].point, e[1].point / e[2].point,
      e[0].path / e[1].path, e[1].path / e[2].path, point, path);
  EXPECT_GE(point, 3.5);
  EXPECT_GE(path, 3.5);
}

TEST(SharpGrinOrder, LinearSlabIsFourthOrderOnTheConvexPlanes) { expectFourthOrder("", false); }

TEST(SharpGrinOrder, LinearSlabIsFourthOrderOnTheExactShapes) {
  expectFourthOrder(R"(, {"shape": "box", "center": [7.5, 7.5, 0], "size": [0.5, 0.5, 0.5],
                          "material": "glass"})",
                    true);
}

}  // namespace
}  // namespace eikon
