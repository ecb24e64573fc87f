// The sharp-boundary field on the GPU: the GLSL twin of core/volume/boundary.{h,cpp}
// under the same names — boundaryPhi, boundaryRegion, locateCrossing — and of the analytic shapes'
// signed distance and gradient (core/scene/shapes.cpp), in single precision. docs/twins.md lists
// the pairs; tests/core/volume/boundary_gpu_test.cpp holds them to each other.
//
// The including kernel declares, before `#include "boundary.glsl"`:
//   P              its parameter block with grid_origin (xyz: bounds_min (mm), w: voxel edge h)
//                  and grid_dims (xyz: voxels per axis);
//   regionImg      layout(r32ui) uimage3D: the region owning each voxel centre (0 = ambient);
//   boundaryDist   layout(r32f) image3D: the distance (voxels, ≤ cap) to its region's boundary;
//   shapeTable     vec4[]: the shape table (layout in eikon_shared.h, EIKON_SHAPE_*).
// Everything here follows the CPU code step by step (same cell walk, same cubic split at its
// turning points, same bisections, same tie rules), so the two differ by float rounding only.
#ifndef EIKON_BOUNDARY_GLSL
#define EIKON_BOUNDARY_GLSL
#extension GL_EXT_control_flow_attributes : require

// ---- Analytic shapes (core/scene/shapes.cpp) ----

// Whether any shape may be a convex polyhedron: march.glsl makes it a specialization constant
// (EIKON_F_CONVEX), so that a scene without one compiles the plane loops out (lavapipe runs them,
// masked, on every signed distance otherwise: docs/performance.md).
#ifndef EIKON_BOUNDARY_HAS_CONVEX
#define EIKON_BOUNDARY_HAS_CONVEX true
#endif
// Likewise whether any shape may be a non-convex triangle mesh (EIKON_F_MESH: its traversal).
#ifndef EIKON_BOUNDARY_HAS_MESH
#define EIKON_BOUNDARY_HAS_MESH true
#endif
// Whether every shape is a convex polyhedron apart from the others (EIKON_F_CONVEX_APART in the
// view kernel; core/volume/boundary.h convex_apart): nextCrossing (sharp.glsl) then takes
// convexCrossing instead of the walk. Other kernels keep the walk.
#ifndef EIKON_BOUNDARY_CONVEX_APART
#define EIKON_BOUNDARY_CONVEX_APART false
#endif

// The shape table's rows: the includer's EIKON_SHAPE_ROW where it has one (march.glsl: its uniform
// block when the table is small, EIKON_F_SMALL_SHAPES), else the storage buffer.
#ifndef EIKON_SHAPE_ROW
#define EIKON_SHAPE_ROW(i) shapeTable[i]
#endif
int shapeKind(int s) { return int(EIKON_SHAPE_ROW(EIKON_SHAPE_STRIDE * s).x); }

// Local components Rᵀv of a world vector v in shape s (s = region − 1).
vec3 shapeLocalDir(int s, vec3 v) {
  int o = EIKON_SHAPE_STRIDE * s;
  return vec3(dot(EIKON_SHAPE_ROW(o + 2).xyz, v), dot(EIKON_SHAPE_ROW(o + 3).xyz, v),
              dot(EIKON_SHAPE_ROW(o + 4).xyz, v));
}

// Local coordinates p = Rᵀ(x − c) of world point x in shape s.
vec3 shapeLocal(int s, vec3 x) {
  return shapeLocalDir(s, x - EIKON_SHAPE_ROW(EIKON_SHAPE_STRIDE * s + 1).xyz);
}

float boxDistance(vec3 p, vec3 half_size) {
  vec3 q = abs(p) - half_size;
  return length(max(q, vec3(0.0))) + min(max(q.x, max(q.y, q.z)), 0.0);
}

vec3 boxGradient(vec3 p, vec3 half_size) {
  vec3 q = abs(p) - half_size;
  vec3 sgn = vec3(p.x < 0.0 ? -1.0 : 1.0, p.y < 0.0 ? -1.0 : 1.0, p.z < 0.0 ? -1.0 : 1.0);
  vec3 outside = max(q, vec3(0.0));
  if (length(outside) > 0.0) return sgn * outside / length(outside);
  int a = q.x > q.y ? (q.x > q.z ? 0 : 2) : (q.y > q.z ? 1 : 2);
  vec3 g = vec3(0.0);
  g[a] = sgn[a];
  return g;
}

// lavapipe's loop budget (gallivm, LP_MAX_TGSI_LOOP_ITERATIONS in lp_bld_limits.h): one counter
// per SIMD group of invocations (8 lanes), set to 65535 when the shader starts and decremented at
// the end of every pass of every loop, whichever loop and whichever lanes are active; at zero,
// every loop stops after its current pass, silently. A group runs each loop until its last lane
// is done, so divergent neighbours spend the budget together. The sharp march of a 49-plane
// brilliant spent ~1800 passes per crossing, ~1500 of them one plane per pass in the ~40 signed
// distances of the refinement below: rays of 12–30 total internal reflections had their plane
// loops cut and left through a wrong facet (docs/view-renderer.md). Hence:
//  - the plane loops take kShapePlanesPerPass planes per pass (an unrolled inner loop; the index
//    clamped to the last plane, which a max repeats harmlessly and a strict `>` never picks
//    twice: the values and the plane chosen are those of one plane per pass) and test at the end
//    of a pass (a for loop's failing test costs a pass of its own);
//  - the 8-corner "seen before" loops have a constant count, so that they unroll;
// ~280 passes per crossing; and marchSharp reports a ray whose loops may have been cut as one
// that ran out of steps (loopLimitReached, sharp.glsl).
const int kShapePlanesPerPass = 32;

// Plane k of a convex shape at local point p (k clamped to the last plane).
float shapePlaneValue(int first, int count, int k, vec3 p) {
  vec4 pl = EIKON_SHAPE_ROW(first + min(k, count - 1));
  return dot(pl.xyz, p) - pl.w;
}

// Signed distance (mm, negative inside) of shape s at world point x: Shape::signedDistance.
float shapeSignedDistance(int s, vec3 x) {
  int o = EIKON_SHAPE_STRIDE * s;
  vec4 head = EIKON_SHAPE_ROW(o), par = EIKON_SHAPE_ROW(o + 5);
  vec3 p = shapeLocal(s, x);
  int kind = int(head.x);
  if (kind == EIKON_SHAPE_SPHERE) return length(p) - par.x;
  if (kind == EIKON_SHAPE_BOX) return boxDistance(p, par.xyz);
  if (kind == EIKON_SHAPE_ROUNDED_BOX) return boxDistance(p, par.xyz) - par.w;
  // A mesh has no signed distance here: its crossings are meshFirstHit's (locateCrossing).
  if (EIKON_BOUNDARY_HAS_MESH && kind == EIKON_SHAPE_MESH) return 0.0;
  float m = -3.0e38;
  if (!(EIKON_BOUNDARY_HAS_CONVEX)) return m;  // unreachable then: no shape has planes
  int first = int(head.y), count = int(head.z);
  for (int k = 0; count > 0;) {  // the test at the end: no pass is spent on a failing test
    [[unroll]] for (int j = 0; j < kShapePlanesPerPass; ++j)
      m = max(m, shapePlaneValue(first, count, k + j, p));
    k += kShapePlanesPerPass;
    if (k >= count) break;
  }
  return m;
}

// ∇ of the signed distance (world; the active face's normal for convex shapes):
// Shape::distanceGradient.
vec3 shapeDistanceGradient(int s, vec3 x) {
  int o = EIKON_SHAPE_STRIDE * s;
  vec4 head = EIKON_SHAPE_ROW(o), par = EIKON_SHAPE_ROW(o + 5);
  vec3 p = shapeLocal(s, x);
  int kind = int(head.x);
  vec3 g = vec3(0.0);
  if (kind == EIKON_SHAPE_SPHERE) {
    float l = length(p);
    g = l > 0.0 ? p / l : vec3(0.0, 0.0, 1.0);
  } else if (kind == EIKON_SHAPE_BOX || kind == EIKON_SHAPE_ROUNDED_BOX) {
    g = boxGradient(p, par.xyz);
  } else if (EIKON_BOUNDARY_HAS_MESH && kind == EIKON_SHAPE_MESH) {
    g = vec3(0.0);  // (see shapeSignedDistance)
  } else if (EIKON_BOUNDARY_HAS_CONVEX) {  // (else unreachable: no shape has planes)
    float m = -3.0e38;
    int first = int(head.y), count = int(head.z);
    g = vec3(0.0);
    for (int k = 0; count > 0;) {
      [[unroll]] for (int j = 0; j < kShapePlanesPerPass; ++j) {
        float v = shapePlaneValue(first, count, k + j, p);
        if (v > m) {
          m = v;
          g = EIKON_SHAPE_ROW(first + min(k + j, count - 1)).xyz;
        }
      }
      k += kShapePlanesPerPass;
      if (k >= count) break;
    }
  }
  return g.x * EIKON_SHAPE_ROW(o + 2).xyz + g.y * EIKON_SHAPE_ROW(o + 3).xyz + g.z * EIKON_SHAPE_ROW(o + 4).xyz;
}

// ---- Triangle meshes (core/scene/mesh.cpp: MeshDistance::firstHit) ----

// Where the segment o + t·d, t ∈ [t0, t1], enters the box [lo, hi]; 3e38 if it misses. inv =
// 1/d with zero components replaced by ±1e-30 (no NaN from 0·∞; the boxes are padded).
float meshBoxEntry(vec3 o, vec3 inv, float t0, float t1, vec4 lo, vec4 hi) {
  vec3 a = (lo.xyz - o) * inv, b = (hi.xyz - o) * inv;
  vec3 n = min(a, b), f = max(a, b);
  float enter = max(t0, max(n.x, max(n.y, n.z)));
  float leave = min(t1, min(f.x, min(f.y, f.z)));
  return enter <= leave ? enter : 3.0e38;
}

// The watertight ray–triangle test (Woop, Benthin & Wald 2013) in the ray frame: corners and
// origin already permuted to (kx, ky, kz), sh = (d_kx/d_kz, d_ky/d_kz, 1/d_kz). Returns t, or −1
// if the ray misses. `precise` keeps the edge functions free of fused multiply-adds, so the two
// triangles of an edge compute exact negatives of each other from the same sheared corners and a
// ray through the edge cannot slip between them (floats otherwise; no double fallback).
float meshTriangleHit(vec3 sh, vec3 op, vec3 a, vec3 b, vec3 c) {
  precise vec3 A = a - op, B = b - op, C = c - op;
  precise float ax = A.x - sh.x * A.z, ay = A.y - sh.y * A.z;
  precise float bx = B.x - sh.x * B.z, by = B.y - sh.y * B.z;
  precise float cx = C.x - sh.x * C.z, cy = C.y - sh.y * C.z;
  precise float u = cx * by - cy * bx, v = ax * cy - ay * cx, w = bx * ay - by * ax;
  if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) return -1.0;
  precise float det = u + v + w;
  if (det == 0.0) return -1.0;
  return (u * sh.z * A.z + v * sh.z * B.z + w * sh.z * C.z) / det;
}

vec3 meshPermute(vec3 v, int kx, int ky, int kz) { return vec3(v[kx], v[ky], v[kz]); }

// The first hit in (t0, t1] of the local segment o + t·d with a triangle of mesh s whose outward
// normal n has sign(n·d) = facing (±1): MeshDistance::firstHit. One node per loop pass (a leaf's
// ≤ 4 triangles unrolled in it), nearer child first, at most EIKON_MESH_MAX_PASSES passes (a search
// cut there finds nothing, as on the CPU); the test at the end of a pass (no pass for a failing
// test). gMeshPasses counts the passes (boundary_probe reports them): a global, not state passed
// along, because it is instrumentation only: no result depends on it, and in every other kernel
// nothing reads it and the compiler drops it.
int gMeshPasses = 0;
bool meshFirstHit(int s, vec3 o, vec3 d, float t0, float t1, float facing, out float tHit,
                  out vec3 nHit, out int faceHit) {
  tHit = t1;
  nHit = vec3(0.0);
  faceHit = -1;
  int leafHit = 0;  // the hit triangle's place in the leaves' order
  vec4 head = EIKON_SHAPE_ROW(EIKON_SHAPE_STRIDE * s);
  int nodes = int(head.y), tris = int(head.w);
  vec3 ad = abs(d);
  int kz = ad.x >= ad.y && ad.x >= ad.z ? 0 : (ad.y >= ad.z ? 1 : 2);
  int kx = kz == 2 ? 0 : kz + 1;
  int ky = kx == 2 ? 0 : kx + 1;
  if (d[kz] < 0.0) {
    int tmp = kx;
    kx = ky;
    ky = tmp;
  }
  vec3 sh = vec3(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
  vec3 op = meshPermute(o, kx, ky, kz);
  vec3 inv = 1.0 / mix(d, mix(vec3(-1e-30), vec3(1e-30), greaterThanEqual(d, vec3(0.0))),
                       equal(d, vec3(0.0)));
  bool found = false;
  int stack[EIKON_MESH_STACK];
  int top = 0;
  if (meshBoxEntry(o, inv, t0, t1, EIKON_SHAPE_ROW(nodes), EIKON_SHAPE_ROW(nodes + 1)) < 3.0e38)
    stack[top++] = 0;
  int pass = 0;
  if (top > 0) {
    for (;;) {
      int id = stack[--top];
      vec4 lo = EIKON_SHAPE_ROW(nodes + 2 * id), hi = EIKON_SHAPE_ROW(nodes + 2 * id + 1);
      int count = int(hi.w), first = int(lo.w);
      if (count == 0) {
        int l = id + 1, r = first;
        float el = meshBoxEntry(o, inv, t0, tHit, EIKON_SHAPE_ROW(nodes + 2 * l),
                                EIKON_SHAPE_ROW(nodes + 2 * l + 1));
        float er = meshBoxEntry(o, inv, t0, tHit, EIKON_SHAPE_ROW(nodes + 2 * r),
                                EIKON_SHAPE_ROW(nodes + 2 * r + 1));
        bool leftFirst = el <= er;
        if ((leftFirst ? er : el) < 3.0e38) stack[top++] = leftFirst ? r : l;
        if ((leftFirst ? el : er) < 3.0e38) stack[top++] = leftFirst ? l : r;
      } else {
        [[unroll]] for (int j = 0; j < EIKON_MESH_LEAF; ++j) {
          int leaf = first + min(j, count - 1);
          int k = tris + 3 * leaf;
          vec4 va = EIKON_SHAPE_ROW(k), vb = EIKON_SHAPE_ROW(k + 1), vc = EIKON_SHAPE_ROW(k + 2);
          vec3 n = vec3(va.w, vb.w, vc.w);
          if (j < count && dot(n, d) * facing > 0.0) {
            float t = meshTriangleHit(sh, op, meshPermute(va.xyz, kx, ky, kz),
                                      meshPermute(vb.xyz, kx, ky, kz),
                                      meshPermute(vc.xyz, kx, ky, kz));
            if (t > t0 && t <= tHit && (!found || t < tHit)) {
              found = true;
              tHit = t;
              nHit = n;
              leafHit = leaf;
            }
          }
        }
      }
      ++pass;
      if (top == 0) break;
      if (pass >= EIKON_MESH_MAX_PASSES) {
        found = false;  // cut: a nearer hit may be left on the stack
        break;
      }
    }
  }
  gMeshPasses += pass;
  if (found) faceHit = int(EIKON_SHAPE_ROW(int(EIKON_SHAPE_ROW(EIKON_SHAPE_STRIDE * s + 5).z) +
                                           leafHit / 4)[leafHit % 4]);
  return found;
}

// ---- The trilinear cell (boundary.cpp: Cell, cellAt) ----

// A cell around voxel coordinates u (voxel centres at integers), with its 8 corners' regions and
// distances loaded (bit 0: +x, bit 1: +y, bit 2: +z). Clamped axes (beyond the outermost centres)
// have a constant fraction and no derivative.
struct BoundaryCell {
  ivec3 lo;
  vec3 f;
  bvec3 clamped;
  int reg[8];
  float dist[8];
};

vec3 boundaryToVoxel(vec3 x) { return (x - P.grid_origin.xyz) / P.grid_origin.w - 0.5; }

// The corner span of the cell around u: lo, hi (= lo + 1 but on one-voxel axes), the fraction f
// and whether each axis is clamped.
void boundaryCellSpan(vec3 u, out ivec3 lo, out ivec3 hi, out vec3 f, out bvec3 clamped) {
  for (int a = 0; a < 3; ++a) {
    int n = P.grid_dims[a];
    if (n == 1 || u[a] <= 0.0) {
      lo[a] = 0;
      f[a] = 0.0;
      clamped[a] = true;
    } else if (u[a] >= float(n - 1)) {
      lo[a] = n - 2;
      f[a] = 1.0;
      clamped[a] = true;
    } else {
      lo[a] = min(int(floor(u[a])), n - 2);
      f[a] = u[a] - float(lo[a]);
      clamped[a] = false;
    }
    hi[a] = min(lo[a] + 1, n - 1);
  }
}

// Whether all 8 corners of the cell around u are in `region` (boundaryCellAt's corners, regions
// only): the walk's test for a cell with no zero of φ, 8 fetches instead of 16 and no arrays.
bool boundaryCellUniform(vec3 u, int region) {
  ivec3 lo, hi;
  vec3 f;
  bvec3 clamped;
  boundaryCellSpan(u, lo, hi, f, clamped);
  uint r = uint(region);
  return imageLoad(regionImg, lo).x == r && imageLoad(regionImg, ivec3(hi.x, lo.y, lo.z)).x == r &&
         imageLoad(regionImg, ivec3(lo.x, hi.y, lo.z)).x == r &&
         imageLoad(regionImg, ivec3(hi.x, hi.y, lo.z)).x == r &&
         imageLoad(regionImg, ivec3(lo.x, lo.y, hi.z)).x == r &&
         imageLoad(regionImg, ivec3(hi.x, lo.y, hi.z)).x == r &&
         imageLoad(regionImg, ivec3(lo.x, hi.y, hi.z)).x == r && imageLoad(regionImg, hi).x == r;
}

BoundaryCell boundaryCellAt(vec3 u) {
  BoundaryCell c;
  ivec3 hi;
  boundaryCellSpan(u, c.lo, hi, c.f, c.clamped);
  for (int k = 0; k < 8; ++k) {
    ivec3 v = ivec3((k & 1) != 0 ? hi.x : c.lo.x, (k & 2) != 0 ? hi.y : c.lo.y,
                    (k & 4) != 0 ? hi.z : c.lo.z);
    c.reg[k] = int(imageLoad(regionImg, v).x);
    c.dist[k] = imageLoad(boundaryDist, v).x;
  }
  return c;
}

// φ_r at the cell's point (voxels) and its gradient in voxel coordinates (= ∂φ_mm/∂x_mm).
float boundaryCellPhi(BoundaryCell c, int r, out vec3 grad) {
  float phi = 0.0;
  grad = vec3(0.0);
  for (int k = 0; k < 8; ++k) {
    float v = c.reg[k] == r ? c.dist[k] : -c.dist[k];
    vec3 w, dw;
    for (int a = 0; a < 3; ++a) {
      bool up = ((k >> a) & 1) != 0;
      w[a] = up ? c.f[a] : 1.0 - c.f[a];
      dw[a] = c.clamped[a] ? 0.0 : (up ? 1.0 : -1.0);
    }
    phi += v * w.x * w.y * w.z;
    grad += v * vec3(dw.x * w.y * w.z, w.x * dw.y * w.z, w.x * w.y * dw.z);
  }
  return phi;
}

// φ_r along u(t) = ua + t·du inside the cell: a cubic, coefficients of t⁰…t³.
vec4 boundaryCellCubic(BoundaryCell c, int r, vec3 ua, vec3 du) {
  vec4 sum = vec4(0.0);
  for (int k = 0; k < 8; ++k) {
    float v = c.reg[k] == r ? c.dist[k] : -c.dist[k];
    vec4 p = vec4(v, 0.0, 0.0, 0.0);
    for (int a = 0; a < 3; ++a) {
      float p0 = c.clamped[a] ? c.f[a] : ua[a] - float(c.lo[a]);
      float p1 = c.clamped[a] ? 0.0 : du[a];
      bool up = ((k >> a) & 1) != 0;
      float al = up ? p0 : 1.0 - p0, be = up ? p1 : -p1;
      p = vec4(p.x * al, p.y * al + p.x * be, p.z * al + p.y * be, p.w * al + p.z * be);
    }
    sum += p;
  }
  return sum;
}

float boundaryCubicAt(vec4 p, float t) { return ((p.w * t + p.z) * t + p.y) * t + p.x; }

// The first t in [t0, t1] where the cubic turns negative, bisected to tol; −1 if none. The
// interval is split at the cubic's turning points so that each piece is monotone.
float boundaryFirstNegative(vec4 p, float t0, float t1, float tol) {
  if (boundaryCubicAt(p, t0) < 0.0) return t0;
  float s[4];
  int n = 0;
  s[n++] = t0;
  float A = 3.0 * p.w, B = 2.0 * p.z, C = p.y;
  if (A != 0.0) {
    float disc = B * B - 4.0 * A * C;
    if (disc >= 0.0) {
      float q = -0.5 * (B + (B < 0.0 ? -sqrt(disc) : sqrt(disc)));
      float r0 = q / A, r1 = q != 0.0 ? C / q : t0;
      if (r1 < r0) {
        float tmp = r0;
        r0 = r1;
        r1 = tmp;
      }
      if (r0 > t0 && r0 < t1) s[n++] = r0;
      if (r1 > t0 && r1 < t1) s[n++] = r1;
    }
  } else if (B != 0.0 && -C / B > t0 && -C / B < t1) {
    s[n++] = -C / B;
  }
  s[n++] = t1;
  for (int k = 1; k < n; ++k) {
    float lo = s[k - 1], hi = s[k];
    if (boundaryCubicAt(p, hi) >= 0.0) continue;
    for (int it = 0; it < 64 && hi - lo > tol; ++it) {
      float mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;  // float resolution reached
      if (boundaryCubicAt(p, mid) >= 0.0) lo = mid;
      else hi = mid;
    }
    return 0.5 * (lo + hi);
  }
  return -1.0;
}

// ---- The public functions ----

// φ_region at world point x (mm; > 0 inside the region), its gradient in grad.
float boundaryPhi(vec3 x, int region, out vec3 grad) {
  return boundaryCellPhi(boundaryCellAt(boundaryToVoxel(x)), region, grad) * P.grid_origin.w;
}

// The region at x: of the 8 surrounding voxels' regions, the one whose φ is largest (first in
// corner order on ties, as on the CPU).
int boundaryRegionOfCell(BoundaryCell c) {
  int best = c.reg[0];
  bool single = true;
  for (int k = 1; k < 8; ++k) single = single && c.reg[k] == best;
  if (single) return best;
  float bestPhi = -3.0e38;
  vec3 g;
  for (int k = 0; k < 8; ++k) {
    // j < 8, not j < k: a constant count, so that both loops unroll (kShapePlanesPerPass).
    bool seen = false;
    for (int j = 0; j < 8; ++j) seen = seen || (j < k && c.reg[j] == c.reg[k]);
    if (seen) continue;
    float phi = boundaryCellPhi(c, c.reg[k], g);
    if (phi > bestPhi) {
      bestPhi = phi;
      best = c.reg[k];
    }
  }
  return best;
}

int boundaryRegion(vec3 x) { return boundaryRegionOfCell(boundaryCellAt(boundaryToVoxel(x))); }

struct BoundaryCrossing {
  bool found;
  float t;      // along [a, b]
  vec3 point;   // world (mm)
  vec3 normal;  // unit, from `from` into `to` (analytic when asked)
  int from;
  int to;
  int face;  // the owner polyhedron's plane crossed (convexCrossing), a mesh's face colour; −1: not known
};

// Refine a crossing on the owner shape's exact signed distance: the nearest sign change to t,
// bracketed in brackets widening from 0.05 to 3.2 voxels (boundary.cpp: refineOnShape).
bool boundaryRefineOnShape(int s, bool leavingOwner, vec3 a, vec3 b, float lenVox, inout float t) {
  for (float w = 0.05; w <= 3.2; w *= 4.0) {
    float lo = max(0.0, t - w / lenVox), hi = min(1.0, t + w / lenVox);
    if ((shapeSignedDistance(s, mix(a, b, lo)) > 0.0) == leavingOwner ||
        (shapeSignedDistance(s, mix(a, b, hi)) > 0.0) != leavingOwner)
      continue;
    for (int it = 0; it < 64; ++it) {
      float mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      if ((shapeSignedDistance(s, mix(a, b, mid)) > 0.0) != leavingOwner) lo = mid;
      else hi = mid;
    }
    t = 0.5 * (lo + hi);
    return true;
  }
  return false;
}

// A crossing of mesh s (boundary.cpp: meshCrossing): the first triangle hit of the crossing's
// orientation within kMeshBracketVoxels (3.2) of the field's t, with the triangle's plane normal;
// if there is none the field's zero and normal stand.
void boundaryMeshCrossing(int s, bool leavingOwner, vec3 a, vec3 b, float lenVox,
                          inout BoundaryCrossing c) {
  int o = EIKON_SHAPE_STRIDE * s;
  vec3 R0 = EIKON_SHAPE_ROW(o + 2).xyz, R1 = EIKON_SHAPE_ROW(o + 3).xyz, R2 = EIKON_SHAPE_ROW(o + 4).xyz;
  vec3 ba = b - a;
  vec3 d = vec3(dot(R0, ba), dot(R1, ba), dot(R2, ba));
  float w = 3.2 / lenVox, tHit;
  vec3 n;
  int face;
  if (!meshFirstHit(s, shapeLocal(s, a), d, max(0.0, c.t - w), min(1.0, c.t + w),
                    leavingOwner ? 1.0 : -1.0, tHit, n, face))
    return;
  c.t = tHit;
  c.face = face;
  c.point = mix(a, b, tHit);
  c.normal = (leavingOwner ? 1.0 : -1.0) * normalize(n.x * R0 + n.y * R1 + n.z * R2);
}

// The crossing in the cell between breaks t0 and t1 of the walk, if any: t and the region entered.
bool boundaryCrossCell(int from, vec3 ua, vec3 du, float t0, float t1, float tol,
                       inout BoundaryCrossing out_) {
  BoundaryCell c = boundaryCellAt(ua + 0.5 * (t0 + t1) * du);
  bool others = false;
  for (int k = 0; k < 8; ++k) others = others || c.reg[k] != from;
  if (!others) return false;  // φ is a mean of positive distances: no zero in this cell
  // The cubic in s = t − t0 about the cell's entry point: the same polynomial as the CPU's in t,
  // but its coefficients stay of the order of the cell's distances (in t over a long segment they
  // grow as |du|³ and cancel in float).
  float s = boundaryFirstNegative(boundaryCellCubic(c, from, ua + t0 * du, du), 0.0, t1 - t0, tol);
  if (s < 0.0) return false;
  float t = t0 + s;
  // The region entered: of the others, the one with the largest φ just past the zero.
  BoundaryCell past = boundaryCellAt(ua + min(t + tol, t1) * du);
  float best = -3.0e38;
  vec3 g;
  for (int k = 0; k < 8; ++k) {
    bool seen = c.reg[k] == from;
    for (int j = 0; j < 8; ++j) seen = seen || (j < k && c.reg[j] == c.reg[k]);
    if (seen) continue;
    float phi = boundaryCellPhi(past, c.reg[k], g);
    if (phi > best) {
      best = phi;
      out_.to = c.reg[k];
    }
  }
  out_.found = true;
  out_.t = t;
  return true;
}

// The first point where [a, b] (world, mm) leaves the region of a (boundary.h: locateCrossing),
// walking the trilinear cells the segment crosses in order; tolVoxels: the bisection's bracket
// along the segment (floats resolve ~1e-6 of the segment at best).
BoundaryCrossing locateCrossing(vec3 a, vec3 b, float tolVoxels, bool analytic) {
  BoundaryCrossing out_;
  out_.found = false;
  out_.t = 1.0;
  out_.point = b;
  out_.normal = vec3(0.0);
  out_.from = boundaryRegion(a);
  out_.to = 0;
  out_.face = -1;
  vec3 ua = boundaryToVoxel(a), du = boundaryToVoxel(b) - ua;
  float lenVox = length(du);
  if (!(lenVox > 0.0)) return out_;
  float tol = max(tolVoxels, 1e-12) / lenVox;
  // Per axis, the next voxel-centre plane m the segment crosses in (0, 1), and the last one.
  ivec3 m, mEnd, stepDir;
  for (int ax = 0; ax < 3; ++ax) {
    int n = P.grid_dims[ax];
    if (du[ax] > 0.0) {
      m[ax] = max(int(ceil(ua[ax])), 0);
      if (float(m[ax]) <= ua[ax]) m[ax] += 1;
      mEnd[ax] = min(int(floor(ua[ax] + du[ax])), n - 1);
      stepDir[ax] = 1;
    } else if (du[ax] < 0.0) {
      m[ax] = min(int(floor(ua[ax])), n - 1);
      if (float(m[ax]) >= ua[ax]) m[ax] -= 1;
      mEnd[ax] = max(int(ceil(ua[ax] + du[ax])), 0);
      stepDir[ax] = -1;
    } else {
      m[ax] = 0;
      mEnd[ax] = 0;
      stepDir[ax] = 0;
    }
  }
  // The walk in two loops: the inner one steps over cells whose corners are all in `from` (8
  // region fetches each), the outer one solves the mixed cell it stops at. lavapipe runs a loop's
  // whole body for every lane while any lane goes on, so the cubic, the bisection and the
  // region-entered search run once per mixed cell instead of once per cell; the cells visited,
  // their [t0, t1] and the answer are the CPU's.
  float t0 = 0.0, t1 = 1.0;
  int axis = -1;
  int maxBreaks = P.grid_dims.x + P.grid_dims.y + P.grid_dims.z + 4;
  for (int it = 0; it < maxBreaks && t0 < 1.0;) {
    bool mixed = false;
    for (; it < maxBreaks && t0 < 1.0; ++it) {
      t1 = 1.0;
      axis = -1;
      for (int ax = 0; ax < 3; ++ax) {
        if (stepDir[ax] == 0 || (m[ax] - mEnd[ax]) * stepDir[ax] > 0) continue;
        float t = (float(m[ax]) - ua[ax]) / du[ax];
        if (t < t1) {
          t1 = t;
          axis = ax;
        }
      }
      if (axis >= 0) m[axis] += stepDir[axis];
      if (t1 > t0 && !boundaryCellUniform(ua + 0.5 * (t0 + t1) * du, out_.from)) {
        mixed = true;
        break;
      }
      t0 = max(t0, t1);
      if (axis < 0) {
        t0 = 1.0;  // the segment's end: the walk is over
        break;
      }
    }
    if (!mixed) break;
    if (boundaryCrossCell(out_.from, ua, du, t0, t1, tol, out_)) break;
    t0 = max(t0, t1);
    ++it;
    if (axis < 0) break;
  }
  if (!out_.found) return out_;
  int owner = max(out_.from, out_.to);
  out_.point = mix(a, b, out_.t);
  vec3 grad;
  boundaryCellPhi(boundaryCellAt(boundaryToVoxel(out_.point)), out_.from, grad);
  if (length(grad) > 0.0) out_.normal = -normalize(grad);
  if (analytic && owner >= 1) {
    bool leaving = out_.from == owner;
    if (EIKON_BOUNDARY_HAS_MESH && shapeKind(owner - 1) == EIKON_SHAPE_MESH) {
      boundaryMeshCrossing(owner - 1, leaving, a, b, lenVox, out_);
      return out_;
    }
    if (boundaryRefineOnShape(owner - 1, leaving, a, b, lenVox, out_.t))
      out_.point = mix(a, b, out_.t);
    vec3 n = shapeDistanceGradient(owner - 1, out_.point);
    if (length(n) > 0.0) out_.normal = (leaving ? 1.0 : -1.0) * normalize(n);
  }
  return out_;
}

// ---- Convex polyhedra apart from each other (boundary.cpp: convexCrossingOutOf) ----

// march.glsl makes the exact path's four constants (kExact); other kernels have none.
#ifndef EIKON_BOUNDARY_EXACT
#define EIKON_BOUNDARY_EXACT false
#define EIKON_BOUNDARY_EXACT_ROWS 0
#define EIKON_BOUNDARY_EXACT_SHAPES 0
#define EIKON_BOUNDARY_EXACT_KINDS 0
#endif
// (convexCrossingUnrolled, below)
#define EIKON_CONVEX_UNROLLED                                                                   \
  (EIKON_BOUNDARY_CONVEX_APART && EIKON_BOUNDARY_EXACT_SHAPES >= 1 &&                          \
   EIKON_BOUNDARY_EXACT_SHAPES <= 4 && EIKON_BOUNDARY_EXACT_KINDS == (1 << EIKON_SHAPE_CONVEX) && \
   EIKON_BOUNDARY_EXACT_SHAPES * (EIKON_BOUNDARY_EXACT_ROWS -                                   \
                                  EIKON_SHAPE_STRIDE * EIKON_BOUNDARY_EXACT_SHAPES) <= 512)

// A crossing this close to the segment's start (voxels) is a graze at the point the ray is on.
const float kGrazeVoxels = 1e-3;

// The line a + t(b − a) in convex shape s: (t_in, t_out, plane of t_in, plane of t_out), planes
// −1 where none; t_in > t_out when it misses. Planes as in shapeSignedDistance (clamped index:
// the strict comparisons never take a repeated plane twice).
// Plane i of the shape whose record is at o: the table's, or a box's ±x, ±y, ±z
// (boundary.cpp localPlanes).
vec4 slabPlane(int o, int i) {
  if (int(EIKON_SHAPE_ROW(o).x) != EIKON_SHAPE_BOX) return EIKON_SHAPE_ROW(int(EIKON_SHAPE_ROW(o).y) + i);
  vec3 n = vec3(0.0);
  n[i >> 1] = (i & 1) != 0 ? 1.0 : -1.0;
  return vec4(n, EIKON_SHAPE_ROW(o + 5)[i >> 1]);
}

// Plane `pl` (number i) of a shape narrows the slab r of the local line p + t d (convexSlab).
void slabNarrow(vec4 pl, float i, vec3 p, vec3 d, inout vec4 r) {
  float nd = dot(pl.xyz, d), v = dot(pl.xyz, p) - pl.w;
  float t = -v / (nd != 0.0 ? nd : 1.0);
  if (nd > 0.0 && t < r.y) r.yw = vec2(t, i);
  else if (nd < 0.0 && t > r.x) r.xz = vec2(t, i);
  else if (nd == 0.0 && v > 0.0) r.xy = vec2(3.0e38, -3.0e38);  // parallel, outside
}

vec4 convexSlab(int s, vec3 a, vec3 b) {
  int o = EIKON_SHAPE_STRIDE * s;
  int count = int(EIKON_SHAPE_ROW(o).x) == EIKON_SHAPE_BOX ? 6 : int(EIKON_SHAPE_ROW(o).z);
  vec3 p = shapeLocal(s, a), ab = b - a;
  vec3 d = vec3(dot(EIKON_SHAPE_ROW(o + 2).xyz, ab), dot(EIKON_SHAPE_ROW(o + 3).xyz, ab),
                dot(EIKON_SHAPE_ROW(o + 4).xyz, ab));
  vec4 r = vec4(-3.0e38, 3.0e38, -1.0, -1.0);
  for (int k = 0; count > 0;) {
    [[unroll]] for (int j = 0; j < kShapePlanesPerPass; ++j) {
      int i = min(k + j, count - 1);
      slabNarrow(slabPlane(o, i), float(i), p, d, r);
    }
    k += kShapePlanesPerPass;
    if (k >= count) break;
  }
  return r;
}

// What a search that finds nothing on [a, b] reports: the segment's end, still in `region`.
BoundaryCrossing noCrossing(vec3 b, int region) {
  BoundaryCrossing c;
  c.found = false;
  c.t = 1.0;
  c.point = b;
  c.normal = vec3(0.0);
  c.from = region;
  c.to = region;
  c.face = -1;
  return c;
}

// The first crossing on [a, b] out of `region` where every shape is a convex polyhedron apart
// from the others: inside a polyhedron, the first of its planes ahead (into the ambient); in the
// ambient, the nearest polyhedron the segment passes through (beyond kGrazeVoxels). One loop over
// the shapes it may cross (its own, or all: the record's w), one pass per 32 planes each.
BoundaryCrossing convexCrossingUnrolled(vec3 a, vec3 b, int region);

// Shape k's slab sl on the segment: keep it if the segment leaves it (inside) or enters it
// (outside, beyond the graze) before the crossing kept so far.
void convexKeep(vec4 sl, int k, bool inside, float graze, inout float t, inout int shape,
                inout int face) {
  bool hit = inside ? sl.w >= 0.0 && sl.y <= 1.0
                    : sl.x <= sl.y && sl.y > graze && sl.x <= 1.0 && sl.z >= 0.0;
  float tk = max(inside ? sl.y : sl.x, 0.0);
  if (hit && tk < t) {
    t = tk;
    shape = k;
    face = int(inside ? sl.w : sl.z);
  }
}

// The crossing kept (shape ≥ 0: at t on face `face` of `shape`), or none.
BoundaryCrossing convexFound(vec3 a, vec3 b, int region, float t, int shape, int face) {
  BoundaryCrossing c = noCrossing(b, region);
  if (shape < 0) return c;
  bool inside = region >= 1;
  int o = EIKON_SHAPE_STRIDE * shape;
  vec3 g = slabPlane(o, face).xyz;
  vec3 n = g.x * EIKON_SHAPE_ROW(o + 2).xyz + g.y * EIKON_SHAPE_ROW(o + 3).xyz +
           g.z * EIKON_SHAPE_ROW(o + 4).xyz;
  c.found = true;
  c.t = t;
  c.point = mix(a, b, t);
  c.normal = (inside ? 1.0 : -1.0) * normalize(n);
  c.to = inside ? 0 : shape + 1;
  c.face = face;
  return c;
}

BoundaryCrossing convexCrossing(vec3 a, vec3 b, int region) {
  if (EIKON_CONVEX_UNROLLED) return convexCrossingUnrolled(a, b, region);
  float graze = kGrazeVoxels * P.grid_origin.w / length(b - a);
  bool inside = region >= 1;
  int k0 = inside ? region - 1 : 0, k1 = inside ? region : int(EIKON_SHAPE_ROW(0).w);
  int shape = -1, face = -1;
  float t = 3.0e38;
  for (int k = k0; k < k1; ++k) convexKeep(convexSlab(k, a, b), k, inside, graze, t, shape, face);
  return convexFound(a, b, region, t, shape, face);
}


// ---- Crossings on the analytic shapes (boundary.cpp: regionAt, exactCrossingOutOf;
// shapes.cpp: Shape::clipLine) ----
// EIKON_BOUNDARY_EXACT: every shape is analytic and not convex_apart (EIKON_F_EXACT in the view
// kernels; core/volume/boundary.h exact): nextCrossing (sharp.glsl) then takes exactCrossingOutOf
// and sharpEnter exactRegionAt. EIKON_BOUNDARY_EXACT_ROWS: the shape table's rows (6 per shape,
// one per plane), _SHAPES: the shape count, _KINDS: the kinds present (bit 1 << EIKON_SHAPE_*), so
// that the clip of a kind the scene lacks is compiled out (a rounded box's is ~100 distances).
// march.glsl makes all four specialization constants (kExact); other kernels keep the walk.
#define EIKON_EXACT_HAS(kind) ((EIKON_BOUNDARY_EXACT_KINDS & (1 << (kind))) != 0)
const float kExactMergeVoxels = 1e-4;

// convexCrossing unrolled (the view kernels, kExact also set for convex_apart scenes): every shape
// a convex polyhedron, at most 4 of them and at most 512 (shape, plane row) pairs. Both loops run
// unrolled over constant counts, so that every shape-table row is read at a constant index: one
// scalar load on llvmpipe where the pass of 32 planes at a varying index gathered each plane lane
// by lane. Each shape tests every plane row, keeping its own (first ≤ row < first + count): the
// same slabs in the same order as convexSlab, so the same crossing.
BoundaryCrossing convexCrossingUnrolled(vec3 a, vec3 b, int region) {
  const int S = EIKON_BOUNDARY_EXACT_SHAPES, rows = EIKON_BOUNDARY_EXACT_ROWS;
  float graze = kGrazeVoxels * P.grid_origin.w / length(b - a);
  bool inside = region >= 1;
  int shape = -1, face = -1;
  float t = 3.0e38;
  vec3 ab = b - a;
  [[unroll]] for (int k = 0; k < S; ++k) {
    const int o = EIKON_SHAPE_STRIDE * k;
    vec4 head = EIKON_SHAPE_ROW(o);
    int first = int(head.y), count = int(head.z);
    vec3 p = shapeLocal(k, a);
    vec3 d = vec3(dot(EIKON_SHAPE_ROW(o + 2).xyz, ab), dot(EIKON_SHAPE_ROW(o + 3).xyz, ab),
                  dot(EIKON_SHAPE_ROW(o + 4).xyz, ab));
    vec4 r = vec4(-3.0e38, 3.0e38, -1.0, -1.0);
    [[unroll]] for (int q = EIKON_SHAPE_STRIDE * S; q < rows; ++q)
      if (q >= first && q < first + count) slabNarrow(EIKON_SHAPE_ROW(q), float(q - first), p, d, r);
    if (!inside || region - 1 == k) convexKeep(r, k, inside, graze, t, shape, face);
  }
  return convexFound(a, b, region, t, shape, face);
}
// The loops over the shapes read the table's rows through EIKON_EXACT_ROW. The view kernels
// (march.glsl) define it as their uniform block of the table's first rows (EIKON_B_EXACT_ROWS: a
// vector gather on llvmpipe); other includers get a private copy made once per invocation
// (exactLoadShapes): llvmpipe reads a storage buffer at a varying index inside divergent control
// flow one lane at a time (a loop over the 8 lanes, each behind a branch). kExactMaxRows
// (core/volume/boundary.h) bounds both.
const int kExactMaxRows = EIKON_EXACT_MAX_ROWS;
// Scenes of up to kExactUnrollShapes shapes run the loops over the shapes unrolled
// (exactCrossingOutOf, exactRegionAt): every row index is then a constant, which llvmpipe reads
// from the uniform block with one scalar load instead of a gather per lane (a loop counter is
// never "uniform" to it). More shapes take do-while loops.
const int kExactUnrollShapes = 4;
#ifdef EIKON_EXACT_ROW
void exactLoadShapes() {}
#else
// A copy of the shape table's first rows, loaded once per invocation (exactLoadShapes) and read
// only afterwards: globals, like the parameter block P, since they are the same for every ray and
// every function of the kernel reads them; no result depends on when the copy was made.
vec4 gShapeRows[kExactMaxRows];
bool gShapeRowsLoaded = false;
#define EIKON_EXACT_ROW(i) gShapeRows[i]

void exactLoadShapes() {
  if (gShapeRowsLoaded) return;
  gShapeRowsLoaded = true;
  for (int k = 0; k < min(EIKON_BOUNDARY_EXACT_ROWS, kExactMaxRows); ++k)
    gShapeRows[k] = shapeTable[k];
}
#endif

struct LineClip {
  bool hit;
  float t0, t1;  // the line o + t·d inside the shape for t ∈ [t0, t1]
  vec3 n0, n1;   // local outward normals at the two ends
  int f0, f1;    // the polyhedron's planes there (LineClip::f0, f1 in shapes.h); −1: curved, open
};

LineClip clipOpen() {
  LineClip c;
  c.hit = true;
  c.t0 = -3.0e38;
  c.t1 = 3.0e38;
  c.n0 = vec3(0.0);
  c.n1 = vec3(0.0);
  c.f0 = -1;
  c.f1 = -1;
  return c;
}

// The slab of one plane n·(p + t q) ≤ d narrows [t0, t1] (shapes.cpp clipPlane).
void clipPlaneInto(vec3 n, float d, vec3 p, vec3 q, int face, inout LineClip c) {
  float denom = dot(n, q), num = d - dot(n, p);
  float t = num / (denom != 0.0 ? denom : 1.0);
  if (denom > 0.0 && t < c.t1) {
    c.t1 = t;
    c.n1 = n;
    c.f1 = face;
  } else if (denom < 0.0 && t > c.t0) {
    c.t0 = t;
    c.n0 = n;
    c.f0 = face;
  } else if (denom == 0.0 && num < 0.0) {
    c.hit = false;  // parallel to the plane and outside it
  }
}

// |p + t q| = r without cancellation (clipSphere).
LineClip clipSphereLocal(vec3 p, vec3 q, float r) {
  LineClip c = clipOpen();
  float a = dot(q, q), b = dot(p, q), cc = dot(p, p) - r * r;
  float disc = b * b - a * cc;
  c.hit = a > 0.0 && disc >= 0.0;
  float k = -(b + (b < 0.0 ? -sqrt(max(disc, 0.0)) : sqrt(max(disc, 0.0))));
  float ta = k / a, tb = k != 0.0 ? cc / k : -ta;
  c.t0 = min(ta, tb);
  c.t1 = max(ta, tb);
  c.n0 = (p + c.t0 * q) / r;
  c.n1 = (p + c.t1 * q) / r;
  return c;
}

float roundedAlong(vec3 p, vec3 q, vec4 par, float t) {
  return boxDistance(p + t * q, par.xyz) - par.w;
}

// A rounded box (the box `core` = par.xyz grown by r = par.w): its signed distance along the line
// is convex inside the outer box, so a golden-section search finds its minimum and bisections its
// two zeros (clipRoundedBox). Four steps per loop pass (lavapipe's loop budget).
LineClip clipRoundedBoxLocal(vec3 p, vec3 q, vec4 par, LineClip outer) {
  const float g = 0.6180339887;
  float lo = outer.t0, hi = outer.t1;
  float x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
  float f1 = roundedAlong(p, q, par, x1), f2 = roundedAlong(p, q, par, x2);
  for (int it = 0; it < 10; ++it) {
    [[unroll]] for (int j = 0; j < 4; ++j) {
      if (f1 < f2) {
        hi = x2;
        x2 = x1;
        f2 = f1;
        x1 = hi - g * (hi - lo);
        f1 = roundedAlong(p, q, par, x1);
      } else {
        lo = x1;
        x1 = x2;
        f1 = f2;
        x2 = lo + g * (hi - lo);
        f2 = roundedAlong(p, q, par, x2);
      }
    }
  }
  float tm = f1 < f2 ? x1 : x2;
  LineClip c = outer;
  c.hit = outer.hit && roundedAlong(p, q, par, tm) <= 0.0;
  [[unroll]] for (int e = 0; e < 2; ++e) {
    float inside = tm, outside = e == 0 ? outer.t0 : outer.t1;
    if (roundedAlong(p, q, par, outside) <= 0.0) {
      inside = outside;
    } else {
      for (int it = 0; it < 8; ++it) {
        [[unroll]] for (int j = 0; j < 4; ++j) {
          float mid = 0.5 * (inside + outside);
          if (roundedAlong(p, q, par, mid) <= 0.0) inside = mid;
          else outside = mid;
        }
      }
    }
    if (e == 0) c.t0 = inside;
    else c.t1 = inside;
  }
  c.n0 = boxGradient(p + c.t0 * q, par.xyz);
  c.n1 = boxGradient(p + c.t1 * q, par.xyz);
  return c;
}

const int kExactPlanesPerPass = 8;

// Shape s's interval along the world line o + t·d (Shape::clipLine), normals in the shape's local
// frame. A box and a convex polyhedron share one plane loop (a box's six planes made from its
// half sizes, boundary.cpp localPlanes), so that llvmpipe, which runs every kind's code for every
// shape, runs one; kExactPlanesPerPass planes a pass (the index clamped to the last plane, which
// a repeated slab leaves unchanged).
LineClip exactClip(int s, vec3 o, vec3 d) {
  int off = EIKON_SHAPE_STRIDE * s;
  vec4 head = EIKON_EXACT_ROW(off), par = EIKON_EXACT_ROW(off + 5);
  vec3 R0 = EIKON_EXACT_ROW(off + 2).xyz, R1 = EIKON_EXACT_ROW(off + 3).xyz, R2 = EIKON_EXACT_ROW(off + 4).xyz;
  vec3 x = o - EIKON_EXACT_ROW(off + 1).xyz;
  vec3 p = vec3(dot(R0, x), dot(R1, x), dot(R2, x)), q = vec3(dot(R0, d), dot(R1, d), dot(R2, d));
  int kind = int(head.x);
  if (EIKON_EXACT_HAS(EIKON_SHAPE_SPHERE) && kind == EIKON_SHAPE_SPHERE)
    return clipSphereLocal(p, q, par.x);
  bool rounded = EIKON_EXACT_HAS(EIKON_SHAPE_ROUNDED_BOX) && kind == EIKON_SHAPE_ROUNDED_BOX;
  bool box = kind == EIKON_SHAPE_BOX || rounded;
  LineClip c = clipOpen();
  if (!EIKON_EXACT_HAS(EIKON_SHAPE_BOX) && !EIKON_EXACT_HAS(EIKON_SHAPE_CONVEX) &&
      !EIKON_EXACT_HAS(EIKON_SHAPE_ROUNDED_BOX)) {
    c.hit = false;  // unreachable: spheres only
    return c;
  }
  vec3 half_size = rounded ? par.xyz + vec3(par.w) : par.xyz;
  int first = int(head.y), count = box ? 6 : int(head.z);
  for (int k = 0; count > 0;) {  // the test at the end: no pass is spent on a failing test
    [[unroll]] for (int j = 0; j < kExactPlanesPerPass; ++j) {
      int i = min(k + j, count - 1);
      vec4 pl;
      if (!EIKON_EXACT_HAS(EIKON_SHAPE_CONVEX) || box) {
        vec3 n = vec3(0.0);
        n[i >> 1] = (i & 1) != 0 ? 1.0 : -1.0;
        pl = vec4(n, half_size[i >> 1]);
      } else {
        pl = EIKON_EXACT_ROW(min(first + i, kExactMaxRows - 1));
      }
      clipPlaneInto(pl.xyz, pl.w, p, q, i, c);
    }
    k += kExactPlanesPerPass;
    if (k >= count) break;
  }
  c.hit = c.hit && c.t0 <= c.t1;
  if (rounded && c.hit) {
    LineClip r = clipRoundedBoxLocal(p, q, par, c);
    r.f0 = r.f1 = -1;  // curved where it matters
    return r;
  }
  return c;
}

// A local normal of shape s in world space.
vec3 exactToWorld(int s, vec3 n) {
  int off = EIKON_SHAPE_STRIDE * s;
  return n.x * EIKON_EXACT_ROW(off + 2).xyz + n.y * EIKON_EXACT_ROW(off + 3).xyz +
         n.z * EIKON_EXACT_ROW(off + 4).xyz;
}

// A mesh's part in exactCrossingOutOf (boundary.cpp meshClip), as the interval the two passes
// read of an analytic shape: the ray's own mesh (own): where the line a + t·d first leaves it in
// (0, 1] (t1, its triangle's local normal and face colour; t0 open, t1 open if it does not
// leave); a later one: where the line first enters it in (eps, 1] (t0, t1 = t0 + 2·eps: a mesh is
// not grazed). Only the first change along the line counts.
LineClip exactMeshClip(int s, vec3 a, vec3 d, bool own, float eps) {
  vec3 dl = shapeLocalDir(s, d);
  float tHit;
  vec3 n;
  int face;
  bool found = meshFirstHit(s, shapeLocal(s, a), dl, own ? 0.0 : eps, 1.0, own ? 1.0 : -1.0,
                            tHit, n, face);
  LineClip c = clipOpen();
  if (own) {
    if (found) {
      c.t1 = tHit;
      c.n1 = n;
      c.f1 = face;
    }
  } else {
    c.hit = found;
    c.t0 = tHit;
    c.t1 = tHit + 2.0 * eps;
    c.n0 = n;
    c.f0 = face;
  }
  return c;
}

// Whether mesh s holds the point o + tq·d of the local line (boundary.cpp meshHolds): the line's
// first crossing past tq, out to beyond the mesh's bounding sphere (radius: the record's [5].w),
// leaves it (parity along the line of a closed mesh; the watertight hits let none slip through).
bool exactMeshHolds(int s, vec3 o, vec3 d, float tq) {
  float radius = EIKON_SHAPE_ROW(EIKON_SHAPE_STRIDE * s + 5).w;
  float far = tq + (length(o) + 2.0 * radius + 1.0) / length(d);
  float tHit;
  vec3 n;
  int face;
  return meshFirstHit(s, o, d, tq, far, 0.0, tHit, n, face) && dot(n, d) > 0.0;
}

// Whether world point x lies in shape s (signed distance ≤ 0, Shape::signedDistance's sign; a
// mesh: exactMeshHolds along a fixed direction from x).
bool exactInside(int s, vec3 x) {
  int off = EIKON_SHAPE_STRIDE * s;
  vec4 head = EIKON_EXACT_ROW(off), par = EIKON_EXACT_ROW(off + 5);
  vec3 y = x - EIKON_EXACT_ROW(off + 1).xyz;
  vec3 p = vec3(dot(EIKON_EXACT_ROW(off + 2).xyz, y), dot(EIKON_EXACT_ROW(off + 3).xyz, y),
                dot(EIKON_EXACT_ROW(off + 4).xyz, y));
  int kind = int(head.x);
  if (EIKON_EXACT_HAS(EIKON_SHAPE_MESH) && kind == EIKON_SHAPE_MESH)
    return exactMeshHolds(s, p, vec3(0.5773502, 0.5773503, 0.5773504), 0.0);
  if (kind == EIKON_SHAPE_SPHERE) return length(p) <= par.x;
  if (kind == EIKON_SHAPE_BOX) return boxDistance(p, par.xyz) <= 0.0;
  if (kind == EIKON_SHAPE_ROUNDED_BOX) return boxDistance(p, par.xyz) <= par.w;
  float m = -3.0e38;
  if (!EIKON_EXACT_HAS(EIKON_SHAPE_CONVEX)) return false;  // (unreachable then)
  int first = int(head.y), count = int(head.z);
  for (int k = 0; count > 0;) {
    [[unroll]] for (int j = 0; j < kExactPlanesPerPass; ++j) {
      vec4 pl = EIKON_EXACT_ROW(min(first + min(k + j, count - 1), kExactMaxRows - 1));
      m = max(m, dot(pl.xyz, p) - pl.w);
    }
    k += kExactPlanesPerPass;
    if (k >= count) break;
  }
  return m <= 0.0;
}

// The later of the objects containing x (boundary.cpp regionAt); 0 for none.
int exactRegionAt(vec3 x) {
  exactLoadShapes();
  if (EIKON_BOUNDARY_EXACT_SHAPES == 0) return 0;
  int r = 0, i = 0;
  if (EIKON_BOUNDARY_EXACT_SHAPES <= kExactUnrollShapes) {  // (unrolled: see exactCrossingOutOf)
    [[unroll]] for (int j = 0; j < EIKON_BOUNDARY_EXACT_SHAPES; ++j)
      if (exactInside(j, x)) r = j + 1;
    return r;
  }
  do {  // (a do-while: see exactCrossingOutOf)
    if (exactInside(i, x)) r = i + 1;
  } while (++i < EIKON_BOUNDARY_EXACT_SHAPES);
  return r;
}

// The region at x (boundary.cpp regionAt): on the shapes where the kernel has their constants
// (the exact path, and convex_apart scenes whose table fits kExact:
// BoundaryField::regionsOnShapes), else the field's.
#define EIKON_REGION_ON_SHAPES \
  (EIKON_BOUNDARY_EXACT || (EIKON_BOUNDARY_CONVEX_APART && EIKON_BOUNDARY_EXACT_SHAPES > 0))
int regionAt(vec3 x) { return EIKON_REGION_ON_SHAPES ? exactRegionAt(x) : boundaryRegion(x); }

// The first point of [a, b] where the region changes from `region` (boundary.cpp
// exactCrossingOutOf): pass 0 over the shapes from the ray's own on finds where the line leaves
// its shape or enters a later one, pass 1 over all the region just past that point (the last
// shape whose interval holds it) and its entry normal. One loop body (exactClip inlined once);
// at most ~2 × the shape count loop passes (with more than kExactUnrollShapes shapes, pass 1 only
// over the shapes up to the ray's own) and no voxel read per crossing.
// One shape's clip folded into pass 0 (the ray's own shape: where the line leaves it; a later one:
// where it enters) or pass 1 (the last shape holding the point tq just past the crossing).
void exactPass0(int i, int region, float eps, LineClip c, inout float t, inout vec3 nOwn,
                inout int fOwn) {
  if (!c.hit) return;
  if (i + 1 == region) {
    t = min(t, max(c.t1, 0.0));
    nOwn = c.n1;
    fOwn = c.f1;
  } else if (c.t0 > eps && c.t1 - c.t0 > eps) {
    t = min(t, c.t0);
  }
}
void exactPass1(int i, float tq, LineClip c, inout int to, inout vec3 nTo, inout int fTo) {
  if (c.hit && c.t0 <= tq && tq <= c.t1) {
    to = i + 1;
    nTo = c.n0;
    fTo = c.f0;
  }
}

// Shape i's clip for the passes: exactClip, or a mesh's exactMeshClip (the ray's own or a later
// one; an earlier mesh is asked in pass 1 whether it holds tq: exactEarlierMeshClip).
LineClip exactShapeClip(int i, vec3 a, vec3 d, int region, float eps) {
  if (EIKON_EXACT_HAS(EIKON_SHAPE_MESH) && int(EIKON_EXACT_ROW(EIKON_SHAPE_STRIDE * i).x) == EIKON_SHAPE_MESH)
    return exactMeshClip(i, a, d, i + 1 == region, eps);
  return exactClip(i, a, d);
}
bool exactEarlierMesh(int i, int region) {
  return EIKON_EXACT_HAS(EIKON_SHAPE_MESH) && i < region - 1 &&
         int(EIKON_EXACT_ROW(EIKON_SHAPE_STRIDE * i).x) == EIKON_SHAPE_MESH;
}
LineClip exactEarlierMeshClip(int i, vec3 a, vec3 d, float tq) {
  LineClip c = clipOpen();
  c.hit = exactMeshHolds(i, shapeLocal(i, a), shapeLocalDir(i, d), tq);
  return c;
}

BoundaryCrossing exactCrossingOutOf(vec3 a, vec3 b, int region) {
  exactLoadShapes();
  BoundaryCrossing out_ = noCrossing(b, region);
  vec3 d = b - a;
  float len = length(d);
  if (!(len > 0.0)) return out_;
  float eps = kExactMergeVoxels * P.grid_origin.w / len;
  float t = 2.0, tq = 0.0;
  int to = 0, fOwn = -1, fTo = -1;
  vec3 nOwn = vec3(0.0), nTo = vec3(0.0);
  const int S = EIKON_BOUNDARY_EXACT_SHAPES;
  bool none = false;
  if (S <= kExactUnrollShapes) {
    // Each shape clipped once, both passes reading the clip (constant indices: registers).
    LineClip clips[kExactUnrollShapes];
    [[unroll]] for (int i = 0; i < S; ++i) clips[i] = exactShapeClip(i, a, d, region, eps);
    [[unroll]] for (int i = 0; i < S; ++i)
      if (i >= region - 1) exactPass0(i, region, eps, clips[i], t, nOwn, fOwn);
    none = t > 1.0;
    tq = t + eps;
    [[unroll]] for (int i = 0; i < S; ++i) {
      if (exactEarlierMesh(i, region)) clips[i] = exactEarlierMeshClip(i, a, d, tq);
      exactPass1(i, tq, clips[i], to, nTo, fTo);
    }
  } else {
    // Both passes in one do-while over k: shape k of pass 0 for k < S (from the ray's own shape
    // on), shape k − S of pass 1 after it. llvmpipe leaves a loop only at the end of its body, so
    // a while-loop of N passes runs its body N + 1 times (the last one masked off): a do-while
    // runs it N times. Pass 0 keeps the clip of the last later shape that holds t + ε for the t
    // found so far (`held`, shape `cand`); t only falls at a later shape that is then the last one
    // to hold it, so after pass 0 `cand` is the shape pass 1 would end on, and pass 1 runs only
    // over the shapes before the ray's own and its own (kept: `own`), never clipping a later
    // shape, or a later mesh's tree, twice. cand = −1: no later shape holds tq; −2: t fell at a
    // shape that does not hold t + ε (float rounding), so pass 1 asks every shape as before.
    int k = max(region - 1, 0), end = S, cand = -1;
    LineClip held = clipOpen(), own = clipOpen();
    own.hit = false;
    do {
      const bool second = k >= S;
      const int i = second ? k - S : k;
      LineClip c = second && i + 1 == region ? own
                   : second && exactEarlierMesh(i, region) ? exactEarlierMeshClip(i, a, d, tq)
                   : exactShapeClip(i, a, d, region, eps);
      if (second) {
        exactPass1(i, tq, c, to, nTo, fTo);
      } else {
        const float before = t;
        exactPass0(i, region, eps, c, t, nOwn, fOwn);
        const float tNow = t + eps;
        if (i + 1 == region) {
          own = c;
        } else if (c.hit && c.t0 <= tNow && tNow <= c.t1) {
          cand = i;
          held = c;
        } else if (t < before) {
          cand = -2;
        }
      }
      if (++k == S) {  // pass 0 done: no crossing on [a, b], or the point just past it
        none = t > 1.0;
        tq = t + eps;
        if (!none && cand >= 0) exactPass1(cand, tq, held, to, nTo, fTo);
        end = none || cand >= 0 ? S : S + (cand == -2 ? S : region);
      }
    } while (k < end);
  }
  if (none || to == region) return out_;
  int owner = max(region, to);
  vec3 n = exactToWorld(owner - 1, to == owner ? -nTo : nOwn);
  out_.found = true;
  out_.t = t;
  out_.point = a + t * d;
  out_.normal = length(n) > 0.0 ? normalize(n) : n;
  out_.to = to;
  out_.face = to == owner ? fTo : fOwn;
  return out_;
}

#endif  // EIKON_BOUNDARY_GLSL
