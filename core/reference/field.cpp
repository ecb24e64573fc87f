// The CPU twin's field/medium layer: see field.h (GPU twin: shaders/field.glsl).
#include "core/reference/field.h"

#include <algorithm>
#include <cmath>

#include "anisotropic/pleochroism.h"
#include "core/volume/media.h"

namespace eikon {

// ------------------------------------------------------------------ field.glsl's functions
namespace field {

glm::dvec4 sampleIndex(const Field& f, const glm::dvec3& x, double il2, double il4, int mode) {
  double n;
  glm::dvec3 g;
  if (mode == 0)
    f.index(x, il2, il4, n, g);
  else
    f.indexE(x, il2, il4, n, g);
  return {n, g};
}

glm::dvec4 sampleMedium(const Field& f, const glm::dvec3& x, int mode) {
  return mode == 0 ? f.medium(x) : f.mediumE(x);
}

double bandAt(const glm::dvec3& rgb, double l) { return bandValueAt(rgb, l); }

glm::dvec4 axisField(const Field& f, const glm::dvec3& x) { return f.axisField(x); }

void eModeRates(const glm::dvec3& p, const glm::dvec4& af, const glm::dvec4& o, const glm::dvec4& e,
                glm::dvec3& Mp, glm::dvec3& dp) {
  const glm::dvec3 a(af), go(o.y, o.z, o.w), ge(e.y, e.z, e.w);
  const double no = o.x, ne = e.x, pa = glm::dot(p, a), p2 = glm::dot(p, p);
  Mp = applyM(p, a, no, ne);
  dp = (pa * pa / (no * no * no)) * go + ((p2 - pa * pa) / (ne * ne * ne)) * ge;
  if (af.w > 0.0) dp -= pa * (1.0 / (no * no) - 1.0 / (ne * ne)) * (p - pa * a) * af.w;
}

glm::dvec3 attenuationE(const glm::dvec3& so, const glm::dvec3& se, const glm::dvec3& w,
                        const glm::dvec3& a, double no, double ne) {
  const glm::dvec3 s = glm::normalize(w), t = glm::normalize(applyM(w, a, no, ne));
  const double theta = std::acos(std::clamp(glm::dot(s, a), -1.0, 1.0));
  return extraordinaryAttenuation(theta, no, ne, so, se) * glm::dot(s, t);
}

}  // namespace field
}  // namespace eikon
