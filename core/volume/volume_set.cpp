#include "core/volume/volume_set.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <thread>

#include "core/volume/host_memory.h"

namespace eikon {
namespace {

// Scalar fields composited per voxel before smoothing.
enum Field : int {
  kAo, kBo, kCo, kAe, kBe, kCe,      // Cauchy coefficients, o and e
  kSor, kSog, kSob, kOpacity,        // attenuation o (band values), opacity
  kSer, kSeg, kSeb,                  // attenuation e
  kEr, kEg, kEb,                     // emission
  kAlr, kAlg, kAlb, kPhaseG,         // scattering albedo (or diffuse reflectance), HG asymmetry
  kFieldCount
};

template <typename F>
void parallelFor(int n, int threads, F&& body) {
  int t = threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
  t = std::min(t, n);
  if (t <= 1) {
    for (int i = 0; i < n; ++i) body(i);
    return;
  }
  std::atomic<int> next{0};
  std::vector<std::thread> pool;
  for (int w = 0; w < t; ++w)
    pool.emplace_back([&] {
      for (int i = next++; i < n; i = next++) body(i);
    });
  for (auto& th : pool) th.join();
}

struct MaterialValues {
  float v[kFieldCount];
};

// The voxel index range [lo, hi] of a world box widened by `margin` voxels, clamped to the grid.
// The clamping is done in double before converting to int: an object far outside the volume
// (centre 1e300, or 4294967296 mm) gives voxel coordinates beyond int's range, whose conversion
// is undefined behaviour (UBSan: signed overflow). False if the box misses the grid (or is NaN).
bool voxelRange(const glm::dvec3& bmin, const glm::dvec3& bmax, const Grid& g, int margin,
                int lo[3], int hi[3]) {
  for (int a = 0; a < 3; ++a) {
    const double top = double(g.dims[a] - 1);
    double l = std::floor((bmin[a] - g.origin[a]) / g.h) - margin;
    double h = std::ceil((bmax[a] - g.origin[a]) / g.h) + margin;
    if (!(l <= top) || !(h >= 0.0) || !(l <= h)) return false;  // also false for NaN
    lo[a] = int(std::max(l, 0.0));
    hi[a] = int(std::min(h, top));
  }
  return true;
}

}  // namespace

Grid makeGrid(const VolumeSpec& spec) {
  Grid g;
  glm::dvec3 ext = spec.bounds_max - spec.bounds_min;
  double longest = std::max(ext.x, std::max(ext.y, ext.z));
  g.h = longest / spec.resolution;
  for (int a = 0; a < 3; ++a) g.dims[a] = std::max(1, int(std::ceil(ext[a] / g.h - 1e-9)));
  g.origin = spec.bounds_min;
  g.extent = glm::dvec3(g.dims[0], g.dims[1], g.dims[2]) * g.h;
  return g;
}

size_t VolumeSet::deviceBytes() const {
  size_t texels = 0;
  for (const auto& mode : index)
    for (const auto& f : mode) texels += f.size();
  for (const auto& m : medium) texels += m.size();
  texels += emission.size() + axis.size() + scatter.size() + light_fluence.size() + light_flux.size();
  return texels * sizeof(glm::vec4);
}

void gaussianSmooth(std::vector<float>& f, const std::array<int, 3>& dims, double sigma, int threads) {
  if (sigma <= 0.0) return;
  const int r = int(std::ceil(3.0 * sigma));
  std::vector<float> w(size_t(2 * r + 1));
  double sum = 0.0;
  for (int k = -r; k <= r; ++k) sum += std::exp(-0.5 * k * k / (sigma * sigma));
  for (int k = -r; k <= r; ++k) w[size_t(k + r)] = float(std::exp(-0.5 * k * k / (sigma * sigma)) / sum);
  const size_t nx = size_t(dims[0]), ny = size_t(dims[1]), nz = size_t(dims[2]);
  std::vector<float> out(f.size());
  for (int axis = 0; axis < 3; ++axis) {
    const int n = dims[axis];
    const size_t stride = axis == 0 ? 1 : axis == 1 ? nx : nx * ny;
    // Lines along `axis`: iterate over the other two coordinates.
    const int lines_outer = axis == 2 ? int(ny) : int(nz);
    parallelFor(lines_outer, threads, [&](int o) {
      const size_t inner_n = axis == 0 ? ny : nx;
      for (size_t in = 0; in < inner_n; ++in) {
        size_t base;
        if (axis == 0) base = (size_t(o) * ny + in) * nx;
        else if (axis == 1) base = size_t(o) * nx * ny + in;
        else base = size_t(o) * nx + in;
        for (int i = 0; i < n; ++i) {
          float acc = 0.0f;
          for (int k = -r; k <= r; ++k) {
            int j = std::clamp(i + k, 0, n - 1);
            acc += w[size_t(k + r)] * f[base + size_t(j) * stride];
          }
          out[base + size_t(i) * stride] = acc;
        }
      }
    });
    std::swap(f, out);
  }
}

double voxelizeHostBytes(const Scene& scene, const Grid& g) {
  // Per voxel, everything voxelize() holds at once near its end (the smoothing's and the axis
  // dilation's temporaries included).
  const bool uniaxial = scene.anyUniaxial();
  bool scattering = false;
  for (const auto& [name, m] : scene.materials)
    scattering = scattering || m.albedo != glm::dvec3(0.0);
  const bool analytic = scene.volume.smoothing_voxels > 0 &&
                        scene.volume.smoothing == VolumeSpec::Smoothing::Analytic;
  double per_voxel = kFieldCount * sizeof(float);                 // composited fields
  per_voxel += analytic ? 6 * sizeof(glm::vec3) : sizeof(float);  // exact gradients / smoothing
  per_voxel += (uniaxial ? 6 : 3) * sizeof(glm::vec4);            // index volumes
  per_voxel += (uniaxial ? 2 : 1) * sizeof(glm::vec4);            // medium volumes
  per_voxel += sizeof(glm::vec4) + (scattering ? sizeof(glm::vec4) : 0);  // emission, scatter
  per_voxel += uniaxial ? 2 * sizeof(glm::vec4) : 0;  // axis and its dilation copy
  per_voxel += 2 * sizeof(uint8_t);                   // skip distances
  return per_voxel * double(g.dims[0]) * double(g.dims[1]) * double(g.dims[2]);
}

VolumeSet voxelize(const Scene& scene, const VoxelizeOptions& opt) {
  // Calls may come from the worker threads (per slab): one at a time, and skipped rather than
  // waited for when another thread is reporting.
  std::mutex progress_mutex;
  auto progress = [&](double x, const char* stage) {
    if (!opt.progress) return;
    std::unique_lock<std::mutex> lock(progress_mutex, std::try_to_lock);
    if (lock.owns_lock()) opt.progress(x, stage);
  };
  VolumeSet vs;
  vs.grid = makeGrid(scene.volume);
  const Grid& g = vs.grid;
  if (double(g.dims[0]) * g.dims[1] * g.dims[2] > double(1u << 31))
    throw SceneError(scene.file.string() + ": /volume/resolution: " + std::to_string(g.dims[0]) + "x" +
                     std::to_string(g.dims[1]) + "x" + std::to_string(g.dims[2]) + " voxels is too many");
  {
    const double need = voxelizeHostBytes(scene, g);
    const HostMemory mem = availableHostMemory();
    if (need > double(mem.available))
      throw SceneError(scene.file.string() + ": /volume/resolution: voxelising " +
                       std::to_string(g.dims[0]) + "x" + std::to_string(g.dims[1]) + "x" +
                       std::to_string(g.dims[2]) + " voxels needs " + formatBytes(need) +
                       " of host memory, " + formatBytes(double(mem.available)) + " available (" +
                       mem.limited_by + "); lower the resolution");
  }
  const size_t N = g.count();
  vs.uniaxial = scene.anyUniaxial();
  vs.ambient_index = scene.ambient_index;

  // Per-material constant values (GRIN materials override A per voxel).
  std::map<std::string, MaterialValues> values;
  auto bands = [](const Attenuation& a) {
    return glm::dvec3(a.at(612.0), a.at(549.0), a.at(465.0));
  };
  for (const auto& [name, m] : scene.materials) {
    MaterialValues mv{};
    auto co = m.n_o.cauchyApproximation(380.0, 780.0), ce = m.n_e.cauchyApproximation(380.0, 780.0);
    for (int c = 0; c < 3; ++c) {
      mv.v[kAo + c] = float(co.coeffs[size_t(c)]);
      mv.v[kAe + c] = float(ce.coeffs[size_t(c)]);
    }
    glm::dvec3 so = bands(m.attenuation_o), se = bands(m.attenuation_e);
    for (int c = 0; c < 3; ++c) {
      mv.v[kSor + c] = float(so[c]);
      mv.v[kSer + c] = float(se[c]);
      mv.v[kEr + c] = float(m.emission[c]);
      mv.v[kAlr + c] = float(m.albedo[c]);
    }
    mv.v[kPhaseG] = float(m.phase_g);
    mv.v[kOpacity] = float(m.opacity);
    values[name] = mv;
    if (mv.v[kBo] != 0 || mv.v[kCo] != 0 || mv.v[kBe] != 0 || mv.v[kCe] != 0) vs.dispersive = true;
    for (int f : {kSor, kSog, kSob, kSer, kSeg, kSeb})
      if (mv.v[f] != 0) vs.attenuating = true;
    for (int f : {kEr, kEg, kEb})
      if (mv.v[f] != 0) vs.emissive = true;
    if (mv.v[kOpacity] != 0) vs.opaque = true;
    for (int f : {kAlr, kAlg, kAlb})
      if (mv.v[f] != 0) vs.scattering = true;
  }

  std::vector<std::vector<float>> fields(kFieldCount, std::vector<float>(N, 0.0f));
  std::fill(fields[kAo].begin(), fields[kAo].end(), float(scene.ambient_index));
  std::fill(fields[kAe].begin(), fields[kAe].end(), float(scene.ambient_index));
  std::vector<glm::vec4> axis;
  if (vs.uniaxial) axis.assign(N, glm::vec4(0.0f));
  // Analytic smoothing carries exact gradients of the index fields through the compositing
  // (∇ of the smoothed indicator = −F′·∇sd/3σ, along the face normal), so a flat face bends rays
  // exactly along its normal whatever its orientation to the grid. Central differences of the
  // sampled profile would not: their components are attenuated unequally for oblique faces, which
  // biased the prism deviation by −0.15° independently of resolution (docs/volumes.md).
  std::vector<std::vector<glm::vec3>> gradients;

  const double half_diag = 0.5 * std::sqrt(3.0) * g.h;
  const double sigma = scene.volume.smoothing_voxels;
  const bool analytic = sigma > 0 && scene.volume.smoothing == VolumeSpec::Smoothing::Analytic;
  // Analytic smoothing: the indicator of each object blurred across its surface by the triweight
  // kernel K(u) = 35/32 (1 − u²)³ on |u| ≤ 1 scaled to half-width 3σ (variance σ², the same as a
  // Gaussian of σ, but compact so that the fields are exactly constant 3σ from every surface):
  // coverage = F(−sd/3σ) with F the kernel's CDF, sd the signed distance (exact for planes and
  // spheres). A flat face is then smoothed exactly along its normal, with no staircase.
  const double half_width = 3.0 * sigma * g.h;
  auto triweightCdf = [](double u) {
    if (u <= -1.0) return 0.0;
    if (u >= 1.0) return 1.0;
    double u2 = u * u;
    return 0.5 + 35.0 / 32.0 * u * (1.0 - u2 + 0.6 * u2 * u2 - u2 * u2 * u2 / 7.0);
  };
  const int margin = 1 + (analytic ? int(std::ceil(3.0 * sigma)) : 0);
  auto triweight = [](double u) {
    if (u <= -1.0 || u >= 1.0) return 0.0;
    double v = 1.0 - u * u;
    return 35.0 / 32.0 * v * v * v;
  };
  const bool exactGradients = analytic;
  if (exactGradients) gradients.assign(6, std::vector<glm::vec3>(N, glm::vec3(0.0f)));
  for (size_t oi = 0; oi < scene.objects.size(); ++oi) {
    const SceneObject& obj = scene.objects[oi];
    const Material& mat = scene.materials.at(obj.material);
    const MaterialValues& mv = values.at(obj.material);
    // Axis texel: (a, 0) for a uniform axis; (centre, −1) for a radial field, evaluated exactly
    // by the marchers as a(x) = (x − centre)/|x − centre| (so dilation copies stay exact).
    glm::vec4 ax(0.0f);
    if (mat.uniaxial && obj.radial_axis) ax = glm::vec4(glm::vec3(obj.shape.center()), -1.0f);
    else if (mat.uniaxial) ax = glm::vec4(glm::vec3(obj.optic_axis ? *obj.optic_axis : *mat.optic_axis), 0.0f);
    auto [bmin, bmax] = obj.shape.bounds();
    int lo[3], hi[3];
    if (!voxelRange(bmin, bmax, g, margin, lo, hi)) {  // wholly outside the grid: nothing to add
      progress(0.4 * double(oi + 1) / double(scene.objects.size()), "voxelising");
      continue;
    }
    const int slabs = hi[2] - lo[2] + 1;
    std::atomic<int> slabs_done{0};
    parallelFor(slabs, opt.threads, [&](int kk) {
      const int k = lo[2] + kk;
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) {
          glm::dvec3 c = g.center(i, j, k);
          double sd = obj.shape.signedDistance(c);
          double cov;
          glm::dvec3 gcov(0.0);
          if (analytic) {
            if (sd >= half_width) continue;
            cov = triweightCdf(-sd / half_width);
            gcov = -triweight(-sd / half_width) / half_width * obj.shape.distanceGradient(c);
          } else if (sd > half_diag) {
            continue;
          } else if (sd < -half_diag) {
            cov = 1.0;
          } else {
            int inside = 0;
            for (int s = 0; s < 64; ++s) {
              glm::dvec3 off((s & 3) + 0.5, ((s >> 2) & 3) + 0.5, (s >> 4) + 0.5);
              if (obj.shape.contains(c + (off / 4.0 - 0.5) * g.h)) ++inside;
            }
            cov = inside / 64.0;
          }
          if (cov <= 0.0) continue;
          const size_t idx = g.index(i, j, k);
          const float fc = float(cov);
          // Property values here (GRIN materials vary A in space).
          float prop[kFieldCount];
          for (int f = 0; f < kFieldCount; ++f) prop[f] = mv.v[f];
          glm::dvec3 gprop(0.0);
          if (mat.grin.type != GrinProfile::Type::None) {
            prop[kAo] = prop[kAe] = float(mat.grin.index(c));
            gprop = mat.grin.indexGradient(c);
          }
          if (exactGradients)  // ∇[v(1 − c) + p c] = ∇v (1 − c) + (p − v)∇c + c∇p
            for (int f = 0; f < 6; ++f) {
              glm::dvec3 gv = glm::dvec3(gradients[size_t(f)][idx]) * (1.0 - cov) +
                              (double(prop[f]) - fields[size_t(f)][idx]) * gcov +
                              ((f == kAo || f == kAe) ? cov * gprop : glm::dvec3(0.0));
              gradients[size_t(f)][idx] = glm::vec3(gv);
            }
          for (int f = 0; f < kFieldCount; ++f)
            fields[size_t(f)][idx] = fields[size_t(f)][idx] * (1 - fc) + prop[f] * fc;
          if (vs.uniaxial && mat.uniaxial) axis[idx] = ax;
        }
      // Progress per z slab: a large object alone takes seconds at 256³. The count is read under
      // the lock, so the reported fractions never decrease.
      ++slabs_done;
      if (opt.progress) {
        std::unique_lock<std::mutex> lock(progress_mutex, std::try_to_lock);
        if (lock.owns_lock())
          opt.progress(
              0.4 * (double(oi) + double(slabs_done.load()) / slabs) / double(scene.objects.size()),
              "voxelising");
      }
    });
    progress(0.4 * double(oi + 1) / double(scene.objects.size()), "voxelising");
  }

  // Gaussian method: smooth every field that is not constant.
  for (int f = 0; f < kFieldCount && !analytic; ++f) {
    if (!vs.uniaxial && (f == kAe || f == kBe || f == kCe || f == kSer || f == kSeg || f == kSeb)) continue;
    auto& fld = fields[size_t(f)];
    auto [mn, mx] = std::minmax_element(fld.begin(), fld.end());
    if (*mn != *mx) gaussianSmooth(fld, g.dims, sigma, opt.threads);
    progress(0.4 + 0.3 * (f + 1) / double(kFieldCount), "smoothing");
  }

  // Gradients by central differences (one-sided at the grid faces).
  auto withGradient = [&](const std::vector<float>& f) {
    std::vector<glm::vec4> out(N);
    parallelFor(g.dims[2], opt.threads, [&](int k) {
      for (int j = 0; j < g.dims[1]; ++j)
        for (int i = 0; i < g.dims[0]; ++i) {
          int c[3] = {i, j, k};
          glm::vec4 t(f[g.index(i, j, k)], 0, 0, 0);
          for (int a = 0; a < 3; ++a) {
            int lo_c[3] = {i, j, k}, hi_c[3] = {i, j, k};
            lo_c[a] = std::max(c[a] - 1, 0);
            hi_c[a] = std::min(c[a] + 1, g.dims[a] - 1);
            int span = hi_c[a] - lo_c[a];
            if (span > 0)
              t[a + 1] = float((double(f[g.index(hi_c[0], hi_c[1], hi_c[2])]) - f[g.index(lo_c[0], lo_c[1], lo_c[2])]) / (span * g.h));
          }
          out[g.index(i, j, k)] = t;
        }
    });
    return out;
  };
  for (int m = 0; m < (vs.uniaxial ? 2 : 1); ++m)
    for (int c = 0; c < 3; ++c) {
      int f = m == 0 ? kAo + c : kAe + c;
      if (analytic) {
        std::vector<glm::vec4> out(N);
        for (size_t i = 0; i < N; ++i) out[i] = glm::vec4(fields[size_t(f)][i], gradients[size_t(f)][i]);
        vs.index[size_t(m)][size_t(c)] = std::move(out);
      } else {
        vs.index[size_t(m)][size_t(c)] = withGradient(fields[size_t(f)]);
      }
      progress(0.7 + 0.15 * double(m * 3 + c + 1) / (vs.uniaxial ? 6.0 : 3.0), "gradients");
    }
  progress(0.85, "gradients");

  auto pack = [&](int a, int b, int c, int d) {
    std::vector<glm::vec4> out(N);
    for (size_t i = 0; i < N; ++i)
      out[i] = glm::vec4(fields[size_t(a)][i], fields[size_t(b)][i], fields[size_t(c)][i], d >= 0 ? fields[size_t(d)][i] : 0.0f);
    return out;
  };
  vs.medium[0] = pack(kSor, kSog, kSob, kOpacity);
  if (vs.uniaxial) {
    vs.medium[1] = pack(kSer, kSeg, kSeb, kOpacity);
    // Dilate the optic axis over the smoothing reach so every voxel where n_o ≠ n_e (the
    // smoothed crystal surface) knows the axis; elsewhere n_o = n_e and the axis is irrelevant.
    const int reach = int(std::ceil(3.0 * sigma)) + 2;
    for (int pass = 0; pass < reach; ++pass) {
      std::vector<glm::vec4> next = axis;
      parallelFor(g.dims[2], opt.threads, [&](int k) {
        for (int j = 0; j < g.dims[1]; ++j)
          for (int i = 0; i < g.dims[0]; ++i) {
            size_t idx = g.index(i, j, k);
            if (axis[idx] != glm::vec4(0.0f)) continue;
            for (int d = 0; d < 6; ++d) {
              int c[3] = {i, j, k};
              c[d / 2] += (d & 1) ? 1 : -1;
              if (c[d / 2] < 0 || c[d / 2] >= g.dims[size_t(d / 2)]) continue;
              const glm::vec4& nb = axis[g.index(c[0], c[1], c[2])];
              if (nb != glm::vec4(0.0f)) {
                next[idx] = nb;
                break;
              }
            }
          }
      });
      axis.swap(next);
      progress(0.85 + 0.05 * double(pass + 1) / reach, "optic axis");
    }
    vs.axis = std::move(axis);
  }
  vs.emission = pack(kEr, kEg, kEb, -1);
  if (vs.scattering) vs.scatter = pack(kAlr, kAlg, kAlb, kPhaseG);

  // Active voxels: any field differs from a 26-neighbour. Then the capped Chebyshev distance.
  std::vector<int> used;
  for (int f = 0; f < kFieldCount; ++f) {
    auto [mn, mx] = std::minmax_element(fields[size_t(f)].begin(), fields[size_t(f)].end());
    if (*mn != *mx) used.push_back(f);
  }
  const int cap = vs.skip_cap;
  std::vector<uint8_t> dist(N, uint8_t(cap));
  parallelFor(g.dims[2], opt.threads, [&](int k) {
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        size_t idx = g.index(i, j, k);
        bool active = false;
        for (int dz = -1; dz <= 1 && !active; ++dz)
          for (int dy = -1; dy <= 1 && !active; ++dy)
            for (int dx = -1; dx <= 1 && !active; ++dx) {
              int x = std::clamp(i + dx, 0, g.dims[0] - 1), y = std::clamp(j + dy, 0, g.dims[1] - 1),
                  z = std::clamp(k + dz, 0, g.dims[2] - 1);
              size_t n = g.index(x, y, z);
              for (int f : used)
                if (fields[size_t(f)][n] != fields[size_t(f)][idx]) {
                  active = true;
                  break;
                }
            }
        // A radial axis field varies everywhere inside its crystal: never straight-step there.
        if (!vs.axis.empty() && vs.axis[idx].w < -0.5f) active = true;
        if (active) dist[idx] = 0;
      }
  });
  // Separable L∞ distance transform: D_a(v) = min_j max(|v_a − j|, D_{a−1}(…j…)).
  for (int a = 0; a < 3; ++a) {
    std::vector<uint8_t> out(N);
    const size_t stride = a == 0 ? 1 : a == 1 ? size_t(g.dims[0]) : size_t(g.dims[0]) * size_t(g.dims[1]);
    parallelFor(g.dims[2], opt.threads, [&](int k) {
      for (int j = 0; j < g.dims[1]; ++j)
        for (int i = 0; i < g.dims[0]; ++i) {
          int c[3] = {i, j, k};
          size_t idx = g.index(i, j, k);
          int best = dist[idx];
          for (int d = 1; d < best; ++d) {
            int lo_i = c[a] - d, hi_i = c[a] + d;
            if (lo_i >= 0) best = std::min(best, std::max(d, int(dist[idx - size_t(d) * stride])));
            if (hi_i < g.dims[a]) best = std::min(best, std::max(d, int(dist[idx + size_t(d) * stride])));
          }
          out[idx] = uint8_t(best);
        }
    });
    dist.swap(out);
    progress(0.9 + 0.03 * (a + 1), "skip distances");
  }
  for (size_t i = 0; i < N; ++i) vs.emission[i].w = float(dist[i]);
  progress(1.0, "done");
  return vs;
}

}  // namespace eikon
