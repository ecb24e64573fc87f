// Where a light's wavefront starts: the seed patches both light simulators launch (docs/design.md
// §2 "Light simulator", docs/light-simulator.md). The CPU twin (core/reference/wavefront.h) and
// the GPU twin (core/render/light_simulator.h) both seed from here, so that they start from
// identical patches and differ only in how they propagate them; the settings are checked here for
// both, with the same messages.
//
//   eikon::VolumeField field(volume);
//   std::vector<eikon::Patch> seeds = eikon::seedWavefront(field, volume.grid, settings, light);
#pragma once

#include <cmath>
#include <glm/glm.hpp>
#include <utility>
#include <vector>

#include "core/light/wavefront_types.h"
#include "core/scene/scene.h"
#include "core/volume/field.h"
#include "core/volume/volume_set.h"

namespace eikon {

/// Patch geometry shared by the seeding and the CPU twin's time steps.
namespace light {

inline glm::dvec3 centre(const Patch& p) { return 0.25 * (p.x[0] + p.x[1] + p.x[2] + p.x[3]); }
inline glm::dvec3 meanW(const Patch& p) { return 0.25 * (p.w[0] + p.w[1] + p.w[2] + p.w[3]); }
/// Vector area (normal · area) of the quad from its diagonals; exact for planar quads.
inline glm::dvec3 vectorArea(const Patch& p) {
  return 0.5 * glm::cross(p.x[2] - p.x[0], p.x[3] - p.x[1]);
}
inline int orientationOf(const Patch& p) {
  double s = glm::dot(vectorArea(p), meanW(p));
  return s > 0 ? 1 : (s < 0 ? -1 : 0);
}

inline bool inside(const glm::dvec3& x, const glm::dvec3& lo, const glm::dvec3& hi) {
  return x.x >= lo.x && x.y >= lo.y && x.z >= lo.z && x.x <= hi.x && x.y <= hi.y && x.z <= hi.z;
}

/// Does the ray o + s·d (s ≥ 0) meet the box?
inline bool rayHitsBox(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& lo,
                       const glm::dvec3& hi) {
  double t0 = 0.0, t1 = 1e300;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (o[a] < lo[a] || o[a] > hi[a]) return false;
      continue;
    }
    double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}

}  // namespace light

/// The settings a run uses on `grid`: dt ≤ 0 becomes 0.5·h, point_radius ≤ 0 becomes 0.5·h.
/// Throws std::invalid_argument ("wavefront: …") for an empty grid or a bad setting.
WavefrontSettings checkedWavefrontSettings(const WavefrontSettings& settings, const Grid& grid);

/// Wave vector along the unit direction s at x on the shell of `mode`: n·s for the o-mode (and
/// where there is no axis), s/√(sᵀM_e s) for the e-mode. il2 = 1/λ², il4 = 1/λ⁴ (λ in µm).
glm::dvec3 onModeShell(const Field& field, int mode, double il2, double il4, const glm::dvec3& x,
                       const glm::dvec3& s);

/// The launch patches for a light (settings checked with checkedWavefrontSettings): directional —
/// a regular grid in the plane perpendicular to the direction through the most upstream corner of
/// the field's bounds, covering the bounds' projection (with beam_radius > 0: a grid centred on the
/// beam axis, only cells whose centre lies within the radius); point — a cube-sphere of radius
/// point_radius, flux I·Ω; spot — the cells of that cube-sphere whose centre direction lies within
/// the cone. Only patches whose centre ray meets the bounds are launched. Corner wave vectors point
/// along the launch direction (the wave normal) and lie on the mode's shell. Throws
/// std::invalid_argument for bad settings or a light without a direction or cone.
std::vector<Patch> seedWavefront(const Field& field, const Grid& grid,
                                 const WavefrontSettings& settings, const Light& light);

}  // namespace eikon
