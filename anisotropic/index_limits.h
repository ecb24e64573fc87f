// The range of refractive indices eikon takes, a fact of the optics that the scene parser, the
// session's range checks, the fitting tool (fitting/index_data.h) and Python's optics helpers
// share. core/scene/limits.h includes it with the scene's other limits.
#pragma once

namespace eikon {

/// Every refractive index eikon takes lies in [kMinIndex, kMaxIndex]: a material's over the
/// visible window, ambient_index, a gradient-index profile inside its object, a fit's data
/// (fitting/index_data.h) and Python's optics helpers and analytic fields. An index of 1e20 (or
/// an infinite one) makes the Fresnel terms and the march's gradients overflow to NaN in float.
inline constexpr double kMinIndex = 1.0;
inline constexpr double kMaxIndex = 10.0;

}  // namespace eikon
