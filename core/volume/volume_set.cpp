#include "core/volume/volume_set.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>

namespace eikon {
namespace {

// Scalar fields composited per voxel before smoothing.
enum Field : int {
  kAo, kBo, kCo, kAe, kBe, kCe,      // Cauchy coefficients, o and e
  kSor, kSog, kSob, kOpacity,        // attenuation o (band values), opacity
  kSer, kSeg, kSeb,                  // attenuation e
  kEr, kEg, kEb,                     // emission
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
  texels += emission.size() + axis.size();
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

VolumeSet voxelize(const Scene& scene, const VoxelizeOptions& opt) {
  auto progress = [&](double x, const char* stage) {
    if (opt.progress) opt.progress(x, stage);
  };
  VolumeSet vs;
  vs.grid = makeGrid(scene.volume);
  const Grid& g = vs.grid;
  if (double(g.dims[0]) * g.dims[1] * g.dims[2] > double(1u << 31))
    throw SceneError(scene.file.string() + ": /volume/resolution: " + std::to_string(g.dims[0]) + "x" +
                     std::to_string(g.dims[1]) + "x" + std::to_string(g.dims[2]) + " voxels is too many");
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
    }
    mv.v[kOpacity] = float(m.opacity);
    values[name] = mv;
    if (mv.v[kBo] != 0 || mv.v[kCo] != 0 || mv.v[kBe] != 0 || mv.v[kCe] != 0) vs.dispersive = true;
  }

  std::vector<std::vector<float>> fields(kFieldCount, std::vector<float>(N, 0.0f));
  std::fill(fields[kAo].begin(), fields[kAo].end(), float(scene.ambient_index));
  std::fill(fields[kAe].begin(), fields[kAe].end(), float(scene.ambient_index));
  std::vector<glm::vec4> axis;
  if (vs.uniaxial) axis.assign(N, glm::vec4(0.0f));

  const double half_diag = 0.5 * std::sqrt(3.0) * g.h;
  for (size_t oi = 0; oi < scene.objects.size(); ++oi) {
    const SceneObject& obj = scene.objects[oi];
    const Material& mat = scene.materials.at(obj.material);
    const MaterialValues& mv = values.at(obj.material);
    glm::vec3 ax(0.0f);
    if (mat.uniaxial) ax = glm::vec3(obj.optic_axis ? *obj.optic_axis : *mat.optic_axis);
    auto [bmin, bmax] = obj.shape.bounds();
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::clamp(int(std::floor((bmin[a] - g.origin[a]) / g.h)) - 1, 0, g.dims[a] - 1);
      hi[a] = std::clamp(int(std::ceil((bmax[a] - g.origin[a]) / g.h)) + 1, 0, g.dims[a] - 1);
    }
    parallelFor(hi[2] - lo[2] + 1, opt.threads, [&](int kk) {
      const int k = lo[2] + kk;
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) {
          glm::dvec3 c = g.center(i, j, k);
          double sd = obj.shape.signedDistance(c);
          double cov;
          if (sd > half_diag) continue;
          if (sd < -half_diag) cov = 1.0;
          else {
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
          for (int f = 0; f < kFieldCount; ++f) fields[size_t(f)][idx] = fields[size_t(f)][idx] * (1 - fc) + mv.v[f] * fc;
          if (mat.grin.type != GrinProfile::Type::None) {
            float a = float(mat.grin.index(c));
            fields[kAo][idx] = fields[kAo][idx] + (a - float(mv.v[kAo])) * fc;
            fields[kAe][idx] = fields[kAe][idx] + (a - float(mv.v[kAe])) * fc;
          }
          if (vs.uniaxial && cov >= 0.5) axis[idx] = glm::vec4(ax, 0.0f);
        }
    });
    progress(0.4 * double(oi + 1) / double(scene.objects.size()), "voxelising");
  }

  // Smooth every field that is not constant.
  const double sigma = scene.volume.smoothing_voxels;
  for (int f = 0; f < kFieldCount; ++f) {
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
    for (int c = 0; c < 3; ++c) vs.index[size_t(m)][size_t(c)] = withGradient(fields[size_t(m == 0 ? kAo + c : kAe + c)]);
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
    vs.axis = std::move(axis);
  }
  vs.emission = pack(kEr, kEg, kEb, -1);

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
  }
  for (size_t i = 0; i < N; ++i) vs.emission[i].w = float(dist[i]);
  progress(1.0, "done");
  return vs;
}

}  // namespace eikon
