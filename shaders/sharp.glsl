// The sharp march (docs/view-renderer.md "Sharp interfaces: the march"): the GPU twin of
// RayMarch::marchSharp and its stages in core/reference/reference_marcher.cpp, under the same
// names (docs/twins.md). Included by march.glsl after MarchState/MarchResult and the medium
// helpers; reads the boundary field and shape table (boundary.glsl) and the medium table
// (mediaTable: core/volume/media.h packMediaTable, EIKON_MEDIUM_VEC4S vec4s per region).
//
// The ray carries its region; a homogeneous region is crossed in one straight segment, a varying
// one (GRIN, radial optic axis) is integrated with RK4 on the region's own analytic medium, the
// optical path with it; each segment or step chord is tested with nextCrossing, a step that meets
// a face ends on it on its own path (sharpLand), and at a crossing the exact interface laws
// (anisotropic/interface.h, anisotropic/fresnel.h) are applied.
//
// The light simulator (wavefront.comp) defines EIKON_SHARP_NO_MARCH before including this file: it
// takes the medium table, the interface laws and nextCrossing, not the march's stages.
#ifndef EIKON_SHARP_GLSL
#define EIKON_SHARP_GLSL

// How far past a crossing (voxels) a search may skip a sliver where the trilinear region field and
// the exact surface disagree (≤ 3h²/(8r) for a sphere of radius r voxels; 0 on planes), and the
// step past a sliver's end at which the search restarts.
const float kSliverVoxels = 0.25;
const float kNudgeVoxels = 1e-4;

// ---- The medium table (core/volume/media.h) ----

// Through the includer's EIKON_MEDIUM_ROW where it has one (march.glsl: its uniform block).
#ifndef EIKON_MEDIUM_ROW
#define EIKON_MEDIUM_ROW(i) mediaTable[i]
#endif
vec4 mediumRow(int r, int k) { return EIKON_MEDIUM_ROW(r * EIKON_MEDIUM_VEC4S + k); }

// σ per mm for D along principal axis k of region r (0: σ_o, 1: σ_e, 2: σ_beta) at the wavelength
// EIKON_FIELD_LAMBDA_UM: its 5 nm spectrum (the block after the records whose first row is row
// 21's w, read from the storage buffer) where the material gives one, else bandAt of the band
// values (media.h mediumSigmaAt).
float regionSigmaAt(int r, int k) {
  int block = int(mediumRow(r, 21).w);
  if (block == 0) return bandAt(mediumRow(r, k == 0 ? 8 : (k == 1 ? 9 : 21)).xyz);
  float u = clamp((EIKON_FIELD_LAMBDA_UM * 1000.0 - 380.0) / 5.0, 0.0, 80.0);
  int i = min(int(u), 79);
  return mix(mediaTable[block + i][k], mediaTable[block + i + 1][k], u - float(i));
}
int mediumFlags(int r) { return int(mediumRow(r, 7).w); }
bool mediumHomogeneous(int r) { return (mediumFlags(r) & EIKON_MEDIUM_HOMOGENEOUS) != 0; }
bool mediumUniaxial(int r) { return (mediumFlags(r) & EIKON_MEDIUM_UNIAXIAL) != 0; }
bool mediumOpaque(int r) { return (mediumFlags(r) & EIKON_MEDIUM_OPAQUE) != 0; }
bool mediumBiaxial(int r) {
  return hasFlag(EIKON_F_BIAXIAL) && (mediumFlags(r) & EIKON_MEDIUM_BIAXIAL) != 0;
}

// n of a region's dispersion record (mode 0: n_o or n_α, 1: n_e or n_γ, 2: n_β) at the march's wavelength: the
// material's own formula (mediumIndex). Sets `dispersive` where the formula depends on λ
// (march.glsl PathRecord: wavelength sharing and hero sampling, view.comp).
//
// The view kernel's RGB renders march at the one render wavelength: there the includer defines
// EIKON_INDEX_AT_RENDER_WAVELENGTH true and the index is the host's (v15, BoundaryDevice::
// setRenderWavelength), which folds the formulas away (lavapipe runs all of their code, loops
// included, at every crossing otherwise).
float mediumIndex(int r, int mode, inout bool dispersive) {
#ifdef EIKON_INDEX_AT_RENDER_WAVELENGTH
  if (EIKON_INDEX_AT_RENDER_WAVELENGTH) {
    vec4 atRender = mediumRow(r, 15);
    if (hasFlag(EIKON_F_BIAXIAL) && mode == 2) return atRender.z;
    return mode == 1 ? atRender.y : atRender.x;
  }
#endif
  // mode 2 (biaxial scenes only, folded away elsewhere): n_beta, rows 16–19.
  bool beta = hasFlag(EIKON_F_BIAXIAL) && mode == 2;
  vec4 head = beta ? mediumRow(r, 16) : mediumRow(r, 0);
  int kind = int(mode == 1 ? head.z : head.x), terms = min(int(mode == 1 ? head.w : head.y), 6);
  int b = beta ? 17 : mode == 1 ? 4 : 1;
  vec4 c0 = mediumRow(r, b), c1 = mediumRow(r, b + 1), c2 = mediumRow(r, b + 2);
  float coeff[6] = float[6](c0.x, c0.y, c0.z, c0.w, c1.x, c1.y);
  float sc[6] = float[6](c1.z, c1.w, c2.x, c2.y, c2.z, c2.w);
  if (kind == 0) return coeff[0];
  // Dispersive unless a Cauchy formula without λ terms (its B, C, ... all zero).
  if (kind != 1) dispersive = true;
  for (int k = 1; k < 6; ++k)  // a constant count: unrolled (the loop budget)
    if (k < terms && coeff[k] != 0.0) dispersive = true;
  float l = EIKON_FIELD_LAMBDA_UM, l2 = l * l;
  if (kind == 1) {
    float n = 0.0, p = 1.0;
    for (int k = 0; k < terms; ++k, p /= l2) n += coeff[k] * p;
    return n;
  }
  if (kind == 2) {
    float n2 = 1.0;
    for (int k = 0; k < terms; ++k) n2 += coeff[k] * l2 / (l2 - sc[k]);
    return n2 > 0.0 ? sqrt(n2) : uintBitsToFloat(0x7fc00000u);
  }
  return coeff[0] + coeff[1] / l + coeff[2] / (l2 * l * sqrt(l));
}

// The same where nothing notes dispersion (wavefront.comp).
float mediumIndex(int r, int mode) {
  bool unused = false;
  return mediumIndex(r, mode, unused);
}

// n_o / n_e of region r at x and its gradient (mediumIndexAt): a GRIN profile replaces the index.
// `dispersive` as mediumIndex's.
float regionIndex(int r, int mode, vec3 x, out vec3 grad, inout bool dispersive) {
  grad = vec3(0.0);
  if (!hasFlag(EIKON_F_VARYING)) return mediumIndex(r, mode, dispersive);  // no GRIN region in the scene
  int grin = int(mediumRow(r, 11).w);
  if (grin == 0) return mediumIndex(r, mode, dispersive);
  vec4 g = mediumRow(r, 12), c = mediumRow(r, 13);  // (n0, ∇n), (origin, radius)
  vec3 d = x - c.xyz;
  float R2 = c.w * c.w, r2 = dot(d, d) / R2;
  if (grin == 1) {  // linear
    grad = g.yzw;
    return g.x + dot(g.yzw, d);
  }
  // Luneburg and fisheye: the profile's own formula continued smoothly past the surface inside
  // the region (RK4's stages may sample just outside; mediumIndexAt), not clamped at n = 1.
  if (grin == 2 && r2 < 1.9) {
    float n = sqrt(2.0 - r2);
    grad = -d / (R2 * n);
    return n;
  }
  if (grin == 3) {
    grad = -2.0 * g.x * d / (R2 * (1.0 + r2) * (1.0 + r2));
    return g.x / (1.0 + r2);
  }
  if (2.0 - r2 > 1.0) grad = -d / (R2 * sqrt(2.0 - r2));  // Luneburg beyond r² = 1.9R²
  return sqrt(max(2.0 - r2, 1.0));
}

float regionIndex(int r, int mode, vec3 x, inout bool dispersive) {
  vec3 g;
  return regionIndex(r, mode, x, g, dispersive);
}

// The same where nothing notes dispersion (polarised_trace.comp).
float regionIndex(int r, int mode, vec3 x) {
  bool unused = false;
  return regionIndex(r, mode, x, unused);
}

// The optic axis field of a region at x: (unit axis, 1/r of a radial field or 0); zero where
// isotropic (mediumAxisField).
vec4 regionAxisField(int r, vec3 x) {
  if (!hasFlag(EIKON_F_UNIAXIAL)) return vec4(0.0);  // no crystal in the scene
  int f = mediumFlags(r);
  if ((f & EIKON_MEDIUM_UNIAXIAL) == 0) return vec4(0.0);
  if ((f & EIKON_MEDIUM_RADIAL_AXIS) == 0) return vec4(mediumRow(r, 7).xyz, 0.0);
  vec3 d = x - mediumRow(r, 14).xyz;
  float len = length(d);
  if (!(len > 1e-12)) return vec4(0.0, 0.0, 1.0, 0.0);
  return vec4(d / len, 1.0 / len);
}

// ---- The interface laws (anisotropic/interface.cpp) ----

struct ModeWave {
  bool exists;
  vec3 s;   // unit wave normal
  float n;  // |p|
  vec3 t;   // unit ray direction ∝ M p
};

// M p for the medium of an outgoing wave: M_e (eMat, axis a) or I/n_o².
vec3 applyMedium(vec3 p, bool eMat, vec3 a, float no, float ne) {
  return eMat ? applyM(p, a, no, ne) : p / (no * no);
}

// The Beyerle–McDermid mapping (anisotropic/bm_mapping.h): γ = aaᵀ/n_o + (I − aaᵀ)/n_e = M_e^{1/2}
// puts the e-mode's index surface pᵀM_e p = 1 on the unit sphere |γp| = 1. Wave vectors and normals
// map with γ, back with γ⁻¹ = n_o aaᵀ + n_e (I − aaᵀ).
vec3 bmGamma(vec3 v, vec3 a, float no, float ne) {
  float av = dot(a, v);
  return a * (av / no) + (v - a * av) / ne;
}
vec3 bmGammaInverse(vec3 v, vec3 a, float no, float ne) {
  float av = dot(a, v);
  return a * (av * no) + (v - a * av) * ne;
}

// The outgoing wave with tangential wave vector pt (⊥ m) on its mode's shell (anisotropic/
// interface.cpp solveUniaxialMode): the o-wave (and an isotropic medium) on the sphere |p| = n_o,
// the root of the quadratic pᵀp/n_o² = 1 along (transmitted) or against (reflected) m; the e-wave
// (eMat, axis a) by the mapping: the phase-matched line p = pt + q m maps to p' = γpt + q γm, and
// the e-shell to the unit sphere |p'| = 1, so q is a root of |γpt + q γm|² = 1 (no normalising: a
// square root fewer in float) and the tangential part stays pt.
ModeWave solveInterfaceMode(vec3 pt, vec3 m, bool eMat, vec3 a, float no, float ne, bool transmitted) {
  ModeWave w;
  w.exists = false;
  w.s = vec3(0.0);
  w.n = 0.0;
  w.t = vec3(0.0);
  float q;
  vec3 pmapped;
  if (eMat) {
    vec3 gp = bmGamma(pt, a, no, ne), gm = bmGamma(m, a, no, ne);
    float A = dot(gm, gm), Bh = dot(gp, gm), C = dot(gp, gp) - 1.0;
    float disc = Bh * Bh - A * C;  // A (1 − |p'_t|²), p'_t the part of γpt ⊥ γm
    if (disc < 0.0) return w;      // evanescent for this mode
    q = (-Bh + (transmitted ? sqrt(disc) : -sqrt(disc))) / A;
    pmapped = gp + q * gm;
  } else {  // the quadratic of pᵀp/n_o² = 1 in q
    vec3 Mm = applyMedium(m, false, a, no, ne);
    float A = dot(m, Mm), B = 2.0 * dot(pt, Mm), C = dot(pt, applyMedium(pt, false, a, no, ne)) - 1.0;
    float disc = B * B - 4.0 * A * C;
    if (disc < 0.0) return w;  // evanescent for this mode
    float root = sqrt(disc);
    q = (-B + (transmitted ? root : -root)) / (2.0 * A);
  }
  vec3 p = pt + q * m;
  w.n = length(p);
  w.s = p / w.n;
  w.t = eMat ? normalize(bmGamma(pmapped, a, no, ne)) : w.s;  // ∝ γp' = M_e p
  w.exists = true;
  return w;
}

vec3 orientNormal(vec3 N, vec3 flow) { return dot(N, flow) < 0.0 ? -N : N; }

// ---- Biaxial media (anisotropic/tensor_medium.h, the product form) ----

// A biaxial region's dielectric tensor at the march's wavelength: the principal axes α̂, β̂ = γ̂ × α̂,
// γ̂ (rows 20, 7), the indices n_α ≤ n_β ≤ n_γ and the wave-normal optic axes c₁,₂ = ±sinV α̂ +
// cosV γ̂ with cos²V ∝ a_β − a_γ, sin²V ∝ a_α − a_β (a_i = 1/n_i², the gaps formed as
// (x − y)(x + y)/(x²y²): no cancellation). n_α = n_β (or n_β = n_γ) gives the uniaxial limit.
struct Biaxial {
  vec3 a, b, g;  // α̂, β̂, γ̂
  vec3 n;        // n_α, n_β, n_γ
  vec3 c1, c2;   // the optic axes
};

float inverseSquareGap(float x, float y) { return (x - y) * (x + y) / (x * x * y * y); }

Biaxial biaxialOf(int r, inout bool dispersive) {
  Biaxial B;
  B.g = mediumRow(r, 7).xyz;
  B.a = mediumRow(r, 20).xyz;
  B.b = cross(B.g, B.a);
  // A dispersion formula that lets n_β leave [n_α, n_γ] between the wavelengths the scene checks
  // is clamped back (the CPU twin's tensorOf).
  float na = mediumIndex(r, 0, dispersive), ng = max(mediumIndex(r, 1, dispersive), na);
  B.n = vec3(na, clamp(mediumIndex(r, 2, dispersive), na, ng), ng);
  float c2 = inverseSquareGap(B.n.z, B.n.y), s2 = inverseSquareGap(B.n.y, B.n.x), sum = s2 + c2;
  float sv = sum > 0.0 ? sqrt(s2 / sum) : 0.0, cv = sum > 0.0 ? sqrt(c2 / sum) : 1.0;
  B.c1 = sv * B.a + cv * B.g;
  B.c2 = -sv * B.a + cv * B.g;
  return B;
}

// ε⁻¹v = Σ ê_i (ê_i·v)/n_i².
vec3 biaxialInverseEpsilon(Biaxial B, vec3 v) {
  return B.a * (dot(B.a, v) / (B.n.x * B.n.x)) + B.b * (dot(B.b, v) / (B.n.y * B.n.y)) +
         B.g * (dot(B.g, v) / (B.n.z * B.n.z));
}

// sin θ_k = |ŝ × c_k| below this (float: a few ulp of a unit cross product): on an optic axis.
const float kOpticAxisSin = 1e-6;

// 1/n² of mode 0 (fast) or 1 (slow) along the unit wave normal u, by the product form
// u_fast, u_slow = ½(a_α + a_γ) + ½(a_α − a_γ)(cos θ₁ cos θ₂ ± sin θ₁ sin θ₂) (TensorMedium::
// indices): the splitting is the product sin θ₁ sin θ₂, exact near the optic axes.
float biaxialInverseSquare(Biaxial B, vec3 u, int mode) {
  float s12 = length(cross(u, B.c1)) * length(cross(u, B.c2));
  float mean = 0.5 * (1.0 / (B.n.x * B.n.x) + 1.0 / (B.n.z * B.n.z));
  return mean + 0.5 * inverseSquareGap(B.n.z, B.n.x) * (dot(u, B.c1) * dot(u, B.c2) + (mode == 0 ? s12 : -s12));
}

struct BiaxialWave {
  float n;  // the mode's index along s
  vec3 D;   // unit D
  vec3 t;   // unit ray direction ∝ ŝ − Ê(Ê·ŝ), E ∝ ε⁻¹D
};

// The wave of mode 0 (fast) or 1 (slow) along wave normal s (any length; TensorMedium::modes): D
// bisects the planes (ŝ, c₁) and (ŝ, c₂) (Biot–Fresnel; the longer bisector, completed by ŝ × it),
// the fast one the larger D̂ᵀε⁻¹D̂; on an optic axis the deterministic pair D_fast = unit(β̂ −
// (β̂·ŝ)ŝ), D_slow = ŝ × D_fast, both at n_β (the product form's).
BiaxialWave biaxialWave(Biaxial B, vec3 s, int mode) {
  vec3 u = normalize(s), p1 = cross(u, B.c1), p2 = cross(u, B.c2);
  float l1 = length(p1), l2 = length(p2);
  vec3 da, db;
  if (min(l1, l2) <= kOpticAxisSin) {
    da = normalize(B.b - dot(B.b, u) * u);
    db = cross(u, da);
  } else {
    vec3 plus = p1 / l1 + p2 / l2, minus = p1 / l1 - p2 / l2;
    da = normalize(dot(plus, plus) >= dot(minus, minus) ? plus : minus);
    db = normalize(cross(u, da));
    if (dot(da, biaxialInverseEpsilon(B, da)) < dot(db, biaxialInverseEpsilon(B, db))) {
      vec3 keep = da;
      da = db;
      db = keep;
    }
  }
  BiaxialWave W;
  W.n = inversesqrt(biaxialInverseSquare(B, u, mode));
  W.D = mode == 0 ? da : db;
  vec3 E = normalize(biaxialInverseEpsilon(B, W.D));
  W.t = normalize(u - E * dot(E, u));
  return W;
}

// Trichroic attenuation of a mode per unit RAY length: σ = n³ Σ σ_i (D̂·ê_i)²/n_i³ per unit
// wave-normal length (TensorMedium::attenuation, FirstOrder) times cos ρ = ŝ·t̂. For a uniaxial
// medium in biaxial keys it is attenuationE (e) and σ_o (o).
vec3 biaxialAttenuation(Biaxial B, vec3 sa, vec3 sb, vec3 sg, vec3 s, BiaxialWave W) {
  float wa = dot(W.D, B.a), wb = dot(W.D, B.b), wg = dot(W.D, B.g);
  vec3 k = wa * wa * sa / (B.n.x * B.n.x * B.n.x) + wb * wb * sb / (B.n.y * B.n.y * B.n.y) +
           wg * wg * sg / (B.n.z * B.n.z * B.n.z);
  return W.n * W.n * W.n * k * dot(normalize(s), W.t);
}

// The outgoing wave of a biaxial mode with tangential wave vector pt (⊥ m): the root q of the mode's
// dispersion relation G(p) = |p|²/n_m(p̂)² = 1 at p = pt + q m whose ray points along m
// (transmitted) or against it (reflected) — the largest or the smallest root, as the mode's shell
// is closed around p = 0 and t ∝ ∇G is its outward normal (anisotropic/tensor_interface finds the
// same root among the Booker quartic's four). G is homogeneous of degree 2, so ∇G = 2G t/(t·p) and
// dG/dq = 2G (t·m)/(t·p); G'' ≈ 2/n_m(m̂)² (exact for a sphere or the uniaxial e-ellipsoid). Each
// pass solves that quadratic model for the step (the stable root form), from q₀ = ±√(n_γ² − |pt|²)
// outside every shell: Newton's rate where the model is exact, and no halving near grazing where a
// tangent's steps would (in double on random geometries three passes reach 3e-7 of the quartic's
// root, four 1e-12: docs/view-renderer.md). A root exists where the last pass's G is 1 to kBiaxialSolveTolerance with
// its ray on the right side; else the mode is evanescent. D: the wave's unit D.
const int kBiaxialSolvePasses = 4;
const float kBiaxialSolveTolerance = 1e-5;
ModeWave solveBiaxialMode(vec3 pt, vec3 m, Biaxial B, int mode, bool transmitted, out vec3 D) {
  ModeWave w;
  w.exists = false;
  w.s = vec3(0.0);
  w.n = 0.0;
  w.t = vec3(0.0);
  D = vec3(0.0);
  float xi2 = dot(pt, pt), sgn = transmitted ? 1.0 : -1.0;
  if (!(xi2 < B.n.z * B.n.z)) return w;  // beyond the largest index: both modes evanescent
  float c = biaxialInverseSquare(B, m, mode), q = sgn * sqrt(B.n.z * B.n.z - xi2), G = 0.0;
  vec3 p = pt + q * m;
  BiaxialWave W;
  for (int pass = 0;; ++pass) {  // the last pass evaluates the final q
    p = pt + q * m;
    W = biaxialWave(B, p, mode);
    G = dot(p, p) / (W.n * W.n);
    if (pass == kBiaxialSolvePasses) break;
    // c δ² + G' δ + (G − 1) = 0 in the mirrored coordinate sgn·q (its largest root).
    float h = sgn * 2.0 * G * dot(W.t, m) / dot(W.t, p), c0 = G - 1.0;
    float disc = h * h - 4.0 * c * c0, root = sqrt(max(disc, 0.0));
    float dq = disc < 0.0 ? -h / (2.0 * c) : (h > 0.0 ? -2.0 * c0 / (h + root) : (root - h) / (2.0 * c));
    q += sgn * dq;
  }
  if (!(abs(G - 1.0) <= kBiaxialSolveTolerance) || !(sgn * dot(W.t, m) > 0.0)) return w;
  w.n = length(p);
  w.s = p / w.n;
  w.t = W.t;
  w.exists = true;
  D = W.D;
  return w;
}

// ---- The stages (RayMarch::sharp*) ----
#ifndef EIKON_SHARP_NO_MARCH

// Box entry: the region there, and the wave vector of the mode in its medium along d (p = n_m(d) d).
void sharpEnter(inout MarchState S, inout bool dispersive, vec3 x, vec3 d, int mode) {
  S.x = x;
  S.region = regionAt(x);  // on the shapes on the exact path, else the field's
  float n = regionIndex(S.region, 0, x, dispersive);
  vec4 af = regionAxisField(S.region, x);
  if (mode == 1 && hasAxis(af.xyz))
    n = inversesqrt(dot(d, applyM(d, af.xyz, n, regionIndex(S.region, 1, x, dispersive))));
  if (mediumBiaxial(S.region)) n = inversesqrt(biaxialInverseSquare(biaxialOf(S.region, dispersive), d, mode));
  S.w = n * d;
}

// The ray (energy) direction in the ray's region: w/|w|, or M_e w for the e-mode in a crystal, or
// the biaxial mode's t.
vec3 sharpDirection(MarchState S, int mode, inout bool dispersive) {
  if (mediumBiaxial(S.region)) return biaxialWave(biaxialOf(S.region, dispersive), S.w, mode).t;
  vec4 af = regionAxisField(S.region, S.x);
  if (mode == 0 || !hasAxis(af.xyz)) return normalize(S.w);
  return normalize(applyM(S.w, af.xyz, regionIndex(S.region, 0, S.x, dispersive),
                          regionIndex(S.region, 1, S.x, dispersive)));
}

#endif  // EIKON_SHARP_NO_MARCH

// The first crossing on [a, b] out of the ray's region by the one dispatch of both twins
// (core/volume/boundary.h crossingOutOf): the planes of convex polyhedra apart from each other
// (convexCrossing), else the analytic shapes (exactCrossingOutOf), else the walk over the field
// (a mesh's crossing refined on its BVH), skipping slivers (a crossing back into the ray's own
// region within kSliverVoxels of a).
BoundaryCrossing nextCrossing(vec3 a, vec3 b, int region) {
  BoundaryCrossing none = noCrossing(b, region);
  float total = length(b - a);
  if (!(total > 0.0)) return none;
  if (EIKON_BOUNDARY_CONVEX_APART) return convexCrossing(a, b, region);
  if (EIKON_BOUNDARY_EXACT) return exactCrossingOutOf(a, b, region);
  vec3 dir = (b - a) / total;
  float h = P.grid_origin.w;
  vec3 start = a;
  for (int k = 0; k < 4; ++k) {
    BoundaryCrossing c = locateCrossing(start, b, 1e-6, true);
    if (!c.found) return c;
    float along = dot(c.point - a, dir);
    bool sliver = c.from != region && c.to == region && along <= kSliverVoxels * h;
    if (!sliver) {
      c.t = clamp(along / total, 0.0, 1.0);
      c.from = region;
      return c;
    }
    start = a + (along + kNudgeVoxels * h) * dir;
    if (along + kNudgeVoxels * h >= total) return none;
  }
  return none;
}

#ifndef EIKON_SHARP_NO_MARCH
// σ of a principal axis of region r (regionSigmaAt at the march's λ, or the band values).
vec3 regionSigma(int r, int k) {
  return gScalar ? vec3(regionSigmaAt(r, k)) : mediumRow(r, k == 0 ? 8 : (k == 1 ? 9 : 21)).xyz;
}

// Emission, attenuation (exact: e^{−σ len}) and in-scatter along a straight piece in the ray's
// region.
void absorbAlong(inout MarchState S, inout bool dispersive, vec3 dir, float len, int mode) {
  // Nothing to add where no medium attenuates, emits or scatters light (S.L += 0, S.T *= 1).
  if (!hasFlag(EIKON_F_ATTENUATION) && !hasFlag(EIKON_F_EMISSION) && !hasFlag(EIKON_F_LIT)) return;
  int r = S.region;
  vec3 sig = regionSigma(r, 0);
  vec4 af = regionAxisField(r, S.x);
  if (mode == 1 && hasAxis(af.xyz))
    sig = attenuationE(sig, regionSigma(r, 1), S.w, af.xyz, regionIndex(r, 0, S.x, dispersive),
                       regionIndex(r, 1, S.x, dispersive));
  if (mediumBiaxial(r)) {  // trichroic: σ_α, σ_β, σ_γ (regionSigma 0, 2, 1)
    Biaxial B = biaxialOf(r, dispersive);
    sig = biaxialAttenuation(B, sig, regionSigma(r, 2), regionSigma(r, 1), S.w,
                             biaxialWave(B, S.w, mode));
  }
  vec3 e = colourOf(mediumRow(r, 10).xyz);
  vec3 alb = mediumRow(r, 11).xyz;
  if (hasFlag(EIKON_F_LIT) && alb.x + alb.y + alb.z > 0.0) e += inScatter(S.x + 0.5 * len * dir, dir, sig);
  // What depends on λ ends wavelength sharing (march.glsl): any attenuation or light added.
  if (any(notEqual(sig, vec3(0.0))) || any(notEqual(e, vec3(0.0)))) dispersive = true;
  vec3 att = exp(-sig * len);
  S.L += S.T * mix(e * len, e * (1.0 - att) / max(sig, vec3(1e-30)), greaterThan(sig, vec3(1e-6)));
  S.T *= att;
}

const int kSharpGo = 0;     // still inside the region
const int kSharpCross = 1;  // at a boundary crossing
const int kSharpLeave = 2;  // out of the volume

// The ray equation in a varying region from its own analytic medium (deriv's twin).
void sharpDeriv(int region, vec3 x, vec3 w, int mode, inout bool dispersive, out vec3 dx, out vec3 dw) {
  vec3 g;
  float n = regionIndex(region, 0, x, g, dispersive);
  vec4 af = mode == 1 ? regionAxisField(region, x) : vec4(0.0);
  if (!hasAxis(af.xyz)) {
    float lw = length(w);
    dx = w / lw;
    dw = g * (lw / n);
    return;
  }
  vec3 ge;
  float ne = regionIndex(region, 1, x, ge, dispersive);
  vec3 Mp, dp;
  eModeRates(w, af, vec4(n, g), vec4(ne, ge), Mp, dp);
  float L = length(Mp);
  dx = Mp / L;
  dw = dp / L;
}

// Classical RK4 as a loop over its four stages (one inlined sharpDeriv: lavapipe compiles every
// inlined copy), summed in the CPU's order k1 + 2k2 + 2k3 + k4, on (x, w) and the optical path L
// with dL/ds = w·dx/ds (n for the o-mode, p·t for the e-mode): one more component of the same
// ODE, so L keeps the integrator's fourth order. `tangent` is the last stage's dx/ds (sharpLand's
// rate).
void sharpRk4(int region, float ds, int mode, inout bool dispersive, inout vec3 x, inout vec3 w,
              inout float opl, out vec3 tangent) {
  vec3 kx = vec3(0.0), kw = vec3(0.0), sx = vec3(0.0), sw = vec3(0.0);
  float sl = 0.0;
  for (int st = 0; st < 4; ++st) {
    float c = st == 0 ? 0.0 : (st == 3 ? 1.0 : 0.5);
    vec3 dx, dw, ws = w + c * ds * kw;
    sharpDeriv(region, x + c * ds * kx, ws, mode, dispersive, dx, dw);
    float b = (st == 0 || st == 3) ? 1.0 : 2.0;
    sx += b * dx;
    sw += b * dw;
    sl += b * dot(ws, dx);
    kx = dx;
    kw = dw;
  }
  x += ds / 6.0 * sx;
  w += ds / 6.0 * sw;
  opl += ds / 6.0 * sl;
  tangent = kx;
}

// The outward normal of the side of the box by which the line o + t·d leaves it: the axis whose
// exit parameter is boxHit's t1 (reference_marcher.cpp volumeSide).
vec3 volumeSide(vec3 o, vec3 d, vec3 bmin, vec3 bmax) {
  vec3 inv = 1.0 / mix(d, vec3(1e-30), equal(d, vec3(0.0)));
  vec3 hi = max((bmin - o) * inv, (bmax - o) * inv);
  int k = hi.x <= hi.y && hi.x <= hi.z ? 0 : (hi.y <= hi.z ? 1 : 2);
  vec3 n = vec3(0.0);
  n[k] = d[k] < 0.0 ? -1.0 : 1.0;
  return n;
}

// The RK4 step from (x0, w0) that ends on the plane through q with normal N (along the ray: the
// face crossed, or the volume's side), by Newton's method on its length s from the chord's guess:
// f(s) = (x(s) − q)·N, f'(s) ≈ tangent·N (the last stage's dx/ds, within O(s²) of the end's, so
// each pass cuts f by O((κs)²) or better), s kept in [0, ds]. A graze (tangent·N ≤ kLandMinRate)
// keeps the s it has. The end is then put on the plane (a move of the last residual), so x1, w1
// and the step's optical path belong to the one point of the integrator's path on the plane.
// Called once, from sharpAdvance (one inlined copy of its sharpRk4).
const int kLandPasses = 3;
const float kLandMinRate = 1e-3;
void sharpLand(int region, int mode, inout bool dispersive, vec3 x0, vec3 w0, float s, float ds,
               vec3 q, vec3 N, out vec3 x1, out vec3 w1, out float opl) {
  for (int pass = 0;; ++pass) {
    vec3 tangent;
    x1 = x0;
    w1 = w0;
    opl = 0.0;
    sharpRk4(region, s, mode, dispersive, x1, w1, opl, tangent);
    float rate = dot(tangent, N);
    if (pass == kLandPasses || !(rate > kLandMinRate)) break;
    s = clamp(s - dot(x1 - q, N) / rate, 0.0, ds);
  }
  x1 -= dot(x1 - q, N) * N;
}

// One piece of the march in the ray's region, the CPU's two stages in one function so that
// nextCrossing and absorbAlong are inlined once:
//   sharpSegment (homogeneous region): one straight segment to the volume's exit (a voxel at a
//     time in a lit scattering medium) or to the first crossing on it;
//   sharpStep (varying region): one RK4 step of ds; where its chord leaves the volume or crosses
//     a face first, the step is shortened to the one that ends on that plane (sharpLand), so that
//     x, w and the optical path belong to where it ends, and the crossing is that point of the
//     path.
int sharpAdvance(inout MarchState S, inout MarchResult R, inout bool dispersive, out BoundaryCrossing c,
                 int mode) {
  const vec3 bmin = P.grid_origin.xyz, bmax = P.grid_origin.xyz + P.grid_extent.xyz;
  const float h = P.grid_origin.w;
  bool straight = !hasFlag(EIKON_F_VARYING) || mediumHomogeneous(S.region);
  vec3 x0 = S.x, w0 = S.w, x1 = x0, w1 = w0, dir;
  float len = 0.0, ds = P.march.x * h, keep = 1.0, opl = 0.0;
  bool leaving = true;
  if (straight) {  // sharpSegment
    dir = sharpDirection(S, mode, dispersive);
    float tb0, tb1;
    boxHit(S.x, dir, bmin, bmax, tb0, tb1);
    len = max(tb1, 0.0);
    vec3 alb = mediumRow(S.region, 11).xyz;
    if (hasFlag(EIKON_F_LIT) && alb.x + alb.y + alb.z > 0.0 && len > h) {
      len = h;
      leaving = false;
    }
    x1 = S.x + dir * len;
  } else {  // sharpStep
    vec3 tangent;
    sharpRk4(S.region, ds, mode, dispersive, x1, w1, opl, tangent);
    vec3 chord = x1 - x0;
    float a0, a1;
    dir = normalize(chord);
    leaving = !boxHit(x0, dir, bmin, bmax, a0, a1) || a1 < length(chord);
    keep = leaving ? clamp(max(a1, 0.0) / length(chord), 0.0, 1.0) : 1.0;
    x1 = x0 + keep * chord;
  }
  c = nextCrossing(x0, x1, S.region);
  if (straight) {
    if (c.found) len *= c.t;
    R.opl += dot(S.w, dir) * len;
    x1 = c.found ? c.point : S.x + dir * len;
  } else {
    if (c.found) keep *= c.t;
    if (keep < 1.0) {
      vec3 onPlane = c.found ? c.point : x1;  // x1: the chord's exit from the volume
      vec3 N = c.found ? c.normal : volumeSide(x0, dir, bmin, bmax);
      sharpLand(S.region, mode, dispersive, x0, w0, keep * ds, ds, onPlane, N, x1, w1, opl);
      if (c.found) c.point = x1;
    }
    R.opl += opl;
    if (mode == 0) R.drift = max(R.drift, abs(length(w1) - regionIndex(S.region, 0, x1, dispersive)));
    S.x = 0.5 * (x0 + x1);
    S.w = 0.5 * (w0 + w1);
    dir = normalize(x1 - x0 + 1e-30);
    len = length(x1 - x0);
  }
  absorbAlong(S, dispersive, dir, len, mode);
  S.x = x1;
  S.w = w1;
  return c.found ? kSharpCross : leaving ? kSharpLeave : kSharpGo;
}

// ---- Mode conversion at a face met inside a crystal (the CPU twin's RayMarch::convertAtFace) ----

// The unit D of a uniaxial crystal's mode along wave normal s: o along s × a, e in the principal
// plane ⊥ s; where s ∥ a (degenerate) es for the o-mode.
vec3 uniaxialModeD(vec3 s, vec3 a, int mode, vec3 es) {
  vec3 o = cross(s, a);
  o = dot(o, o) < 1e-12 ? es : normalize(o);
  return mode == 0 ? o : normalize(cross(s, o));
}

// The D-projection share of an outgoing wave with unit D (fresnel.glsl fresnelReflectedMix):
// |F·D|² of the field F = c_s a_s ês + c_p a_p p̂ (p̂ = ês × ŝ_out) with mix = (|c_s|², |c_p|²,
// Re c_s c_p*).
float projectedShare(vec3 mix, float as, float ap, vec3 es, vec3 pOut, vec3 D) {
  float X = as * dot(es, D), Y = ap * dot(pOut, D);
  return max(mix.x * X * X + mix.y * Y * Y + 2.0 * mix.z * X * Y, 0.0);
}

// The outgoing waves of a face met inside crystal A: both reflected modes in A (r, unit D's Dr) and
// the transmitted ones in B (t, Dt; an isotropic B: t[0] alone), with the incident tangential
// wave vector pt on the normal m oriented along the incident ray. True: B is a crystal (a uniaxial
// medium with n_o = n_e is not, as TensorMedium's snapping on the CPU).
bool faceWaves(int A, int B, vec3 x, vec3 pt, vec3 m, vec3 es, inout bool dispersive,
               out ModeWave r[2], out vec3 Dr[2], out ModeWave t[2], out vec3 Dt[2]) {
  bool bA = mediumBiaxial(A), bB = mediumBiaxial(B);
  bool uB = !bB && hasFlag(EIKON_F_UNIAXIAL) && mediumUniaxial(B);
  Biaxial BA, BB;
  if (bA) BA = biaxialOf(A, dispersive);
  if (bB) BB = biaxialOf(B, dispersive);
  vec3 aA = regionAxisField(A, x).xyz, aB = regionAxisField(B, x).xyz;
  float noA = regionIndex(A, 0, x, dispersive), neA = regionIndex(A, 1, x, dispersive);
  float noB = regionIndex(B, 0, x, dispersive), neB = regionIndex(B, 1, x, dispersive);
  uB = uB && noB != neB;
  for (int k = 0; k < 2; ++k) {
    r[k] = bA ? solveBiaxialMode(pt, m, BA, k, false, Dr[k])
              : solveInterfaceMode(pt, m, k == 1, aA, noA, neA, false);
    if (!bA) Dr[k] = uniaxialModeD(r[k].s, aA, k, es);
    t[k] = bB ? solveBiaxialMode(pt, m, BB, k, true, Dt[k])
              : solveInterfaceMode(pt, m, uB && k == 1, aB, noB, neB, true);
    if (!bB) Dt[k] = uniaxialModeD(t[k].s, aB, k, es);
  }
  if (!(bB || uB)) t[1].exists = false;
  return bB || uB;
}

// Mode conversion (Transport::Full, Fresnel on) at a face met inside crystal A: the path chooses
// one outgoing propagating wave with the probability of its power share, keeping its weight. The
// shares are the D-projection's: the reflected power R = a_s²R_s + a_p²R_p (a_s, a_p: the
// incident mode's unit D on ês = N × ŝ and p̂ = ês × ŝ; R_s, R_p those of an isotropic face from
// |w| into the transmitted wave's index), shared between the two outgoing modes of the chosen
// side in proportion to |F·D_mode|² of that side's field F (projectedShare). The draws are the
// CPU twin's: reflection or transmission (followReflection, none when nothing is transmitted),
// then, where the chosen side has both modes propagating in a crystal, the mode (drawMode). The
// path continues in that wave's mode (`mode`), wave vector and region. false: not such a face
// (crossInterface applies the same-mode laws).
bool convertAtFace(inout MarchState S, inout MarchResult R, inout PathRecord rec, BoundaryCrossing c,
                   inout int mode) {
  int A = S.region, B = c.to;
  vec3 x = S.x, N = c.normal, s = normalize(S.w);
  vec4 afA = regionAxisField(A, x), afB = regionAxisField(B, x);
  bool uA = hasFlag(EIKON_F_UNIAXIAL) && mediumUniaxial(A), bA = mediumBiaxial(A);
  bool uB = hasFlag(EIKON_F_UNIAXIAL) && mediumUniaxial(B), bB = mediumBiaxial(B);
  if (P.transport.x == 0 || hasFlag(EIKON_F_NO_FRESNEL) || !(bA || (uA && hasAxis(afA.xyz))) ||
      (uB && !hasAxis(afB.xyz)))
    return false;
  float noA = regionIndex(A, 0, x, rec.dispersive), neA = regionIndex(A, 1, x, rec.dispersive);
  if (!bA && noA == neA) return false;  // no birefringence: nothing to convert
  // The incident mode's ray (the normal oriented along it) and unit D.
  vec3 flow = s, Din;
  if (bA) {
    BiaxialWave W = biaxialWave(biaxialOf(A, rec.dispersive), s, mode);
    flow = W.t;
    Din = W.D;
  } else if (mode == 1) {
    flow = normalize(applyM(s, afA.xyz, noA, neA));
  }
  vec3 m = orientNormal(N, flow), pt = S.w - dot(S.w, m) * m, es = cross(m, s);
  es = dot(es, es) < 1e-12 ? normalize(cross(abs(m.x) < 0.9 ? vec3(1, 0, 0) : vec3(0, 1, 0), m))
                           : normalize(es);
  if (!bA) Din = uniaxialModeD(s, afA.xyz, mode, es);
  ModeWave r[2], t[2];
  vec3 Dr[2], Dt[2];
  bool crystalB = faceWaves(A, B, x, pt, m, es, rec.dispersive, r, Dr, t, Dt);
  bool transmits = t[0].exists || t[1].exists;
  int kt = !crystalB ? 0 : t[mode].exists ? mode : 1 - mode;
  float n1 = length(S.w), n2 = transmits ? t[kt].n : regionIndex(B, 0, x, rec.dispersive);
  float ci = min(1.0, abs(dot(s, N))), as = dot(Din, es), ap = dot(Din, cross(es, s));
  vec3 rmix = fresnelReflectedMix(ci, n1, n2);
  bool reflects = true;
  if (transmits) {
    float Rf = as * as * rmix.x + ap * ap * rmix.y;
    R.interfaces += 1;
    reflects = followReflection(S, Rf);
    if (!reflects && singlePathWeights(S)) {
      if (n2 > n1) S.L += environmentWeighted(rec, S.T * Rf, reflect(s, N));
      S.T *= 1.0 - Rf;
    }
  } else {
    R.tir += 1;
  }
  bool crystal = reflects || crystalB;
  bool both = reflects ? r[0].exists && r[1].exists : crystal && t[0].exists && t[1].exists;
  int k = reflects ? (r[0].exists ? 0 : 1) : crystal ? (t[0].exists ? 0 : 1) : 0;
  if (both) {
    vec3 sOut = reflects ? reflect(s, N) : t[kt].s, pOut = cross(es, sOut);
    vec3 mix = reflects ? rmix : fresnelTransmittedMix(ci, n1, n2);
    float P0 = projectedShare(mix, as, ap, es, pOut, reflects ? Dr[0] : Dt[0]);
    float P1 = projectedShare(mix, as, ap, es, pOut, reflects ? Dr[1] : Dt[1]);
    k = drawMode(S, P0 / max(P0 + P1, 1e-30));
  }
  ModeWave o = reflects ? r[k] : t[k];
  if (crystal && o.exists) mode = k;
  S.w = o.exists ? o.n * o.s : reflect(S.w, N);
  if (!reflects) S.region = B;
  return true;
}

// The exact laws at a crossing: Snell, or the o/e waves into / out of a crystal; TIR is a lossless
// mirror; otherwise the path reflects with probability R or refracts (full transport,
// followReflection), or carries (1 − R) on while an external reflection adds R × environment
// (single path).
// (refractIsotropic, refractIntoUniaxial, refractOutOfUniaxial and reflectInsideUniaxial are one
// solveInterfaceMode each: the incident wave's tangential part on the outgoing mode's shell.)
void crossInterface(inout MarchState S, inout MarchResult R, inout PathRecord rec, BoundaryCrossing c,
                    inout int mode) {
  int A = S.region, B = c.to;
  vec3 x = S.x, N = c.normal, s = normalize(S.w);
  vec4 afA = regionAxisField(A, x), afB = regionAxisField(B, x);
  bool uA = hasFlag(EIKON_F_UNIAXIAL) && mediumUniaxial(A);
  bool uB = hasFlag(EIKON_F_UNIAXIAL) && mediumUniaxial(B);
  bool bA = mediumBiaxial(A), bB = mediumBiaxial(B);  // false unless EIKON_F_BIAXIAL
  // Equal biaxial media also share their principal axes (an object's own axes make its own tensor).
  bool sameTensor = !hasFlag(EIKON_F_BIAXIAL) ||
                    (mediumRow(A, 7).xyz == mediumRow(B, 7).xyz && mediumRow(A, 20).xyz == mediumRow(B, 20).xyz);
  if ((hasFlag(EIKON_F_OPACITY) && mediumOpaque(B)) || (mediumRow(A, 10).w == mediumRow(B, 10).w && int(mediumRow(A, 11).w) == 0 &&
                          afA.xyz == afB.xyz && sameTensor)) {
    S.region = B;  // equal media: nothing changes (an opaque one stops the ray next)
    return;
  }
  if (convertAtFace(S, R, rec, c, mode)) return;
  float noA = regionIndex(A, 0, x, rec.dispersive), neA = regionIndex(A, 1, x, rec.dispersive);
  float noB = regionIndex(B, 0, x, rec.dispersive), neB = regionIndex(B, 1, x, rec.dispersive);
  float n1 = length(S.w);
  // Leaving a crystal the normal is oriented along the incident ray (energy) direction and the
  // incident wave's index is the mode's n(θ); otherwise along s with |w|. A biaxial A: its mode's
  // wave along s (WA), once for the flow, the index, the reflection and the Fresnel weight.
  Biaxial BA, BB;
  BiaxialWave WA;
  if (bA) {
    BA = biaxialOf(A, rec.dispersive);
    WA = biaxialWave(BA, s, mode);
  }
  if (bB) BB = biaxialOf(B, rec.dispersive);
  bool outOfCrystal = (uA || bA) && !(uB || bB);
  bool eIn = uA && mode == 1;
  vec3 flowA = eIn ? normalize(applyM(s, afA.xyz, noA, neA)) : bA ? WA.t : s;
  float nInA = bA ? WA.n : eIn ? inversesqrt(dot(s, applyM(s, afA.xyz, noA, neA))) : noA;
  float nIn = outOfCrystal ? nInA : n1;
  // Next to a biaxial crystal the normal follows the incident ray (energy) direction always (the
  // CPU twin's outgoingMode), which differs from s only in a crystal.
  vec3 m = orientNormal(N, outOfCrystal || bA || bB ? flowA : s);
  vec3 pt = nIn * s - dot(nIn * s, m) * m;
  bool eOut = uB && mode == 1;  // into a crystal: the mode's shell there
  vec3 DB = vec3(0.0);
  ModeWave o = bB ? solveBiaxialMode(pt, m, BB, mode, true, DB)
                  : solveInterfaceMode(pt, m, eOut, afB.xyz, noB, neB, true);
  // The mirror wave in A (total internal reflection, or a partial reflection followed): in a
  // crystal the reflected wave of the same mode (reflectInsideUniaxial, or the biaxial mode's),
  // else w mirrored.
  bool reflects = !o.exists;
  R.interfaces += reflects ? 0 : 1;
  if (o.exists && !hasFlag(EIKON_F_NO_FRESNEL)) {
    vec2 rsp = fresnelRsRp(min(1.0, abs(dot(s, N))), n1, o.n);
    float Rf = 0.5 * (rsp.x + rsp.y);
    if (uA || uB) {
      float wsw = sWeight(uB ? o.s : s, uB ? afB.xyz : afA.xyz, N, s, mode);
      Rf = wsw * rsp.x + (1.0 - wsw) * rsp.y;
    }
    // A biaxial crystal's share: its mode's D along the s direction (the crystal side's wave, B's
    // where B is a crystal), as sWeight's for the uniaxial modes.
    if ((bB || (bA && !uB))) {
      vec3 es = cross(N, s), Dc = bB ? DB : WA.D;
      float wsw = dot(es, es) < 1e-12 ? 0.5 : dot(Dc, normalize(es)) * dot(Dc, normalize(es));
      Rf = wsw * rsp.x + (1.0 - wsw) * rsp.y;
    }
    reflects = followReflection(S, Rf);  // the partial reflection, internal or external
    if (!reflects && singlePathWeights(S)) {
      if (o.n > n1) S.L += environmentWeighted(rec, S.T * Rf, reflect(s, N));
      S.T *= 1.0 - Rf;
    }
  }
  if (reflects) {  // the ray stays in A
    if (uA || bA) {
      m = orientNormal(N, flowA);
      vec3 ptr = nInA * s - dot(nInA * s, m) * m;
      vec3 DA;
      ModeWave r = bA ? solveBiaxialMode(ptr, m, BA, mode, false, DA)
                      : solveInterfaceMode(ptr, m, eIn, afA.xyz, noA, neA, false);
      S.w = r.exists ? r.n * r.s : reflect(S.w, N);
    } else {
      S.w = reflect(S.w, N);
    }
    R.tir += o.exists ? 0 : 1;
    return;
  }
  S.w = o.n * o.s;
  S.region = B;
}

// Whether lavapipe's loop budget is spent (boundary.glsl, before kShapePlanesPerPass): past it
// every loop stops after one pass, so a loop of two passes makes one. The march asks after each
// step and reports a ray whose loops may have been cut as one that ran out of steps (not left),
// never as a wrong exit. A driver without the budget always makes both passes.
bool loopLimitReached() {
  int passes = 0;
  for (int k = 0; k < 1 + int(P.limits.x > 0); ++k) ++passes;
  return passes < 2;
}

MarchResult marchSharp(vec3 o, vec3 d, int mode, inout PathRecord rec) {
  MarchResult R;
  float t0;
  if (!enterVolume(o, d, rec, R, t0)) return R;
  MarchState S = startState(vec3(0.0), vec3(0.0), mode, rec);  // nn, the layer: unused here
  sharpEnter(S, rec.dispersive, o + d * t0, d, mode);
  R.opl = P.march.z * t0;
  const int maxSteps = P.limits.x;
  int steps = 0;
  bool cut = false;
  for (; steps < maxSteps; ++steps) {
    if (hasFlag(EIKON_F_OPACITY) && mediumOpaque(S.region)) {  // surface emission over the coverage, as the smoothed path
      S.L += surfaceWeighted(rec, S.T, mediumRow(S.region, 10).xyz / mediumRow(S.region, 8).w,
                             diffuseSurface(S.x, mode));
      S.stopped = true;
      break;
    }
    BoundaryCrossing c;
    int ev = sharpAdvance(S, R, rec.dispersive, c, mode);
    if (kAov && ev == kSharpCross && !R.hit) {  // the AOV layer: the exact crossing
      R.hit = true;
      R.hitPoint = c.point;
      R.hitNormal = dot(c.normal, S.w) > 0.0 ? -c.normal : c.normal;
      R.hitObject = max(c.from, c.to) - 1;
    }
    if (ev == kSharpCross) crossInterface(S, R, rec, c, mode);
    if (loopLimitReached()) {
      cut = true;
      break;
    }
    if (ev == kSharpLeave) break;
  }
  R.steps = steps;
  R.exit_point = S.x;
  R.exit_dir = sharpDirection(S, mode, rec.dispersive);
  R.wave_normal = normalize(S.w);
  // The check in the loop sees a budget spent in the loops of a pass; one spent by the march
  // loop's own last pass stops it silently after that pass, which only a check after it sees.
  cut = cut || loopLimitReached();
  R.cut = cut || (!S.stopped && steps >= maxSteps);  // the loop limit, or out of steps
  R.left = !S.stopped && !cut && steps < maxSteps;
  if (R.left) S.L += environmentWeighted(rec, S.T, R.exit_dir);
  R.radiance = S.L;
  R.throughput = S.T;
  R.split = S.split;
  return R;
}
#endif  // EIKON_SHARP_NO_MARCH

#endif  // EIKON_SHARP_GLSL
