// A scene as read from scene.json (format: docs/scene-format.md; docs/design.md §3).
//
//   eikon::Scene scene = eikon::loadScene("scenes/glass_sphere.json");   // throws SceneError
//   scene.camera.width = 400;                                           // override before use
//
// Every user error is an eikon::SceneError whose message names the file and the JSON path
// ("scenes/x.json: /objects/1/radius: must be > 0, got -3"). Unknown keys are errors; nothing is
// clamped. Lengths are millimetres, wavelengths nanometres, attenuation per millimetre.
#pragma once

#include <filesystem>
#include <glm/glm.hpp>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "anisotropic/dispersion.h"
#include "core/scene/messages.h"
#include "core/scene/shapes.h"

namespace eikon {

/// Its message is made printable (core/scene/messages.h) on construction: it quotes user input.
struct SceneError : std::runtime_error {
  explicit SceneError(const std::string& message) : std::runtime_error(printable(message)) {}
};

/// A gradient-index profile that replaces a constant index inside an object (world coordinates).
struct GrinProfile {
  enum class Type { None, Linear, Luneburg, MaxwellFisheye } type = Type::None;
  double n0 = 1.0;           ///< Linear: index at `origin`; Fisheye: n₀ of n₀/(1 + r²/R²)
  glm::dvec3 gradient{0.0};  ///< Linear: ∇n per mm
  glm::dvec3 origin{0.0};    ///< Linear origin / Luneburg and fisheye centre
  double radius = 1.0;       ///< Luneburg: n = √(2 − r²/R²); fisheye R
  /// Index at a world point (valid inside the object only).
  double index(const glm::dvec3& x) const;
  /// ∇n at a world point (per mm).
  glm::dvec3 indexGradient(const glm::dvec3& x) const;
};

/// Wavelength-dependent attenuation σ(λ) per mm, given as RGB band values (placed at 612, 549 and
/// 465 nm, linear in between, constant beyond) or as explicit spectral samples.
struct Attenuation {
  glm::dvec3 rgb{0.0};
  std::vector<double> wavelengths_nm, values;  ///< spectral form (sorted), overrides rgb if set
  double at(double lambda_nm) const;
  /// The band values the renderer stores, σ at 612, 549 and 465 nm (r, g, b): the RGB triple
  /// itself, or the spectrum interpolated linearly at those wavelengths (core/volume/media.cpp).
  glm::dvec3 bands() const { return {at(612.0), at(549.0), at(465.0)}; }
  bool isZero() const;
};

struct Material {
  std::string name;
  std::string source;  ///< where the data came from (library files)
  bool uniaxial = false;
  Dispersion n_o;    ///< the index of an isotropic material, or the ordinary index
  Dispersion n_e;    ///< extraordinary index (uniaxial only)
  GrinProfile grin;  ///< isotropic gradient-index profile (replaces n_o if set)
  std::optional<glm::dvec3> optic_axis;  ///< unit vector, world space
  Attenuation attenuation_o, attenuation_e;
  /// A biaxial crystal (docs/scene-format.md "Biaxial materials"): the principal indices
  /// n_α ≤ n_β ≤ n_γ of light polarised along alpha_axis, betaAxis() and gamma_axis (unit,
  /// orthogonal, world space) and the attenuation of each. Scenes render objects of it with sharp
  /// interfaces (docs/biaxial-optics.md "In the renderer"); n_o, n_e and the o/e attenuation keep
  /// their defaults.
  bool biaxial = false;
  Dispersion n_alpha, n_beta, n_gamma;
  glm::dvec3 alpha_axis{1, 0, 0}, gamma_axis{0, 0, 1};
  Attenuation attenuation_alpha, attenuation_beta, attenuation_gamma;
  glm::dvec3 betaAxis() const { return glm::cross(gamma_axis, alpha_axis); }  ///< γ × α
  glm::dvec3 emission{0.0};  ///< radiance per mm (translucent) or surface radiance (opaque)
  double opacity = 0.0;      ///< 1 = opaque: rays stop at the surface
  /// Translucent: single-scattering albedo σ_s/σ_t per RGB band (σ_t = the attenuation), so the
  /// scattering coefficient is albedo·σ_t; opaque: the diffuse (Lambertian) reflectance of the
  /// surface, which then shows the simulated irradiance as albedo·E/π. Zero: no scattering.
  glm::dvec3 albedo{0.0};
  double phase_g = 0.0;  ///< Henyey–Greenstein asymmetry g ∈ (−1, 1) of the in-scatter
};

/// The polarisation state of the environment or of a light (docs/polarisation.md): a Stokes
/// vector normalised to S0 = 1 in the frame whose reference direction x̂ is `reference` projected
/// ⊥ the propagation direction (Mitsuba 3's stokes_basis of that direction when unset; ŷ =
/// k̂ × x̂). The default (1, 0, 0, 0) is unpolarised; the radiance itself is given elsewhere.
struct Polarization {
  glm::dvec4 stokes{1.0, 0.0, 0.0, 0.0};
  std::optional<glm::dvec3> reference;  ///< unit, world space
  bool unpolarized() const { return stokes.y == 0.0 && stokes.z == 0.0 && stokes.w == 0.0; }
};

/// An ideal linear polariser sheet, {"shape": "polarizer", ...} in /objects (docs/scene-format.md):
/// a width × height rectangle centred on `center` in the plane ⊥ `normal`, transmitting the field
/// along `axis`; width is measured along the axis, height along normal × axis. It is not part of
/// the index volume and may lie outside it.
struct PolarizerSheet {
  glm::dvec3 center{0.0};
  glm::dvec3 normal{0, 0, 1};  ///< unit
  glm::dvec3 axis{1, 0, 0};    ///< unit, ⊥ normal: the transmission axis
  double width = 1.0, height = 1.0;
  size_t object_index = 0;  ///< its index in the scene file's /objects (messages)
};

struct Camera {
  glm::dvec3 position{0, 0, -60}, look_at{0.0}, up{0, 1, 0};
  double fov_deg = 30.0;  ///< vertical field of view
  int width = 800, height = 600;
  /// An ideal linear analyser in front of the camera: its transmission axis (unit; the image
  /// plane's component of it is used). Unset: no analyser.
  std::optional<glm::dvec3> analyzer;
};

struct Environment {
  enum class Type { Checker, Constant, LatLong } type = Type::Checker;
  int squares = 16;                        ///< checker squares per 180° of latitude
  glm::dvec3 color_a{1.0}, color_b{0.05};  ///< checker colours (linear sRGB radiance)
  glm::dvec3 radiance{1.0};                ///< constant
  double intensity = 1.0;                  ///< scale applied to every type
  std::filesystem::path image_path;        ///< latlong EXR
  int image_width = 0, image_height = 0;
  std::vector<float> image_rgba;  ///< latlong texels, rows from the top (north)
  Polarization polarization;      ///< of the light arriving from the environment
  /// Radiance seen in a world direction (unit vector), linear sRGB. Same formula as the shader.
  glm::dvec3 lookup(const glm::dvec3& dir) const;
};

struct VolumeSpec {
  glm::dvec3 bounds_min{-12.0}, bounds_max{12.0};
  int resolution = 128;  ///< voxels along the longest side; voxels are cubes
  double smoothing_voxels =
      0.75;  ///< σ of the pre-smoothing, in voxels (0 = none: sharp, anti-aliased)
  /// How the σ-smoothing is done: "analytic" (default) smooths each object's indicator through its
  /// signed distance with a compact kernel of variance σ² (exact normals for flat faces);
  /// "gaussian" supersamples coverage and convolves with a Gaussian (the seed's method).
  enum class Smoothing { Analytic, Gaussian } smoothing = Smoothing::Analytic;
};

/// "render": the quality a scene is meant to be rendered at (docs/scene-format.md "render"), the
/// defaults of `eikon render` and Python's render; options given there override them. Unset: the
/// renderer's own defaults (1 sample, 16 wavelengths for dispersive scenes, exposure 0).
struct RenderHints {
  std::optional<int> spp;          ///< [1, 4096] jittered samples per pixel
  std::optional<int> wavelengths;  ///< [0, 256] spectral samples per pixel sample (0 = RGB)
  std::optional<double> exposure;  ///< [-64, 64] stops of the PNG preview (and the viewer)
};

struct SceneObject {
  Shape shape;
  std::string material;                  ///< key into Scene::materials
  std::optional<glm::dvec3> optic_axis;  ///< per-object override (unit, world space)
  /// "optic_axis_field": "radial" — the axis points away from the object's centre everywhere
  /// (a spherulite); the e-ray equation then includes the axis' derivative.
  bool radial_axis = false;
  /// Per-object principal axes of a biaxial material (both or neither; unit, orthogonal, world
  /// space), overriding the material's alpha_axis and gamma_axis: the crystal's orientation.
  std::optional<glm::dvec3> alpha_axis, gamma_axis;
};

/// A light of the light simulator (docs/light-simulator.md). Its power is `irradiance`
/// (directional: E in W/mm² across the beam; point and spot: intensity I in W/sr), the integral
/// over 380–780 nm of a spectral distribution of the given shape. Colours are normalised so that a
/// light of any spectrum and power E lights a white diffuse surface at normal incidence to
/// linear-sRGB luminance Y = E (D65: rgb ≈ (E, E, E)).
struct Light {
  enum class Type { Directional, Point, Spot } type = Type::Directional;
  glm::dvec3 direction{0, -1,
                       0};  ///< directional and spot: unit propagation direction (spot: cone axis)
  glm::dvec3 position{
      0.0};  ///< point and spot: the source; directional with a beam: a point on the beam axis
  double irradiance = 1.0;  ///< directional: E (W/mm²); point, spot: intensity I (W/sr)
  /// Directional only: radius (mm) of a collimated beam of circular cross-section about the axis
  /// through `position` (a laser or a slit-less collimator); 0 = the whole volume is lit.
  double beam_radius = 0.0;
  /// Spot only: half-angle (degrees) of the cone of directions about `direction` that is lit.
  double cone_half_angle_deg = 0.0;
  /// Relative spectral power distribution (any scale); empty = D65 (CIE standard daylight).
  std::vector<double> spectrum_nm, spectrum_power;
  Polarization polarization;  ///< of the emitted light (default unpolarised)
  /// Relative spectral power at λ (nm): the tabulated shape, linear in between, 0 outside; D65
  /// when no table is given.
  double spectralPower(double lambda_nm) const;
};

struct Scene {
  std::filesystem::path file;
  Camera camera;
  Environment environment;
  VolumeSpec volume;
  std::map<std::string, Material> materials;
  std::vector<SceneObject> objects;
  std::vector<Light> lights;
  std::vector<PolarizerSheet> polarizers;  ///< ideal sheets, not voxelised
  double ambient_index = 1.0;              ///< index of the medium around the objects (air)
  RenderHints render;                      ///< "render": its intended quality
  /// "interfaces": how boundaries between media are marched. Sharp (default): located on the
  /// boundary field (core/volume/boundary.h) and crossed with exact Snell/Fresnel; Smoothed: the
  /// smoothed layer is integrated (the fields are built either way).
  enum class Interfaces { Sharp, Smoothed } interfaces = Interfaces::Sharp;
  /// Messages for the user that are not errors (e.g. a wavelength outside a material's range).
  std::vector<std::string> warnings;

  bool anyUniaxial() const;
  /// True if some material of the scene is biaxial (renders then march its fast and slow modes).
  bool anyBiaxial() const;
  /// Its crystals are all biaxial: modes 0 and 1 are named fast and slow (modeName).
  bool fastSlowModes() const { return anyBiaxial() && !anyUniaxial(); }
  bool anyDispersive() const;
  /// Some material has an albedo (a translucent medium's in-scatter or a diffuse surface): the
  /// only places a render shows the light volumes of the scene's lights (VolumeSet::scattering).
  bool anyScattering() const;
};

/// Parse a scene file. Material names not defined in the file are looked up in the material
/// library (materials/<name>.json in the source tree, or directories in EIKON_MATERIALS_PATH).
Scene loadScene(const std::filesystem::path& path);
/// Parse a scene from JSON text; `origin` names the source in error messages and resolves
/// relative paths (latlong images).
Scene parseScene(const std::string& json_text, const std::filesystem::path& origin);
/// The camera and the volume as a scene file's "camera" and "volume" would be checked (SceneError
/// "FILE: /camera/width: ..."), for scenes edited after parsing (Python's Scene.camera and
/// Scene.volume): the session checks them before it voxelises or renders.
void checkCamera(const Camera& camera, const std::filesystem::path& file);
void checkVolumeSpec(const VolumeSpec& volume, const std::filesystem::path& file);

/// Load a material file (format: docs/scene-format.md, "Material files").
Material loadMaterialFile(const std::filesystem::path& path);
/// Directories searched for library materials, in order.
std::vector<std::filesystem::path> materialSearchPath();

}  // namespace eikon
