// Seed patches of both light simulators: see seeding.h, and core/reference/wavefront.h for the
// method and the units.
#include "core/light/seeding.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "anisotropic/units.h"

namespace eikon {
namespace {

using light::centre;
using light::meanW;
using light::orientationOf;
using light::rayHitsBox;
using light::vectorArea;
/// Solid angle of the spherical triangle with unit vertices a, b, c (Van Oosterom & Strackee).
double triangleSolidAngle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  double num = std::abs(glm::dot(a, glm::cross(b, c)));
  double den = 1.0 + glm::dot(a, b) + glm::dot(b, c) + glm::dot(c, a);
  return 2.0 * std::atan2(num, den);
}

/// What seeding reads: the field, its bounds, the splat grid, checked settings and 1/λ², 1/λ⁴.
struct Seeder {
  const Field& field;
  const Grid& grid;
  WavefrontSettings s;
  double il2, il4;
  glm::dvec3 lo, hi;

  glm::dvec3 shell(const glm::dvec3& x, const glm::dvec3& d) const {
    return onModeShell(field, s.mode, il2, il4, x, d);
  }
  void directional(const Light& light, std::vector<Patch>& out) const;
  void point(const Light& light, std::vector<Patch>& out) const;
};

void Seeder::directional(const Light& light, std::vector<Patch>& out) const {
  const double len = glm::length(light.direction);
  if (!(len > 0)) throw std::invalid_argument("wavefront: directional light without a direction");
  const glm::dvec3 d = light.direction / len;
  // Basis with u × v = d: a is the coordinate axis least aligned with d.
  int ai = 0;
  for (int a = 1; a < 3; ++a)
    if (std::abs(d[a]) < std::abs(d[ai])) ai = a;
  glm::dvec3 a(0.0);
  a[ai] = 1.0;
  const glm::dvec3 u = glm::normalize(glm::cross(a, d)), v = glm::cross(d, u);
  double s0 = 1e300, umin = 1e300, umax = -1e300, vmin = 1e300, vmax = -1e300;
  for (int c = 0; c < 8; ++c) {
    glm::dvec3 p((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
    s0 = std::min(s0, glm::dot(p, d));
    umin = std::min(umin, glm::dot(p, u)), umax = std::max(umax, glm::dot(p, u));
    vmin = std::min(vmin, glm::dot(p, v)), vmax = std::max(vmax, glm::dot(p, v));
  }
  double edge = s.seed_span_voxels * grid.h;
  const double R = light.beam_radius;
  const bool beam = R > 0;
  int nu, nv;
  double du, dv;
  double pu = 0, pv = 0;  // beam axis in the launch plane
  if (beam) {
    // A grid of exact squares centred on the beam axis, symmetric about it in u and v, so that
    // the launched cells (centre within R) form a disc whose flux centroid is on the axis.
    edge = std::min(edge, R / s.beam_min_cells);
    pu = glm::dot(light.position, u), pv = glm::dot(light.position, v);
    const int half = int(std::ceil(R / edge - 1e-9));
    nu = nv = 2 * half;
    du = dv = edge;
    umin = pu - half * edge, vmin = pv - half * edge;
  } else {
    nu = std::max(1, int(std::ceil((umax - umin) / edge - 1e-9)));
    nv = std::max(1, int(std::ceil((vmax - vmin) / edge - 1e-9)));
    du = (umax - umin) / nu, dv = (vmax - vmin) / nv;
  }
  const glm::dvec3 base = s0 * d;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const double uc[4] = {umin + i * du, umin + (i + 1) * du, umin + (i + 1) * du, umin + i * du};
      const double vc[4] = {vmin + j * dv, vmin + j * dv, vmin + (j + 1) * dv, vmin + (j + 1) * dv};
      if (beam) {
        const double cu = umin + (i + 0.5) * du - pu, cv = vmin + (j + 0.5) * dv - pv;
        if (cu * cu + cv * cv > R * R) continue;
      }
      Patch p;
      for (int k = 0; k < 4; ++k) {
        p.x[size_t(k)] = base + uc[k] * u + vc[k] * v;
        p.w[size_t(k)] = shell(p.x[size_t(k)], d);
      }
      if (!rayHitsBox(centre(p), d, lo, hi)) continue;
      p.area0 = du * dv;
      p.energy = light.irradiance * p.area0;
      p.orientation = orientationOf(p);
      p.seed_energy = p.energy;
      out.push_back(p);
    }
}

void Seeder::point(const Light& light, std::vector<Patch>& out) const {
  const bool spot = light.type == Light::Type::Spot;
  int N = s.point_cells_per_face;
  glm::dvec3 axis(0.0);
  double cosCone = -2.0;
  if (spot) {
    const double len = glm::length(light.direction);
    if (!(len > 0)) throw std::invalid_argument("wavefront: spot light without a direction");
    if (!(light.cone_half_angle_deg > 0))
      throw std::invalid_argument("wavefront: spot light cone must be > 0");
    axis = light.direction / len;
    const double half = light.cone_half_angle_deg * std::numbers::pi / 180.0;
    cosCone = std::cos(half);
    // The cone meets a cube face (at distance 1) in a disc of radius ≈ tan(half); a cell edge
    // there is 2/N, so N ≥ 2·beam_min_cells/tan(half) puts beam_min_cells cells across it.
    if (half < 0.25 * std::numbers::pi)
      N = std::max(N, std::min(4096, int(std::ceil(2.0 * s.beam_min_cells / std::tan(half)))));
  }
  const double eps = s.point_radius;
  const glm::dvec3 src = light.position;
  for (int ax = 0; ax < 3; ++ax)
    for (int sg = -1; sg <= 1; sg += 2) {
      const int ua = (ax + 1) % 3, va = (ax + 2) % 3;
      for (int j = 0; j < N; ++j)
        for (int i = 0; i < N; ++i) {
          const double a0 = -1.0 + 2.0 * i / N, a1 = -1.0 + 2.0 * (i + 1) / N;
          const double b0 = -1.0 + 2.0 * j / N, b1 = -1.0 + 2.0 * (j + 1) / N;
          if (spot) {
            glm::dvec3 q(0.0);
            q[ax] = sg;
            q[ua] = 0.5 * (a0 + a1);
            q[va] = 0.5 * (b0 + b1);
            if (glm::dot(glm::normalize(q), axis) < cosCone) continue;
          }
          const double ac[4] = {a0, a1, a1, a0}, bc[4] = {b0, b0, b1, b1};
          Patch p;
          glm::dvec3 dir[4];
          for (int k = 0; k < 4; ++k) {
            glm::dvec3 q(0.0);
            q[ax] = sg;
            q[ua] = ac[k];
            q[va] = bc[k];
            dir[k] = glm::normalize(q);
            p.x[size_t(k)] = src + eps * dir[k];
            p.w[size_t(k)] = shell(p.x[size_t(k)], dir[k]);
          }
          if (!rayHitsBox(centre(p), glm::normalize(meanW(p)), lo, hi)) continue;
          const double omega = triangleSolidAngle(dir[0], dir[1], dir[2]) +
                               triangleSolidAngle(dir[0], dir[2], dir[3]);
          p.area0 = glm::length(vectorArea(p));
          p.energy = light.irradiance * omega;
          p.orientation = orientationOf(p);
          p.seed_energy = p.energy;
          out.push_back(p);
        }
    }
}

}  // namespace

WavefrontSettings checkedWavefrontSettings(const WavefrontSettings& settings, const Grid& grid) {
  WavefrontSettings s = settings;
  if (!(grid.h > 0) || grid.count() == 0)
    throw std::invalid_argument("wavefront: empty splat grid");
  if (s.dt <= 0) s.dt = 0.5 * grid.h;
  if (s.point_radius <= 0) s.point_radius = 0.5 * grid.h;
  if (!(s.split_span_voxels > 0))
    throw std::invalid_argument("wavefront: split_span_voxels must be > 0");
  if (!(s.seed_span_voxels > 0))
    throw std::invalid_argument("wavefront: seed_span_voxels must be > 0");
  if (s.max_steps < 1) throw std::invalid_argument("wavefront: max_steps must be >= 1");
  if (s.max_patches < 1) throw std::invalid_argument("wavefront: max_patches must be >= 1");
  if (s.point_cells_per_face < 1)
    throw std::invalid_argument("wavefront: point_cells_per_face must be >= 1");
  if (!(s.wavelength_nm > 0)) throw std::invalid_argument("wavefront: wavelength must be > 0");
  if (s.mode != 0 && s.mode != 1)
    throw std::invalid_argument("wavefront: mode must be 0 (o) or 1 (e)");
  if (s.beam_min_cells < 1) throw std::invalid_argument("wavefront: beam_min_cells must be >= 1");
  if (s.threads < 0) throw std::invalid_argument("wavefront: threads must be >= 0");
  if (s.max_reflection_generations < 0 || s.max_reflection_generations > 64)
    throw std::invalid_argument("wavefront: max_reflection_generations must be 0 to 64");
  return s;
}

glm::dvec3 onModeShell(const Field& field, int mode, double il2, double il4, const glm::dvec3& x,
                       const glm::dvec3& s) {
  double n;
  glm::dvec3 g;
  field.index(x, il2, il4, n, g);
  if (mode == 1) {
    const glm::dvec3 a(field.axisField(x));
    if (field::hasAxis(a)) {
      double ne;
      field.indexE(x, il2, il4, ne, g);
      return s / std::sqrt(glm::dot(s, field::applyM(s, a, n, ne)));
    }
  }
  return n * s;
}

std::vector<Patch> seedWavefront(const Field& field, const Grid& grid,
                                 const WavefrontSettings& settings, const Light& light) {
  const WavefrontSettings s = checkedWavefrontSettings(settings, grid);
  const double l_um = micrometresFromNanometres(s.wavelength_nm);
  const double il2 = 1.0 / (l_um * l_um);
  const Seeder seeder{field, grid, s, il2, il2 * il2, field.boundsMin(), field.boundsMax()};
  std::vector<Patch> out;
  if (light.type == Light::Type::Directional)
    seeder.directional(light, out);
  else
    seeder.point(light, out);
  return out;
}

}  // namespace eikon
