// Trilinear sampling of a VolumeSet: see field.h.
#include "core/volume/field.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace eikon {

VolumeField::VolumeField(const VolumeSet& v) : v_(v) {
  if (!v.whole())
    throw std::invalid_argument(
        "VolumeField: the volume has no fields (voxelizeInterfaces); voxelise it whole");
}

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

}  // namespace eikon
