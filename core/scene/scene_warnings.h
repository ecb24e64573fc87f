// Warnings for scenes that parse but cannot show what they were written for (Scene::warnings;
// `eikon render --strict` makes them errors): mistakes that used to render a black or empty image
// with no word said.
//
//   - an object with an albedo (a diffuse surface, a scattering medium) and no emission in a scene
//     without lights: it shows only simulated light, so an opaque one renders black;
//   - an object smaller than a voxel of the volume, or than a pixel's footprint at its distance
//     from the camera (a radius of 0.009 typed for 9 mm): nothing of it is seen;
//   - a light whose beam or cone misses every object: it lights nothing, and `eikon render` skips
//     its simulation when every light misses (lightReachesAnObject).
//
// The tests are conservative (each object's bounding sphere, Shape::bounds): a warning is said
// only where the mistake is certain.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/scene/scene.h"

namespace eikon {

/// Whether some of `light`'s rays can meet some object of the scene: always for a directional
/// light without a beam radius and for a point light; for a beam or a spot cone, whether it
/// reaches some object's bounding sphere.
bool lightReachesAnObject(const Scene& scene, const Light& light);

/// Whether some light of the scene reaches some object (false without lights): without, the
/// light simulation would change no voxel, and a render need not run it.
bool anyLightReachesAnObject(const Scene& scene);

/// Append to scene.warnings the warnings above; `json_index[k]` is object k's index in /objects.
void warnUnseenScene(Scene& scene, const std::vector<size_t>& json_index, const std::string& file);

}  // namespace eikon
