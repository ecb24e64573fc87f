// The voxeliser with objects at coordinates far outside the volume: the voxel
// index range of an object is clamped in floating point before it is converted to int, so a
// sphere of radius 1e9 mm covers every voxel (before: the overflowing conversion — undefined
// behaviour, INT_MIN on x86 — clamped the range to one slab, silently dropping the object) and a
// sphere at 4294967296 mm or 1e300 mm leaves every voxel in the ambient medium. These scenes are
// built in code: the scene parser refuses or warns about them (scene_limits_test.cpp); the
// voxeliser must still be safe for any Scene it is handed (run under UBSan by the audit build).
#include <gtest/gtest.h>

#include "core/scene/scene.h"
#include "core/volume/volume_set.h"

namespace eikon {
namespace {

Scene sphereScene(glm::dvec3 center, double radius, double sigma) {
  Scene s;
  s.file = "extremes.json";
  s.volume.bounds_min = glm::dvec3(-1.0);
  s.volume.bounds_max = glm::dvec3(1.0);
  s.volume.resolution = 8;  // h = 0.25 mm: a radius of 1e9 mm is 4e9 voxels, beyond INT_MAX
  s.volume.smoothing_voxels = sigma;
  Material glass;
  glass.name = "glass";
  glass.n_o = glass.n_e = Dispersion::constant(1.5);
  s.materials["glass"] = glass;
  SceneObject o;
  o.shape = Shape("sphere", SphereShape{radius}, center, glm::dvec3(0.0));
  o.material = "glass";
  s.objects.push_back(o);
  return s;
}

/// Index A of every voxel (o-mode).
std::vector<float> indexA(const Scene& s) {
  const VolumeSet vs = voxelize(s);
  std::vector<float> a;
  for (const auto& t : vs.index[0][0]) a.push_back(t.x);
  EXPECT_EQ(a.size(), vs.grid.count());
  return a;
}

TEST(VoxelizeExtremes, HugeSphereCoversEveryVoxel) {
  for (double sigma : {0.0, 0.75}) {
    const auto a = indexA(sphereScene(glm::dvec3(0.0), 1e9, sigma));
    for (size_t i = 0; i < a.size(); ++i)
      ASSERT_FLOAT_EQ(a[i], 1.5f) << "voxel " << i << ", sigma " << sigma;
  }
}

TEST(VoxelizeExtremes, FarAwaySpheresLeaveTheAmbientMedium) {
  for (double x : {4294967296.0, -4294967296.0, 1e300, -1e300})
    for (double sigma : {0.0, 0.75}) {
      const auto a = indexA(sphereScene(glm::dvec3(x, 0.0, 0.0), 3.0, sigma));
      for (size_t i = 0; i < a.size(); ++i)
        ASSERT_FLOAT_EQ(a[i], 1.0f) << "voxel " << i << ", centre x " << x;
    }
}

}  // namespace
}  // namespace eikon
