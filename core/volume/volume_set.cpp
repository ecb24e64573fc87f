#include "core/volume/volume_set.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <variant>

#include "core/volume/host_memory.h"
#include "core/volume/skip_distance.h"

namespace eikon {
namespace {

// Scalar fields composited per voxel before smoothing.
enum Field : int {
  kAo,
  kBo,
  kCo,
  kAe,
  kBe,
  kCe,  // Cauchy coefficients, o and e
  kSor,
  kSog,
  kSob,
  kOpacity,  // attenuation o (band values), opacity
  kSer,
  kSeg,
  kSeb,  // attenuation e
  kEr,
  kEg,
  kEb,  // emission
  kAlr,
  kAlg,
  kAlb,
  kPhaseG,  // scattering albedo (or diffuse reflectance), HG asymmetry
  kFieldCount
};

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
  texels +=
      emission.size() + axis.size() + scatter.size() + light_fluence.size() + light_flux.size();
  // The boundary field (core/render/boundary_device.h): a 32-bit region id and a float distance
  // per voxel, the shape table (6 vec4 per shape, one per convex plane) and the medium table.
  size_t shape_entries = 6 * boundary.shapes.size();
  for (const Shape& s : boundary.shapes)
    if (const auto* c = std::get_if<ConvexShape>(&s.geometry())) shape_entries += c->planes.size();
  return texels * sizeof(glm::vec4) + boundary.region.size() * sizeof(uint32_t) +
         boundary.distance.size() * sizeof(float) + shape_entries * sizeof(glm::vec4) +
         packMediaTable(media).size() * sizeof(float);
}

void gaussianSmooth(std::vector<float>& f, const std::array<int, 3>& dims, double sigma,
                    int threads) {
  if (sigma <= 0.0) return;
  const int r = int(std::ceil(3.0 * sigma));
  std::vector<float> w(size_t(2 * r + 1));
  double sum = 0.0;
  for (int k = -r; k <= r; ++k) sum += std::exp(-0.5 * k * k / (sigma * sigma));
  for (int k = -r; k <= r; ++k)
    w[size_t(k + r)] = float(std::exp(-0.5 * k * k / (sigma * sigma)) / sum);
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
        if (axis == 0)
          base = (size_t(o) * ny + in) * nx;
        else if (axis == 1)
          base = size_t(o) * nx * ny + in;
        else
          base = size_t(o) * nx + in;
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
  const bool uniaxial = scene.anyUniaxial() || scene.anyBiaxial();  // two modes
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
  const double bytes = per_voxel * double(g.dims[0]) * double(g.dims[1]) * double(g.dims[2]);
  return bytes + (scene.interfaces == Scene::Interfaces::Sharp ? boundaryHostBytes(g) : 0.0);
}

namespace {

// Progress reports, from any thread: one at a time, and skipped rather than waited for when
// another thread is reporting. The fraction is computed under the lock (a callable), so that
// counts read there make the reported fractions non-decreasing.
class ProgressSink {
 public:
  explicit ProgressSink(const std::function<void(double, const char*)>& f) : f_(f) {}
  void operator()(double x, const char* stage) {
    report([x] { return x; }, stage);
  }
  template <typename F>
  void report(F&& fraction, const char* stage) {
    if (!f_) return;
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (lock.owns_lock()) f_(fraction(), stage);
  }

 private:
  const std::function<void(double, const char*)>& f_;
  std::mutex mutex_;
};

// The grid of the scene, refused (SceneError) when its voxel count or the host memory the
// voxeliser needs for it is too large.
Grid checkedGrid(const Scene& scene) {
  const Grid g = makeGrid(scene.volume);
  const std::string dims = std::to_string(g.dims[0]) + "x" + std::to_string(g.dims[1]) + "x" +
                           std::to_string(g.dims[2]) + " voxels";
  if (double(g.dims[0]) * g.dims[1] * g.dims[2] > double(1u << 31))
    throw SceneError(scene.file.string() + ": /volume/resolution: " + dims + " is too many");
  const double need = voxelizeHostBytes(scene, g);
  const HostMemory mem = availableHostMemory();
  if (need > double(mem.available))
    throw SceneError(scene.file.string() + ": /volume/resolution: voxelising " + dims + " needs " +
                     formatBytes(need) + " of host memory, " + formatBytes(double(mem.available)) +
                     " available (" + mem.limited_by + "); lower the resolution");
  return g;
}

// Per-material constant values (GRIN materials override A per voxel); sets the VolumeSet's
// flags (dispersive, attenuating, emissive, opaque, scattering).
std::map<std::string, MaterialValues> materialValues(const Scene& scene, VolumeSet& vs) {
  std::map<std::string, MaterialValues> values;
  auto bands = [](const Attenuation& a) {
    return glm::dvec3(a.at(612.0), a.at(549.0), a.at(465.0));
  };
  for (const auto& [name, m] : scene.materials) {
    MaterialValues mv{};
    // A biaxial crystal's fields (which its sharp march does not read) carry n_α and n_γ.
    const Dispersion &no = m.biaxial ? m.n_alpha : m.n_o, &ne = m.biaxial ? m.n_gamma : m.n_e;
    auto co = no.cauchyApproximation(380.0, 780.0), ce = ne.cauchyApproximation(380.0, 780.0);
    for (int c = 0; c < 3; ++c) {
      mv.v[kAo + c] = float(co.coeffs[size_t(c)]);
      mv.v[kAe + c] = float(ce.coeffs[size_t(c)]);
    }
    glm::dvec3 so = bands(m.biaxial ? m.attenuation_alpha : m.attenuation_o),
               se = bands(m.biaxial ? m.attenuation_gamma : m.attenuation_e);
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
    // Any attenuation, at the band points or anywhere in a spectrum (σ_β of a biaxial crystal,
    // a narrow band between the band points), makes the scene attenuating.
    for (const Attenuation* a : {&m.attenuation_o, &m.attenuation_e, &m.attenuation_alpha,
                                 &m.attenuation_beta, &m.attenuation_gamma})
      if (!a->isZero()) vs.attenuating = true;
    for (int f : {kEr, kEg, kEb})
      if (mv.v[f] != 0) vs.emissive = true;
    if (mv.v[kOpacity] != 0) vs.opaque = true;
    for (int f : {kAlr, kAlg, kAlb})
      if (mv.v[f] != 0) vs.scattering = true;
  }
  return values;
}

// How an object's indicator becomes a coverage in [0, 1]. Analytic smoothing: the indicator
// blurred across the surface by the triweight kernel K(u) = 35/32 (1 − u²)³ on |u| ≤ 1 scaled to
// half-width 3σ (variance σ², the same as a Gaussian of σ, but compact so that the fields are
// exactly constant 3σ from every surface): coverage = F(−sd/3σ) with F the kernel's CDF, sd the
// signed distance (exact for planes and spheres). A flat face is then smoothed exactly along its
// normal, with no staircase. Otherwise 4³ supersampled coverage where the surface crosses a voxel
// (later Gaussian-smoothed as a field when σ > 0).
struct CoverageRule {
  bool analytic = false;
  double half_width = 0.0;  ///< 3σ·h (mm), analytic only
  double half_diag = 0.0;   ///< half a voxel's diagonal (mm)
  int margin = 1;           ///< voxels beyond an object's bounds that it may reach

  CoverageRule(const VolumeSpec& spec, double h) {
    const double sigma = spec.smoothing_voxels;
    analytic = sigma > 0 && spec.smoothing == VolumeSpec::Smoothing::Analytic;
    half_width = 3.0 * sigma * h;
    half_diag = 0.5 * std::sqrt(3.0) * h;
    margin = 1 + (analytic ? int(std::ceil(3.0 * sigma)) : 0);
  }

  static double triweightCdf(double u) {
    if (u <= -1.0) return 0.0;
    if (u >= 1.0) return 1.0;
    double u2 = u * u;
    return 0.5 + 35.0 / 32.0 * u * (1.0 - u2 + 0.6 * u2 * u2 - u2 * u2 * u2 / 7.0);
  }
  static double triweight(double u) {
    if (u <= -1.0 || u >= 1.0) return 0.0;
    double v = 1.0 - u * u;
    return 35.0 / 32.0 * v * v * v;
  }

  /// Coverage of the voxel centred at c (≤ 0: the object does not reach it) and, analytic only,
  /// its exact gradient in *gcov.
  double operator()(const Shape& shape, const glm::dvec3& c, double h, glm::dvec3* gcov) const {
    const double sd = shape.signedDistance(c);
    if (analytic) {
      if (sd >= half_width) return 0.0;
      *gcov = -triweight(-sd / half_width) / half_width * shape.distanceGradient(c);
      return triweightCdf(-sd / half_width);
    }
    if (sd > half_diag) return 0.0;
    if (sd < -half_diag) return 1.0;
    int inside = 0;
    for (int s = 0; s < 64; ++s) {
      glm::dvec3 off((s & 3) + 0.5, ((s >> 2) & 3) + 0.5, (s >> 4) + 0.5);
      if (shape.contains(c + (off / 4.0 - 0.5) * h)) ++inside;
    }
    return inside / 64.0;
  }
};

// The composited fields: kFieldCount scalar fields, the exact gradients of the six index
// coefficients (analytic smoothing only) and the optic axis texels (uniaxial scenes only).
struct Composite {
  std::vector<std::vector<float>> fields;
  std::vector<std::vector<glm::vec3>> gradients;
  std::vector<glm::vec4> axis;
};

// A field that starts at 0 and that no material paints with anything but +0 stays +0 in every
// voxel, its exact gradient too (v(1 − c) + 0·c = +0, and the gradient's update ends by adding
// +0, which turns a −0 into +0): it is not made, and reads as +0 (fieldAt).
bool staysZero(int f, const std::map<std::string, MaterialValues>& values) {
  if (f == kAo || f == kAe) return false;  // starts at the ambient index
  for (const auto& [name, mv] : values)
    if (mv.v[f] != 0.0f || std::signbit(mv.v[f])) return false;
  return true;
}

// The composited fields at their initial values (the ambient index, zeros), all but those that
// stay +0 (staysZero) and, in an isotropic scene, the e-mode fields: every material's n_e and
// attenuation_e are its n_o and attenuation_o (core/scene), so they would be bitwise copies of
// the o-mode fields (painted with the same values and coverages, and not smoothed: smoothFields
// leaves them), which add nothing to the skip distances and are never packed; nor are their
// gradients. The Gaussian method keeps them: there the o-mode fields are smoothed and the copies
// are not. Fewer arrays: voxelising was mostly the kernel handing out their pages.
Composite allocateComposite(const Scene& scene, const Grid& g, const CoverageRule& rule,
                            bool uniaxial, const std::map<std::string, MaterialValues>& values) {
  const bool e_copies =
      !uniaxial && (rule.analytic || scene.volume.smoothing_voxels <= 0.0);  // not made
  Composite cp;
  cp.fields.resize(kFieldCount);
  if (rule.analytic) cp.gradients.resize(6);
  for (int f = 0; f < kFieldCount; ++f) {
    const bool e_field = (f >= kAe && f <= kCe) || (f >= kSer && f <= kSeb);
    if ((e_field && e_copies) || staysZero(f, values)) continue;
    cp.fields[size_t(f)].assign(g.count(),
                                f == kAo || f == kAe ? float(scene.ambient_index) : 0.0f);
    if (rule.analytic && f < 6) cp.gradients[size_t(f)].assign(g.count(), glm::vec3(0.0f));
  }
  if (uniaxial) cp.axis.assign(g.count(), glm::vec4(0.0f));
  return cp;
}

float fieldAt(const Composite& cp, int f, size_t i) {
  const auto& fld = cp.fields[size_t(f)];
  return fld.empty() ? 0.0f : fld[i];
}

// One object's material painted over a voxel with coverage cov: v ← v(1 − c) + p c, and, with
// exact gradients, ∇[v(1 − c) + p c] = ∇v (1 − c) + (p − v)∇c + c∇p.
void paintVoxel(Composite& cp, size_t idx, const glm::dvec3& c, double cov, const glm::dvec3& gcov,
                const Material& mat, const MaterialValues& mv) {
  const float fc = float(cov);
  // Property values here (GRIN materials vary A in space).
  float prop[kFieldCount];
  for (int f = 0; f < kFieldCount; ++f) prop[f] = mv.v[f];
  glm::dvec3 gprop(0.0);
  if (mat.grin.type != GrinProfile::Type::None) {
    prop[kAo] = prop[kAe] = float(mat.grin.index(c));
    gprop = mat.grin.indexGradient(c);
  }
  if (!cp.gradients.empty())
    for (int f = 0; f < 6; ++f) {
      if (cp.gradients[size_t(f)].empty()) continue;  // the e-mode's, in an isotropic scene
      glm::dvec3 gv = glm::dvec3(cp.gradients[size_t(f)][idx]) * (1.0 - cov) +
                      (double(prop[f]) - cp.fields[size_t(f)][idx]) * gcov +
                      ((f == kAo || f == kAe) ? cov * gprop : glm::dvec3(0.0));
      cp.gradients[size_t(f)][idx] = glm::vec3(gv);
    }
  for (int f = 0; f < kFieldCount; ++f)
    if (!cp.fields[size_t(f)].empty())
      cp.fields[size_t(f)][idx] = cp.fields[size_t(f)][idx] * (1 - fc) + prop[f] * fc;
}

// Axis texel of an object: (a, 0) for a uniform axis; (centre, −1) for a radial field, evaluated
// exactly by the marchers as a(x) = (x − centre)/|x − centre| (so dilation copies stay exact).
glm::vec4 axisTexel(const SceneObject& obj, const Material& mat) {
  if (mat.uniaxial && obj.radial_axis) return glm::vec4(glm::vec3(obj.shape.center()), -1.0f);
  if (mat.uniaxial)
    return glm::vec4(glm::vec3(obj.optic_axis ? *obj.optic_axis : *mat.optic_axis), 0.0f);
  return glm::vec4(0.0f);
}

// Paint every object, in scene order, over the fields (progress 0 to 0.4, per z slab: a large
// object alone takes seconds at 256³).
void compositeObjects(const Scene& scene, const Grid& g,
                      const std::map<std::string, MaterialValues>& values, const CoverageRule& rule,
                      bool uniaxial, Composite& cp, ProgressSink& progress, int threads) {
  const double n_obj = double(scene.objects.size());
  for (size_t oi = 0; oi < scene.objects.size(); ++oi) {
    const SceneObject& obj = scene.objects[oi];
    const Material& mat = scene.materials.at(obj.material);
    const MaterialValues& mv = values.at(obj.material);
    const glm::vec4 ax = axisTexel(obj, mat);
    auto [bmin, bmax] = obj.shape.bounds();
    int lo[3], hi[3];
    if (!voxelRange(bmin, bmax, g, rule.margin, lo, hi)) {  // wholly outside the grid
      progress(0.4 * double(oi + 1) / n_obj, "voxelising");
      continue;
    }
    const int slabs = voxelBlockSlabs(lo, hi);
    std::atomic<int> slabs_done{0};
    // In blocks (grid.h forVoxelBlocks): a block whose voxels all lie beyond the rule's reach
    // outside the shape gets no paint, as each voxel would (its coverage is 0); one wholly
    // beyond it inside is painted with coverage 1 and a zero coverage gradient, as each voxel
    // would be (up to the sign of a zero). One signed distance per such block.
    const double reach = rule.analytic ? rule.half_width : rule.half_diag;
    parallelFor(slabs, threads, [&](int slab) {
      auto paint = [&](int i, int j, int k, double cov, const glm::dvec3& gcov) {
        const size_t idx = g.index(i, j, k);
        paintVoxel(cp, idx, g.center(i, j, k), cov, gcov, mat, mv);
        if (uniaxial && mat.uniaxial) cp.axis[idx] = ax;
      };
      forVoxelBlocks(
          g, lo, hi, slab,
          [&](const VoxelBlock& b) {
            const double sd = obj.shape.signedDistance(b.centre);
            if (sd - b.radius >= reach && (rule.analytic || sd - b.radius > reach)) return true;
            if (!(sd + b.radius < -reach)) return false;
            for (int k = b.lo[2]; k <= b.hi[2]; ++k)
              for (int j = b.lo[1]; j <= b.hi[1]; ++j)
                for (int i = b.lo[0]; i <= b.hi[0]; ++i) paint(i, j, k, 1.0, glm::dvec3(0.0));
            return true;
          },
          [&](int i, int j, int k) {
            glm::dvec3 gcov(0.0);
            const double cov = rule(obj.shape, g.center(i, j, k), g.h, &gcov);
            if (cov > 0.0) paint(i, j, k, cov, gcov);
          });
      ++slabs_done;
      progress.report(
          [&] { return 0.4 * (double(oi) + double(slabs_done.load()) / slabs) / n_obj; },
          "voxelising");
    });
    progress(0.4 * double(oi + 1) / n_obj, "voxelising");
  }
}

// Gaussian method: smooth every field that is not constant (progress 0.4 to 0.7).
void smoothFields(Composite& cp, const Grid& g, double sigma, bool uniaxial, ProgressSink& progress,
                  int threads) {
  for (int f = 0; f < kFieldCount; ++f) {
    if (!uniaxial && (f == kAe || f == kBe || f == kCe || f == kSer || f == kSeg || f == kSeb))
      continue;
    auto& fld = cp.fields[size_t(f)];
    if (!fld.empty()) {  // one that stays +0 is not made
      auto [mn, mx] = std::minmax_element(fld.begin(), fld.end());
      if (*mn != *mx) gaussianSmooth(fld, g.dims, sigma, threads);
    }
    progress(0.4 + 0.3 * (f + 1) / double(kFieldCount), "smoothing");
  }
}

// (f, ∇f) texels with ∇f by central differences (one-sided at the grid faces).
std::vector<glm::vec4> withCentralDifferences(const std::vector<float>& f, const Grid& g,
                                              int threads) {
  std::vector<glm::vec4> out(g.count());
  parallelFor(g.dims[2], threads, [&](int k) {
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
            t[a + 1] = float((double(f[g.index(hi_c[0], hi_c[1], hi_c[2])]) -
                              f[g.index(lo_c[0], lo_c[1], lo_c[2])]) /
                             (span * g.h));
        }
        out[g.index(i, j, k)] = t;
      }
  });
  return out;
}

// The index volumes (coefficient, gradient) per mode (progress 0.7 to 0.85).
void indexVolumes(const Composite& cp, const Grid& g, bool analytic, VolumeSet& vs,
                  ProgressSink& progress, int threads) {
  const size_t N = g.count();
  for (int m = 0; m < (vs.uniaxial ? 2 : 1); ++m)
    for (int c = 0; c < 3; ++c) {
      int f = m == 0 ? kAo + c : kAe + c;
      if (cp.fields[size_t(f)].empty()) {  // stays +0, its gradient too
        vs.index[size_t(m)][size_t(c)].assign(N, glm::vec4(0.0f));
      } else if (analytic) {
        std::vector<glm::vec4> out(N);
        const auto& fld = cp.fields[size_t(f)];
        const auto& grad = cp.gradients[size_t(f)];
        parallelFor(g.dims[2], threads, [&](int k) {
          for (size_t i = g.index(0, 0, k), end = g.index(0, 0, k + 1); i < end; ++i)
            out[i] = glm::vec4(fld[i], grad[i]);
        });
        vs.index[size_t(m)][size_t(c)] = std::move(out);
      } else {
        vs.index[size_t(m)][size_t(c)] = withCentralDifferences(cp.fields[size_t(f)], g, threads);
      }
      progress(0.7 + 0.15 * double(m * 3 + c + 1) / (vs.uniaxial ? 6.0 : 3.0), "gradients");
    }
  progress(0.85, "gradients");
}

// Four fields as vec4 texels (d < 0: w = 0).
std::vector<glm::vec4> pack(const Composite& cp, const Grid& g, int a, int b, int c, int d,
                            int threads) {
  std::vector<glm::vec4> out(g.count());
  parallelFor(g.dims[2], threads, [&](int k) {
    for (size_t i = g.index(0, 0, k), end = g.index(0, 0, k + 1); i < end; ++i)
      out[i] = glm::vec4(fieldAt(cp, a, i), fieldAt(cp, b, i), fieldAt(cp, c, i),
                         d >= 0 ? fieldAt(cp, d, i) : 0.0f);
  });
  return out;
}

// Dilate the optic axis over the smoothing reach so every voxel where n_o ≠ n_e (the smoothed
// crystal surface) knows the axis; elsewhere n_o = n_e and the axis is irrelevant (progress 0.85
// to 0.9).
void dilateAxis(std::vector<glm::vec4>& axis, const Grid& g, double sigma, ProgressSink& progress,
                int threads) {
  const int reach = int(std::ceil(3.0 * sigma)) + 2;
  for (int pass = 0; pass < reach; ++pass) {
    std::vector<glm::vec4> next = axis;
    parallelFor(g.dims[2], threads, [&](int k) {
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
}

// Active voxels (distance 0): any field differs from a 26-neighbour (core/volume/skip_distance.h),
// or a radial axis field (it varies everywhere inside its crystal: never straight-step there).
// Others get `cap`.
std::vector<uint8_t> skipSeeds(const Composite& cp, const Grid& g,
                               const std::vector<glm::vec4>& axis, int cap, int threads) {
  std::vector<const std::vector<float>*> used;  // a constant field makes no voxel active
  for (int f = 0; f < kFieldCount; ++f) {
    if (cp.fields[size_t(f)].empty()) continue;  // stays +0, or a copy (allocateComposite)
    auto [mn, mx] = std::minmax_element(cp.fields[size_t(f)].begin(), cp.fields[size_t(f)].end());
    if (*mn != *mx) used.push_back(&cp.fields[size_t(f)]);
  }
  std::vector<uint8_t> dist = activeVoxels(used, g, threads);
  parallelFor(g.dims[2], threads, [&](int k) {
    const size_t begin = g.index(0, 0, k), end = begin + size_t(g.dims[0]) * g.dims[1];
    for (size_t i = begin; i < end; ++i) {
      const bool active = dist[i] || (!axis.empty() && axis[i].w < -0.5f);
      dist[i] = active ? 0 : uint8_t(cap);
    }
  });
  return dist;
}

}  // namespace

VolumeSet voxelize(const Scene& scene, const VoxelizeOptions& opt) {
  ProgressSink progress(opt.progress);
  VolumeSet vs;
  vs.grid = checkedGrid(scene);
  const Grid& g = vs.grid;
  const size_t N = g.count();
  vs.uniaxial = scene.anyUniaxial() || scene.anyBiaxial();  // two modes
  vs.ambient_index = scene.ambient_index;
  const std::map<std::string, MaterialValues> values = materialValues(scene, vs);

  const CoverageRule rule(scene.volume, g.h);
  Composite cp = allocateComposite(scene, g, rule, vs.uniaxial, values);
  // Analytic smoothing carries exact gradients of the index fields through the compositing
  // (∇ of the smoothed indicator = −F′·∇sd/3σ, along the face normal), so a flat face bends rays
  // exactly along its normal whatever its orientation to the grid. Central differences of the
  // sampled profile would not: their components are attenuated unequally for oblique faces, which
  // biased the prism deviation by −0.15° independently of resolution (docs/view-renderer.md).
  compositeObjects(scene, g, values, rule, vs.uniaxial, cp, progress, opt.threads);

  const double sigma = scene.volume.smoothing_voxels;
  if (!rule.analytic) smoothFields(cp, g, sigma, vs.uniaxial, progress, opt.threads);
  indexVolumes(cp, g, rule.analytic, vs, progress, opt.threads);
  cp.gradients.clear();

  vs.medium[0] = pack(cp, g, kSor, kSog, kSob, kOpacity, opt.threads);
  if (vs.uniaxial) {
    vs.medium[1] = pack(cp, g, kSer, kSeg, kSeb, kOpacity, opt.threads);
    dilateAxis(cp.axis, g, sigma, progress, opt.threads);
    vs.axis = std::move(cp.axis);
  }
  vs.emission = pack(cp, g, kEr, kEg, kEb, -1, opt.threads);
  if (vs.scattering) vs.scatter = pack(cp, g, kAlr, kAlg, kAlb, kPhaseG, opt.threads);

  std::vector<uint8_t> dist = skipSeeds(cp, g, vs.axis, vs.skip_cap, opt.threads);
  // The separable L∞ distance transform (progress 0.9 to 0.99).
  chebyshevTransform(dist, g, opt.threads,
                     [&](int a) { progress(0.9 + 0.03 * (a + 1), "skip distances"); });
  for (size_t i = 0; i < N; ++i) vs.emission[i].w = float(dist[i]);
  // The sharp-boundary field (core/volume/boundary.h), unless the scene asks for smoothed
  // interfaces only.
  if (scene.interfaces == Scene::Interfaces::Sharp) {
    cp.fields.clear();
    progress(0.99, "boundaries");
    vs.boundary = buildBoundaryField(scene, g, opt.threads);
    vs.media = buildMediaTable(scene);
  }
  progress(1.0, "done");
  return vs;
}

VolumeSet voxelizeInterfaces(const Scene& scene, const VoxelizeOptions& opt) {
  if (scene.interfaces != Scene::Interfaces::Sharp)
    throw std::invalid_argument("voxelizeInterfaces: the scene's interfaces are smoothed");
  VolumeSet vs;
  vs.grid = checkedGrid(scene);
  vs.uniaxial = scene.anyUniaxial() || scene.anyBiaxial();  // two modes
  vs.ambient_index = scene.ambient_index;
  (void)materialValues(scene, vs);  // the flags
  // Where every crossing and region comes from the shapes (the exact path; convex planes apart)
  // the field's per-voxel arrays are left out too (BoundaryField::hasVoxels), else they are made
  // as voxelize() does.
  vs.boundary = boundaryFieldShapes(scene, vs.grid);
  if (!vs.boundary.regionsOnShapes()) vs.boundary = buildBoundaryField(scene, vs.grid, opt.threads);
  vs.media = buildMediaTable(scene);
  vs.fields = false;
  return vs;
}

}  // namespace eikon
