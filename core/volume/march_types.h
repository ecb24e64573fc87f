// Settings and results shared by the two twins of the march (GPU core/render, CPU
// core/reference), so that both are driven and compared through the same plain structs.
#pragma once

#include <functional>
#include <glm/glm.hpp>
#include <string>
#include <vector>

namespace eikon {

enum class Integrator { Euler = 0, Midpoint = 1, RK4 = 2 };

struct MarchSettings {
  double step_voxels = 0.25;  ///< ds in voxels (the constant spatial step)
  Integrator integrator = Integrator::RK4;
  bool skip_empty = true;             ///< straight steps across homogeneous regions
  bool fresnel = true;                ///< Fresnel losses/reflections at interfaces
  double interface_threshold = 0.02;  ///< |∇n|·h peak that makes a layer an interface
  int max_steps = 20000;              ///< per ray; a ray that runs out is reported as stopped
};

struct RenderImage;

struct RenderSettings {
  int width = 0, height = 0;        ///< 0 = the scene camera's
  int spp = 1;                      ///< jittered samples per pixel
  int wavelengths = 0;              ///< spectral samples per pixel sample; 0 = RGB mode
  double wavelength_nm = 587.5618;  ///< index wavelength of the RGB mode (He d line)
  MarchSettings march;
  /// progress(fraction done); may be empty.
  std::function<void(double)> progress;
  /// Called with the image so far each time a pixel sample is finished (all its wavelengths),
  /// before the last (which render() returns): the mean of `done` of `spp` samples. May be empty.
  std::function<void(const RenderImage& so_far, int done, int spp)> on_pass;
};

/// A rendered image: linear sRGB, rows from the top, 3 floats per pixel.
struct RenderImage {
  int width = 0, height = 0;
  std::vector<float> rgb;
  double mean_steps = 0.0;  ///< integration steps per ray (mean over pixels)
  /// Volume-field reads per ray (trilinear samples, boundary cells); the CPU twin's only, 0 on
  /// the GPU (core/reference/reference_marcher.cpp CountedField).
  double mean_fetches = 0.0;
  double seconds = 0.0;  ///< wall time of the march itself
  /// Pixel samples (passes of a pixel) in which a march was stopped by the device's loop budget
  /// (lavapipe; docs/view-renderer.md) and so lacks the light it would have reached; 0 on the CPU.
  long long cut_samples = 0;
};

/// One traced ray (one mode) as both twins report it. Directions are unit, world space.
struct TraceOutcome {
  glm::dvec3 exit_point{0.0};      ///< where the ray leaves the volume (or stops)
  glm::dvec3 exit_direction{0.0};  ///< ray (energy) direction at exit
  glm::dvec3 wave_normal{0.0};     ///< wave normal at exit (= exit_direction when isotropic)
  double optical_path_mm = 0.0;    ///< ∫ n ds from the origin to the exit point
  double transmittance = 1.0;      ///< Fresnel × attenuation at the ray's wavelength
  bool left_volume = true;         ///< false if stopped by an opaque object or the step limit
  int steps = 0;
  double invariant_drift = 0.0;  ///< max | |w| − n | along the ray
  int interfaces = 0;            ///< interfaces crossed (Fresnel applied)
  int total_internal_reflections = 0;
};

struct TraceRequest {
  glm::dvec3 origin{0.0};
  glm::dvec3 direction{0, 0, 1};  ///< normalised by the tracer; must be non-zero
  double wavelength_nm = 587.5618;
};

}  // namespace eikon
