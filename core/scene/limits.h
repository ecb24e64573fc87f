// Limits on what a scene, and a request about it, may give (docs/scene-format.md, "Limits"), shared
// by the scene parser and the session's range checks.
#pragma once

#include <cstddef>

namespace eikon {

/// Every position a scene (or a trace request) gives lies within ±kMaxCoordinateMm mm on each
/// axis: distances are then computed in double without overflow (squares ≤ 1e24) and a surface
/// 1e12 mm from the origin is still placed to ~1e-4 mm.
inline constexpr double kMaxCoordinateMm = 1e12;

/// Every refractive index eikon takes lies in [kMinIndex, kMaxIndex]: a material's over the
/// visible window, ambient_index, a gradient-index profile inside its object, a fit's data
/// (fitting/index_data.h) and Python's optics helpers and analytic fields. An index of 1e20 (or
/// an infinite one) makes the Fresnel terms and the march's gradients overflow to NaN in float.
inline constexpr double kMinIndex = 1.0;
inline constexpr double kMaxIndex = 10.0;

/// Most objects (polarisers not counted) a scene with sharp interfaces may hold: the boundary
/// field's region ids are 16-bit and 0 is the ambient medium.
inline constexpr size_t kMaxSharpObjects = 65535;

}  // namespace eikon
