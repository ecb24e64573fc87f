// The gem studio's standard lighting (docs/gem-studio.md "Lighting presets"): environments a scene
// names ("environment": {"preset": "dome", ...}) and `eikon gem` applies, each a latitude-longitude
// image made here from its geometry. Every preset is defined in the observer's frame: elevation is
// measured from the plane normal to the viewing direction v (from the stone towards the eye: 90°
// is the eye, 0° the stone's girdle plane when it lies face-up, below 0° behind the stone) and
// azimuth about v from the camera's up. A tilted stone is rendered by moving the camera about the
// stone and building the preset again from the moved camera: the stone tilts, the observer and
// the light stay.
//
//   GemLighting g;  g.preset = GemPreset::Dome;
//   makeGemEnvironment(g, scene.camera, scene.environment);   // a LatLong environment
#pragma once

#include <glm/glm.hpp>
#include <string>

#include "core/scene/scene.h"

namespace eikon {

enum class GemPreset { Dome, Spot, Aset, IdealScope, Lightbox };

/// "dome", "spot", "aset", "idealscope" or "lightbox"; false for any other name.
bool parseGemPreset(const std::string& name, GemPreset& out);
const char* gemPresetName(GemPreset preset);
/// The preset names for messages: "dome, spot, aset, idealscope, lightbox".
const char* gemPresetNames();

struct GemLighting {
  GemPreset preset = GemPreset::Dome;
  /// dome: half-angle of the observer's head shadow about v; GIA's brightness metric darkens a
  /// cone of 23° radius (docs/gem-studio.md). idealscope: the viewing hole's half-angle.
  double head_shadow_deg = 23.0;
  /// spot: angular radius of each source (degrees) and its radiance (linear sRGB, white).
  double spot_radius_deg = 1.5, spot_radiance = 1.0;
  int width = 1024;  ///< latlong texels around (height: width/2)
};

/// The unit viewing direction v of a camera (from look_at towards the eye) and its unit up,
/// orthogonalised against v.
struct GemFrame {
  glm::dvec3 v{0, 1, 0}, up{0, 0, 1}, side{1, 0, 0};
};
GemFrame gemFrame(const Camera& camera);

/// The preset's radiance (linear sRGB) arriving from the world direction d (unit) for the frame.
glm::dvec3 gemRadiance(const GemLighting& g, const GemFrame& f, const glm::dvec3& d);

/// `env` becomes the preset as a LatLong image for the camera's frame (intensity 1, unpolarised).
void makeGemEnvironment(const GemLighting& g, const Camera& camera, Environment& env);

/// Radiance of a white Lambertian diffuser with the unit normal n under `env`: (1/π) ∫ L(d)
/// max(0, d·n) dω over the image's texels (linear sRGB). The brightness metric's normaliser.
glm::dvec3 whiteDiffuserRadiance(const Environment& env, const glm::dvec3& n);

}  // namespace eikon
