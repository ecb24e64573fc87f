#include "core/reference/reference_marcher.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "core/spectrum/cie1931.h"
#include "core/spectrum/color.h"
#include "core/spectrum/rgb_to_spectrum.h"
#include "core/spectrum/wavelength_sampling.h"

namespace eikon {
namespace {

constexpr double kPi = 3.14159265358979323846;

bool boxHit(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& bmin, const glm::dvec3& bmax, double& t0,
            double& t1) {
  t0 = -1e300;
  t1 = 1e300;
  for (int a = 0; a < 3; ++a) {
    double inv = 1.0 / (d[a] == 0.0 ? 1e-30 : d[a]);
    double ta = (bmin[a] - o[a]) * inv, tb = (bmax[a] - o[a]) * inv;
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  return t1 >= std::max(t0, 0.0);
}

/// Fresnel (Rs, Rp) for n1 → n2 at cos θ_i = ci (Born & Wolf §1.5.2); (1, 1) for TIR.
glm::dvec2 fresnelRsRp(double ci, double n1, double n2) {
  double eta = n1 / n2;
  double st2 = eta * eta * std::max(0.0, 1.0 - ci * ci);
  if (st2 >= 1.0) return glm::dvec2(1.0);
  double ct = std::sqrt(1.0 - st2);
  double rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
  double rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
  return {rs * rs, rp * rp};
}

double bandAt(const glm::dvec3& rgb, double l) {
  if (l <= 465.0) return rgb.b;
  if (l >= 612.0) return rgb.r;
  if (l <= 549.0) return rgb.b + (rgb.g - rgb.b) * (l - 465.0) / (549.0 - 465.0);
  return rgb.g + (rgb.r - rgb.g) * (l - 549.0) / (612.0 - 549.0);
}

void validate(const MarchSettings& m) {
  if (!(m.step_voxels > 0 && m.step_voxels <= 4)) throw std::invalid_argument("march step must be in (0, 4] voxels");
  if (m.max_steps < 1) throw std::invalid_argument("max_steps must be >= 1");
}

}  // namespace

// ------------------------------------------------------------------ ReferenceMarcher
struct ReferenceMarcher::Result {
  glm::dvec3 radiance{0.0}, throughput{1.0}, exit_point{0.0}, exit_dir{0.0}, wave_normal{0.0};
  double opl = 0.0, drift = 0.0;
  bool left = true;
  int steps = 0, interfaces = 0, tir = 0;
};

ReferenceMarcher::Result ReferenceMarcher::march(const glm::dvec3& o, const glm::dvec3& d, double lambda_nm,
                                                 bool scalar, const MarchSettings& m, int mode) const {
  const double l_um = lambda_nm * 1e-3, il2 = 1.0 / (l_um * l_um), il4 = il2 * il2;
  auto colour = [&](const glm::dvec3& rgb) {
    return scalar ? glm::dvec3(spectrum::rgbToSpectrum(rgb, lambda_nm)) : rgb;
  };
  auto sigmaOf = [&](const glm::dvec3& b) { return scalar ? glm::dvec3(bandAt(b, lambda_nm)) : b; };
  auto environment = [&](const glm::dvec3& dir) { return colour(env_.lookup(dir)); };
  auto nO = [&](const glm::dvec3& x, double& n, glm::dvec3& g) { field_.index(x, il2, il4, n, g); };
  auto nE = [&](const glm::dvec3& x, double& n, glm::dvec3& g) { field_.indexE(x, il2, il4, n, g); };
  auto hasAxis = [](const glm::dvec3& a) { return glm::dot(a, a) >= 0.25; };
  // M_e p = aaᵀp/n_o² + (I − aaᵀ)p/n_e² (docs/design.md §2).
  auto applyM = [](const glm::dvec3& p, const glm::dvec3& a, double no, double ne) {
    double pa = glm::dot(p, a);
    return a * pa / (no * no) + (p - a * pa) / (ne * ne);
  };
  // Derivatives with respect to ray arc length; see shaders/march.glsl deriv().
  auto deriv = [&](const glm::dvec3& x, const glm::dvec3& w, glm::dvec3& dx, glm::dvec3& dw) {
    double no;
    glm::dvec3 go;
    nO(x, no, go);
    glm::dvec4 af = mode == 1 ? field_.axisField(x) : glm::dvec4(0.0);
    glm::dvec3 a(af);
    if (mode == 0 || !hasAxis(a)) {  // M = I/n²: dx/ds = w/|w|, dw/ds = |w|∇n/n (see march.glsl)
      double lw = glm::length(w);
      dx = w / lw;
      dw = go * (lw / no);
      return;
    }
    double ne;
    glm::dvec3 ge;
    nE(x, ne, ge);
    double pa = glm::dot(w, a), p2 = glm::dot(w, w);
    glm::dvec3 Mp = applyM(w, a, no, ne);
    glm::dvec3 dp = (pa * pa / (no * no * no)) * go + ((p2 - pa * pa) / (ne * ne * ne)) * ge;
    // Radial axis field: −(p·a)(1/n_o² − 1/n_e²)(p − (p·a)a)/r (see march.glsl).
    if (af.w > 0.0) dp -= pa * (1.0 / (no * no) - 1.0 / (ne * ne)) * (w - pa * a) * af.w;
    double L = glm::length(Mp);
    dx = Mp / L;
    dw = dp / L;
  };
  auto rayDirection = [&](const glm::dvec3& x, const glm::dvec3& w) {
    glm::dvec3 a = mode == 1 ? field_.axis(x) : glm::dvec3(0.0);
    if (mode == 0 || !hasAxis(a)) return glm::normalize(w);
    double no, ne;
    glm::dvec3 g;
    nO(x, no, g);
    nE(x, ne, g);
    return glm::normalize(applyM(w, a, no, ne));
  };
  // Attenuation per unit ray length (e-mode: pleochroic σ(θ)·cos ρ, docs/design.md §2).
  auto attenuationAt = [&](const glm::dvec3& x, const glm::dvec3& w) {
    glm::dvec3 so = sigmaOf(glm::dvec3(field_.medium(x)));
    glm::dvec3 a = mode == 1 ? field_.axis(x) : glm::dvec3(0.0);
    if (mode == 0 || !hasAxis(a)) return so;
    glm::dvec3 se = sigmaOf(glm::dvec3(field_.mediumE(x)));
    double no, ne;
    glm::dvec3 g;
    nO(x, no, g);
    nE(x, ne, g);
    glm::dvec3 sn = glm::normalize(w);
    double c = glm::dot(sn, a), c2 = c * c, s2 = 1.0 - c2;
    double n = 1.0 / std::sqrt(c2 / (no * no) + s2 / (ne * ne));
    glm::dvec3 t = glm::normalize(applyM(w, a, no, ne));
    return n * n * n * (so * c2 / (no * no * no) + se * s2 / (ne * ne * ne)) * glm::dot(sn, t);
  };
  // Light from the light simulator: in-scatter σ_s·p·φ and diffuse surfaces albedo·E/π; the
  // formulas and the mean-direction phase model are those of march.glsl inScatter/diffuseSurface.
  const bool lit = field_.lit();
  auto phaseHG = [](double cosTheta, double g) {
    double dd = 1.0 + g * g - 2.0 * g * cosTheta;
    return (1.0 - g * g) / (4.0 * kPi * dd * std::sqrt(dd));
  };
  auto inScatter = [&](const glm::dvec3& x, const glm::dvec3& dir, const glm::dvec3& sigmaT) {
    glm::dvec4 sc = field_.scatter(x);
    if (sc.x + sc.y + sc.z <= 0.0) return glm::dvec3(0.0);
    glm::dvec4 phi = field_.lightFluence(x);
    if (phi.w <= 0.0) return glm::dvec3(0.0);
    glm::dvec3 mdir = field_.lightFlux(x) / phi.w;
    double lm = std::min(glm::length(mdir), 1.0);
    double p = (1.0 - lm) / (4.0 * kPi);
    if (lm > 1e-6) p += lm * phaseHG(glm::dot(glm::normalize(mdir), -dir), sc.w);
    return sigmaOf(glm::dvec3(sc)) * sigmaT * colour(glm::dvec3(phi)) * p;
  };
  auto diffuseSurface = [&](const glm::dvec3& x) {
    // Albedo and opacity are both composited with the coverage: their ratio is the surface's albedo.
    if (!lit) return glm::dvec3(0.0);
    glm::dvec4 sc = field_.scatter(x) / std::max(mode == 1 ? field_.mediumE(x).w : field_.medium(x).w, 0.5);
    if (sc.x + sc.y + sc.z <= 0.0) return glm::dvec3(0.0);
    const double hh = field_.cellSize();
    auto opacity = [&](const glm::dvec3& y) { return mode == 1 ? field_.mediumE(y).w : field_.medium(y).w; };
    glm::dvec3 g;
    for (int a = 0; a < 3; ++a) {
      glm::dvec3 e(0.0);
      e[a] = hh;
      g[a] = opacity(x + e) - opacity(x - e);
    }
    if (glm::dot(g, g) <= 0.0) return glm::dvec3(0.0);
    glm::dvec3 N = -glm::normalize(g);
    glm::dvec3 xs = x + 1.5 * hh * N;
    glm::dvec4 phi = field_.lightFluence(xs);
    if (phi.w <= 0.0) return glm::dvec3(0.0);
    double cosFactor = std::max(0.0, -glm::dot(field_.lightFlux(xs), N)) / phi.w;
    return sigmaOf(glm::dvec3(sc)) * colour(glm::dvec3(phi)) * (cosFactor / kPi);
  };
  auto sWeight = [](const glm::dvec3& s_crystal, const glm::dvec3& a, const glm::dvec3& N, const glm::dvec3& dIn,
                    int md) {
    glm::dvec3 es = glm::cross(N, dIn);
    if (glm::dot(a, a) < 0.25 || glm::dot(es, es) < 1e-12) return 0.5;
    glm::dvec3 Do = glm::cross(s_crystal, a);
    if (glm::dot(Do, Do) < 1e-12) return 0.5;
    Do = glm::normalize(Do);
    es = glm::normalize(es);
    double wo = glm::dot(Do, es) * glm::dot(Do, es);
    return md == 0 ? wo : 1.0 - wo;
  };

  Result R;
  const glm::dvec3 bmin = field_.boundsMin(), bmax = field_.boundsMax();
  const double h = field_.cellSize();
  double t0, t1;
  if (!boxHit(o, d, bmin, bmax, t0, t1)) {
    R.radiance = environment(d);
    R.exit_point = o;
    R.exit_dir = d;
    R.wave_normal = d;
    return R;
  }
  t0 = std::max(t0, 0.0);
  glm::dvec3 x = o + d * t0;
  R.opl = field_.ambientIndex() * t0;
  double n;
  glm::dvec3 grad;
  nO(x, n, grad);
  glm::dvec3 w = n * d;
  const double ds = m.step_voxels * h;
  const double thrLow = 1e-6, thrIface = m.interface_threshold;
  bool inLayer = false, stopped = false;
  double peak = 0.0;
  glm::dvec3 wBefore = w, gAcc(0.0), T(1.0), L(0.0), xOpen = x;
  int steps = 0;
  for (; steps < m.max_steps; ++steps) {
    double D = field_.skipDistance(x);
    if (!inLayer && D >= 2.0 && m.skip_empty) {
      glm::dvec3 dir = rayDirection(x, w);
      double tb0, tb1;
      boxHit(x, dir, bmin, bmax, tb0, tb1);
      double tExit = std::max(tb1, 0.0);
      double len = (D - 1.5) * h;
      // A lit scattering medium is homogeneous but its light is not: sample the light every voxel.
      glm::dvec4 scHere = lit ? field_.scatter(x) : glm::dvec4(0.0);
      bool scattering = scHere.x + scHere.y + scHere.z > 0.0;
      if (scattering) len = std::min(len, h);
      bool leaving = len >= tExit;
      len = std::min(len, tExit);
      glm::dvec4 med = field_.medium(x);
      glm::dvec3 e = colour(field_.emission(x));
      if (med.w >= 0.5) {
        L += T * (e / med.w + diffuseSurface(x));
        stopped = true;
        break;
      }
      glm::dvec3 sig = attenuationAt(x, w);
      if (scattering) e += inScatter(x + 0.5 * len * dir, dir, sig);
      for (int c = 0; c < 3; ++c) {
        double a = std::exp(-sig[c] * len);
        L[c] += T[c] * (sig[c] > 1e-6 ? e[c] * (1.0 - a) / sig[c] : e[c] * len);
        T[c] *= a;
      }
      R.opl += glm::dot(w, dir) * len;
      x += dir * len;
      if (leaving) break;
      continue;
    }
    glm::dvec3 x0 = x, w0 = w;
    double n0 = n;
    glm::dvec3 k1x, k1w, k2x, k2w, k3x, k3w, k4x, k4w;
    deriv(x, w, k1x, k1w);
    if (m.integrator == Integrator::Euler) {
      x += ds * k1x;
      w += ds * k1w;
    } else if (m.integrator == Integrator::Midpoint) {
      deriv(x + 0.5 * ds * k1x, w + 0.5 * ds * k1w, k2x, k2w);
      x += ds * k2x;
      w += ds * k2w;
    } else {
      deriv(x + 0.5 * ds * k1x, w + 0.5 * ds * k1w, k2x, k2w);
      deriv(x + 0.5 * ds * k2x, w + 0.5 * ds * k2w, k3x, k3w);
      deriv(x + ds * k3x, w + ds * k3w, k4x, k4w);
      x += ds / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
      w += ds / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
    }
    nO(x, n, grad);
    glm::dvec3 gradN = grad;
    glm::dvec3 aHere = mode == 1 ? field_.axis(x) : glm::dvec3(0.0);
    bool eHere = mode == 1 && hasAxis(aHere);
    double ne = n;
    glm::dvec3 gradE = grad;
    if (eHere) nE(x, ne, gradE);
    if (mode == 0) {
      R.drift = std::max(R.drift, std::abs(glm::length(w) - n));
      R.opl += 0.5 * (n0 + n) * ds;
    } else {
      R.opl += 0.5 * glm::dot(w0 + w, x - x0);
      if (eHere) gradN = 0.5 * (grad + gradE);
    }
    glm::dvec3 xm = 0.5 * (x0 + x);
    L += T * colour(field_.emission(xm)) * ds;
    glm::dvec3 sig = attenuationAt(xm, 0.5 * (w0 + w));
    if (lit) L += T * inScatter(xm, glm::normalize(x - x0), sig) * ds;
    T *= glm::exp(-sig * ds);
    if (field_.medium(x).w >= 0.5) {
      // Surface emission: the emission field over the coverage (opacity ≥ 0.5 here), as the albedo.
      L += T * (colour(field_.emission(x)) / field_.medium(x).w + diffuseSurface(x));
      stopped = true;
      break;
    }
    double g = std::max(glm::length(grad), glm::length(gradE)) * h;
    if (!inLayer && g > thrLow) {
      inLayer = true;
      wBefore = w0;
      gAcc = glm::dvec3(0.0);
      peak = 0.0;
      xOpen = x0;
    }
    if (inLayer) {
      gAcc += gradN * ds;
      peak = std::max(peak, g);
      if (g <= thrLow) {
        inLayer = false;
        glm::dvec3 N = glm::dot(gAcc, gAcc) > 0.0 ? glm::normalize(gAcc) : glm::dvec3(0.0);
        if (glm::dot(N, N) > 0.0 && std::abs(glm::dot(x - xOpen, N)) <= 12.0 * h) {
          // Back onto H = 0 along the layer normal (see shaders/march.glsl).
          double wn = glm::dot(w, N);
          glm::dvec3 wt = w - wn * N;
          if (!eHere) {
            double rem = n * n - glm::dot(wt, wt);
            if (rem > 0.25 * wn * wn) w = wt + (wn < 0 ? -1.0 : 1.0) * std::sqrt(rem) * N;
          } else {
            glm::dvec3 MN = applyM(N, aHere, n, ne);
            double qa = glm::dot(N, MN), qb = glm::dot(wt, MN), qc = glm::dot(wt, applyM(wt, aHere, n, ne)) - 1.0;
            double disc = qb * qb - qa * qc;
            if (disc > 0.0) {
              double l1 = (-qb + std::sqrt(disc)) / qa, l2 = (-qb - std::sqrt(disc)) / qa;
              double lam = std::abs(l1 - wn) < std::abs(l2 - wn) ? l1 : l2;
              if (std::abs(lam - wn) < 0.5 * std::abs(wn)) w = wt + lam * N;
            }
          }
        }
        if (peak > thrIface && m.fresnel && glm::dot(N, N) > 0.0) {
          glm::dvec3 dIn = glm::normalize(wBefore), dOut = glm::normalize(w);
          double ci = glm::dot(dIn, N), co = glm::dot(dOut, N);
          double n1 = glm::length(wBefore), n2 = glm::length(w);
          if (ci * co > 0.0) {
            // The crystal side is the layer end with the larger birefringence (the axis field is
            // dilated into the air around crystals).
            double noA, neA, noB, neB;
            glm::dvec3 gtmp;
            nO(x, noA, gtmp);
            nE(x, neA, gtmp);
            nO(xOpen, noB, gtmp);
            nE(xOpen, neB, gtmp);
            bool outCrystal = std::abs(neA - noA) >= std::abs(neB - noB);
            glm::dvec3 a = field_.axis(outCrystal ? x : xOpen);
            double wsw = sWeight(outCrystal ? dOut : dIn, a, N, dIn, mode);
            glm::dvec2 rsp = fresnelRsRp(std::abs(ci), n1, n2);
            double Rf = field_.uniaxial() ? wsw * rsp.x + (1.0 - wsw) * rsp.y : 0.5 * (rsp.x + rsp.y);
            if (n2 > n1) L += T * Rf * environment(glm::reflect(dIn, N));
            T *= 1.0 - Rf;
            R.interfaces++;
          } else {
            R.tir++;
          }
        }
      }
    }
    bool outside = false;
    for (int a = 0; a < 3; ++a) outside = outside || x[a] < bmin[a] || x[a] > bmax[a];
    if (outside) {
      glm::dvec3 dd = glm::normalize(x - x0);
      double a0, a1;
      boxHit(x0, dd, bmin, bmax, a0, a1);
      double stepLen = glm::length(x - x0);
      double keep = std::clamp(std::max(a1, 0.0) / std::max(stepLen, 1e-300), 0.0, 1.0);
      R.opl -= (1.0 - keep) * 0.5 * glm::dot(w0 + w, x - x0);
      x = x0 + (x - x0) * keep;
      w = glm::mix(w0, w, keep);
      break;
    }
  }
  R.steps = steps;
  R.exit_point = x;
  R.exit_dir = rayDirection(x, w);
  R.wave_normal = glm::normalize(w);
  R.left = !stopped && steps < m.max_steps;
  if (R.left) L += T * environment(R.exit_dir);
  R.radiance = L;
  R.throughput = T;
  return R;
}

TraceOutcome ReferenceMarcher::trace(const TraceRequest& ray, const MarchSettings& m, int mode) const {
  validate(m);
  double len = glm::length(ray.direction);
  if (!(len > 0) || !std::isfinite(len)) throw std::invalid_argument("trace direction must be a non-zero finite vector");
  if (!(ray.wavelength_nm > 0)) throw std::invalid_argument("trace wavelength must be > 0 nm");
  if (mode != 0 && mode != 1) throw std::invalid_argument("mode must be 0 (o) or 1 (e)");
  Result r = march(ray.origin, ray.direction / len, ray.wavelength_nm, true, m, field_.uniaxial() ? mode : 0);
  TraceOutcome t;
  t.exit_point = r.exit_point;
  t.exit_direction = r.exit_dir;
  t.wave_normal = r.wave_normal;
  t.optical_path_mm = r.opl;
  t.transmittance = r.throughput.x;
  t.left_volume = r.left;
  t.steps = r.steps;
  t.invariant_drift = r.drift;
  t.interfaces = r.interfaces;
  t.total_internal_reflections = r.tir;
  return t;
}

RenderImage ReferenceMarcher::render(const Camera& cam, const RenderSettings& s, int threads) const {
  validate(s.march);
  RenderImage img;
  img.width = s.width > 0 ? s.width : cam.width;
  img.height = s.height > 0 ? s.height : cam.height;
  img.rgb.assign(size_t(img.width) * size_t(img.height) * 3, 0.0f);
  const glm::dvec3 fwd = glm::normalize(cam.look_at - cam.position);
  const glm::dvec3 right = glm::normalize(glm::cross(fwd, cam.up));
  const glm::dvec3 up = glm::cross(right, fwd);
  const double tanh = std::tan(0.5 * cam.fov_deg * kPi / 180.0), aspect = double(img.width) / img.height;
  const glm::dmat3 M = spectrum::spectralToLinearSrgbMatrix();
  std::atomic<int> next{0}, rows_done{0};
  std::atomic<long long> total_steps{0};
  std::mutex progress_mutex;  // progress per row, one report at a time (skipped when busy)
  auto worker = [&] {
    long long local_steps = 0;
    for (int y = next++; y < img.height; y = next++) {
      if (y > 0 && s.progress) {
        std::unique_lock<std::mutex> lock(progress_mutex, std::try_to_lock);
        if (lock.owns_lock()) s.progress(double(rows_done.load()) / img.height);
      }
      for (int x = 0; x < img.width; ++x) {
        uint32_t pixel = uint32_t(y * img.width + x);
        glm::dvec3 sum(0.0);
        double steps = 0;
        for (int sidx = 0; sidx < s.spp; ++sidx) {
          double jx = 0.5, jy = 0.5;
          if (s.spp > 1) {
            uint32_t hs = spectrum::pcgHash(pixel * 9781u + uint32_t(sidx) * 6271u + 17u);
            jx = double(hs & 0xffffu) / 65536.0;
            jy = double(hs >> 16u) / 65536.0;
          }
          double u = ((x + jx) / img.width * 2.0 - 1.0) * tanh * aspect;
          double v = (1.0 - (y + jy) / img.height * 2.0) * tanh;
          glm::dvec3 d = glm::normalize(fwd + u * right + v * up);
          if (s.wavelengths > 0) {
            auto lambdas = spectrum::stratifiedWavelengths(pixel, uint32_t(sidx), uint32_t(s.wavelengths));
            glm::dvec3 xyz(0.0);
            for (double l : lambdas) {
              Result r = march(cam.position, d, l, true, s.march, 0);
              double rad = r.radiance.x;
              steps += double(r.steps) / s.wavelengths;
              if (field_.uniaxial()) {  // unpolarised: each mode carries half
                Result re = march(cam.position, d, l, true, s.march, 1);
                rad = 0.5 * (rad + re.radiance.x);
                steps += double(re.steps) / s.wavelengths;
              }
              xyz += rad * spectrum::sampleWeightXyz(l, uint32_t(s.wavelengths));
            }
            sum += M * xyz;
          } else {
            Result r = march(cam.position, d, s.wavelength_nm, false, s.march, 0);
            glm::dvec3 rad = r.radiance;
            steps += r.steps;
            if (field_.uniaxial()) {
              Result re = march(cam.position, d, s.wavelength_nm, false, s.march, 1);
              rad = 0.5 * (rad + re.radiance);
              steps += re.steps;
            }
            sum += rad;
          }
        }
        size_t o = (size_t(y) * size_t(img.width) + size_t(x)) * 3;
        for (int c = 0; c < 3; ++c) img.rgb[o + size_t(c)] = float(sum[c] / s.spp);
        local_steps += (long long)(steps / s.spp);
      }
      ++rows_done;
    }
    total_steps += local_steps;
  };
  int t = threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
  auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  for (int i = 0; i < t; ++i) pool.emplace_back(worker);
  for (auto& th : pool) th.join();
  if (s.progress) s.progress(1.0);
  img.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  img.mean_steps = double(total_steps) / (double(img.width) * img.height);
  return img;
}

}  // namespace eikon
