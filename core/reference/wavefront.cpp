// CPU reference of the light simulator: see wavefront.h for the method and the units.
#include "core/reference/wavefront.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace eikon {
namespace {

// Attenuation band at λ from the (612, 549, 465) nm band values (same rule as the marcher).
double sigmaAt(const glm::dvec3& rgb, double l) {
  if (l <= 465.0) return rgb.b;
  if (l >= 612.0) return rgb.r;
  if (l <= 549.0) return rgb.b + (rgb.g - rgb.b) * (l - 465.0) / (549.0 - 465.0);
  return rgb.g + (rgb.r - rgb.g) * (l - 549.0) / (612.0 - 549.0);
}

glm::dvec3 centre(const Patch& p) { return 0.25 * (p.x[0] + p.x[1] + p.x[2] + p.x[3]); }
glm::dvec3 meanW(const Patch& p) { return 0.25 * (p.w[0] + p.w[1] + p.w[2] + p.w[3]); }
/// Vector area (normal · area) of the quad from its diagonals; exact for planar quads.
glm::dvec3 vectorArea(const Patch& p) { return 0.5 * glm::cross(p.x[2] - p.x[0], p.x[3] - p.x[1]); }
int orientationOf(const Patch& p) {
  double s = glm::dot(vectorArea(p), meanW(p));
  return s > 0 ? 1 : (s < 0 ? -1 : 0);
}

bool inside(const glm::dvec3& x, const glm::dvec3& lo, const glm::dvec3& hi) {
  return x.x >= lo.x && x.y >= lo.y && x.z >= lo.z && x.x <= hi.x && x.y <= hi.y && x.z <= hi.z;
}

/// Does the ray o + s·d (s ≥ 0) meet the box?
bool rayHitsBox(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& lo, const glm::dvec3& hi) {
  double t0 = 0.0, t1 = 1e300;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (o[a] < lo[a] || o[a] > hi[a]) return false;
      continue;
    }
    double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}

/// Solid angle of the spherical triangle with unit vertices a, b, c (Van Oosterom & Strackee).
double triangleSolidAngle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  double num = std::abs(glm::dot(a, glm::cross(b, c)));
  double den = 1.0 + glm::dot(a, b) + glm::dot(b, c) + glm::dot(c, a);
  return 2.0 * std::atan2(num, den);
}

}  // namespace

WavefrontSimulator::WavefrontSimulator(const Field& field, const Grid& splat_grid, const WavefrontSettings& settings)
    : field_(field), grid_(splat_grid), s_(settings) {
  if (!(grid_.h > 0) || grid_.count() == 0) throw std::invalid_argument("wavefront: empty splat grid");
  if (s_.dt <= 0) s_.dt = 0.5 * grid_.h;
  if (s_.point_radius <= 0) s_.point_radius = 0.5 * grid_.h;
  if (!(s_.split_span_voxels > 0)) throw std::invalid_argument("wavefront: split_span_voxels must be > 0");
  if (!(s_.seed_span_voxels > 0)) throw std::invalid_argument("wavefront: seed_span_voxels must be > 0");
  if (s_.max_steps < 1) throw std::invalid_argument("wavefront: max_steps must be >= 1");
  if (s_.max_patches < 1) throw std::invalid_argument("wavefront: max_patches must be >= 1");
  if (s_.point_cells_per_face < 1) throw std::invalid_argument("wavefront: point_cells_per_face must be >= 1");
  if (!(s_.wavelength_nm > 0)) throw std::invalid_argument("wavefront: wavelength must be > 0");
  const double l_um = s_.wavelength_nm * 1e-3;
  il2_ = 1.0 / (l_um * l_um);
  il4_ = il2_ * il2_;
}

std::vector<Patch> WavefrontSimulator::seed(const Light& light) const {
  const glm::dvec3 lo = field_.boundsMin(), hi = field_.boundsMax();
  std::vector<Patch> out;
  auto nAt = [&](const glm::dvec3& x) {
    double n;
    glm::dvec3 g;
    field_.index(x, il2_, il4_, n, g);
    return n;
  };
  if (light.type == Light::Type::Directional) {
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
    const double edge = s_.seed_span_voxels * grid_.h;
    const int nu = std::max(1, int(std::ceil((umax - umin) / edge - 1e-9)));
    const int nv = std::max(1, int(std::ceil((vmax - vmin) / edge - 1e-9)));
    const double du = (umax - umin) / nu, dv = (vmax - vmin) / nv;
    const glm::dvec3 base = s0 * d;
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) {
        const double uc[4] = {umin + i * du, umin + (i + 1) * du, umin + (i + 1) * du, umin + i * du};
        const double vc[4] = {vmin + j * dv, vmin + j * dv, vmin + (j + 1) * dv, vmin + (j + 1) * dv};
        Patch p;
        for (int k = 0; k < 4; ++k) {
          p.x[size_t(k)] = base + uc[k] * u + vc[k] * v;
          p.w[size_t(k)] = nAt(p.x[size_t(k)]) * d;
        }
        if (!rayHitsBox(centre(p), d, lo, hi)) continue;
        p.area0 = du * dv;
        p.energy = light.irradiance * p.area0;
        p.orientation = orientationOf(p);
        p.seed_energy = p.energy;
        out.push_back(p);
      }
  } else {
    const int N = s_.point_cells_per_face;
    const double eps = s_.point_radius;
    const glm::dvec3 src = light.position;
    for (int axis = 0; axis < 3; ++axis)
      for (int sg = -1; sg <= 1; sg += 2) {
        const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
        for (int j = 0; j < N; ++j)
          for (int i = 0; i < N; ++i) {
            const double a0 = -1.0 + 2.0 * i / N, a1 = -1.0 + 2.0 * (i + 1) / N;
            const double b0 = -1.0 + 2.0 * j / N, b1 = -1.0 + 2.0 * (j + 1) / N;
            const double ac[4] = {a0, a1, a1, a0}, bc[4] = {b0, b0, b1, b1};
            Patch p;
            glm::dvec3 dir[4];
            for (int k = 0; k < 4; ++k) {
              glm::dvec3 q(0.0);
              q[axis] = sg;
              q[ua] = ac[k];
              q[va] = bc[k];
              dir[k] = glm::normalize(q);
              p.x[size_t(k)] = src + eps * dir[k];
              p.w[size_t(k)] = nAt(p.x[size_t(k)]) * dir[k];
            }
            if (!rayHitsBox(centre(p), glm::normalize(meanW(p)), lo, hi)) continue;
            const double omega = triangleSolidAngle(dir[0], dir[1], dir[2]) + triangleSolidAngle(dir[0], dir[2], dir[3]);
            p.area0 = glm::length(vectorArea(p));
            p.energy = light.irradiance * omega;
            p.orientation = orientationOf(p);
            p.seed_energy = p.energy;
            out.push_back(p);
          }
      }
  }
  return out;
}

WavefrontResult WavefrontSimulator::run(const Light& light) const {
  WavefrontResult res;
  WavefrontStats& st = res.stats;
  const glm::dvec3 lo = field_.boundsMin(), hi = field_.boundsMax();
  const double h = grid_.h, h3 = h * h * h, dt = s_.dt;
  const double maxEdge = s_.split_span_voxels * h;
  std::vector<double> acc(grid_.count(), 0.0), best(grid_.count(), 0.0);
  std::vector<glm::dvec3> dirAcc(grid_.count(), glm::dvec3(0.0));

  std::vector<Patch> cur = seed(light), next, work;
  st.seeded = cur.size();
  for (Patch& p : cur) {
    st.flux_emitted += p.energy;
    const glm::dvec3 c = centre(p);
    p.entered = inside(c, lo, hi);
    if (s_.probe_axis >= 0) p.probe_side = c[s_.probe_axis] >= s_.probe_position ? 1 : -1;
  }
  size_t live = cur.size();
  st.max_live = live;

  auto deriv = [&](const glm::dvec3& x, const glm::dvec3& w, glm::dvec3& dx, glm::dvec3& dw) {
    double n;
    glm::dvec3 g;
    field_.index(x, il2_, il4_, n, g);
    dx = w / (n * n);
    dw = g / n;
  };
  auto rk4 = [&](glm::dvec3& x, glm::dvec3& w) {
    glm::dvec3 k1x, k1w, k2x, k2w, k3x, k3w, k4x, k4w;
    deriv(x, w, k1x, k1w);
    deriv(x + 0.5 * dt * k1x, w + 0.5 * dt * k1w, k2x, k2w);
    deriv(x + 0.5 * dt * k2x, w + 0.5 * dt * k2w, k3x, k3w);
    deriv(x + dt * k3x, w + dt * k3w, k4x, k4w);
    x += dt / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
    w += dt / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
  };
  auto splat = [&](const glm::dvec3& m, double fluxDs, double irr, const glm::dvec3& dir) {
    int idx[3];
    for (int a = 0; a < 3; ++a) {
      double f = std::floor((m[a] - grid_.origin[a]) / h);
      if (!(f >= 0 && f < grid_.dims[size_t(a)])) return;
      idx[a] = int(f);
    }
    const size_t v = grid_.index(idx[0], idx[1], idx[2]);
    acc[v] += fluxDs / h3;
    dirAcc[v] += (fluxDs / h3) * dir;
    best[v] = std::max(best[v], irr);
  };
  // Split p (repeatedly) until no edge exceeds maxEdge or the patch budget is spent.
  auto emit = [&](const Patch& p0) {
    work.clear();
    work.push_back(p0);
    while (!work.empty()) {
      Patch p = work.back();
      work.pop_back();
      double e = 0;
      for (int k = 0; k < 4; ++k) e = std::max(e, glm::length(p.x[size_t((k + 1) % 4)] - p.x[size_t(k)]));
      if (e <= maxEdge) {
        next.push_back(p);
        continue;
      }
      if (live + 3 > size_t(s_.max_patches)) {
        ++st.splits_refused;
        next.push_back(p);
        continue;
      }
      live += 3;
      ++st.splits;
      st.max_live = std::max(st.max_live, live);
      // 3×3 lattice of bilinear points; the parent's own corners are kept exactly.
      glm::dvec3 X[3][3], W[3][3];
      for (int b = 0; b < 3; ++b)
        for (int a = 0; a < 3; ++a) {
          const double fa = 0.5 * a, fb = 0.5 * b;
          X[b][a] = (1 - fa) * (1 - fb) * p.x[0] + fa * (1 - fb) * p.x[1] + fa * fb * p.x[2] + (1 - fa) * fb * p.x[3];
          glm::dvec3 w = (1 - fa) * (1 - fb) * p.w[0] + fa * (1 - fb) * p.w[1] + fa * fb * p.w[2] + (1 - fa) * fb * p.w[3];
          if ((a == 1 || b == 1)) {
            double n;
            glm::dvec3 g;
            field_.index(X[b][a], il2_, il4_, n, g);
            w = glm::normalize(w) * n;
          }
          W[b][a] = w;
        }
      X[0][0] = p.x[0], X[0][2] = p.x[1], X[2][2] = p.x[2], X[2][0] = p.x[3];
      W[0][0] = p.w[0], W[0][2] = p.w[1], W[2][2] = p.w[2], W[2][0] = p.w[3];
      for (int cb = 0; cb < 2; ++cb)
        for (int ca = 0; ca < 2; ++ca) {
          Patch c = p;
          const int pa[4] = {ca, ca + 1, ca + 1, ca}, pb[4] = {cb, cb, cb + 1, cb + 1};
          for (int k = 0; k < 4; ++k) {
            c.x[size_t(k)] = X[pb[k]][pa[k]];
            c.w[size_t(k)] = W[pb[k]][pa[k]];
          }
          c.energy = 0.25 * p.energy;  // equal parameter area: a quarter of the parent's ray tubes
          c.area0 = 0.25 * p.area0;
          work.push_back(c);
        }
    }
  };

  // A patch ends: it leaves the live set; note its flux if it never got past the probe plane.
  auto ended = [&](const Patch& p) {
    --live;
    if (s_.probe_axis >= 0 && p.probe_side < 0) st.flux_ended_before_probe += p.energy;
  };

  while (!cur.empty() && st.steps < s_.max_steps) {
    ++st.steps;
    next.clear();
    for (Patch p : cur) {
      const glm::dvec3 c0 = centre(p);
      for (int k = 0; k < 4; ++k) rk4(p.x[size_t(k)], p.w[size_t(k)]);
      const glm::dvec3 c1 = centre(p), m = 0.5 * (c0 + c1);
      const double ds = glm::length(c1 - c0);
      const glm::dvec4 med = field_.medium(m);
      const double sigma = sigmaAt(glm::dvec3(med), s_.wavelength_nm);
      const double att = std::exp(-sigma * ds), fluxMid = p.energy * std::exp(-0.5 * sigma * ds);
      st.flux_absorbed += p.energy * (1.0 - att);
      p.energy *= att;
      p.transmittance *= att;
      const glm::dvec3 va = vectorArea(p);
      const double area = glm::length(va);
      const glm::dvec3 wm = meanW(p);
      const double wl = glm::length(wm);
      splat(m, fluxMid * ds, area > 0 ? fluxMid / area : 0.0, wl > 0 ? wm / wl : glm::dvec3(0.0));
      if (s_.probe_axis >= 0) {
        const int side = c1[s_.probe_axis] >= s_.probe_position ? 1 : -1;
        if (side != p.probe_side) st.flux_probe += side * fluxMid;
        p.probe_side = side;
      }
      // Kills, each accounted by reason.
      if (med.w >= 0.5) {
        ++st.kills_opaque;
        st.flux_absorbed += p.energy;
        ended(p);
        continue;
      }
      if (inside(c1, lo, hi)) {
        p.entered = true;
      } else if (p.entered || !(wl > 0) || !rayHitsBox(c1, wm / wl, lo, hi)) {
        ++st.kills_left;
        st.flux_left += p.energy;
        ended(p);
        continue;
      }
      const double o = glm::dot(va, wm);
      if ((o > 0 && p.orientation < 0) || (o < 0 && p.orientation > 0)) {
        ++st.kills_caustic;
        st.flux_caustic += p.energy;
        st.caustic_centroid += p.energy * c1;
        ended(p);
        continue;
      }
      if (p.energy < s_.min_energy_fraction * p.seed_energy) {
        ++st.kills_energy;
        st.flux_energy += p.energy;
        ended(p);
        continue;
      }
      emit(p);
    }
    st.max_live = std::max(st.max_live, live);
    std::swap(cur, next);
  }
  if (st.flux_caustic > 0) st.caustic_centroid /= st.flux_caustic;
  st.live_at_end = cur.size();
  for (const Patch& p : cur) {
    st.flux_live_at_end += p.energy;
    if (s_.probe_axis >= 0 && p.probe_side < 0) st.flux_ended_before_probe += p.energy;
  }

  res.irradiance.resize(grid_.count());
  res.direction.resize(grid_.count());
  const bool highest = s_.splat == WavefrontSettings::Splat::HighestEnergy;
  for (size_t v = 0; v < grid_.count(); ++v) {
    res.irradiance[v] = float(highest ? best[v] : acc[v]);
    const glm::dvec3 d = acc[v] > 0 ? dirAcc[v] / acc[v] : glm::dvec3(0.0);
    res.direction[v] = glm::vec4(glm::vec3(d), float(acc[v]));
  }
  return res;
}

}  // namespace eikon
