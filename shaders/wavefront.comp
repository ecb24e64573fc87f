#version 450
// Light simulator kernel (GPU twin of core/reference/wavefront.cpp; see docs/light-simulator.md).
// One thread per patch; each dispatch advances a patch by up to control.y constant-time steps
//
//     dx/dt = w / n²,   dw/dt = ∇n / n     (c = 1, t = optical path, |w| = n)
//
// or, for the e-mode of a uniaxial volume (P.control.w = 1), where the optic axis a is non-zero,
// the mode Hamiltonian H = ½(pᵀM_e p − 1) of docs/design.md §2 in the same constant time (w = p):
//
//     dx/dt = M_e p,   dp/dt = (p·a)²/n_o³ ∇n_o + (|p|² − (p·a)²)/n_e³ ∇n_e [− radial-axis term]
//
// with classical RK4 on each of the four corners, the index sampled trilinearly from the A (and,
// when dispersive, B, C) field exactly as march.glsl / VolumeField do. Per step, in the order of
// the reference: flux ← flux·exp(−σΔs) (σ at the step midpoint of the centre path), splat of
// flux_mid·Δs/h³ into the voxel holding the midpoint, then the kills (opaque, left, caustic,
// energy) and the split test. In homogeneous regions (WaveParams.options.x = 1, skip distance
// D ≥ 2 at the centre and the corners) a straight step of k time steps replaces the RK4 step and
// its centre's path is splatted into every voxel it crosses (straightSteps, splatSegment; the
// rules of wavefront.cpp). A patch that needs a split stops there with state EIKON_PATCH_SPLIT
// and the list is rebuilt on the GPU before the next propagation (so a patch never runs ahead of
// a split it needs; patches are independent, so they need not share the same clock between
// dispatches — each carries its own step count in state.w).
//
// The list rebuild between propagations (see docs/light-simulator.md, "List rebuild"):
//   COUNT (wavefront_count.comp): scan[i] = 0 (killed, or out of steps), 1 (keep), 2 (split into
//     halves, or a reflected copy) or 4 (split into quarters, or torn into pencils), and the
//     workgroup's kill statistics into tally[group]; COUNT_SPLITS / COUNT_BUDGET only when the
//     total exceeds max_patches (rank the split requests, grant the first ones);
//   scan.comp turns scan[] into exclusive offsets and writes the total;
//   SCATTER (this shader, push constant control.y): survivors and the four or two children
//     (bilinear 3×3 lattice, new w rescaled to the float n(x), ¼ or ½ of the flux and area0 each)
//     go to the other list at their offset; a child whose edge still exceeds the split span is
//     written as due its split (SPLIT, HALVE_U, HALVE_V) and is split again by the next rebuild
//     without propagating (the reference's recursive split).
//
// Sharp interfaces (specialisation constant kSharpLight, set by the host only when the
// scene's boundary field applies, as the view renderer's kSharpMarch): every corner crosses its
// region's homogeneous medium on a straight line in constant time, is stopped at the first
// boundary (nextCrossing of sharp.glsl, locateCrossing of boundary.glsl), refracted or totally
// reflected there (solveInterfaceMode) and goes on for the rest of the step; the patch takes the
// product of its corners' Fresnel transmissions T^¼ (fresnel.glsl). The stages are
// PatchStepper's sharp ones in core/reference/wavefront.cpp under the same names: sharpCorner,
// crossInterface, mediumShell, mediumVelocity, mediumSigma, straddles.
//
// Splat: GLSL float atomics (GL_EXT_shader_atomic_float) are not available everywhere (lavapipe),
// so the Accumulate sums are signed 64-bit fixed point held as (lo, hi) uint pairs: lo by
// atomicAdd, hi by the carry and the sign extension (exact, order independent). One splat is
// rounded to the nearest 1/scale (W/mm²); the host picks scale so that the largest possible single
// splat is ≤ 2^29 units (see light_simulator.cpp). HighestEnergy uses atomicMax on the float bits
// (non-negative floats order as uints).
#extension GL_GOOGLE_include_directive : require
#include "eikon_shared.h"

layout(local_size_x = EIKON_WAVE_WG) in;

layout(std430, binding = EIKON_WB_PARAMS) readonly buffer ParamsBuf { WaveParams params; };
// A private copy of the parameter block, made once at the top of main(): llvmpipe reads a storage
// buffer lane by lane in a scalar loop wherever a lane mask is active (inside any branch or loop),
// so every P.x read in the step loop was a loop per component (docs/performance.md).
WaveParams P;

// Specialisation constants (docs/performance.md, "Light simulator"): llvmpipe runs both sides of
// every branch under masks, so what a run does not use is compiled out. GpuWavefront makes one
// pipeline per set of constants on first use.
//   kSharpLight: the scene's boundary field applies (sharp interfaces);
//   kWaveFlags:  EIKON_F_DISPERSIVE | _ATTENUATION | _OPACITY of the volume, _UNIAXIAL for an
//                e-mode run in a uniaxial volume, _CONVEX when some shape is a convex polyhedron
//                (sharp: boundary.glsl's plane loops); always given (GpuWavefront), also in
//                P.grid_dims.w;
//   kWaveOptions: EIKON_WO_* bits (straight steps, pass caustics, probe plane, the highest-energy
//                 splat's maximum, straight steps up to the next boundary); −1: from P.
layout(constant_id = 0) const bool kSharpLight = false;
layout(constant_id = 1) const int kWaveFlags = -1;
layout(constant_id = 2) const int kWaveOptions = -1;
layout(constant_id = 3) const int kExact = 0;
#define EIKON_WO_SKIP 1
#define EIKON_WO_PASS_CAUSTICS 2
#define EIKON_WO_PROBE 4
#define EIKON_WO_HIGHEST 8
#define EIKON_WO_TO_BOUNDARY 16
#define EIKON_WO_REFLECT 32
bool hasOption(int o) {
  if (kWaveOptions != -1) return (kWaveOptions & o) != 0;
  if (o == EIKON_WO_REFLECT) return P.options.w > 0;
  if (o == EIKON_WO_SKIP) return P.options.x != 0;
  if (o == EIKON_WO_PASS_CAUSTICS) return P.options.y != 0;
  if (o == EIKON_WO_TO_BOUNDARY) return P.options.z != 0;
  if (o == EIKON_WO_HIGHEST) return true;  // (the maximum costs an atomic; it is always right)
  return P.control.x >= 0;
}
layout(binding = EIKON_WB_INDEX_A, rgba32f) readonly uniform image3D idxOA;
layout(binding = EIKON_WB_INDEX_B, rgba32f) readonly uniform image3D idxOB;
layout(binding = EIKON_WB_INDEX_C, rgba32f) readonly uniform image3D idxOC;
layout(binding = EIKON_WB_MEDIUM, rgba32f) readonly uniform image3D mediumO;
layout(binding = EIKON_WB_INDEX_E_A, rgba32f) readonly uniform image3D idxEA;
layout(binding = EIKON_WB_INDEX_E_B, rgba32f) readonly uniform image3D idxEB;
layout(binding = EIKON_WB_INDEX_E_C, rgba32f) readonly uniform image3D idxEC;
layout(binding = EIKON_WB_MEDIUM_E, rgba32f) readonly uniform image3D mediumE;
layout(binding = EIKON_WB_AXIS, rgba32f) readonly uniform image3D axisImg;
layout(binding = EIKON_WB_SKIP, rgba32f) readonly uniform image3D skipImg;
layout(std430, binding = EIKON_WB_PATCHES) buffer PatchBuf { WavePatch patchesA[]; };
layout(std430, binding = EIKON_WB_PATCHES_B) buffer PatchBufB { WavePatch patchesB[]; };
layout(std430, binding = EIKON_WB_SPLAT) buffer SplatBuf { uint splat[]; };
layout(std430, binding = EIKON_WB_SCAN) readonly buffer ScanBuf { uint scan[]; };
layout(push_constant) uniform PushBlock { WavePush pc; };

// The source list is A or B (control.w bit 0); SCATTER writes the other one.
bool sourceIsB() { return (pc.control.w & 1u) != 0u; }
WavePatch loadPatch(uint i) {
  if (sourceIsB()) return patchesB[i];
  return patchesA[i];
}
void storePatch(uint i, WavePatch p) {
  if (sourceIsB())
    patchesB[i] = p;
  else
    patchesA[i] = p;
}
void storeOther(uint i, WavePatch p) {
  if (sourceIsB())
    patchesA[i] = p;
  else
    patchesB[i] = p;
}

#define EIKON_FIELD_INV_H P.grid_max.w
#define EIKON_FIELD_LAMBDA_UM P.wavelength.x
#define EIKON_FIELD_IL2 P.wavelength.y
#define EIKON_FIELD_IL4 P.wavelength.z
#define EIKON_FIELD_FLAGS kWaveFlags
#define EIKON_FIELD_HAS_AXIS hasFlag(EIKON_F_UNIAXIAL)
#include "field.glsl"

// The e-mode of a uniaxial volume (the host sets EIKON_F_UNIAXIAL only for such a run).
bool eMode() { return hasFlag(EIKON_F_UNIAXIAL); }

// ---- Sharp interfaces: the boundary field (boundary.glsl), the medium table and the interface
// laws (sharp.glsl, without the view march's stages), the Fresnel factors (fresnel.glsl) ----
layout(binding = EIKON_B_REGION, r32ui) readonly uniform uimage3D regionImg;
layout(binding = EIKON_B_BOUNDARY_DIST, r32f) readonly uniform image3D boundaryDist;
layout(std430, binding = EIKON_B_SHAPES) readonly buffer ShapeBuf { vec4 shapeTable[]; };
layout(std430, binding = EIKON_B_MEDIA) readonly buffer MediaBuf { vec4 mediaTable[]; };
// The shape table's first rows and the medium table as uniform blocks, as the view kernel reads
// them (march.glsl): llvmpipe gathers a uniform block's vec4s where it reads a storage buffer one
// lane at a time.
layout(std140, binding = EIKON_B_EXACT_ROWS) uniform ExactRowsBuf { vec4 exactRows[EIKON_EXACT_MAX_ROWS]; };
layout(std140, binding = EIKON_B_SMALL_MEDIA) uniform SmallMediaBuf {
  vec4 smallMedia[EIKON_SMALL_MEDIA_REGIONS * EIKON_MEDIUM_VEC4S];
};
#define EIKON_SHAPE_ROW(i) (hasFlag(EIKON_F_SMALL_SHAPES) ? exactRows[i] : shapeTable[i])
#define EIKON_MEDIUM_ROW(i) (hasFlag(EIKON_F_SMALL_MEDIA) ? smallMedia[i] : mediaTable[i])
#define EIKON_BOUNDARY_HAS_CONVEX hasFlag(EIKON_F_CONVEX)
#define EIKON_BOUNDARY_HAS_MESH hasFlag(EIKON_F_MESH)
#define EIKON_BOUNDARY_CONVEX_APART hasFlag(EIKON_F_CONVEX_APART)
#define EIKON_BOUNDARY_EXACT (hasFlag(EIKON_F_EXACT) && kExact != 0)
#define EIKON_BOUNDARY_EXACT_ROWS (kExact & 0x3FF)
#define EIKON_BOUNDARY_EXACT_SHAPES ((kExact >> 10) & 0x3FF)
#define EIKON_BOUNDARY_EXACT_KINDS ((kExact >> 20) & 0x1F)
#define EIKON_EXACT_ROW(i) exactRows[i]
#include "boundary.glsl"
#include "fresnel.glsl"
#define EIKON_SHARP_NO_MARCH
// A run is at one wavelength: the media's indices there come from the host (sharp.glsl
// mediumIndex; GpuWavefront sets BoundaryDevice::setRenderWavelength), which folds the
// dispersion formulas away.
#define EIKON_INDEX_AT_RENDER_WAVELENGTH true
#include "sharp.glsl"

int regionOf(int corner) { return corner & EIKON_CORNER_REGION; }

// The run's mode index: 1 (the e-wave, or a biaxial crystal's slow wave) or 0 (o, or fast).
int runMode() { return eMode() ? 1 : 0; }

// A biaxial region's tensor at the run's wavelength (sharp.glsl biaxialOf).
Biaxial biaxialAt(int r) {
  bool dispersive = false;
  return biaxialOf(r, dispersive);
}

// The constant-time velocity dx/dt in region r's medium (deriv in a constant field): w/n², or in a
// crystal of the e-mode M_e w; in a biaxial crystal the mode's energy velocity t̂/(p·t̂).
vec3 mediumVelocity(int r, vec3 w) {
  if (mediumBiaxial(r)) {
    const vec3 t = biaxialWave(biaxialAt(r), w, runMode()).t;
    return t / dot(w, t);
  }
  float no = mediumIndex(r, 0);
  if (eMode() && mediumUniaxial(r)) return applyM(w, mediumRow(r, 7).xyz, no, mediumIndex(r, 1));
  return w / (no * no);
}

// The wave vector along the unit direction s on region r's shell: n·s, or in a crystal of the
// e-mode s/√(sᵀM_e s).
vec3 mediumShell(int r, vec3 s) {
  if (mediumBiaxial(r)) return s * inversesqrt(biaxialInverseSquare(biaxialAt(r), s, runMode()));
  if (eMode() && mediumUniaxial(r)) return s * inversesqrt(dot(s, mediumVelocity(r, s)));
  return mediumIndex(r, 0) * s;
}

// Attenuation per unit ray length in region r for wave vector w: σ_o at the wavelength, or in a
// crystal of the e-mode the pleochroic σ(θ)·cos ρ (attenuationE).
float mediumSigma(int r, vec3 w) {
  float so = regionSigmaAt(r, 0);
  if (mediumBiaxial(r)) {  // trichroism per unit ray length (sharp.glsl biaxialAttenuation)
    const float sb = regionSigmaAt(r, 2), sg = regionSigmaAt(r, 1);
    if (so == 0.0 && sb == 0.0 && sg == 0.0) return 0.0;
    const Biaxial B = biaxialAt(r);
    return biaxialAttenuation(B, vec3(so), vec3(sb), vec3(sg), w, biaxialWave(B, w, runMode())).x;
  }
  if (!eMode() || !mediumUniaxial(r)) return so;
  float se = regionSigmaAt(r, 1);
  if (so == 0.0 && se == 0.0) return so;
  return attenuationE(vec3(so), vec3(se), w, mediumRow(r, 7).xyz, mediumIndex(r, 0), mediumIndex(r, 1)).x;
}

// Wave vector along the unit direction s at x on the simulated mode's shell (onModeShell in
// core/light/seeding.cpp, which PatchStepper::onShell calls).
vec3 onShell(vec3 x, vec3 s) {
  float n = sampleIndex(x, 0).x;
  if (eMode()) {
    vec3 a = axisField(x).xyz;
    if (hasAxis(a)) return onShellE(s, a, n, sampleIndex(x, 1).x);
  }
  return s * n;
}

// (σ at 612, 549, 465 nm, opacity) of the o-mode; zero when the volume has neither.
vec4 mediumAt(vec3 x) {
  if (!hasFlag(EIKON_F_ATTENUATION) && !hasFlag(EIKON_F_OPACITY)) return vec4(0.0);
  return sampleMediumO(x);
}

// Constant-time rates: dx/dt = w/n², dw/dt = ∇n/n; in a crystal of the e-mode eModeRates (field.glsl).
void deriv(vec3 x, vec3 w, out vec3 dx, out vec3 dw) {
  vec4 a = sampleIndex(x, 0);
  if (eMode()) {
    vec4 af = axisField(x);
    if (hasAxis(af.xyz)) {
      eModeRates(w, af, a, sampleIndex(x, 1), dx, dw);
      return;
    }
  }
  dx = w / (a.x * a.x);
  dw = a.yzw / a.x;
}

// e-mode attenuation per unit ray length at x for wave vector w: σ(θ)·cos ρ (attenuationE,
// field.glsl), at the simulator's wavelength; the o-mode σ where there is no axis.
float sigmaE(vec3 x, vec3 w) {
  float so = bandAt(mediumAt(x).xyz);
  vec3 a = axisField(x).xyz;
  if (!hasAxis(a) || !(dot(w, w) > 0.0)) return so;
  float se = hasFlag(EIKON_F_ATTENUATION) ? bandAt(sampleMedium(x, 1).xyz) : 0.0;
  return attenuationE(vec3(so), vec3(se), w, a, sampleIndex(x, 0).x, sampleIndex(x, 1).x).x;
}

void rk4(inout vec3 x, inout vec3 w, float dt) {
  vec3 k1x, k1w, k2x, k2w, k3x, k3w, k4x, k4w;
  deriv(x, w, k1x, k1w);
  deriv(x + 0.5 * dt * k1x, w + 0.5 * dt * k1w, k2x, k2w);
  deriv(x + 0.5 * dt * k2x, w + 0.5 * dt * k2w, k3x, k3w);
  deriv(x + dt * k3x, w + dt * k3w, k4x, k4w);
  x += dt / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
  w += dt / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
}

bool insideBounds(vec3 x) { return all(greaterThanEqual(x, P.grid_origin.xyz)) && all(lessThanEqual(x, P.grid_max.xyz)); }

// Does the ray o + s·d (s ≥ 0) meet the bounds? (rayHitsBox in core/light/seeding.h)
bool rayHitsBox(vec3 o, vec3 d) {
  float t0 = 0.0, t1 = 1e30;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (o[a] < P.grid_origin[a] || o[a] > P.grid_max[a]) return false;
      continue;
    }
    float ta = (P.grid_origin[a] - o[a]) / d[a], tb = (P.grid_max[a] - o[a]) / d[a];
    if (ta > tb) {
      float t = ta;
      ta = tb;
      tb = t;
    }
    t0 = max(t0, ta);
    t1 = min(t1, tb);
  }
  return t0 <= t1;
}

// Add v (already in fixed-point units) to the signed 64-bit sum at words (base, base + 1).
void addFixed(uint base, int v) {
  if (v == 0) return;
  uint u = uint(v);
  uint old = atomicAdd(splat[base], u);
  uint hiAdd = ((old + u) < old ? 1u : 0u) + (v < 0 ? 0xFFFFFFFFu : 0u);
  if (hiAdd != 0u) atomicAdd(splat[base + 1u], hiAdd);
}

int toFixed(float value) { return int(clamp(round(value * P.wavelength.w), -2147483520.0, 2147483520.0)); }

// Voxel i's sums += value (≥ 0) and value·dir. The direction's sums are kept biased, as
// value·(1 + dir) ≥ 0 (readSplat takes the weight back off), so that no sum ever adds a negative
// word: its high word then changes only on a carry, so almost no lane does addFixed's second
// atomic (llvmpipe runs a buffer atomic as a loop over the active lanes; the signed sums added
// the sign's 0xFFFFFFFF to the high word of every negative component: up to three more atomics a
// splat).
void splatVoxel(ivec3 i, float value, vec3 dir) {
  const uint v = uint((i.z * P.grid_dims.y + i.y) * P.grid_dims.x + i.x);
  const uint base = v * uint(EIKON_SPLAT_ACC_WORDS);
  const vec3 biased = max(vec3(1.0) + dir, vec3(0.0));  // (|dir| ≤ 1 but for its rounding)
  addFixed(base, toFixed(value));
  addFixed(base + 2u, toFixed(value * biased.x));
  addFixed(base + 4u, toFixed(value * biased.y));
  addFixed(base + 6u, toFixed(value * biased.z));
}

// The highest-energy splat's maximum (Splat::HighestEnergy only: an Accumulate run reads only the
// sums).
void splatHighest(ivec3 i, float irr) {
  const uint v = uint((i.z * P.grid_dims.y + i.y) * P.grid_dims.x + i.x);
  const uint count = uint(P.grid_dims.x * P.grid_dims.y * P.grid_dims.z);
  atomicMax(splat[count * uint(EIKON_SPLAT_ACC_WORDS) + v], floatBitsToUint(max(irr, 0.0)));
}

void splatAt(vec3 m, float value, float irr, vec3 dir) {
  vec3 g = floor((m - P.grid_origin.xyz) * P.grid_max.w);
  if (any(lessThan(g, vec3(0.0))) || any(greaterThanEqual(g, vec3(P.grid_dims.xyz)))) return;
  splatVoxel(ivec3(g), value, dir);
  if (hasOption(EIKON_WO_HIGHEST)) splatHighest(ivec3(g), irr);
}

vec3 centreOf(vec3 x[4]) { return 0.25 * (x[0] + x[1] + x[2] + x[3]); }

// How a patch splits (PatchStepper::splitWays): 0 when no edge exceeds the split span; 1 (two
// halves across the u edges 0→1 and 3→2) or 2 (across 1→2 and 0→3) when only one pair of opposite
// edges does; 3 (quarters) when both do, or always when WaveParams.probe.y (split_halves) is 0.
const int kSplitNone = 0, kSplitU = 1, kSplitV = 2, kSplitQuarters = 3;
int splitWays(vec3 x[4]) {
  const float maxEdge = P.step.y;
  const bool u = max(length(x[1] - x[0]), length(x[2] - x[3])) > maxEdge;
  const bool v = max(length(x[2] - x[1]), length(x[3] - x[0])) > maxEdge;
  if (P.probe.y < 0.5) return u || v ? kSplitQuarters : kSplitNone;
  return (u ? kSplitU : kSplitNone) | (v ? kSplitV : kSplitNone);
}
// The state of a patch due a split `ways` (≠ kSplitNone).
int splitState(int ways) {
  return ways == kSplitQuarters ? EIKON_PATCH_SPLIT : ways == kSplitU ? EIKON_PATCH_HALVE_U : EIKON_PATCH_HALVE_V;
}

// Whether a patch of flux `flux`, descended from a seed of `seedFlux`, may be split `ways`: only
// while its children (halves or quarters) keep at least the energy threshold (min_energy_fraction
// of the seed's flux). A patch due a split it may not make ends as a kill by energy (endOfStep),
// as its children would have after one step each; a child of a split that would need another is
// stepped once first (scatter). Near grazing incidence on a smoothed interface a stretched patch
// split until then made thousands of such children per seed (PatchStepper::mayBeSplit).
bool mayBeSplit(float flux, float seedFlux, int ways) {
  return (ways == kSplitQuarters ? 0.25 : 0.5) * flux >= P.step.z * seedFlux;
}

float maxEdgeOf(vec3 x[4]) {
  float e = 0.0;
  for (int k = 0; k < 4; ++k) e = max(e, length(x[(k + 1) % 4] - x[k]));
  return e;
}

// ---- Straight steps across homogeneous regions (splatSegment / straightSteps in wavefront.cpp;
// docs/light-simulator.md, "Straight steps") ----

// Skip distance D (voxels) of the voxel holding x (VolumeField::skipDistance: nearest voxel, clamped).
float skipAt(vec3 x) { return imageLoad(skipImg, voxelAt(x)).w; }

// The centre's straight path c0 + s·u, s ∈ [0, L], deposits flux(s)·len/h³ into every voxel it
// crosses (flux(s) = E0·exp(−σs) at the piece's midpoint, len the piece's length), and
// HighestEnergy sees flux(s)/area(s) with area(τ) = |½ (A + τB) × (C + τD)|, τ = s/ds1 steps.
// A voxel walk (Amanatides & Woo 1987) over the part of the segment inside the grid.
void splatSegment(vec3 c0, vec3 u, float L, float E0, float sigma, vec3 dir, float ds1, vec3 dA, vec3 dB, vec3 dC,
                  vec3 dD) {
  const float h = P.grid_origin.w;
  const vec3 g0 = P.grid_origin.xyz, g1 = P.grid_origin.xyz + vec3(P.grid_dims.xyz) * h;
  float sA = 0.0, sB = L;
  for (int a = 0; a < 3; ++a) {
    if (u[a] == 0.0) {
      if (c0[a] < g0[a] || c0[a] >= g1[a]) return;
      continue;
    }
    float t0 = (g0[a] - c0[a]) / u[a], t1 = (g1[a] - c0[a]) / u[a];
    sA = max(sA, min(t0, t1));
    sB = min(sB, max(t0, t1));
  }
  if (!(sA < sB)) return;
  ivec3 i, stepI;
  vec3 tNext, tDelta;
  for (int a = 0; a < 3; ++a) {
    const float ga = (c0[a] + sA * u[a] - g0[a]) / h;
    i[a] = clamp(int(floor(ga)), 0, P.grid_dims[a] - 1);
    if (u[a] > 0.0) {
      stepI[a] = 1, tDelta[a] = h / u[a];
      tNext[a] = (g0[a] + float(i[a] + 1) * h - c0[a]) / u[a];
    } else if (u[a] < 0.0) {
      stepI[a] = -1, tDelta[a] = -h / u[a];
      tNext[a] = (g0[a] + float(i[a]) * h - c0[a]) / u[a];
    } else {
      stepI[a] = 0, tDelta[a] = 0.0, tNext[a] = 1e30;
    }
  }
  float sCur = sA;
  const int guard = P.grid_dims.x + P.grid_dims.y + P.grid_dims.z + 3;
  for (int it = 0; it < guard; ++it) {
    const int a = tNext.x <= tNext.y ? (tNext.x <= tNext.z ? 0 : 2) : (tNext.y <= tNext.z ? 1 : 2);
    const float sEnd = min(tNext[a], sB);
    if (sEnd > sCur) {
      const float sm = 0.5 * (sCur + sEnd), flux = E0 * exp(-sigma * sm);
      const float value = flux * (sEnd - sCur) * P.step.w;  // W/mm²; toFixed scales
      const float tau = ds1 > 0.0 ? sm / ds1 : 0.0;
      splatVoxel(i, value, dir);
      if (hasOption(EIKON_WO_HIGHEST)) {
        const float area = 0.5 * length(cross(dA + tau * dB, dC + tau * dD));
        splatHighest(i, area > 0.0 ? flux / area : 0.0);
      }
      sCur = sEnd;
    }
    if (sCur >= sB) break;
    i[a] += stepI[a];
    if (i[a] < 0 || i[a] >= P.grid_dims[a]) break;
    tNext[a] += tDelta[a];
  }
}

// The corners lie in different regions, or only some have been mirrored: the patch is being torn
// by a boundary; it is not split and not tested for a caustic until all four are on one side.
// Reflected copies: so are a copy's corners while only some of them have turned back.
bool straddles(ivec4 region) {
  const ivec4 r = region & EIKON_CORNER_REGION;
  const ivec4 mir = region & (EIKON_CORNER_MIRRORED | EIKON_CORNER_PENDING);
  return r.y != r.x || r.z != r.x || r.w != r.x || mir.y != mir.x || mir.z != mir.x || mir.w != mir.x;
}

bool anyPending(ivec4 region) { return any(notEqual(region & EIKON_CORNER_PENDING, ivec4(0))); }

bool anyMirrored(ivec4 region) { return any(notEqual(region & EIKON_CORNER_MIRRORED, ivec4(0))); }

// The corners met different boundaries, or one boundary with different outcomes (PatchStepper::torn
// in wavefront.cpp): event counts (modulo 256) more than one apart, or equal counts with different
// regions, mirror bits or face digests.
bool torn(ivec4 region) {
  const ivec4 ev = (region & EIKON_CORNER_EVENTS) >> EIKON_CORNER_EVENT_SHIFT;
  const ivec4 side = region & (EIKON_CORNER_REGION | EIKON_CORNER_MIRRORED | EIKON_CORNER_FACES);
  bool t = false;
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) {
      const int d = (ev[a] - ev[b]) & 0xFF;
      t = t || (d == 0 ? side[a] != side[b] : d != 1 && d != 0xFF);
    }
  return t;
}

// The face digest after crossing plane `face` (≥ 0) of region `owner`'s polyhedron (faceDigest in
// core/light/wavefront_types.h).
int faceDigest(int h, int owner, int face) { return (h * 17 + 7 * owner + face + 1) & 63; }

// Corner k's event count + 1 (modulo 256), its region and mirror bit unchanged.
int addEvent(int corner) {
  return (corner & ~EIKON_CORNER_EVENTS) | ((corner + EIKON_CORNER_EVENT) & EIKON_CORNER_EVENTS);
}

// How far (mm) a corner at x moving along v goes in region r before it meets the region's boundary
// (nextCrossing over the bounds' diagonal), less kStraightMarginVoxels; the diagonal if it meets
// none. PatchStepper::straightClear in wavefront.cpp.
const float kStraightMarginVoxels = 1e-3;
float straightClear(vec3 x, vec3 v, int r) {
  const float L = length(P.grid_max.xyz - P.grid_origin.xyz);
  const BoundaryCrossing c = nextCrossing(x, x + L * normalize(v), r);
  return c.found ? c.t * L - kStraightMarginVoxels * P.grid_origin.w : L;
}

// How many time steps the patch (corners x, w) may take at once along straight lines (0: take
// an RK4 step), and the corners' constant velocities v = dx/dt; the rules of straightSteps in
// wavefront.cpp: centre and corners in voxels of skip distance D ≥ 2, the centre's voxel not
// opaque, no radial axis field, a centre outside the bounds headed for them; k keeps every point
// within (D − 1.5)·h of its start, within max_steps, ends at the first step below the energy
// threshold (σ > 0), and is cut at the first step j at which single steps would split, meet a
// caustic or leave.
int straightSteps(vec3 x[4], vec3 w[4], vec4 flux, ivec4 state, ivec4 region, out vec3 v[4], out float sigma1) {
  for (int k = 0; k < 4; ++k) v[k] = vec3(0.0);
  sigma1 = 0.0;
  if (!hasOption(EIKON_WO_SKIP)) return 0;
  // Sharp interfaces: all four corners in one region on one side of every mirror (a torn patch
  // takes single steps), moving at that medium's constant velocity.
  const int r0 = regionOf(region.x);
  if (kSharpLight && (straddles(region) || mediumOpaque(r0))) return 0;
  const vec3 c0 = centreOf(x);
  // Sharp: the centre reads no field but the opacity, tested below at every time step's midpoint
  // as single steps would, so only the corners need skip distances (the host binds the sharp
  // path's own, core/light/sharp_skip.h).
  const float Dc = kSharpLight ? 0.0 : skipAt(c0);
  if (!kSharpLight && Dc < 2.0) return 0;
  // Sharp, with crossings found on the shapes or their planes (no walk): each corner's way to its
  // region's boundary is searched exactly (straightClear), so a corner near a surface, whose skip
  // distance is below 2, may still go straight up to it.
  const bool exactClear = kSharpLight && hasOption(EIKON_WO_TO_BOUNDARY) &&
                          (EIKON_BOUNDARY_CONVEX_APART || EIKON_BOUNDARY_EXACT);
  float D[4];
  for (int k = 0; k < 4; ++k) {
    D[k] = skipAt(x[k]);
    if (D[k] < 2.0 && !exactClear) return 0;
  }
  if (mediumAt(c0).w >= 0.5) return 0;
  const vec3 wm = 0.25 * (w[0] + w[1] + w[2] + w[3]);
  const float wl = length(wm);
  if (!(wl > 0.0)) return 0;
  const bool in0 = insideBounds(c0);
  if (!in0 && (state.z != 0 || !rayHitsBox(c0, wm / wl))) return 0;
  vec3 vc = vec3(0.0);
  float absorb1 = 0.0;  // sharp: Σ σ·length of the corners over one time step
  for (int k = 0; k < 4; ++k) {
    if (kSharpLight) {
      v[k] = mediumVelocity(r0, w[k]);
      absorb1 += mediumSigma(r0, w[k]) * length(v[k]) * P.step.x;
    } else {
      if (eMode() && axisField(x[k]).w > 0.0) return 0;  // radial axis: a varies
      vec3 dw;
      deriv(x[k], w[k], v[k], dw);
    }
    vc += 0.25 * v[k];
  }
  const float dt = P.step.x, h = P.grid_origin.w, maxEdge = P.step.y;
  float kmax = float(P.control.z - state.w);
  float sp = length(vc) * dt;
  if (!kSharpLight && sp > 0.0) kmax = min(kmax, floor((Dc - 1.5) * h / sp));
  for (int k = 0; k < 4; ++k) {
    sp = length(v[k]) * dt;
    if (!(sp > 0.0)) continue;
    float kk = floor((D[k] - 1.5) * h / sp);
    if (exactClear) kk = max(kk, floor(straightClear(x[k], v[k], r0) / sp));
    kmax = min(kmax, kk);
  }
  // Energy: below the threshold already (a split's child): one step; else the first step below it.
  // Sharp: a single step's factor is exp(−¼ Σ σ·length) over the corners (sharpCorner), the same
  // each step; sigma1 = −log of it per unit of the centre's path.
  const float ds1 = length(vc) * dt, thr = P.step.z * flux.z;
  if (kSharpLight && ds1 > 0.0) sigma1 = 0.25 * absorb1 / ds1;
  if (flux.x < thr) {
    kmax = min(kmax, 1.0);
  } else if (ds1 > 0.0) {
    const vec3 m = c0 + 0.5 * dt * vc;
    const float sigma = kSharpLight ? sigma1 : eMode() ? sigmaE(m, wm) : bandAt(mediumAt(m).xyz);
    if (sigma > 0.0 && thr > 0.0) kmax = min(kmax, floor(log(flux.x / thr) / (sigma * ds1)) + 1.0);
  }
  if (kmax < 1.0) return 0;
  const int K = int(kmax);
  // A mirror reverses the orientation (endOfStep).
  const int orient = kSharpLight && anyMirrored(region) ? -state.y : state.y;
  bool entered = state.z != 0 || in0;
  int j = 1;
  do {  // (K ≥ 1; a do-while: llvmpipe runs a for loop ended by its test one more pass, masked)
    vec3 xj[4];
    for (int k = 0; k < 4; ++k) xj[k] = x[k] + (float(j) * dt) * v[k];
    const float o = dot(0.5 * cross(xj[2] - xj[0], xj[3] - xj[1]), wm);
    const vec3 c = centreOf(xj);
    bool stop = maxEdgeOf(xj) > maxEdge || (o > 0.0 && orient < 0) || (o < 0.0 && orient > 0);
    if (insideBounds(c))
      entered = true;
    else if (entered || !rayHitsBox(c, wm / wl))
      stop = true;
    // Sharp: the opacity kill at the step's midpoint (attenuateStep reads it at the same point).
    if (kSharpLight && mediumAt(c0 + (float(j) - 0.5) * dt * vc).w >= 0.5) stop = true;
    if (stop) return j;
  } while (++j <= K);
  return K;
}

// ---- One propagation, stage by stage (the same stages, under the same names, as the reference's
// in core/reference/wavefront.cpp; docs/twins.md) ----

// What a patch's step leaves for the stages after it.
struct PatchStep {
  int kStraight;  // time steps taken along straight lines (0: one RK4 step)
  vec3 c0, c1;    // the centre before and after
  vec3 wm0;       // the mean w before
  vec3 dA, dB, dC, dD;  // straight step: the diagonals at the start and their change per time step
  vec3 vc;              // straight step: the centre's velocity (the mean of the corners')
  float ds;       // |c1 − c0|
  float sigma;    // attenuation at the step's midpoint
  float E0;       // flux before the step
  float fluxMid;  // flux at the step's middle
  // Sharp interfaces: the factors of the corners' crossings over the step, each the product over
  // the four corners of a fourth root (Fresnel transmission; attenuation exp(−σ·length)).
  float fresnel;
  float attenuation;
  // Reflected copies: the product over the pending corners that reflected in this step of T^¼.
  float gain;
};

// ---- Sharp interfaces: the stages of PatchStepper (core/reference/wavefront.cpp) ----

// Biaxial regions A and B with the same tensor (indices and axes): a crossing changes the region only.
bool sameBiaxial(int A, int B) {
  return mediumIndex(A, 0) == mediumIndex(B, 0) && mediumIndex(A, 2) == mediumIndex(B, 2) &&
         mediumIndex(A, 1) == mediumIndex(B, 1) && mediumRow(A, 7).xyz == mediumRow(B, 7).xyz &&
         mediumRow(A, 20).xyz == mediumRow(B, 20).xyz;
}

// The outgoing wave of the run's mode in region r with tangential wave vector pt, on the side +m
// (transmitted) or −m (reflected), m along the incident ray (PatchStepper::modeRoot): a biaxial
// region's root (solveBiaxialMode; D its unit D), a uniaxial one's o or e root, an isotropic one's
// Snell root (solveInterfaceMode; D zero).
ModeWave modeRoot(int r, vec3 pt, vec3 m, bool transmitted, out vec3 D) {
  D = vec3(0.0);
  if (mediumBiaxial(r)) return solveBiaxialMode(pt, m, biaxialAt(r), runMode(), transmitted, D);
  const bool u = mediumUniaxial(r);
  const float no = mediumIndex(r, 0);
  return solveInterfaceMode(pt, m, u && eMode(), mediumRow(r, 7).xyz, no, u ? mediumIndex(r, 1) : no, transmitted);
}

// The transmission of the run's mode through a face with a biaxial side, o the outgoing wave (D its
// unit D when B is biaxial): crystal → crystal none lost; otherwise T = 1 − (w_s R_s + (1 − w_s) R_p)
// with the isotropic R_s, R_p from |w| to o.n at the wave normal's incidence and w_s = (D̂·ŝ_⊥)², the
// mode's D on the crystal side along N × ŝ (the view march's biaxial weight; the CPU twin takes the
// exact Maxwell powers, equal at normal incidence).
float biaxialTransmission(int A, int B, vec3 w, vec3 N, ModeWave o, vec3 D) {
  const bool cA = mediumBiaxial(A) || mediumUniaxial(A), cB = mediumBiaxial(B) || mediumUniaxial(B);
  if (cA && cB) return 1.0;
  const vec3 s = normalize(w);
  const vec2 rsp = fresnelRsRp(min(1.0, abs(dot(s, N))), length(w), o.n);
  if (cA) D = biaxialWave(biaxialAt(A), w, runMode()).D;
  const vec3 c = cross(N, s);
  const float ds = dot(c, c) < 1e-12 ? sqrt(0.5) : dot(D, normalize(c)), ws = ds * ds;
  return 1.0 - (ws * rsp.x + (1.0 - ws) * rsp.y);
}

// Corner at the crossing c (x the crossing point, w the incident wave vector, its region A = from):
// the exact laws between the media of A and c.to. Isotropic ↔ isotropic: Snell and T = 1 − ½(Rs +
// Rp); into a crystal: the run's mode (solveInterfaceMode on its shell) with T = 1 − (w_s Rs +
// (1 − w_s) Rp), the D-projection share of fresnel.glsl (the CPU twin takes the exact Maxwell
// share, uniaxialEntryExact: equal at normal incidence, a few 1e-3 apart at oblique incidence on
// calcite, docs/uniaxial-optics.md); out of a crystal: the same with the incident mode's index;
// crystal → crystal: the phase-matched wave of the same mode, no loss; a biaxial side: the mode's
// roots (modeRoot) and the D-projection share (biaxialTransmission). Where the outgoing wave does
// not exist: total internal reflection, the mirror wave of the same mode, no loss; the corner's
// mirror bit flips and it stays in A. Equal media, or an opaque one entered: only the region
// changes. Multiplies `transmission` by T; true if the corner was turned. A pending corner of a
// reflected copy (EIKON_CORNER_PENDING) takes the mirror wave where its twin's corner goes through,
// stays in A and multiplies `gain` by that T instead (PatchStepper::crossInterface).
bool crossInterface(BoundaryCrossing c, int A, inout vec3 w, inout int corner, inout float transmission,
                    inout float gain) {
  const int B = c.to;
  const vec3 N = c.normal;
  const bool uA = mediumUniaxial(A), uB = mediumUniaxial(B), e = eMode();
  const float noA = mediumIndex(A, 0), noB = mediumIndex(B, 0);
  const float neA = uA ? mediumIndex(A, 1) : 0.0, neB = uB ? mediumIndex(B, 1) : 0.0;
  const vec3 aA = mediumRow(A, 7).xyz, aB = mediumRow(B, 7).xyz;
  const bool bA = mediumBiaxial(A), bB = mediumBiaxial(B);
  const bool same = bA || bB ? bA && bB && sameBiaxial(A, B)
                             : noA == noB && neA == neB && (!uA || aA == aB);
  const bool reflects = (corner & EIKON_CORNER_PENDING) != 0;
  corner &= ~EIKON_CORNER_PENDING;
  corner = addEvent(corner);  // every region change or mirror is an event (torn)
  if (c.face >= 0) {
    const int h = (corner & EIKON_CORNER_FACES) >> EIKON_CORNER_FACE_SHIFT;
    corner = (corner & ~EIKON_CORNER_FACES) |
             (faceDigest(h, max(A, B), c.face) << EIKON_CORNER_FACE_SHIFT);
  }
  if (same || mediumOpaque(B) || !(length(N) > 0.0)) {
    corner = (corner & ~EIKON_CORNER_REGION) | B;
    return false;
  }
  const vec3 s = normalize(w);
  const int mode = e ? 1 : 0;
  // The incident wave's tangential part: along the energy flow of A's mode (a crystal's ray M_e w).
  const vec3 m = uA && !uB ? orientNormal(N, normalize(mediumVelocity(A, s))) : orientNormal(N, s);
  const float nIn = uA && e ? inversesqrt(dot(s, applyM(s, aA, noA, neA))) : noA;
  const vec3 pt = nIn * s - dot(nIn * s, m) * m;
  ModeWave o;
  float T = 1.0;
  bool mirror = false;
  // A biaxial side: m̂ along the incident ray, the mode's roots (modeRoot).
  vec3 mb = N, ptb = w;
  if (bA || bB) {
    mb = orientNormal(N, mediumVelocity(A, w));
    ptb = w - dot(w, mb) * mb;
    vec3 D;
    o = modeRoot(B, ptb, mb, true, D);
    if (o.exists) T = biaxialTransmission(A, B, w, N, o, D);
    if (!o.exists) {
      o = modeRoot(A, ptb, mb, false, D);
      mirror = true;
    }
  } else if (!uB || !uA) {  // isotropic → isotropic, into a crystal, out of a crystal
    o = solveInterfaceMode(pt, m, uB && e, aB, noB, uB ? neB : noB, true);
    if (o.exists) {
      const vec2 rsp = fresnelRsRp(min(1.0, abs(dot(s, N))), nIn, o.n);
      const float ws = uA || uB ? sWeight(uB ? o.s : s, uB ? aB : aA, N, s, mode) : 0.5;
      T = 1.0 - (ws * rsp.x + (1.0 - ws) * rsp.y);
    }
  } else {  // crystal → crystal
    const vec3 mc = dot(mediumVelocity(A, w), N) >= 0.0 ? N : -N;
    const vec3 ptc = w - dot(w, mc) * mc;
    o = solveInterfaceMode(ptc, mc, e, aB, noB, neB, true);
    if (!o.exists || reflects) {
      o = solveInterfaceMode(ptc, mc, e, aA, noA, neA, false);
      mirror = true;
    }
  }
  if (reflects && o.exists && !mirror) {  // a reflected copy's corner: the mirror, gain T
    gain *= T;
    o.exists = false;
  }
  if (!o.exists && !mirror) {  // total internal reflection (or a crystal mode that cannot enter)
    vec3 D;
    o = bA ? modeRoot(A, ptb, mb, false, D) : solveInterfaceMode(pt, m, uA && e, aA, noA, uA ? neA : noA, false);
    mirror = true;
  }
  if (!o.exists) {  // degenerate (grazing): go on unturned
    corner = (corner & ~EIKON_CORNER_REGION) | B;
    return false;
  }
  w = o.n * o.s;
  if (mirror) {
    corner ^= EIKON_CORNER_MIRRORED;
  } else {
    corner = (corner & ~EIKON_CORNER_REGION) | B;
    transmission *= T;
  }
  return true;
}

// A corner moves for the step's time dt through homogeneous media: straight in its region's medium
// up to the first boundary, turned there (crossInterface) and on for the rest of dt (at most 16
// crossings). Its share of the patch's factors: T^¼ of each transmission, exp(−σ·length/4).
void sharpCorner(inout vec3 x, inout vec3 w, inout int corner, inout PatchStep st) {
  float T = P.step.x, absorb = 0.0, trans = 1.0, gain = 1.0;
  for (int guard = 0; T > 0.0; ++guard) {
    const int r = regionOf(corner);
    const vec3 d = T * mediumVelocity(r, w);
    const float len = length(d);
    BoundaryCrossing c;
    c.found = false;
    if (guard < 16) c = nextCrossing(x, x + d, r);
    if (!c.found) {
      absorb += mediumSigma(r, w) * len;
      x += d;
      break;
    }
    absorb += mediumSigma(r, w) * c.t * len;
    x = c.point;
    T *= 1.0 - c.t;
    crossInterface(c, r, w, corner, trans, gain);
  }
  st.fresnel *= pow(trans, 0.25);
  if (hasOption(EIKON_WO_REFLECT)) st.gain *= pow(gain, 0.25);
  st.attenuation *= exp(-0.25 * absorb);
}


// Whether no shape's surface lies within len of x, so that a corner moving len from x crosses
// none: on the exact path with at most kExactUnrollShapes spheres, boxes and rounded boxes, whose
// signed distances are Euclidean (with a margin of kExactMergeVoxels for their rounding). The
// same answer as the search (no crossing), so the CPU twin, whose search costs little, has none.
bool shapesClear(vec3 x, float len) {
  // (Two tests: glslang 11 makes invalid SPIR-V of a chain of four || over specialisation
  // constants, an OpSpecConstantOp of the short circuit's OpPhi.)
  if (!EIKON_BOUNDARY_EXACT || EIKON_BOUNDARY_EXACT_SHAPES > kExactUnrollShapes) return false;
  if ((EIKON_BOUNDARY_EXACT_KINDS & ((1 << EIKON_SHAPE_CONVEX) | (1 << EIKON_SHAPE_MESH))) != 0)
    return false;
  const float margin = len + kExactMergeVoxels * P.grid_origin.w;
  bool clear = true;
  [[unroll]] for (int i = 0; i < EIKON_BOUNDARY_EXACT_SHAPES; ++i)
    clear = clear && abs(shapeSignedDistance(i, x)) > margin;
  return clear;
}

// The four corners' sharp step. A corner that moves at most (D − 1.5)·h from a voxel of skip
// distance D meets no boundary (the argument of straight steps; the CPU twin's sharpCorner skips
// its search by the same test), nor one that every exact shape lies farther from than its move
// (shapesClear): it moves straight. The others take sharpCorner one after another in a do-while
// over a mask. llvmpipe runs a branch's code under a mask whatever its lanes decide, but a loop's
// body only while some lane of the SIMD group still loops (a do-while: not once more to find that
// none does), so a group runs as many searches as its busiest lane needs, at least one (masked),
// instead of four (docs/performance.md, "Light simulator").
void sharpCorners(inout vec3 x[4], inout vec3 w[4], inout ivec4 region, inout PatchStep st) {
  uint search = 0u;
  float absorb = 0.0;
  for (int k = 0; k < 4; ++k) {
    const int r = regionOf(region[k]);
    const vec3 d = P.step.x * mediumVelocity(r, w[k]);
    const float len = length(d);
    if ((hasOption(EIKON_WO_SKIP) && len <= (skipAt(x[k]) - 1.5) * P.grid_origin.w) || shapesClear(x[k], len)) {
      absorb += mediumSigma(r, w[k]) * len;
      x[k] += d;
    } else {
      search |= 1u << k;
    }
  }
  st.attenuation *= exp(-0.25 * absorb);
  if (search != 0u) do {
    const int k = findLSB(search);
    vec3 xk = x[0], wk = w[0];
    int rk = region[0];
    for (int j = 1; j < 4; ++j)
      if (j == k) xk = x[j], wk = w[j], rk = region[j];
    sharpCorner(xk, wk, rk, st);
    for (int j = 0; j < 4; ++j)
      if (j == k) x[j] = xk, w[j] = wk, region[j] = rk;
    search &= search - 1u;
  } while (search != 0u);
}

vec3 meanOf(vec3 w[4]) { return 0.25 * (w[0] + w[1] + w[2] + w[3]); }

// Advance the corners by one RK4 time step, or by k time steps along straight lines (w is then
// unchanged: ∇n = 0), and count the time steps in state.w.
PatchStep moveStep(inout vec3 x[4], inout vec3 w[4], inout WavePatch p) {
  const float dt = P.step.x;
  PatchStep st;
  st.c0 = centreOf(x);
  st.wm0 = meanOf(w);
  vec3 vel[4];
  float sigma1;
  // (the flux ahead: a reflected copy's own and what its pending corners will reflect in)
  st.kStraight = straightSteps(x, w, vec4(p.flux.x + p.refl.x, p.flux.yzw), p.state, p.region, vel, sigma1);
  st.dA = vec3(0.0), st.dB = vec3(0.0), st.dC = vec3(0.0), st.dD = vec3(0.0);
  st.vc = vec3(0.0);
  st.fresnel = 1.0;
  st.attenuation = 1.0;
  st.gain = 1.0;
  // The sharp corners and RK4 under the constant kSharpLight, so that each run's pipeline holds
  // only one of them (llvmpipe would run both under masks).
  if (st.kStraight > 0) {
    st.dA = x[2] - x[0], st.dB = dt * (vel[2] - vel[0]), st.dC = x[3] - x[1], st.dD = dt * (vel[3] - vel[1]);
    for (int k = 0; k < 4; ++k) st.vc += 0.25 * vel[k];  // as straightSteps sums it
    const float T = float(st.kStraight) * dt;
    for (int k = 0; k < 4; ++k) x[k] += T * vel[k];
    p.state.w += st.kStraight;
    // Sharp: no boundary on the way (no Fresnel), the corners' attenuation over the path.
    if (kSharpLight) st.attenuation = exp(-sigma1 * length(centreOf(x) - st.c0));
  } else if (kSharpLight) {
    sharpCorners(x, w, p.region, st);
    ++p.state.w;
  } else {
    for (int k = 0; k < 4; ++k) rk4(x[k], w[k], dt);
    ++p.state.w;
  }
  st.c1 = centreOf(x);
  st.ds = length(st.c1 - st.c0);
  return st;
}

// flux ← flux·exp(−σΔs), σ at the midpoint of the centre's path; returns the medium there.
// Sharp interfaces: first the corners' Fresnel losses (added to `reflected`), then their
// attenuation; σ is the mean over the centre's path.
vec4 attenuateStep(inout WavePatch p, inout PatchStep st, vec3 w[4], inout float reflected) {
  // Sharp straight steps: the medium (the opacity kill) at the last time step's midpoint, where
  // single steps would have read it (straightSteps stops there when it is opaque).
  const vec3 m = kSharpLight && st.kStraight > 0 ? st.c0 + (float(st.kStraight) - 0.5) * P.step.x * st.vc
                                                 : 0.5 * (st.c0 + st.c1);
  const vec4 med = mediumAt(m);
  float att;
  if (kSharpLight) {
    reflected += p.flux.x * (1.0 - st.fresnel);
    p.flux.x *= st.fresnel;
    if (hasOption(EIKON_WO_REFLECT)) {
      // A reflected copy: what its pending corners reflected, taken from the flux the crossing
      // dropped; once all four have reflected the rest of the shadow is the transmitted twin's.
      const float gained = p.refl.x * (1.0 - st.gain);
      p.flux.x += gained;
      reflected -= gained;
      p.refl.x = anyPending(p.region) ? p.refl.x - gained : 0.0;
    }
    st.sigma = st.ds > 0.0 ? -log(st.attenuation) / st.ds : 0.0;
    att = st.attenuation;
    st.fluxMid = p.flux.x * sqrt(att);
  } else {
    st.sigma = eMode() ? sigmaE(m, 0.5 * (st.wm0 + meanOf(w))) : bandAt(med.xyz);
    att = exp(-st.sigma * st.ds);
    st.fluxMid = p.flux.x * exp(-0.5 * st.sigma * st.ds);
  }
  st.E0 = p.flux.x;
  p.flux.w += p.flux.x * (1.0 - att);
  p.flux.x *= att;
  p.refl.x *= att;
  return med;
}

// Splat the step (splatSegment after a straight step, else splatAt at the midpoint); returns the
// propagation direction: ŵ for the o-mode, the centre's motion (the energy direction) for the e-mode.
vec3 splatStep(PatchStep st, vec3 x[4], vec3 w[4]) {
  const float area = length(0.5 * cross(x[2] - x[0], x[3] - x[1]));
  const vec3 wm = meanOf(w);
  const float wl = length(wm);
  const vec3 dir = eMode() || hasFlag(EIKON_F_BIAXIAL) ? (st.ds > 0.0 ? (st.c1 - st.c0) / st.ds : vec3(0.0)) : (wl > 0.0 ? wm / wl : vec3(0.0));
  if (st.kStraight > 0) {
    if (st.ds > 0.0)
      splatSegment(st.c0, (st.c1 - st.c0) / st.ds, st.ds, st.E0, st.sigma, dir, st.ds / float(st.kStraight), st.dA,
                   st.dB, st.dC, st.dD);
  } else {
    splatAt(0.5 * (st.c0 + st.c1), st.fluxMid * st.ds * P.step.w, area > 0.0 ? st.fluxMid / area : 0.0, dir);
  }
  return dir;
}

// Probe plane: the centre crossed it over this step (the side before the step is that of c0;
// the reference keeps the side through splits, which differs only for a child whose centre
// lies across the plane from its parent's).
void probeStep(PatchStep st, inout vec4 probePos, inout vec3 probeDir) {
  if (!hasOption(EIKON_WO_PROBE)) return;
  const int probeAxis = P.control.x;
  const float pp = P.probe.x;
  const bool before = st.c0[probeAxis] >= pp, after = st.c1[probeAxis] >= pp;
  if (before == after) return;
  const float sg = after ? 1.0 : -1.0, span = st.c1[probeAxis] - st.c0[probeAxis];
  const float f = span != 0.0 ? clamp((pp - st.c0[probeAxis]) / span, 0.0, 1.0) : 0.5;
  // Flux at the crossing: mid-step (RK4 step) or at the crossing point (straight step).
  const float fx = st.kStraight > 0 ? st.E0 * exp(-st.sigma * f * st.ds) : st.fluxMid;
  probePos += sg * fx * vec4(st.c0 + f * (st.c1 - st.c0), 1.0);
  if (st.ds > 0.0) probeDir += sg * fx * (st.c1 - st.c0) / st.ds;
}

// The end-of-step tests, in the reference's order: opaque, left, caustic (or passed through),
// energy, split. True if the patch stops here (p.state.x says why).
bool endOfStep(inout WavePatch p, PatchStep st, vec4 med, vec3 x[4], vec3 w[4]) {
  if (med.w >= 0.5) {
    p.state.x = EIKON_PATCH_OPAQUE;
    return true;
  }
  const vec3 wm = meanOf(w);
  const float wl = length(wm);
  if (insideBounds(st.c1)) {
    p.state.z = 1;
  } else if (p.state.z != 0 || !(wl > 0.0) || !rayHitsBox(st.c1, wm / wl)) {
    p.state.x = EIKON_PATCH_LEFT;
    return true;
  }
  const float o = dot(0.5 * cross(x[2] - x[0], x[3] - x[1]), wm);
  // Sharp interfaces: a mirror reverses the orientation; a patch torn by a boundary is not tested.
  const int orient = kSharpLight && anyMirrored(p.region) ? -p.state.y : p.state.y;
  const bool straddling = kSharpLight && straddles(p.region);
  if (!straddling && ((o > 0.0 && orient < 0) || (o < 0.0 && orient > 0))) {
    if (!hasOption(EIKON_WO_PASS_CAUSTICS)) {
      p.state.x = EIKON_PATCH_CAUSTIC;
      return true;
    }
    p.state.y = -p.state.y;  // pass_caustics: through the focal line, orientation reversed
  }
  // Energy: below the threshold, or due a split whose children would be (mayBeSplit).
  const int ways = straddling ? kSplitNone : splitWays(x);
  const bool stretched = ways != kSplitNone;
  const float ahead = p.flux.x + p.refl.x;  // a reflected copy's flux and its shadow
  if (ahead < P.step.z * p.flux.z || (stretched && !mayBeSplit(ahead, p.flux.z, ways))) {
    p.state.x = EIKON_PATCH_ENERGY;
    return true;
  }
  if (kSharpLight && torn(p.region)) {  // four pencils (the list rebuild, as a split)
    p.state.x = EIKON_PATCH_TORN;
    return true;
  }
  if (stretched) {
    p.state.x = splitState(ways);
    return true;
  }
  return false;
}

void propagate(uint id) {
  if (id >= pc.control.x) return;
  WavePatch p = loadPatch(id);
  p.flux.w = 0.0;
  for (int k = 0; k < 4; ++k) {  // the probe sums are per propagation
    p.x[k].w = 0.0;
    p.w[k].w = 0.0;
  }
  if (p.state.x != EIKON_PATCH_ALIVE) {
    storePatch(id, p);
    return;
  }
  vec4 probePos = vec4(0.0);
  vec3 probeDir = vec3(0.0);
  float reflected = 0.0;
  vec3 x[4], w[4];
  for (int k = 0; k < 4; ++k) {
    x[k] = p.x[k].xyz;
    w[k] = p.w[k].xyz;
  }
  if (kSharpLight && p.region.x < 0)  // a seed: each corner in its region, on its medium's shell
    for (int k = 0; k < 4; ++k) {
      p.region[k] = regionAt(x[k]);
      w[k] = mediumShell(p.region[k], normalize(w[k]));
    }
  // The steps of this dispatch: a do-while, as a for loop ended by its test runs one more whole
  // step on llvmpipe, masked, to find that no lane goes on.
  int it = 0;
  if (P.control.y > 0 && p.state.w < P.control.z) do {
      // Reflected wavefronts: a step of a whole patch that takes a Fresnel loss at a crossing is
      // undone, and the list rebuild writes the patch (armed) and its reflected copy, which both
      // take it from the state before (PatchStepper::advance).
      const bool mayReflect = hasOption(EIKON_WO_REFLECT) && float(P.options.w) > p.refl.y &&
                              p.refl.z == 0.0 && !anyPending(p.region) && !straddles(p.region);
      const vec3 x0[4] = x, w0[4] = w;
      const ivec4 region0 = p.region, state0 = p.state;
      PatchStep st = moveStep(x, w, p);
      p.refl.z = 0.0;
      if (mayReflect && st.kStraight == 0 && st.fresnel < 1.0) {
        x = x0, w = w0, p.region = region0, p.state = state0;
        p.state.x = EIKON_PATCH_REFLECT;
        break;
      }
      const vec4 med = attenuateStep(p, st, w, reflected);
      splatStep(st, x, w);
      probeStep(st, probePos, probeDir);
      if (endOfStep(p, st, med, x, w)) break;
    } while (++it < P.control.y && p.state.w < P.control.z);
  p.x[0] = vec4(x[0], probePos.x);
  p.x[1] = vec4(x[1], probePos.y);
  p.x[2] = vec4(x[2], probePos.z);
  p.x[3] = vec4(x[3], probePos.w);
  p.w[0] = vec4(w[0], probeDir.x);
  p.w[1] = vec4(w[1], probeDir.y);
  p.w[2] = vec4(w[2], probeDir.z);
  p.w[3] = vec4(w[3], reflected);
  storePatch(id, p);
}

// ---- list rebuild (the COUNT* passes are in wavefront_count.comp, so that this shader carries no
// barrier: llvmpipe implements barriers with coroutines) ----
void scatter(uint id) {
  const uint n = pc.control.x;
  if (id >= n) return;
  const uint o = scan[id], next = id + 1u < n ? scan[id + 1u] : scan[pc.control.z];
  if (next == o) return;
  WavePatch p = loadPatch(id);
  p.flux.w = 0.0;
  for (int k = 0; k < 4; ++k) {  // the probe sums were counted
    p.x[k].w = 0.0;
    p.w[k].w = 0.0;
  }
  if (kSharpLight && p.state.x == EIKON_PATCH_REFLECT) {
    // The patch, armed, and (unless the budget refused it) its reflected copy: one generation
    // deeper, every corner pending, no flux of its own and the patch's as its shadow.
    p.state.x = EIKON_PATCH_ALIVE;
    p.refl.z = 1.0;
    storeOther(o, p);
    if (next - o == 2u) {
      WavePatch c = p;
      c.refl = vec4(p.flux.x, p.refl.y + 1.0, 0.0, 0.0);
      c.flux.x = 0.0;
      for (int k = 0; k < 4; ++k) c.region[k] |= EIKON_CORNER_PENDING;
      storeOther(o + 1u, c);
    }
    return;
  }
  if (next - o == 1u) {  // kept (a refused split goes on unsplit, as in the reference)
    p.state.x = EIKON_PATCH_ALIVE;
    storeOther(o, p);
    return;
  }
  if (kSharpLight && p.state.x == EIKON_PATCH_TORN) {
    // Four pencils, one per corner (PatchStepper::emit): all four corners on the corner's ray, in
    // its region, with its mirror bit and event count; a quarter of the flux each.
    for (int k = 0; k < 4; ++k) {
      WavePatch c = p;
      for (int j = 0; j < 4; ++j) {
        c.x[j] = vec4(p.x[k].xyz, 0.0);
        c.w[j] = vec4(p.w[k].xyz, 0.0);
        c.region[j] = p.region[k];
      }
      c.flux.x = 0.25 * p.flux.x;
      c.flux.y = 0.25 * p.flux.y;
      c.refl.x = 0.25 * p.refl.x;
      c.state.x = EIKON_PATCH_ALIVE;
      storeOther(o + uint(k), c);
    }
    return;
  }
  // Quarters (EIKON_PATCH_SPLIT) or halves across the u or v edges (EIKON_PATCH_HALVE_U, _V) on
  // the bilinear 3×3 lattice, only its points the children use; the parent's corners are kept
  // exactly (PatchStepper::splitInto).
  const int ways = p.state.x == EIKON_PATCH_SPLIT ? kSplitQuarters
                   : p.state.x == EIKON_PATCH_HALVE_U ? kSplitU : kSplitV;
  vec3 X[9], W[9];
  for (int b = 0; b < 3; ++b)
    for (int a = 0; a < 3; ++a) {
      if ((ways == kSplitU && b == 1) || (ways == kSplitV && a == 1)) continue;  // not used
      const float fa = 0.5 * float(a), fb = 0.5 * float(b);
      const float w0 = (1.0 - fa) * (1.0 - fb), w1 = fa * (1.0 - fb), w2 = fa * fb, w3 = (1.0 - fa) * fb;
      X[b * 3 + a] = w0 * p.x[0].xyz + w1 * p.x[1].xyz + w2 * p.x[2].xyz + w3 * p.x[3].xyz;
      vec3 ww = w0 * p.w[0].xyz + w1 * p.w[1].xyz + w2 * p.w[2].xyz + w3 * p.w[3].xyz;
      // Back onto the region's medium's shell (sharp), or the mode's shell in the field (the
      // test on the constant first, so that a sharp kernel keeps no read of the index fields).
      if (kSharpLight) {
        if (a == 1 || b == 1) ww = mediumShell(regionOf(p.region.x), normalize(ww));
      } else if (a == 1 || b == 1) {
        ww = onShell(X[b * 3 + a], normalize(ww));
      }
      W[b * 3 + a] = ww;
    }
  X[0] = p.x[0].xyz, X[2] = p.x[1].xyz, X[8] = p.x[2].xyz, X[6] = p.x[3].xyz;
  W[0] = p.w[0].xyz, W[2] = p.w[1].xyz, W[8] = p.w[2].xyz, W[6] = p.w[3].xyz;
  const int children = ways == kSplitQuarters ? 4 : 2;
  const float share = ways == kSplitQuarters ? 0.25 : 0.5;  // equal parameter areas
  for (int i = 0; i < children; ++i) {
    // The child's parameter ranges [a0, a1] × [b0, b1] on the lattice.
    const int a0 = ways == kSplitV ? 0 : (ways == kSplitU ? i : (i & 1));
    const int a1 = ways == kSplitV ? 2 : a0 + 1;
    const int b0 = ways == kSplitU ? 0 : (ways == kSplitV ? i : (i >> 1));
    const int b1 = ways == kSplitU ? 2 : b0 + 1;
    WavePatch c = p;
    const int pa[4] = int[4](a0, a1, a1, a0), pb[4] = int[4](b0, b0, b1, b1);
    vec3 cx[4];
    for (int k = 0; k < 4; ++k) {
      cx[k] = X[pb[k] * 3 + pa[k]];
      c.x[k] = vec4(cx[k], 0.0);
      c.w[k] = vec4(W[pb[k] * 3 + pa[k]], 0.0);
    }
    c.flux.x = share * p.flux.x;
    c.flux.y = share * p.flux.y;
    c.refl.x = share * p.refl.x;
    const int cw = splitWays(cx);
    c.state.x = cw != kSplitNone && mayBeSplit(c.flux.x + c.refl.x, c.flux.z, cw) ? splitState(cw)
                                                                                  : EIKON_PATCH_ALIVE;
    storeOther(o + uint(i), c);
  }
}

void main() {
  const uint id = gl_GlobalInvocationID.x, mode = pc.control.y;
  P = params;
  if (mode == EIKON_WM_PROPAGATE)
    propagate(id);
  else if (mode == EIKON_WM_SCATTER)
    scatter(id);
}
