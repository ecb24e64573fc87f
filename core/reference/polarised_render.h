// The CPU twin of polarised renders (docs/polarisation.md "Polarised renders"): the
// shared driver core/contract/polarised_render.h over this twin's polarised trace (tracePolarised,
// core/reference/polarised_trace.h, in double precision), the pixel samples' rays spread over
// threads. The GPU twin is ViewRenderer::renderPolarised.
//
//   eikon::VolumeField field(volume);
//   RenderSettings s;  s.wavelengths = 16;  s.stokes_layers = true;
//   eikon::RenderImage img = eikon::renderPolarised(field, scene, s);
//   // img.rgb: S0 after the camera's analyser; img.stokes: S0..S3 × RGB per pixel
#pragma once

#include "core/contract/march_types.h"
#include "core/contract/polarised.h"
#include "core/scene/scene.h"
#include "core/volume/field.h"

namespace eikon {

/// Render `scene`'s camera polarised through `field`'s sharp boundaries and the scene's polariser
/// sheets (threads = 0: hardware concurrency). Throws as renderPolarisedWith and tracePolarised.
RenderImage renderPolarised(const Field& field, const Scene& scene, const RenderSettings& settings,
                            int threads = 0, const PolarisedTraceSettings& trace = {});

}  // namespace eikon
