// Scenes of given shapes in the cube [−1, 1]³ and their boundary fields, for the tests of the
// boundary field and of the crossings found on it or on the shapes (boundary_test,
// exact_crossing_test).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "core/scene/scene.h"
#include "core/scene/shapes.h"
#include "core/volume/boundary.h"
#include "core/volume/volume_set.h"

namespace eikon::test {

/// A scene of `objects` (shape, material name; each material default-constructed) in [−1, 1]³
/// at `resolution` voxels a side, read from `file` (what its errors name).
inline Scene boundarySceneOf(const std::vector<std::pair<Shape, std::string>>& objects,
                             int resolution, const char* file = "boundary.json") {
  Scene s;
  s.file = file;
  s.volume.bounds_min = glm::dvec3(-1.0);
  s.volume.bounds_max = glm::dvec3(1.0);
  s.volume.resolution = resolution;
  for (const auto& [shape, material] : objects) {
    s.materials[material].name = material;
    SceneObject o;
    o.shape = shape;
    o.material = material;
    s.objects.push_back(o);
  }
  return s;
}

/// The scene's boundary field on its grid, built on 2 threads.
inline BoundaryField boundaryFieldOf(const Scene& s) {
  return buildBoundaryField(s, makeGrid(s.volume), 2);
}

}  // namespace eikon::test
