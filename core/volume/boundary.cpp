#include "core/volume/boundary.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/scene/limits.h"
#include "core/scene/mesh.h"
#include "core/scene/scene.h"

namespace eikon {
namespace {

constexpr size_t kMaxRegions = kMaxSharpObjects;  // region ids are 16-bit; 0 is the ambient

// The trilinear cell around a point given in voxel coordinates u (voxel centres at integers):
// its 8 corners (bit 0: +x, bit 1: +y, bit 2: +z) and, per axis, the lower corner and the
// fraction. Beyond the outermost centres the fraction is clamped (clamp to edge), so the field is
// constant along that axis there.
struct Cell {
  std::array<size_t, 8> idx{};
  glm::ivec3 lo{0};
  glm::dvec3 f{0.0};
  glm::bvec3 clamped{false};
};

Cell cellAt(const Grid& g, const glm::dvec3& u) {
  Cell c;
  glm::ivec3 hi(0);
  for (int a = 0; a < 3; ++a) {
    const int n = g.dims[size_t(a)];
    if (n == 1 || u[a] <= 0.0) {
      c.lo[a] = 0;
      c.f[a] = 0.0;
      c.clamped[a] = true;
    } else if (u[a] >= n - 1) {
      c.lo[a] = n - 2;
      c.f[a] = 1.0;
      c.clamped[a] = true;
    } else {
      c.lo[a] = std::min(int(std::floor(u[a])), n - 2);
      c.f[a] = u[a] - c.lo[a];
    }
    hi[a] = std::min(c.lo[a] + 1, n - 1);
  }
  for (int k = 0; k < 8; ++k)
    c.idx[size_t(k)] = g.index(k & 1 ? hi.x : c.lo.x, k & 2 ? hi.y : c.lo.y, k & 4 ? hi.z : c.lo.z);
  return c;
}

// φ_r at the cell's point (voxels) and its gradient in voxel coordinates (= ∂φ_mm/∂x_mm).
double cellPhi(const BoundaryField& bf, const Cell& c, int r, glm::dvec3* grad) {
  double phi = 0.0;
  glm::dvec3 gr(0.0);
  for (int k = 0; k < 8; ++k) {
    const size_t i = c.idx[size_t(k)];
    const double v = bf.region[i] == r ? double(bf.distance[i]) : -double(bf.distance[i]);
    glm::dvec3 w, dw;
    for (int a = 0; a < 3; ++a) {
      const bool up = (k >> a) & 1;
      w[a] = up ? c.f[a] : 1.0 - c.f[a];
      dw[a] = c.clamped[a] ? 0.0 : (up ? 1.0 : -1.0);
    }
    phi += v * w.x * w.y * w.z;
    gr += v * glm::dvec3(dw.x * w.y * w.z, w.x * dw.y * w.z, w.x * w.y * dw.z);
  }
  if (grad) *grad = gr;
  return phi;
}

glm::dvec3 toVoxel(const Grid& g, const glm::dvec3& x) { return (x - g.origin) / g.h - 0.5; }

// The regions of a cell's corners, `exclude` left out, each once.
std::vector<int> cellRegions(const BoundaryField& bf, const Cell& c, int exclude) {
  std::vector<int> out;
  for (size_t i : c.idx) {
    const int r = bf.region[i];
    if (r != exclude && std::find(out.begin(), out.end(), r) == out.end()) out.push_back(r);
  }
  return out;
}

// φ_r along u(t) = ua + t·du inside one cell: a cubic, coefficients of t⁰…t³.
std::array<double, 4> cellCubic(const BoundaryField& bf, const Cell& c, int r, const glm::dvec3& ua,
                                const glm::dvec3& du) {
  std::array<double, 4> sum{};
  for (int k = 0; k < 8; ++k) {
    const size_t i = c.idx[size_t(k)];
    const double v = bf.region[i] == r ? double(bf.distance[i]) : -double(bf.distance[i]);
    std::array<double, 4> p{v, 0.0, 0.0, 0.0};
    for (int a = 0; a < 3; ++a) {
      // Fraction along axis a: f = p0 + p1·t (constant where clamped).
      const double p0 = c.clamped[a] ? c.f[a] : ua[a] - c.lo[a], p1 = c.clamped[a] ? 0.0 : du[a];
      const bool up = (k >> a) & 1;
      const double al = up ? p0 : 1.0 - p0, be = up ? p1 : -p1;
      for (int d = 3; d >= 0; --d)
        p[size_t(d)] = p[size_t(d)] * al + (d > 0 ? p[size_t(d - 1)] * be : 0.0);
    }
    for (size_t d = 0; d < 4; ++d) sum[d] += p[d];
  }
  return sum;
}

double cubicAt(const std::array<double, 4>& p, double t) {
  return ((p[3] * t + p[2]) * t + p[1]) * t + p[0];
}

// The first t in [t0, t1] where the cubic turns negative, bisected to `tol`; −1 if none. The
// interval is split at the cubic's turning points so that each piece is monotone.
double firstNegative(const std::array<double, 4>& p, double t0, double t1, double tol) {
  std::vector<double> s{t0};
  const double A = 3 * p[3], B = 2 * p[2], C = p[1];
  if (A != 0.0) {
    const double disc = B * B - 4 * A * C;
    if (disc >= 0) {
      const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
      for (double r : {q / A, q != 0.0 ? C / q : t0})
        if (r > t0 && r < t1) s.push_back(r);
    }
  } else if (B != 0.0 && -C / B > t0 && -C / B < t1) {
    s.push_back(-C / B);
  }
  std::sort(s.begin() + 1, s.end());
  s.push_back(t1);
  if (cubicAt(p, t0) < 0.0) return t0;
  for (size_t k = 1; k < s.size(); ++k) {
    double lo = s[k - 1], hi = s[k];
    if (cubicAt(p, hi) >= 0.0) continue;
    for (int it = 0; it < 200 && hi - lo > tol; ++it) {
      const double mid = 0.5 * (lo + hi);
      (cubicAt(p, mid) >= 0.0 ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }
  return -1.0;
}

// The cell boundaries (and clamp planes) the segment ua + t·du, t ∈ [0, 1], crosses, with 0, 1.
std::vector<double> cellBreaks(const Grid& g, const glm::dvec3& ua, const glm::dvec3& du) {
  std::vector<double> ts{0.0, 1.0};
  for (int a = 0; a < 3; ++a) {
    if (du[a] == 0.0) continue;
    const double u0 = std::min(ua[a], ua[a] + du[a]), u1 = std::max(ua[a], ua[a] + du[a]);
    const double m0 = std::max(std::ceil(u0), 0.0),
                 m1 = std::min(std::floor(u1), double(g.dims[size_t(a)] - 1));
    for (double m = m0; m <= m1; m += 1.0) {
      const double t = (m - ua[a]) / du[a];
      if (t > 0.0 && t < 1.0) ts.push_back(t);
    }
  }
  std::sort(ts.begin(), ts.end());
  return ts;
}

// Refine a crossing on the owner's exact signed distance: the nearest sign change to the field's
// t, bracketed in brackets widening from 0.05 to 3.2 voxels. False if none is found.
bool refineOnShape(const Shape& s, bool leaving_owner, const glm::dvec3& a, const glm::dvec3& b,
                   double len_vox, double& t) {
  auto outside = [&](double x) { return s.signedDistance(a + x * (b - a)) > 0.0; };
  for (double w = 0.05; w <= 3.2; w *= 4.0) {
    double lo = std::max(0.0, t - w / len_vox), hi = std::min(1.0, t + w / len_vox);
    // Leaving the owner: inside (sd ≤ 0) at lo, outside at hi; entering it: the reverse.
    if (outside(lo) == leaving_owner || outside(hi) != leaving_owner) continue;
    for (int it = 0; it < 200 && (hi - lo) * len_vox > 1e-12; ++it) {
      const double mid = 0.5 * (lo + hi);
      (outside(mid) != leaving_owner ? lo : hi) = mid;
    }
    t = 0.5 * (lo + hi);
    return true;
  }
  return false;
}

/// The line a + t·d (world) in shape s's local frame: {origin, direction}, t unchanged.
std::pair<glm::dvec3, glm::dvec3> localLine(const Shape& s, const glm::dvec3& a,
                                            const glm::dvec3& d) {
  const glm::dmat3 to_local = glm::transpose(s.rotation());
  return {to_local * (a - s.center()), to_local * d};
}

// A crossing of a mesh's surface: the first exact ray–triangle hit (MeshDistance::firstHit) of
// the right orientation (a triangle facing along the segment when leaving the mesh, against it
// when entering) within kMeshBracketVoxels of the field's t, with its triangle's plane normal:
// the facet refracts at its own plane. False (the field's zero and normal stand, as on the GPU,
// which has no signed distance of a mesh to refine on) if there is none.
bool meshCrossing(const Shape& s, const MeshShape& m, bool leaving_owner, const glm::dvec3& a,
                  const glm::dvec3& b, double len_vox, BoundaryCrossing& out) {
  const auto [o, d] = localLine(s, a, b - a);
  const double w = kMeshBracketVoxels / len_vox;
  const MeshDistance::Hit hit = m.distance->firstHit(
      o, d, std::max(0.0, out.t - w), std::min(1.0, out.t + w), leaving_owner ? 1 : -1);
  if (!hit.found) return false;
  out.t = hit.t;
  out.point = a + hit.t * (b - a);
  out.normal = (leaving_owner ? 1.0 : -1.0) * (s.rotation() * hit.normal);
  out.face = hit.face;
  return true;
}

}  // namespace

double boundaryHostBytes(const Grid& g) {
  return (sizeof(float) + sizeof(uint16_t)) * double(g.dims[0]) * double(g.dims[1]) *
         double(g.dims[2]);
}

BoundaryField boundaryFieldShapes(const Scene& scene, const Grid& g) {
  if (scene.objects.size() > kMaxRegions)
    throw SceneError(scene.file.string() + ": /objects: sharp interfaces allow at most " +
                     std::to_string(kMaxRegions) + " objects, got " +
                     std::to_string(scene.objects.size()) +
                     " (or set \"interfaces\": \"smoothed\")");
  BoundaryField bf;
  bf.grid = g;
  std::map<std::string, int> material_ids;
  bf.media = {""};
  for (const auto& [name, m] : scene.materials) {
    material_ids.emplace(name, int(material_ids.size()) + 1);
    bf.media.push_back(name);
  }
  bf.medium = {0};
  for (const SceneObject& obj : scene.objects) {
    bf.shapes.push_back(obj.shape);
    bf.medium.push_back(material_ids.at(obj.material));
  }
  bf.convex_apart = convexShapesApart(bf.shapes, g.h);
  bf.exact = shapesTakeExactPath(bf.shapes, bf.convex_apart);
  return bf;
}

bool shapesTakeExactPath(const std::vector<Shape>& shapes, bool convex_apart) {
  // Every shape qualifies: the analytic ones by their clips, a mesh by its triangle hits. No shape
  // at all too: every point is the ambient region and no segment crosses anything, found without a
  // voxel (a walk through the voxels of an empty scene costs more than the sphere's clip).
  return !convex_apart && exactTableRows(shapes) <= kExactMaxRows;
}

BoundaryField buildBoundaryField(const Scene& scene, const Grid& g, int threads) {
  BoundaryField bf = boundaryFieldShapes(scene, g);
  bf.region.assign(g.count(), 0);
  bf.distance.assign(g.count(), bf.cap);
  // Objects in scene order, each painting over the earlier ones where it contains the centre (the
  // compositing's order). Inside object i the distance restarts at −sd_i; outside it, sd_i bounds
  // the distance to the region boundary it makes (the region r < i + 1 is cut by it).
  const int margin = int(std::ceil(bf.cap)) + 1;
  for (size_t oi = 0; oi < scene.objects.size(); ++oi) {
    const Shape& shape = scene.objects[oi].shape;
    auto [bmin, bmax] = shape.bounds();
    int lo[3], hi[3];
    if (!voxelRange(bmin, bmax, g, margin, lo, hi)) continue;
    // In blocks (grid.h forVoxelBlocks): a block wholly more than the cap outside the shape
    // changes nothing (its distances are at most the cap already), one wholly more than the cap
    // inside is the object's region at the cap; the others voxel by voxel. The signed distances
    // are 1-Lipschitz, so this is what the voxels would give, one distance per block where
    // it applies (a mesh's is a nearest-triangle search).
    parallelFor(voxelBlockSlabs(lo, hi), threads, [&](int slab) {
      forVoxelBlocks(
          g, lo, hi, slab,
          [&](const VoxelBlock& b) {
            const double s0 = shape.signedDistance(b.centre) / g.h, r = b.radius / g.h;
            if (s0 - r >= double(bf.cap)) return true;
            if (s0 + r > -double(bf.cap)) return false;
            for (int k = b.lo[2]; k <= b.hi[2]; ++k)
              for (int j = b.lo[1]; j <= b.hi[1]; ++j)
                for (int i = b.lo[0]; i <= b.hi[0]; ++i) {
                  const size_t idx = g.index(i, j, k);
                  bf.region[idx] = uint16_t(oi + 1);
                  bf.distance[idx] = bf.cap;
                }
            return true;
          },
          [&](int i, int j, int k) {
            const size_t idx = g.index(i, j, k);
            const double s = shape.signedDistance(g.center(i, j, k)) / g.h;
            if (s <= 0.0) {
              bf.region[idx] = uint16_t(oi + 1);
              bf.distance[idx] = float(std::min(-s, double(bf.cap)));
            } else {
              bf.distance[idx] = std::min(bf.distance[idx], float(std::min(s, double(bf.cap))));
            }
          });
    });
  }
  return bf;
}

double boundaryPhi(const BoundaryField& bf, const glm::dvec3& x, int region, glm::dvec3* gradient) {
  const Cell c = cellAt(bf.grid, toVoxel(bf.grid, x));
  return cellPhi(bf, c, region, gradient) * bf.grid.h;
}

int boundaryRegion(const BoundaryField& bf, const glm::dvec3& x) {
  const Cell c = cellAt(bf.grid, toVoxel(bf.grid, x));
  const std::vector<int> regions = cellRegions(bf, c, -1);
  int best = regions.front();
  double best_phi = -1e300;
  for (int r : regions) {
    const double phi = regions.size() == 1 ? 0.0 : cellPhi(bf, c, r, nullptr);
    if (phi > best_phi) best_phi = phi, best = r;
  }
  return best;
}

BoundaryCrossing locateCrossing(const BoundaryField& bf, const glm::dvec3& a, const glm::dvec3& b,
                                const LocateOptions& opt) {
  BoundaryCrossing out;
  const Grid& g = bf.grid;
  out.from = boundaryRegion(bf, a);
  const glm::dvec3 ua = toVoxel(g, a), du = toVoxel(g, b) - ua;
  const double len_vox = glm::length(du);
  if (!(len_vox > 0.0)) return out;
  const double tol = std::max(opt.tolerance_voxels, 1e-12) / len_vox;
  const std::vector<double> ts = cellBreaks(g, ua, du);
  for (size_t k = 1; k < ts.size(); ++k) {
    if (ts[k] <= ts[k - 1]) continue;
    const Cell c = cellAt(g, ua + 0.5 * (ts[k - 1] + ts[k]) * du);
    const std::vector<int> others = cellRegions(bf, c, out.from);
    if (others.empty()) continue;  // φ is a mean of positive distances: no zero in this cell
    const double t = firstNegative(cellCubic(bf, c, out.from, ua, du), ts[k - 1], ts[k], tol);
    if (t < 0.0) continue;
    // The region entered: of the others, the one with the largest φ just past the zero.
    const Cell past = cellAt(g, ua + std::min(t + tol, ts[k]) * du);
    double best = -1e300;
    for (int r : others) {
      const double phi = cellPhi(bf, past, r, nullptr);
      if (phi > best) best = phi, out.to = r;
    }
    out.found = true;
    out.t = t;
    break;
  }
  if (!out.found) return out;
  out.owner = std::max(out.from, out.to);
  out.from_medium = bf.medium[size_t(out.from)];
  out.to_medium = bf.medium[size_t(out.to)];
  glm::dvec3 grad;
  out.point = a + out.t * (b - a);
  cellPhi(bf, cellAt(g, toVoxel(g, out.point)), out.from, &grad);
  if (glm::length(grad) > 0.0) out.field_normal = -glm::normalize(grad);
  out.normal = out.field_normal;
  if (opt.analytic && out.owner >= 1) {
    const Shape& s = bf.shapes[size_t(out.owner - 1)];
    const bool leaving = out.from == out.owner;
    if (const auto* m = std::get_if<MeshShape>(&s.geometry())) {
      meshCrossing(s, *m, leaving, a, b, len_vox, out);  // else the field's answer, as the GPU
      return out;
    }
    if (refineOnShape(s, leaving, a, b, len_vox, out.t)) out.point = a + out.t * (b - a);
    const glm::dvec3 n = s.distanceGradient(out.point);
    if (glm::length(n) > 0.0) out.normal = (leaving ? 1.0 : -1.0) * glm::normalize(n);
  }
  return out;
}

BoundaryCrossing nextCrossingOutOf(
    const BoundaryField& field, const glm::dvec3& a, const glm::dvec3& b, int region,
    const std::function<void(const glm::dvec3&, const BoundaryCrossing&)>& on_locate) {
  const double total = glm::length(b - a), h = field.grid.h;
  if (!(total > 0.0)) return BoundaryCrossing{};
  const glm::dvec3 dir = (b - a) / total;
  glm::dvec3 start = a;
  for (int k = 0; k < 4; ++k) {
    BoundaryCrossing c = locateCrossing(field, start, b);
    if (on_locate) on_locate(start, c);
    if (!c.found) return c;
    const double along = glm::dot(c.point - a, dir);
    const bool sliver = c.from != region && c.to == region && along <= kSliverVoxels * h;
    if (!sliver) {
      c.t = std::clamp(along / total, 0.0, 1.0);
      c.from = region;
      return c;
    }
    start = a + (along + kNudgeVoxels * h) * dir;
    if (along + kNudgeVoxels * h >= total) return BoundaryCrossing{};
  }
  return BoundaryCrossing{};
}

}  // namespace eikon

namespace eikon {

// Boxes count as the convex polyhedra they are (localPlanes: six planes).
bool convexShapesApart(const std::vector<Shape>& shapes, double h) {
  if (shapes.empty()) return false;
  const double gap = kCrossingApartVoxels * h;
  for (size_t i = 0; i < shapes.size(); ++i) {
    if (!std::holds_alternative<ConvexShape>(shapes[i].geometry()) &&
        !std::holds_alternative<BoxShape>(shapes[i].geometry()))
      return false;
    const auto [amin, amax] = shapes[i].bounds();
    for (size_t j = 0; j < i; ++j) {
      const auto [bmin, bmax] = shapes[j].bounds();
      bool apart = false;
      for (int c = 0; c < 3; ++c)
        apart = apart || amin[c] > bmax[c] + gap || bmin[c] > amax[c] + gap;
      if (!apart) return false;
    }
  }
  return true;
}

namespace {

/// The parameters [t_in, t_out] of the line a + t·(b − a) inside a convex shape and the planes
/// that bound them (−1: none); t_in > t_out when the line misses it.
struct Slab {
  double t_in = -1e300, t_out = 1e300;
  int face_in = -1, face_out = -1;
};

/// The local planes of a convex polyhedron or a box (±x, ±y, ±z: boundary.glsl's order), without
/// a copy: a polyhedron's own, or a box's six in `box` (convexSlab runs per corner and step in the
/// light simulator's sharp path, where copying the planes was a fifth of its time).
struct LocalPlanes {
  const Plane* planes = nullptr;
  size_t count = 0;
  std::array<Plane, 6> box{};
  explicit LocalPlanes(const Shape& s) {
    if (const auto* c = std::get_if<ConvexShape>(&s.geometry())) {
      planes = c->planes.data(), count = c->planes.size();
      return;
    }
    const glm::dvec3 half = 0.5 * std::get<BoxShape>(s.geometry()).size;
    for (int a = 0; a < 3; ++a)
      for (int i = 0; i < 2; ++i) {
        glm::dvec3 n(0.0);
        n[a] = i == 0 ? -1.0 : 1.0;
        box[size_t(2 * a + i)] = {n, half[a]};
      }
    planes = box.data(), count = 6;
  }
  LocalPlanes(const LocalPlanes&) = delete;
  LocalPlanes& operator=(const LocalPlanes&) = delete;
};

Slab convexSlab(const Shape& s, const glm::dvec3& a, const glm::dvec3& b) {
  const LocalPlanes lp(s);
  const Plane* planes = lp.planes;
  const glm::dmat3 to_local = glm::transpose(s.rotation());
  const glm::dvec3 p = to_local * (a - s.center()), d = to_local * (b - a);
  Slab out;
  for (size_t k = 0; k < lp.count; ++k) {
    const double nd = glm::dot(planes[k].normal, d),
                 v = glm::dot(planes[k].normal, p) - planes[k].d;
    if (nd > 0.0) {
      if (-v / nd < out.t_out) out.t_out = -v / nd, out.face_out = int(k);
    } else if (nd < 0.0) {
      if (-v / nd > out.t_in) out.t_in = -v / nd, out.face_in = int(k);
    } else if (v > 0.0) {
      out.t_in = 1e300, out.t_out = -1e300;  // parallel to a plane, outside it
    }
  }
  return out;
}

}  // namespace

BoundaryCrossing convexCrossingOutOf(const BoundaryField& bf, const glm::dvec3& a,
                                     const glm::dvec3& b, int region) {
  BoundaryCrossing out;
  out.from = out.to = region;
  out.point = b;
  const double len_vox = glm::length(b - a) / bf.grid.h;
  if (!(len_vox > 0.0)) return out;
  const double graze = kGrazeVoxels / len_vox;
  int shape = -1, face = -1;
  double t = 1e300;
  if (region >= 1) {  // leaving the polyhedron: the first plane ahead
    const Slab sl = convexSlab(bf.shapes[size_t(region - 1)], a, b);
    if (sl.face_out < 0 || sl.t_out > 1.0) return out;
    shape = region - 1;
    face = sl.face_out;
    t = std::max(sl.t_out, 0.0);
    out.to = 0;
  } else {  // entering the nearest polyhedron the segment passes through
    for (size_t k = 0; k < bf.shapes.size(); ++k) {
      const Slab sl = convexSlab(bf.shapes[k], a, b);
      if (sl.t_in > sl.t_out || sl.t_out <= graze || sl.t_in > 1.0 || sl.face_in < 0) continue;
      if (std::max(sl.t_in, 0.0) < t) t = std::max(sl.t_in, 0.0), shape = int(k), face = sl.face_in;
    }
    if (shape < 0) return out;
    out.to = shape + 1;
  }
  const Shape& s = bf.shapes[size_t(shape)];
  const LocalPlanes lp(s);
  const glm::dvec3 n = s.rotation() * lp.planes[size_t(face)].normal;
  out.found = true;
  out.t = t;
  out.point = a + t * (b - a);
  out.normal = (region >= 1 ? 1.0 : -1.0) * glm::normalize(n);
  out.owner = shape + 1;
  out.face = face;
  out.from_medium = bf.medium[size_t(out.from)];
  out.to_medium = bf.medium[size_t(out.to)];
  glm::dvec3 grad;
  boundaryPhi(bf, out.point, out.from, &grad);
  out.field_normal = glm::length(grad) > 0.0 ? -glm::normalize(grad) : out.normal;
  return out;
}

}  // namespace eikon

namespace eikon {

int exactTableRows(const std::vector<Shape>& shapes) {
  size_t rows = 6 * shapes.size();
  for (const Shape& s : shapes)
    if (const auto* c = std::get_if<ConvexShape>(&s.geometry())) rows += c->planes.size();
  return int(std::min(rows, size_t(1) << 30));
}

bool BoundaryField::regionsOnShapes() const {
  return exact || (convex_apart && !shapes.empty() && exactTableRows(shapes) <= kExactMaxRows);
}

namespace {

/// A mesh's part in exactCrossingOutOf, as the interval the two passes read of an analytic shape
/// (boundary.glsl exactMeshClip): the ray's own mesh (`own`): where the line o + t·d first leaves
/// it in (0, 1] (t1, its triangle's normal and face colour; t0 open below, t1 open above if it
/// does not leave); a later one: where the line first enters it in (eps, 1] (t0, with t1 = t0 +
/// 2·eps: a mesh is not grazed). A non-convex mesh may be left and entered again along the line,
/// but only the first change counts.
LineClip meshClip(const Shape& s, const MeshShape& m, const glm::dvec3& a, const glm::dvec3& d,
                  bool own, double eps) {
  const auto [o, dl] = localLine(s, a, d);
  const MeshDistance::Hit h = m.distance->firstHit(o, dl, own ? 0.0 : eps, 1.0, own ? 1 : -1);
  LineClip c;
  if (own) {
    c.hit = true;
    c.t0 = -HUGE_VAL;
    c.t1 = h.found ? h.t : HUGE_VAL;
    c.n1 = s.rotation() * h.normal;
    c.f1 = h.face;
  } else if (h.found) {
    c.hit = true;
    c.t0 = h.t;
    c.t1 = h.t + 2.0 * eps;
    c.n0 = s.rotation() * h.normal;
    c.f0 = h.face;
  }
  return c;
}

/// Whether the point o + tq·d lies in the mesh: the line's first crossing past tq, out to beyond
/// the mesh's bounding sphere, leaves it (parity along the line of a closed mesh; the watertight
/// hits let no crossing slip between triangles). boundary.glsl exactMeshHolds.
bool meshHolds(const Shape& s, const MeshShape& m, const glm::dvec3& a, const glm::dvec3& d,
               double tq) {
  const auto [o, dl] = localLine(s, a, d);
  const double far = tq + (glm::length(o) + 2.0 * m.bounding_radius + 1.0) / glm::length(d);
  const MeshDistance::Hit h = m.distance->firstHit(o, dl, tq, far, 0);
  return h.found && glm::dot(h.normal, dl) > 0.0;
}

}  // namespace

int regionAt(const BoundaryField& bf, const glm::dvec3& x) {
  if (!bf.regionsOnShapes()) return boundaryRegion(bf, x);
  for (size_t i = bf.shapes.size(); i-- > 0;) {
    const Shape& s = bf.shapes[i];
    // A mesh by the parity of its hits along a fixed direction from x, as the GPU twin
    // (boundary.glsl exactInside): one ray through the hierarchy, where the signed distance
    // searches for the nearest triangle.
    const MeshShape* m = std::get_if<MeshShape>(&s.geometry());
    if (m ? meshHolds(s, *m, x, glm::dvec3(0.5773502, 0.5773503, 0.5773504), 0.0)
          : s.signedDistance(x) <= 0.0)
      return int(i) + 1;
  }
  return 0;
}

BoundaryCrossing exactCrossingOutOf(const BoundaryField& bf, const glm::dvec3& a,
                                    const glm::dvec3& b, int region) {
  BoundaryCrossing out;
  out.from = out.to = region;
  out.point = b;
  const glm::dvec3 d = b - a;
  const double len = glm::length(d);
  if (!(len > 0.0)) return out;
  const double eps = kExactMergeVoxels * bf.grid.h / len;
  const size_t n = bf.shapes.size();
  // Pass 1: where the line leaves the ray's own shape (clamped to the start: a ray already past
  // it leaves at once) or first enters a later one. Earlier shapes are painted over by the ray's.
  double t = 2.0;
  glm::dvec3 n_own(0.0);
  int f_own = -1;
  // Pass 2 reads the clips of pass 1 (a mesh's: its entry, or its own exit) and clips only the
  // shapes before the ray's own (an earlier mesh: whether it holds tq). The exact path holds at
  // most kExactMaxRows / 6 shapes (shapesTakeExactPath), so they fit a fixed array.
  constexpr size_t kMaxShapes = size_t(kExactMaxRows) / 6;
  if (n > kMaxShapes)
    throw std::logic_error("exactCrossingOutOf: more shapes than the exact path holds");
  std::array<LineClip, kMaxShapes> clips;
  const size_t first = region >= 1 ? size_t(region - 1) : 0;
  for (size_t i = first; i < n; ++i) {
    const Shape& sh = bf.shapes[i];
    const MeshShape* mesh = std::get_if<MeshShape>(&sh.geometry());
    const LineClip& c = clips[i] =
        mesh ? meshClip(sh, *mesh, a, d, int(i) + 1 == region, eps) : sh.clipLine(a, d);
    if (!c.hit) continue;
    if (int(i) + 1 == region) {
      t = std::min(t, std::max(c.t1, 0.0));
      n_own = c.n1;
      f_own = c.f1;
    } else if (c.t0 > eps && c.t1 - c.t0 > eps) {
      t = std::min(t, c.t0);
    }
  }
  if (t > 1.0) return out;
  // Pass 2: the region just past t (the last shape whose interval holds it) and its entry normal.
  const double tq = t + eps;
  int to = 0, f_to = -1;
  glm::dvec3 n_to(0.0);
  for (size_t i = 0; i < n; ++i) {
    const Shape& sh = bf.shapes[i];
    if (i < first) {  // not clipped in pass 1
      if (const MeshShape* mesh = std::get_if<MeshShape>(&sh.geometry())) {
        clips[i] = LineClip{};
        clips[i].hit = meshHolds(sh, *mesh, a, d, tq);
        clips[i].t0 = -HUGE_VAL;
        clips[i].t1 = HUGE_VAL;
      } else {
        clips[i] = sh.clipLine(a, d);
      }
    }
    const LineClip& c = clips[i];
    if (c.hit && c.t0 <= tq && tq <= c.t1) to = int(i) + 1, n_to = c.n0, f_to = c.f0;
  }
  if (to == region) return out;  // (unreachable but for rounding: no change of region)
  out.found = true;
  out.t = t;
  out.to = to;
  out.owner = std::max(region, to);
  out.from_medium = bf.medium[size_t(region)];
  out.to_medium = bf.medium[size_t(to)];
  out.point = a + t * d;
  // Entering the owner: its entry face, the normal pointing into it; leaving it (the ray's own
  // shape): its exit face, outward. Either way from `from` into `to`.
  const glm::dvec3 nrm = to == out.owner ? -n_to : n_own;
  out.face = to == out.owner ? f_to : f_own;
  out.normal = glm::length(nrm) > 0.0 ? glm::normalize(nrm) : nrm;
  out.field_normal = out.normal;
  return out;
}

BoundaryCrossing crossingOutOf(
    const BoundaryField& field, const glm::dvec3& a, const glm::dvec3& b, int region,
    const std::function<void(const glm::dvec3&, const BoundaryCrossing&)>& on_locate) {
  if (field.convex_apart) return convexCrossingOutOf(field, a, b, region);
  if (field.exact) return exactCrossingOutOf(field, a, b, region);
  return nextCrossingOutOf(field, a, b, region, on_locate);
}

}  // namespace eikon
