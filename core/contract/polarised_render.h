// Polarised renders (docs/polarisation.md "Polarised renders"), shared by both twins:
// each pixel sample's camera ray is traced BACKWARDS by a twin's polarised trace (the same o/e
// ray tree as a forward trace: ray optics in reciprocal, non-magnetic media is time-reversible, the
// e-rays too), every beam leaving the scene looks up the environment, and reciprocity turns the
// backward path into the forward one:
//
//   J_f = D·J_bᵀ·D in mirrored frames (x̂, −ŷ) at both ends, so in Stokes M_f = Q·M_bᵀ·Q with
//   Q = diag(1, 1, −1, 1) (with S3 = 2 Im(E_x E_y*): M(Jᵀ) = diag(1,1,1,−1)·M(J)ᵀ·diag(1,1,1,−1)
//   and M(D) = diag(1, 1, −1, −1); tests/core/reference/polarised_render_test.cpp checks both).
//
// For unpolarised environment radiance L the camera receives L × the first column of M_f, i.e.
// Q × the first ROW of M_b: the twins' traces report that row per beam
// (PolarisedTraceSettings::mueller_row), which is all a render needs, linear over the coherent
// groups of a beam. The Stokes vector is then re-expressed in stokesBasis(−v) (v the camera ray;
// kStokesFrame), and the camera's analyser (Camera::analyzer) applied there.
//
// Beams leaving in one direction were already recombined by the trace on a common wavefront: for
// an environment at infinity one direction is one plane wave, and the backward branches' phases
// k₀(S − p·x) are exactly the forward plane wave's phases at the camera, so o and e leaves that
// exit parallel but displaced (a calcite plate's walk-off) add coherently.
//
//   RenderImage img = renderPolarisedWith(scene, settings, batch, threads);
//   // batch(rays, seeds, trace_settings) -> the twin's traces (mueller_row set), one per ray
//
// The trace follows the render's MarchSettings::transport and max_reflections: with
// Transport::Full each branch takes the reflection or the transmission at random (p its reflected
// power fraction; docs/polarisation.md "Interfaces"), drawn from seeds[i] =
// transportSeed(pixel, sample, 2) (the same at every wavelength of a sample), so that S0 equals
// the unpolarised full-transport render within noise.
//
// Left out (documented): lights, emission and in-scatter (the polariscope and conoscope scenes are
// environment-lit), a polarised environment (refused).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/contract/march_types.h"
#include "core/contract/polarised.h"
#include "core/scene/scene.h"

namespace eikon {

/// The frame of the Stokes layers, as written into the EXR header ("stokesFrame").
inline constexpr const char* kStokesFrame =
    "per pixel: x = Mitsuba 3 stokes_basis(-v), y = (-v) x x, v the camera ray (light arrives "
    "along -v); S1 > 0 along x, S2 > 0 at +45 deg towards y, S3 > 0 right circular (exp(-i w t)); "
    "after the camera analyzer";

/// Whether a render of `scene` with `s` is polarised: asked for (s.polarised, s.stokes_layers), or
/// the scene has polariser sheets or a camera analyser.
bool isPolarisedRender(const Scene& scene, const RenderSettings& s);

/// What makes the render polarised, in words ("--polarised", "--layers stokes", "the scene's
/// polariser sheets", "the camera's analyzer"); empty when it is not.
std::string polarisedBecause(const Scene& scene, const RenderSettings& s);

/// Throws std::runtime_error (one line, "FILE: /json/path: ...") for a scene a polarised render
/// cannot take: interfaces not sharp, a polarised environment. Front ends call it before
/// voxelising; renderPolarisedWith calls it too.
void checkPolarisedScene(const Scene& scene, const RenderSettings& s);

/// A twin's polarised trace of many rays (one trace per ray, settings.mueller_row set), seeds[i]
/// drawing ray i's Transport::Full choices.
using PolarisedBatch = std::function<std::vector<PolarisedTrace>(
    const std::vector<TraceRequest>& rays, const std::vector<std::uint32_t>& seeds,
    const PolarisedTraceSettings& settings)>;

/// The camera pixel's Stokes vector (frame stokesBasis(−v)) for unit unpolarised environment
/// radiance from one backward beam: Q × the beam's Mueller row (beam.stokes with mueller_row), in
/// the frame turned from the trace's input frame x_in to stokesBasis(−v).
Stokes cameraStokes(const Stokes& mueller_row, const glm::dvec3& v, const glm::dvec3& x_in);

/// The camera analyser's Mueller matrix in stokesBasis(−v): an ideal linear polariser whose
/// transmission direction is the analyser axis's part ⊥ v (identity without an analyser; zero
/// where the axis is along v).
Mueller analyserMueller(const Camera& cam, const glm::dvec3& v);

/// Render `scene`'s camera view polarised: RenderImage::rgb = S0 after the analyser, ::stokes if
/// s.stokes_layers. Spectral renders (s.wavelengths = N > 0) trace every pixel sample at all N
/// stratified wavelengths (the o/e phases differ per λ: no hero sampling); RGB renders at
/// s.wavelength_nm with the environment's RGB radiance. Throws std::invalid_argument for bad
/// settings or a polarised environment; the batch's errors (std::runtime_error: no sharp
/// interfaces, a gradient-index region on a path) pass through.
RenderImage renderPolarisedWith(const Scene& scene, const RenderSettings& s,
                                const PolarisedBatch& batch,
                                const PolarisedTraceSettings& trace = {});

}  // namespace eikon
