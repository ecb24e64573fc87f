// Fixtures shared by the light-simulator tests (CPU reference and GPU twin): lights, the glass-
// sphere scene, the exact unit Luneburg field (docs/reference-cases.md §7a), and a statistics
// printer.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

#include "core/reference/wavefront.h"
#include "core/scene/scene.h"

namespace eikon::test {

inline Light directionalLight(glm::dvec3 d, double irradiance) {
  Light l;
  l.type = Light::Type::Directional;
  l.direction = d;
  l.irradiance = irradiance;
  return l;
}

// A directional beam of radius `radius` (mm) about the line through axis_point along dir.
inline Light beam(glm::dvec3 axis_point, glm::dvec3 dir, double radius, double E) {
  Light l = directionalLight(dir, E);
  l.position = axis_point;
  l.beam_radius = radius;
  return l;
}

/// Unpolarised Fresnel reflectance n1 → n2 at incidence i (Born & Wolf eq. 1.5.21), written out
/// here rather than taken from anisotropic/ (the code under test calls that).
inline double fresnelR(double n1, double n2, double i) {
  const double si = std::sin(i), st = n1 * si / n2;
  if (st >= 1.0) return 1.0;
  const double ci = std::cos(i), ct = std::sqrt(1.0 - st * st);
  const double rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
  const double rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
  return 0.5 * (rs * rs + rp * rp);
}

// A glass sphere (n = 1.5, R = 1 mm, smoothing 1 voxel) in a 40 × 32 × 32 grid, h = 0.1 mm; the
// paraxial focus f = nR/(2(n − 1)) = 1.5 mm from the centre lies inside the box.
inline const char* kGlassSphereLightScene = R"({
  "environment": {"type": "constant", "radiance": 1},
  "camera": {"width": 8, "height": 8},
  "volume": {"bounds_min": [-1.6, -1.6, -1.6], "bounds_max": [2.4, 1.6, 1.6], "resolution": 40,
             "smoothing_voxels": 1},
  "materials": {"glass": {"n": 1.5}},
  "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 1.0, "material": "glass"}]
})";

// The scenes of the sharp-interface tests, shared by the CPU twin's (tests/core/light/
// sharp_wavefront_test.cpp, which describes their closed forms) and the GPU twin's
// (tests/core/render/sharp_wavefront_twins_test.cpp). kSharpSlabScene's "RES" is replaced by the
// resolution along x.
inline const char* kSharpSlabScene = R"({
  "camera": {"width": 8, "height": 8},
  "environment": {"type": "constant", "radiance": 1},
  "volume": {"bounds_min": [-6.0, -0.5, -1.0], "bounds_max": [6.5, 0.5, 1.2], "resolution": RES},
  "objects": [{"shape": "box", "center": [0, 0, 0], "size": [60, 60, 1], "material": "glass"}],
  "materials": {"glass": {"n": 1.5}}
})";

/// kSharpSlabScene at `resolution` voxels along x (its "RES" replaced).
inline std::string sharpSlabScene(const char* resolution) {
  std::string json = kSharpSlabScene;
  json.replace(json.find("RES"), 3, resolution);
  return json;
}

inline const char* kSharpRightPrismScene = R"({
  "camera": {"width": 8, "height": 8},
  "environment": {"type": "constant", "radiance": 1},
  "volume": {"bounds_min": [-5.0, -2.0, -1.0], "bounds_max": [4.6, 4.4, 1.0], "resolution": 96},
  "objects": [{"shape": "prism", "apex_deg": 90, "side": 6, "height": 20, "material": "glass"}],
  "materials": {"glass": {"n": 1.5}}
})";

inline const char* kSharpPrismScene = R"({
  "camera": {"width": 8, "height": 8},
  "environment": {"type": "constant", "radiance": 1},
  "volume": {"bounds_min": [-4.4, -2.4, -1.2], "bounds_max": [4.2, 3.0, 1.2], "resolution": 86},
  "objects": [{"shape": "prism", "apex_deg": 60, "side": 6, "height": 20, "material": "glass"}],
  "materials": {"glass": {"n": 1.5168}}
})";

/// A 60° prism of side 3 mm (n = 1.5) whose apex is at (0, √3, 0), h = 0.1 mm: lit along +x by a
/// beam whose axis passes below the apex, it opens a dark wedge behind the apex
/// (SharpWavefront.EdgeBehindTheApexIsSharperThanSmoothed, SharpWavefrontTwins.ApexTears…).
inline const char* kSharpApexPrismScene = R"({
  "camera": {"width": 8, "height": 8},
  "environment": {"type": "constant", "radiance": 1},
  "volume": {"bounds_min": [-2.5, -2.5, -0.3], "bounds_max": [3.0, 3.0, 0.3], "resolution": 55},
  "objects": [{"shape": "prism", "apex_deg": 60, "side": 3, "height": 20, "material": "glass"}],
  "materials": {"glass": {"n": 1.5}}
})";

inline const char* kSharpCalcitePlateScene = R"({
  "camera": {"width": 8, "height": 8},
  "environment": {"type": "constant", "radiance": 1},
  "volume": {"bounds_min": [-2.4, -1.5, -5.7], "bounds_max": [2.4, 1.5, 6.3], "resolution": 80},
  "objects": [{"shape": "box", "center": [0, 0, 0], "size": [60, 60, 10], "material": "calcite",
               "optic_axis": [0.70710678118654752, 0, 0.70710678118654752]}]
})";

/// Luneburg lens of radius 1 about the origin: n = √(2 − r²) inside, 1 outside, exact ∇n.
inline void unitLuneburg(const glm::dvec3& x, double& n, glm::dvec3& g) {
  double r2 = glm::dot(x, x);
  if (r2 >= 1.0) {
    n = 1.0;
    g = glm::dvec3(0.0);
  } else {
    n = std::sqrt(2.0 - r2);
    g = -x / n;
  }
}

inline void printWavefrontStats(const char* name, const WavefrontStats& s) {
  std::printf(
      "[ measured ] %s: steps %d, seeded %zu, max live %zu, splits %zu, halvings %zu (refused %zu, "
      "tears %zu), "
      "kills left/caustic/energy/opaque %zu/%zu/%zu/%zu\n             flux emitted %.12g, left "
      "%.12g, caustic %.12g, "
      "energy %.12g, absorbed %.12g, probe %.12g, ended before probe %.12g\n",
      name, s.steps, s.seeded, s.max_live, s.splits, s.halvings, s.splits_refused, s.tears,
      s.kills_left, s.kills_caustic, s.kills_energy, s.kills_opaque, s.flux_emitted, s.flux_left,
      s.flux_caustic, s.flux_energy, s.flux_absorbed, s.flux_probe, s.flux_ended_before_probe);
}

}  // namespace eikon::test
