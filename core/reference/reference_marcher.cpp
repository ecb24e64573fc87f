#include "core/reference/reference_marcher.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
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

/// Unpolarised Fresnel reflectance n1 → n2 at cos θ_i = ci (Born & Wolf §1.5.2); 1 for TIR.
double fresnelR(double ci, double n1, double n2) {
  double eta = n1 / n2;
  double st2 = eta * eta * std::max(0.0, 1.0 - ci * ci);
  if (st2 >= 1.0) return 1.0;
  double ct = std::sqrt(1.0 - st2);
  double rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
  double rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
  return 0.5 * (rs * rs + rp * rp);
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

void VolumeField::index(const glm::dvec3& x, double il2, double il4, double& n, glm::dvec3& grad) const {
  glm::dvec4 a = trilinear(v_.index[0][0], x);
  if (v_.dispersive) a += trilinear(v_.index[0][1], x) * il2 + trilinear(v_.index[0][2], x) * il4;
  n = a.x;
  grad = glm::dvec3(a.y, a.z, a.w);
}

glm::dvec4 VolumeField::medium(const glm::dvec3& x) const { return trilinear(v_.medium[0], x); }
glm::dvec3 VolumeField::emission(const glm::dvec3& x) const { return glm::dvec3(trilinear(v_.emission, x)); }

double VolumeField::skipDistance(const glm::dvec3& x) const {
  const Grid& g = v_.grid;
  int i[3];
  for (int a = 0; a < 3; ++a) i[a] = std::clamp(int(std::floor((x[a] - g.origin[a]) / g.h)), 0, g.dims[size_t(a)] - 1);
  return v_.emission[g.index(i[0], i[1], i[2])].w;
}

// ------------------------------------------------------------------ ReferenceMarcher
struct ReferenceMarcher::Result {
  glm::dvec3 radiance{0.0}, throughput{1.0}, exit_point{0.0}, exit_dir{0.0};
  double opl = 0.0, drift = 0.0;
  bool left = true;
  int steps = 0, interfaces = 0, tir = 0;
};

ReferenceMarcher::Result ReferenceMarcher::march(const glm::dvec3& o, const glm::dvec3& d, double lambda_nm,
                                                 bool scalar, const MarchSettings& m) const {
  const double l_um = lambda_nm * 1e-3, il2 = 1.0 / (l_um * l_um), il4 = il2 * il2;
  auto colour = [&](const glm::dvec3& rgb) {
    return scalar ? glm::dvec3(spectrum::rgbToSpectrum(rgb, lambda_nm)) : rgb;
  };
  auto sigmaOf = [&](const glm::dvec3& b) { return scalar ? glm::dvec3(bandAt(b, lambda_nm)) : b; };
  auto environment = [&](const glm::dvec3& dir) { return colour(env_.lookup(dir)); };

  Result R;
  const glm::dvec3 bmin = field_.boundsMin(), bmax = field_.boundsMax();
  const double h = field_.cellSize();
  double t0, t1;
  if (!boxHit(o, d, bmin, bmax, t0, t1)) {
    R.radiance = environment(d);
    R.exit_point = o;
    R.exit_dir = d;
    return R;
  }
  t0 = std::max(t0, 0.0);
  glm::dvec3 x = o + d * t0;
  R.opl = field_.ambientIndex() * t0;
  double n;
  glm::dvec3 grad;
  field_.index(x, il2, il4, n, grad);
  glm::dvec3 w = n * d;
  const double ds = m.step_voxels * h;
  const double thrLow = 1e-6, thrIface = m.interface_threshold;
  bool inLayer = false, stopped = false;
  double nBefore = n, peak = 0.0;
  glm::dvec3 dBefore = d, gAcc(0.0), T(1.0), L(0.0), xOpen = x;
  auto deriv = [&](const glm::dvec3& xx, const glm::dvec3& ww, glm::dvec3& dx, glm::dvec3& dw) {
    double nn;
    glm::dvec3 gg;
    field_.index(xx, il2, il4, nn, gg);
    dx = ww / nn;
    dw = gg;
  };
  int steps = 0;
  for (; steps < m.max_steps; ++steps) {
    glm::dvec3 dir = glm::normalize(w);
    double tb0, tb1;
    boxHit(x, dir, bmin, bmax, tb0, tb1);
    double tExit = std::max(tb1, 0.0);
    double D = field_.skipDistance(x);
    if (!inLayer && D >= 2.0 && m.skip_empty) {
      double len = (D - 1.5) * h;
      bool leaving = len >= tExit;
      len = std::min(len, tExit);
      glm::dvec4 med = field_.medium(x);
      glm::dvec3 e = colour(field_.emission(x));
      if (med.w >= 0.5) {
        L += T * e;
        stopped = true;
        break;
      }
      glm::dvec3 sig = sigmaOf(glm::dvec3(med));
      for (int c = 0; c < 3; ++c) {
        double a = std::exp(-sig[c] * len);
        L[c] += T[c] * (sig[c] > 1e-6 ? e[c] * (1.0 - a) / sig[c] : e[c] * len);
        T[c] *= a;
      }
      R.opl += glm::length(w) * len;
      x += dir * len;
      if (leaving) break;
      continue;
    }
    glm::dvec3 x0 = x, w0 = w;
    double n0 = glm::length(w0);
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
    field_.index(x, il2, il4, n, grad);
    R.drift = std::max(R.drift, std::abs(glm::length(w) - n));
    R.opl += 0.5 * (n0 + n) * ds;
    glm::dvec3 xm = 0.5 * (x0 + x);
    glm::dvec3 sig = sigmaOf(glm::dvec3(field_.medium(xm)));
    L += T * colour(field_.emission(xm)) * ds;
    T *= glm::exp(-sig * ds);
    if (field_.medium(x).w >= 0.5) {
      L += T * colour(field_.emission(x));
      stopped = true;
      break;
    }
    double g = glm::length(grad) * h;
    if (!inLayer && g > thrLow) {
      inLayer = true;
      nBefore = n0;
      dBefore = glm::normalize(w0);
      gAcc = glm::dvec3(0.0);
      peak = 0.0;
      xOpen = x0;
    }
    if (inLayer) {
      gAcc += grad * ds;
      peak = std::max(peak, g);
      if (g <= thrLow) {
        inLayer = false;
        if (glm::dot(gAcc, gAcc) > 0.0 && std::abs(glm::dot(x - xOpen, glm::normalize(gAcc))) <= 12.0 * h) {
          // Project back onto |w| = n along the layer normal (see shaders/march.glsl).
          glm::dvec3 N = glm::normalize(gAcc);
          double wn = glm::dot(w, N);
          glm::dvec3 wt = w - wn * N;
          double rem = n * n - glm::dot(wt, wt);
          if (rem > 0.25 * wn * wn) w = wt + (wn < 0 ? -1.0 : 1.0) * std::sqrt(rem) * N;
        }
        if (peak > thrIface && m.fresnel && glm::dot(gAcc, gAcc) > 0.0) {
          glm::dvec3 N = glm::normalize(gAcc), dAfter = glm::normalize(w);
          double ci = glm::dot(dBefore, N), co = glm::dot(dAfter, N);
          if (ci * co > 0.0) {
            double Rf = fresnelR(std::abs(ci), nBefore, n);
            if (n > nBefore) L += T * Rf * environment(glm::reflect(dBefore, N));
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
      glm::dvec3 dd = glm::normalize(w);
      double a0, a1;
      boxHit(x0, dd, bmin, bmax, a0, a1);
      double stepLen = glm::length(x - x0);
      double back = stepLen - std::max(a1, 0.0);
      x = x0 + dd * std::max(a1, 0.0);
      R.opl -= std::max(back, 0.0) * n;
      if (stepLen > 0.0) w = glm::mix(w0, w, std::clamp(std::max(a1, 0.0) / stepLen, 0.0, 1.0));
      break;
    }
  }
  R.steps = steps;
  R.exit_point = x;
  R.exit_dir = glm::normalize(w);
  R.left = !stopped && steps < m.max_steps;
  if (R.left) L += T * environment(R.exit_dir);
  R.radiance = L;
  R.throughput = T;
  return R;
}

TraceOutcome ReferenceMarcher::trace(const TraceRequest& ray, const MarchSettings& m) const {
  validate(m);
  double len = glm::length(ray.direction);
  if (!(len > 0) || !std::isfinite(len)) throw std::invalid_argument("trace direction must be a non-zero finite vector");
  if (!(ray.wavelength_nm > 0)) throw std::invalid_argument("trace wavelength must be > 0 nm");
  Result r = march(ray.origin, ray.direction / len, ray.wavelength_nm, true, m);
  TraceOutcome t;
  t.exit_point = r.exit_point;
  t.exit_direction = r.exit_dir;
  t.wave_normal = r.exit_dir;
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
  std::atomic<int> next{0};
  std::atomic<long long> total_steps{0};
  auto worker = [&] {
    long long local_steps = 0;
    for (int y = next++; y < img.height; y = next++) {
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
              Result r = march(cam.position, d, l, true, s.march);
              xyz += r.radiance.x * spectrum::sampleWeightXyz(l, uint32_t(s.wavelengths));
              steps += double(r.steps) / s.wavelengths;
            }
            sum += M * xyz;
          } else {
            Result r = march(cam.position, d, s.wavelength_nm, false, s.march);
            sum += r.radiance;
            steps += r.steps;
          }
        }
        size_t o = (size_t(y) * size_t(img.width) + size_t(x)) * 3;
        for (int c = 0; c < 3; ++c) img.rgb[o + size_t(c)] = float(sum[c] / s.spp);
        local_steps += (long long)(steps / s.spp);
      }
    }
    total_steps += local_steps;
  };
  int t = threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
  auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  for (int i = 0; i < t; ++i) pool.emplace_back(worker);
  for (auto& th : pool) th.join();
  img.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  img.mean_steps = double(total_steps) / (double(img.width) * img.height);
  return img;
}

}  // namespace eikon
