// The CPU twin's count of volume-field reads per ray (RenderImage::mean_fetches, printed by
// `view_bench --interfaces`; core/reference/reference_marcher.cpp CountedField), on one ray whose
// reads can be counted by hand: a 1×1 image looking along +z through a slab 4 mm thick (n = 1.5)
// in a 64³ volume over [-8, 8]³ (h = 0.25 mm, voxel centres at u = (z + 8)/h − 0.5).
//  - Sharp march: the entry's region (1 cell), then one locateCrossing per straight segment, each
//    reading the region at its start (1), the cells it walks (1 + the voxel-centre planes it
//    crosses) and, when it finds a crossing, the cells past and at it (2):
//      z −8 → −2: planes u = 0…23, 25 cells: 1 + 25 + 2 = 28;
//      z −2 → 2:  planes u = 24…39, 17 cells: 1 + 17 + 2 = 20;
//      z 2 → 8:   planes u = 40…63, 25 cells, no crossing: 1 + 25 = 26;
//    75 in all, and 4 more for each face where the search restarts past a sliver: a segment
//    starts on the face (the crossing point), where the trilinear region may be either side's,
//    and then first finds the face itself (the region at the start, the one cell to it, the two
//    at it: 4) before the restart's walk. 0, 1 or 2 restarts: 75, 79 or 83, and 79 measured.
//    A small sphere far from the ray makes every shape analytic and not convex_apart: the
//    crossings are then found on the shapes (BoundaryField::exact, crossingOutOf), which read no
//    cell at all: 0. With exact off (what a scene with a mesh gets) the walk's 75–83 above.
//    A lone box (a convex polyhedron apart from
//    any other) takes its crossings from its planes instead (convexCrossingOutOf), which reads
//    the entry's region (1) and one cell per search (the field normal: 3): 4.
//  - Smoothed march: at least the index samples of its integration steps (4 per RK4 step).
#include <gtest/gtest.h>

#include <string>

#include "core/reference/reference_marcher.h"
#include "core/scene/scene.h"
#include "core/volume/field.h"
#include "core/volume/volume_set.h"

namespace eikon {
namespace {

// walk: the field's search even where the shapes' would be taken (BoundaryField::exact off).
RenderImage renderOnePixel(bool sharp, bool lone_box = false, bool walk = false) {
  const std::string sphere =
      lone_box
          ? ""
          : R"(, {"shape": "sphere", "center": [6, 6, 6], "radius": 0.5, "material": "glass"})";
  const Scene scene = parseScene(
      R"({"environment": {"type": "constant", "radiance": 1}, "interfaces": ")" +
          std::string(sharp ? "sharp" : "smoothed") +
          R"(", "camera": {"position": [0.3, 0.2, -40], "look_at": [0.3, 0.2, 0], "width": 1,
                           "height": 1},
             "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 64},
             "materials": {"glass": {"n": 1.5}},
             "objects": [{"shape": "box", "center": [0, 0, 0], "size": [14, 14, 4],
                          "material": "glass"})" +
          sphere + "]}",
      "fetches.json");
  VolumeSet volume = voxelize(scene);
  if (sharp) {
    EXPECT_EQ(volume.boundary.exact, !lone_box);        // a box and a sphere: analytic, not apart
    EXPECT_EQ(volume.boundary.convex_apart, lone_box);  // a lone box: its planes
  }
  if (walk) volume.boundary.exact = false;
  const VolumeField field(volume);
  const ReferenceMarcher ref(field, scene.environment);
  RenderSettings rs;
  rs.march.transport = Transport::Single;  // one march per sample: the counts are one path's
  return ref.render(scene.camera, rs, 1);
}

TEST(FieldFetches, SharpSlabReadsTheCellsItWalks) {
  const RenderImage img = renderOnePixel(true, false, true);
  const double restarts = (img.mean_fetches - 75.0) / 4.0;
  EXPECT_TRUE(restarts == 0.0 || restarts == 1.0 || restarts == 2.0) << img.mean_fetches;
  EXPECT_EQ(img.mean_steps, 2.0);  // two segments end on a crossing; the third leaves
}

TEST(FieldFetches, ExactSharpSlabReadsNoCell) {
  const RenderImage img = renderOnePixel(true);
  EXPECT_EQ(img.mean_fetches, 0.0);  // regions and crossings on the box itself
  EXPECT_EQ(img.mean_steps, 2.0);
}

TEST(FieldFetches, LoneBoxReadsOneCellPerSearch) {
  const RenderImage img = renderOnePixel(true, true);
  EXPECT_EQ(img.mean_fetches, 4.0);
  EXPECT_EQ(img.mean_steps, 2.0);
}

TEST(FieldFetches, SmoothedSlabReadsTheIndexAtEveryStage) {
  const RenderImage img = renderOnePixel(false);
  EXPECT_GE(img.mean_fetches, 4.0 * img.mean_steps);
  EXPECT_GT(img.mean_steps, 2.0);
}

}  // namespace
}  // namespace eikon
