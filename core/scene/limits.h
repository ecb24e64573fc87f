// Limits on what a scene, and a request about it, may give (docs/scene-format.md, "Limits"), shared
// by the scene parser and the session's range checks.
#pragma once

#include <cstddef>

#include "anisotropic/index_limits.h"  // kMinIndex, kMaxIndex

namespace eikon {

/// Every position a scene (or a trace request) gives lies within ±kMaxCoordinateMm mm on each
/// axis: distances are then computed in double without overflow (squares ≤ 1e24) and a surface
/// 1e12 mm from the origin is still placed to ~1e-4 mm.
inline constexpr double kMaxCoordinateMm = 1e12;

/// Most objects (polarisers not counted) a scene with sharp interfaces may hold: the boundary
/// field's region ids are 16-bit and 0 is the ambient medium.
inline constexpr size_t kMaxSharpObjects = 65535;

}  // namespace eikon
