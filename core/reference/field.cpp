// The CPU twin's field/medium layer: see field.h (GPU twin: shaders/field.glsl).
#include "core/reference/field.h"

#include <algorithm>
#include <cmath>

#include "optics/pleochroism.h"

namespace eikon {

// ------------------------------------------------------------------ VolumeField
glm::dvec4 VolumeField::trilinear(const std::vector<glm::vec4>& f, const glm::dvec3& x) const {
  const Grid& g = v_.grid;
  glm::dvec3 c = (x - g.origin) / g.h - 0.5;
  glm::dvec3 fl = glm::floor(c), t = c - fl;
  int i0[3], i1[3];
  for (int a = 0; a < 3; ++a) {
    int i = int(fl[a]);
    i0[a] = std::clamp(i, 0, g.dims[size_t(a)] - 1);
    i1[a] = std::clamp(i + 1, 0, g.dims[size_t(a)] - 1);
  }
  auto at = [&](int x_, int y_, int z_) { return glm::dvec4(f[g.index(x_, y_, z_)]); };
  glm::dvec4 c00 = glm::mix(at(i0[0], i0[1], i0[2]), at(i1[0], i0[1], i0[2]), t.x);
  glm::dvec4 c10 = glm::mix(at(i0[0], i1[1], i0[2]), at(i1[0], i1[1], i0[2]), t.x);
  glm::dvec4 c01 = glm::mix(at(i0[0], i0[1], i1[2]), at(i1[0], i0[1], i1[2]), t.x);
  glm::dvec4 c11 = glm::mix(at(i0[0], i1[1], i1[2]), at(i1[0], i1[1], i1[2]), t.x);
  return glm::mix(glm::mix(c00, c10, t.y), glm::mix(c01, c11, t.y), t.z);
}

void VolumeField::index(const glm::dvec3& x, double il2, double il4, double& n,
                        glm::dvec3& grad) const {
  glm::dvec4 a = trilinear(v_.index[0][0], x);
  if (v_.dispersive) a += trilinear(v_.index[0][1], x) * il2 + trilinear(v_.index[0][2], x) * il4;
  n = a.x;
  grad = glm::dvec3(a.y, a.z, a.w);
}

void VolumeField::indexE(const glm::dvec3& x, double il2, double il4, double& n,
                         glm::dvec3& grad) const {
  if (!v_.uniaxial) return index(x, il2, il4, n, grad);
  glm::dvec4 a = trilinear(v_.index[1][0], x);
  if (v_.dispersive) a += trilinear(v_.index[1][1], x) * il2 + trilinear(v_.index[1][2], x) * il4;
  n = a.x;
  grad = glm::dvec3(a.y, a.z, a.w);
}

glm::dvec4 VolumeField::axisField(const glm::dvec3& x) const {
  if (!v_.uniaxial) return glm::dvec4(0.0);
  const Grid& g = v_.grid;
  int i[3];
  for (int a = 0; a < 3; ++a)
    i[a] = std::clamp(int(std::floor((x[a] - g.origin[a]) / g.h)), 0, g.dims[size_t(a)] - 1);
  glm::dvec4 t(v_.axis[g.index(i[0], i[1], i[2])]);
  if (t.w > -0.5) return glm::dvec4(glm::dvec3(t), 0.0);
  glm::dvec3 d = x - glm::dvec3(t);  // radial field about the stored centre
  double r = glm::length(d);
  return r > 1e-6 ? glm::dvec4(d / r, 1.0 / r) : glm::dvec4(0.0, 0.0, 1.0, 0.0);
}

glm::dvec4 VolumeField::medium(const glm::dvec3& x) const { return trilinear(v_.medium[0], x); }
glm::dvec4 VolumeField::mediumE(const glm::dvec3& x) const {
  return v_.uniaxial ? trilinear(v_.medium[1], x) : trilinear(v_.medium[0], x);
}
glm::dvec3 VolumeField::emission(const glm::dvec3& x) const {
  return glm::dvec3(trilinear(v_.emission, x));
}
glm::dvec4 VolumeField::scatter(const glm::dvec3& x) const {
  return v_.scatter.empty() ? glm::dvec4(0.0) : trilinear(v_.scatter, x);
}
glm::dvec4 VolumeField::lightFluence(const glm::dvec3& x) const {
  return v_.light_fluence.empty() ? glm::dvec4(0.0) : trilinear(v_.light_fluence, x);
}
glm::dvec3 VolumeField::lightFlux(const glm::dvec3& x) const {
  return v_.light_flux.empty() ? glm::dvec3(0.0) : glm::dvec3(trilinear(v_.light_flux, x));
}

double VolumeField::skipDistance(const glm::dvec3& x) const {
  const Grid& g = v_.grid;
  int i[3];
  for (int a = 0; a < 3; ++a)
    i[a] = std::clamp(int(std::floor((x[a] - g.origin[a]) / g.h)), 0, g.dims[size_t(a)] - 1);
  return v_.emission[g.index(i[0], i[1], i[2])].w;
}

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

double bandAt(const glm::dvec3& rgb, double l) {
  if (l <= 465.0) return rgb.b;
  if (l >= 612.0) return rgb.r;
  if (l <= 549.0) return rgb.b + (rgb.g - rgb.b) * (l - 465.0) / (549.0 - 465.0);
  return rgb.g + (rgb.r - rgb.g) * (l - 549.0) / (612.0 - 549.0);
}

glm::dvec4 axisField(const Field& f, const glm::dvec3& x) { return f.axisField(x); }

bool hasAxis(const glm::dvec3& a) { return glm::dot(a, a) >= 0.25; }

glm::dvec3 applyM(const glm::dvec3& p, const glm::dvec3& a, double no, double ne) {
  const double pa = glm::dot(p, a);
  return a * pa / (no * no) + (p - a * pa) / (ne * ne);
}

void eModeRates(const glm::dvec3& p, const glm::dvec4& af, const glm::dvec4& o, const glm::dvec4& e,
                glm::dvec3& Mp, glm::dvec3& dp) {
  const glm::dvec3 a(af), go(o.y, o.z, o.w), ge(e.y, e.z, e.w);
  const double no = o.x, ne = e.x, pa = glm::dot(p, a), p2 = glm::dot(p, p);
  Mp = applyM(p, a, no, ne);
  dp = (pa * pa / (no * no * no)) * go + ((p2 - pa * pa) / (ne * ne * ne)) * ge;
  if (af.w > 0.0) dp -= pa * (1.0 / (no * no) - 1.0 / (ne * ne)) * (p - pa * a) * af.w;
}

glm::dvec3 onShellE(const glm::dvec3& s, const glm::dvec3& a, double no, double ne) {
  return s / std::sqrt(glm::dot(s, applyM(s, a, no, ne)));
}

glm::dvec3 attenuationE(const glm::dvec3& so, const glm::dvec3& se, const glm::dvec3& w,
                        const glm::dvec3& a, double no, double ne) {
  const glm::dvec3 s = glm::normalize(w), t = glm::normalize(applyM(w, a, no, ne));
  const double theta = std::acos(std::clamp(glm::dot(s, a), -1.0, 1.0));
  return extraordinaryAttenuation(theta, no, ne, so, se) * glm::dot(s, t);
}

}  // namespace field
}  // namespace eikon
