// The polarised trace of the CPU twin (docs/polarisation.md): one ray of light followed
// forwards through the sharp march's regions carrying its field coherently — a Jones vector per
// input basis state, as a 3D complex field — and the Stokes vector of the light leaving along the
// path for a given input Stokes vector.
//
// What happens along the path (anisotropic/polarization.h does the optics):
//   * at every interface the exact Maxwell amplitudes (isotropic: Born & Wolf's r/t with the TIR
//     phase; crystal faces: the 4×4 solve of anisotropic/maxwell_boundary.h, so no D-projection
//     approximation): the path follows the transmitted beam(s), or the reflected one(s) on total
//     internal reflection, where `reflect_at` asks, or (Transport::Full) where a random choice
//     with the branch's reflected power fraction p takes them (fields scaled by 1/√p or
//     1/√(1 − p); `seed` gives the uniforms, as march_types.h transportUniform); a wave entering
//     a crystal splits into an o and an e branch, and one reflected inside a crystal into two,
//     which are traced separately (a ray tree, at most max_branches leaves);
//   * a face with a biaxial region on either side: the same exact amplitudes from
//     anisotropic/tensor_interface.h's solveTensorInterface (each side's Booker quartic; any pair
//     of isotropic, uniaxial and biaxial media); a biaxial crystal's branches are its fast mode
//     (Mode::Ordinary, 'o' in the mode strings) and its slow mode (Mode::Extraordinary, 'e');
//   * in a crystal each branch gains k₀∫p·dx (p the wave vector: walk-off is accounted for) and
//     loses exp(−½σL) of its amplitude (pleochroic σ(θ)cos ρ per ray length, field::attenuationE;
//     biaxial: the trichroic σ of the mode's D, TensorMedium::attenuation, times cos ρ);
//   * a straight piece that crosses a polariser sheet's rectangle (scene "polarizer", outside or
//     inside the volume) keeps only the field across the sheet's absorbing direction;
//   * branches leaving in the same direction (within source_angle_rad) are recombined: coherently
//     (Jones matrices added with their phases on a common wavefront) when their exit rays are
//     within the coherence width λ/source_angle_rad of each other and their optical paths differ
//     by less than the coherence length λ²/bandwidth_nm; otherwise their Stokes vectors add.
//
// Frames: the input Stokes vector is given in Mitsuba 3's stokesBasis of the ray direction, each
// output beam's Stokes vector in the stokesBasis of its own direction (anisotropic/polarization.h).
//
//   eikon::TraceRequest ray{{0, 0, -30}, {0, 0, 1}, 589.29};
//   eikon::PolarisedTrace t = eikon::tracePolarised(field, scene.polarizers, ray, {1, 0, 0, 0});
//   // t.beams[k].stokes: what leaves along direction t.beams[k].direction
//
// The settings and beams are the neutral ones of core/contract/polarised.h, shared with the GPU
// twin (ViewRenderer::tracePolarised, shaders/polarised_trace.comp).
//
// Only homogeneous regions are supported (a gradient-index or radial-axis region on the path is
// a std::runtime_error naming it); an opaque region absorbs the branch.
#pragma once

#include <cstdint>
#include <vector>

#include "anisotropic/polarization.h"
#include "core/contract/march_types.h"
#include "core/contract/polarised.h"
#include "core/scene/scene.h"
#include "core/volume/field.h"

namespace eikon {

/// Trace `ray` (forwards) through the field's sharp boundaries and the given sheets. Throws
/// std::invalid_argument on a bad ray, input Stokes vector (S0 ≤ 0, DoP > 1) or settings, and
/// std::runtime_error when the field has no sharp boundary field or the path meets a region the
/// polarised trace does not support. `seed` draws the choices of Transport::Full (renders:
/// transportSeed(pixel, sample, 2)); a Transport::Single trace does not use it.
PolarisedTrace tracePolarised(const Field& field, const std::vector<PolarizerSheet>& sheets,
                              const TraceRequest& ray, const Stokes& input,
                              const PolarisedTraceSettings& settings = {}, std::uint32_t seed = 0);

}  // namespace eikon
