// The eikonal march shared by view.comp and trace.comp (GPU twin of core/reference/reference_marcher.cpp).
//
// Ray equation with the spatial arc parameter s (docs/design.md §2; Ihrke et al. 2007 eq. 3):
//   dx/ds = w / n(x),   dw/ds = ∇n(x),   w = n·dx/ds, invariant |w| = n.
// Integrated with a fixed step ds = march.x · h by Euler, midpoint (RK2) or classical RK4; inside
// homogeneous regions (skip distance D ≥ 2 voxels) the ray crosses (D − 1.5)·h in one straight
// step, exact because every field is constant there. Interfaces are the layers where |∇n|·h
// rises above 1e-6: on leaving a layer whose peak exceeded march.y, the ray either crossed it
// (Fresnel: transmitted fraction 1 − R with the full unpolarised equations, and an external
// reflection that samples the environment) or was turned back by total internal reflection, which
// the ODE produces by itself (no Fresnel loss).
#ifndef EIKON_MARCH_GLSL
#define EIKON_MARCH_GLSL

layout(std430, binding = EIKON_B_PARAMS) readonly buffer ParamsBuf { ViewParams params; };
// A private copy of the parameter block, made once by loadParams() at the top of main(). llvmpipe
// reads a storage buffer lane by lane in a scalar loop wherever a lane mask is active (inside any
// branch or loop), so P.x read from the buffer in the march loop cost a loop per component; the
// copy is a register (or stack) read (docs/performance.md).
ViewParams P;

void loadParams() { P = params; }

// The PCG integer hash (core/spectrum/wavelength_sampling.h pcgHash, bit-exact).
uint pcg_hash(uint v) {
  uint state = v * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

// Full transport's random choices (core/contract/march_types.h transportSeed, transportUniform;
// bit-exact): the seed of a pixel sample's march in one mode, the same at every wavelength, and
// its k-th uniform number in [0, 1), 24 bits (exact in float).
uint transportSeed(uint pixel, uint sampleIndex, int mode) {
  return pcg_hash(pixel * 0x9E3779B1u ^ pcg_hash(sampleIndex * 4u + uint(mode) + 0x5BD1E995u));
}
float transportUniform(uint seed, uint k) {
  return float(pcg_hash(seed + k * 0x632BE5ABu) >> 8u) * (1.0 / 16777216.0);
}
layout(binding = EIKON_B_INDEX_O_A, rgba32f) readonly uniform image3D idxOA;
layout(binding = EIKON_B_INDEX_O_B, rgba32f) readonly uniform image3D idxOB;
layout(binding = EIKON_B_INDEX_O_C, rgba32f) readonly uniform image3D idxOC;
layout(binding = EIKON_B_INDEX_E_A, rgba32f) readonly uniform image3D idxEA;
layout(binding = EIKON_B_INDEX_E_B, rgba32f) readonly uniform image3D idxEB;
layout(binding = EIKON_B_INDEX_E_C, rgba32f) readonly uniform image3D idxEC;
layout(binding = EIKON_B_MEDIUM_O, rgba32f) readonly uniform image3D mediumO;
layout(binding = EIKON_B_MEDIUM_E, rgba32f) readonly uniform image3D mediumE;
layout(binding = EIKON_B_EMISSION, rgba32f) readonly uniform image3D emissionImg;
layout(binding = EIKON_B_AXIS, rgba32f) readonly uniform image3D axisImg;
layout(binding = EIKON_B_SCATTER, rgba32f) readonly uniform image3D scatterImg;
layout(binding = EIKON_B_LIGHT_FLUENCE, rgba32f) readonly uniform image3D lightFluenceImg;
layout(binding = EIKON_B_LIGHT_FLUX, rgba32f) readonly uniform image3D lightFluxImg;
layout(std430, binding = EIKON_B_ENV_IMAGE) readonly buffer EnvBuf { vec4 envTexels[]; };
// A uniform block (8.9 KiB): the CIE and basis tables are read at a varying index in the march,
// which llvmpipe does with a gather there, one lane at a time for a storage buffer.
layout(std140, binding = EIKON_B_TABLES) uniform TableBuf { vec4 tables[EIKON_TABLE_COUNT]; };
layout(binding = EIKON_B_REGION, r32ui) readonly uniform uimage3D regionImg;
layout(binding = EIKON_B_BOUNDARY_DIST, r32f) readonly uniform image3D boundaryDist;
layout(std430, binding = EIKON_B_SHAPES) readonly buffer ShapeBuf { vec4 shapeTable[]; };
layout(std430, binding = EIKON_B_MEDIA) readonly buffer MediaBuf { vec4 mediaTable[]; };
// The shape table's first rows and the medium table as uniform blocks (eikon_shared.h,
// EIKON_B_EXACT_ROWS and EIKON_B_SMALL_MEDIA): what the exact path and, with EIKON_F_SMALL_MEDIA,
// the sharp march read in their loops.
layout(std140, binding = EIKON_B_EXACT_ROWS) uniform ExactRowsBuf { vec4 exactRows[EIKON_EXACT_MAX_ROWS]; };
layout(std140, binding = EIKON_B_SMALL_MEDIA) uniform SmallMediaBuf {
  vec4 smallMedia[EIKON_SMALL_MEDIA_REGIONS * EIKON_MEDIUM_VEC4S];
};
#define EIKON_EXACT_ROW(i) exactRows[i]
#define EIKON_SHAPE_ROW(i) (hasFlag(EIKON_F_SMALL_SHAPES) ? exactRows[i] : shapeTable[i])
#define EIKON_MEDIUM_ROW(i) (hasFlag(EIKON_F_SMALL_MEDIA) ? smallMedia[i] : mediaTable[i])

// The wavelength of the march (setWavelength, before each march). Globals, unlike the per-ray
// PathRecord below: constant for the length of a march and read by nearly every function of it
// (each field sample through field.glsl's EIKON_FIELD_LAMBDA_UM / IL2 / IL4, each colour through
// colourOf), like the parameter block P.
float gLambdaUm = 0.5876;
float gIl2 = 1.0 / (0.5876 * 0.5876);
float gIl4 = gIl2 * gIl2;
bool gScalar = false;  // spectral/trace: radiance and attenuation at gLambdaUm, carried in .x (broadcast)

void setWavelength(float lambda_um, bool scalar) {
  gLambdaUm = lambda_um;
  gIl2 = 1.0 / (lambda_um * lambda_um);
  gIl4 = gIl2 * gIl2;
  gScalar = scalar;
}

// The record of one pixel sample's path that wavelength sharing and hero sampling evaluate at
// other wavelengths (view.comp), created by the caller of march() and passed to every stage that
// reads or writes it (`inout PathRecord rec`; the field helpers get `inout bool dispersive`).
//
// Wavelength sharing (view.comp, stratified spectral passes): while marching the first wavelength
// of a pixel sample with `record` set, note whether any sample saw dispersion (B or C ≠ 0, a
// dispersive medium) or a weight that depends on λ (attenuation, emission along the path,
// in-scatter, a lit surface: each sets `dispersive` where it adds something), and record every
// environment lookup and opaque surface's emission as (linear sRGB radiance, weight). If none did,
// the path and every weight are the same at all wavelengths: the others are Σ weight·S(λ, rgb),
// without marching.
//
// Hero wavelength sampling (view.comp, docs/spectra.md) uses the same record differently: while
// `hero` is set and the hero's path has met nothing dispersive (`dispersive` false), every
// environment lookup is recorded as (linear sRGB radiance, weight × `weight`) and left out of the
// march's radiance — view.comp evaluates it at all N wavelengths, which share the path up to
// there. From the path's first dispersive event on (or a 7th lookup, which the record cannot hold:
// the cut depends on the path alone, not on λ) lookups are the hero's alone.
const int kRecordMax = 6;
struct PathRecord {
  bool record;      // wavelength sharing: record the lookups
  bool hero;        // hero sampling: record the lookups before the first dispersive event
  float weight;     // hero: the mode's share of the light, times each recorded weight
  bool overflow;    // wavelength sharing: a lookup found the record full
  bool dispersive;  // the path met something that depends on λ
  int count;        // entries used
  uint pixel;       // full transport: the pixel and pixel sample the march's choices are drawn for
  uint sampleIndex; //   (transportSeed)
  int firstChoice;  // full transport: kChoiceDrawn, or the branch of the split first choice to march
  // (linear sRGB radiance, weight). Indexed only by constants (recordPush, and loops of constant
  // count that are unrolled): llvmpipe keeps such an array in registers, where one indexed at run
  // time would live in memory and be copied whole at every inout call.
  vec4 entries[kRecordMax];
};

// Appends (rgb, weight) to the record, which has room (count < kRecordMax).
void recordPush(inout PathRecord rec, vec3 rgb, float weight) {
  for (int i = 0; i < kRecordMax; ++i)  // a constant count: unrolled (constant indices)
    if (i == rec.count) rec.entries[i] = vec4(rgb, weight);
  rec.count++;
}

// A record that records nothing (RGB and trace marches; the start of each strategy's).
PathRecord noRecord() {
  PathRecord rec;
  rec.record = false;
  rec.hero = false;
  rec.weight = 1.0;
  rec.overflow = false;
  rec.dispersive = false;
  rec.count = 0;
  rec.pixel = 0u;
  rec.sampleIndex = 0u;
  rec.firstChoice = 0;
  for (int i = 0; i < kRecordMax; ++i) rec.entries[i] = vec4(0.0);
  return rec;
}

// A record for pixel sample `sampleIndex` of `pixel` (view.comp), which seeds its full transport.
PathRecord sampleRecord(uint pixel, int sampleIndex) {
  PathRecord rec = noRecord();
  rec.pixel = pixel;
  rec.sampleIndex = uint(sampleIndex);
  return rec;
}

// Specialization constants (core/render/view_renderer.cpp: one pipeline per feature set). llvmpipe
// (lavapipe) executes both sides of every branch with a lane mask and every loop body at least
// once, so a step costs all the code in the march loop whatever the scene uses; constants fold
// the features away instead (docs/performance.md).
//   kSharpMarch: the sharp march (EIKON_F_SHARP) instead of the smoothed one;
//   kViewFlags: the EIKON_F_* flags of the scene and the render (also in P.grid_dims.w), always
//     given (core/render/view_renderer.cpp specialisationOf): hasFlag tests the constant itself,
//     so that SPIR-V's own constant folding removes what a flag turns off (core/vk/specialise.h);
//   kIntegrator: EIKON_INT_* (P.march.w; −1: read from P at run time);
//   kExact: on the exact path (EIKON_F_EXACT, core/volume/boundary.h exact) the shape table's
//     rows in bits 0–9, the shape count in bits 10–19 and the kinds present (1 << EIKON_SHAPE_*)
//     in bits 20–24 (boundary.glsl exactCrossingOutOf) and bit 25 set, so that a scene without
//     shapes (whose counts are 0) is on the exact path too; 0 otherwise.
//   kAov: the march notes its first interface (MarchResult.hit…; view.comp's AOV layer). Off, the
//     notes fold away and a render without the layer runs the code it ran before.
layout(constant_id = 0) const bool kSharpMarch = false;
layout(constant_id = 1) const int kViewFlags = -1;
layout(constant_id = 2) const int kIntegrator = -1;
layout(constant_id = 3) const bool kAov = false;
layout(constant_id = 4) const int kExact = 0;

#define EIKON_FIELD_FLAGS kViewFlags
#define EIKON_FIELD_INV_H P.grid_extent.w
#define EIKON_FIELD_LAMBDA_UM gLambdaUm
#define EIKON_FIELD_IL2 gIl2
#define EIKON_FIELD_IL4 gIl4
#define EIKON_FIELD_HAS_AXIS hasFlag(EIKON_F_UNIAXIAL)
#define EIKON_BOUNDARY_HAS_CONVEX hasFlag(EIKON_F_CONVEX)
#define EIKON_BOUNDARY_HAS_MESH hasFlag(EIKON_F_MESH)
#define EIKON_BOUNDARY_CONVEX_APART hasFlag(EIKON_F_CONVEX_APART)
#define EIKON_BOUNDARY_EXACT (hasFlag(EIKON_F_EXACT) && kExact != 0)
#define EIKON_BOUNDARY_EXACT_ROWS (kExact & 0x3FF)
#define EIKON_BOUNDARY_EXACT_SHAPES ((kExact >> 10) & 0x3FF)
#define EIKON_BOUNDARY_EXACT_KINDS ((kExact >> 20) & 0x1F)
#include "field.glsl"
#include "boundary.glsl"

vec3 sampleEmission(vec3 x) {
  Stencil s = stencilAt(x);
  return TRI(emissionImg, s).xyz;
}

// (albedo_r, albedo_g, albedo_b, g); zero where nothing scatters.
vec4 sampleScatter(vec3 x) {
  if (!hasFlag(EIKON_F_SCATTER)) return vec4(0.0);
  Stencil s = stencilAt(x);
  return TRI(scatterImg, s);
}

// Linear sRGB colour → smooth spectrum value at gLambdaUm (core/spectrum/rgb_to_spectrum.h).
float rgbToSpectrum(vec3 rgb) {
  float t = clamp((gLambdaUm * 1000.0 - 380.0) / 5.0, 0.0, 80.0);
  int i = min(int(floor(t)), 79);
  float f = t - float(i);
  vec3 b = mix(tables[EIKON_BASIS_OFFSET + i].xyz, tables[EIKON_BASIS_OFFSET + i + 1].xyz, f);
  return max(rgb.g + (rgb.r - rgb.g) * b.x + (rgb.b - rgb.g) * b.z, 0.0);
}

// Attenuation and colours in the current mode: RGB triplets, or the value at λ broadcast.
vec3 sigmaOf(vec3 bands) { return gScalar ? vec3(bandAt(bands)) : bands; }
vec3 colourOf(vec3 rgb) { return gScalar ? vec3(rgbToSpectrum(rgb)) : rgb; }

// Environment radiance in direction d (unit), linear sRGB (colourOf turns it into the value at λ).
// Same formulas as Environment::lookup (scene.cpp).
vec3 environmentRgb(vec3 d);

// Radiance rgb (linear sRGB, the same at every λ of the path) times a throughput weight, recorded
// for wavelength sharing: the environment's (environmentWeighted) and an opaque surface's own
// emission (surfaceWeighted).
vec3 recordedWeighted(inout PathRecord rec, vec3 weight, vec3 rgb) {
  if (hasFlag(EIKON_F_SPECTRAL) && rec.hero && !rec.dispersive) {
    if (rec.count < kRecordMax) {
      recordPush(rec, rgb, weight.x * rec.weight);
      return vec3(0.0);
    }
    rec.dispersive = true;  // the record is full: from here on the hero's alone
  }
  if (hasFlag(EIKON_F_SPECTRAL) && rec.record) {  // only view.comp's spectral mode records
    if (rec.count < kRecordMax) recordPush(rec, rgb, weight.x);
    else rec.overflow = true;
  }
  return weight * colourOf(rgb);
}

vec3 environmentWeighted(inout PathRecord rec, vec3 weight, vec3 d) {
  return recordedWeighted(rec, weight, environmentRgb(d));
}

// An opaque surface's emission rgb seen with weight, plus the light it reflects (diffuse, which
// depends on λ through the light volumes: a path that sees any is not shared).
vec3 surfaceWeighted(inout PathRecord rec, vec3 weight, vec3 rgb, vec3 diffuse) {
  if (hasFlag(EIKON_F_LIT) && any(notEqual(diffuse, vec3(0.0)))) rec.dispersive = true;
  return recordedWeighted(rec, weight, rgb) + weight * diffuse;
}

vec3 environmentRgb(vec3 d) {
  float u = atan(d.x, -d.z) / (2.0 * kPi) + 0.5;
  float v = acos(clamp(d.y, -1.0, 1.0)) / kPi;
  const int type = hasFlag(EIKON_F_ENV_LATLONG)    ? EIKON_ENV_LATLONG
                   : hasFlag(EIKON_F_ENV_CONSTANT) ? EIKON_ENV_CONSTANT
                                                   : EIKON_ENV_CHECKER;
  vec3 c;
  if (type == EIKON_ENV_CONSTANT) {
    c = P.env_a.xyz;
  } else if (type == EIKON_ENV_CHECKER) {
    float sq = P.env.y;
    int iu = int(floor(u * 2.0 * sq)), iv = int(floor(v * sq));
    c = ((iu + iv) & 1) != 0 ? P.env_b.xyz : P.env_a.xyz;
  } else {
    int W = P.env_size.x, H = P.env_size.y;
    float fx = u * float(W) - 0.5, fy = v * float(H) - 0.5;
    int x0 = int(floor(fx)), y0 = int(floor(fy));
    float tx = fx - float(x0), ty = fy - float(y0);
    int xa = ((x0 % W) + W) % W, xb = (((x0 + 1) % W) + W) % W;
    int ya = clamp(y0, 0, H - 1), yb = clamp(y0 + 1, 0, H - 1);
    c = mix(mix(envTexels[ya * W + xa].xyz, envTexels[ya * W + xb].xyz, tx),
            mix(envTexels[yb * W + xa].xyz, envTexels[yb * W + xb].xyz, tx), ty);
  }
  return c * P.env.z;
}

#include "fresnel.glsl"

// Light from the light simulator (docs/design.md §2 image formation, Tevs eq. 5.10; docs/light-simulator.md).
// φ (fluence rate, W/mm², linear sRGB) and the net flux vector F of its luminance φ_Y, trilinear.
// Henyey–Greenstein phase function of cos θ (θ between the light's and the scattered direction).
float phaseHG(float cosTheta, float g) {
  float d = 1.0 + g * g - 2.0 * g * cosTheta;
  return (1.0 - g * g) / (4.0 * kPi * d * sqrt(d));
}

// Radiance scattered towards the eye per unit length at x, for a ray travelling along d, before
// multiplying by the path transmittance: σ_s·p·φ with σ_s = albedo·σ_t. The light in a voxel is
// one mean direction m = F/φ_Y with |m| ≤ 1 (1 for a single collimated beam): the phase function
// is |m|·p_HG(m̂·(−d)) + (1 − |m|)/4π, i.e. the part of the light that does not share the mean
// direction is treated as isotropic.
vec3 inScatter(vec3 x, vec3 d, vec3 sigmaT) {
  vec4 sc = sampleScatter(x);
  if (sc.x + sc.y + sc.z <= 0.0) return vec3(0.0);
  Stencil s = stencilAt(x);
  vec4 phi = TRI(lightFluenceImg, s);
  if (phi.w <= 0.0) return vec3(0.0);
  vec3 m = TRI(lightFluxImg, s).xyz / phi.w;
  float lm = min(length(m), 1.0);
  float p = (1.0 - lm) / (4.0 * kPi);
  if (lm > 1e-6) p += lm * phaseHG(dot(normalize(m), -d), sc.w);
  return sigmaOf(sc.xyz) * sigmaT * colourOf(phi.xyz) * p;
}

// Radiance of a diffuse (Lambertian) opaque surface hit at x: albedo·E/π with E = φ·max(0, −m·N),
// the irradiance on the surface of outward normal N from the light volumes sampled 1.5 voxels
// outside the surface (clear of the opaque voxels, where nothing is splatted). N is the
// normalised −∇opacity by central differences of the trilinear opacity.
vec3 diffuseSurface(vec3 x, int mode) {
  // The albedo field is composited with the object's coverage, like the opacity: at the stop
  // point (opacity ≥ 0.5) the surface's own albedo is their ratio.
  if (!hasFlag(EIKON_F_LIT)) return vec3(0.0);
  vec4 sc = sampleScatter(x) / max(sampleMedium(x, mode).w, 0.5);
  if (sc.x + sc.y + sc.z <= 0.0) return vec3(0.0);
  float h = P.grid_origin.w;
  vec3 g = vec3(sampleMedium(x + vec3(h, 0, 0), mode).w - sampleMedium(x - vec3(h, 0, 0), mode).w,
                sampleMedium(x + vec3(0, h, 0), mode).w - sampleMedium(x - vec3(0, h, 0), mode).w,
                sampleMedium(x + vec3(0, 0, h), mode).w - sampleMedium(x - vec3(0, 0, h), mode).w);
  if (dot(g, g) <= 0.0) return vec3(0.0);
  vec3 N = -normalize(g);
  Stencil s = stencilAt(x + 1.5 * h * N);
  vec4 phi = TRI(lightFluenceImg, s);
  if (phi.w <= 0.0) return vec3(0.0);
  float cosFactor = max(0.0, -dot(TRI(lightFluxImg, s).xyz, N)) / phi.w;
  return sigmaOf(sc.xyz) * colourOf(phi.xyz) * (cosFactor / kPi);
}

// Ray–box slab test; returns false if the line misses. t0 ≤ t1.
bool boxHit(vec3 o, vec3 d, vec3 bmin, vec3 bmax, out float t0, out float t1) {
  vec3 inv = 1.0 / mix(d, vec3(1e-30), equal(d, vec3(0.0)));
  vec3 ta = (bmin - o) * inv, tb = (bmax - o) * inv;
  vec3 lo = min(ta, tb), hi = max(ta, tb);
  t0 = max(max(lo.x, lo.y), lo.z);
  t1 = min(min(hi.x, hi.y), hi.z);
  return t1 >= max(t0, 0.0);
}

struct MarchResult {
  bool split;  // full transport: the first Fresnel choice was met and split (PathRecord.firstChoice)
  vec3 radiance;
  vec3 exit_point;
  vec3 exit_dir;     // ray (energy) direction
  vec3 wave_normal;
  vec3 throughput;
  float opl;
  bool left;
  bool cut;  // the driver's loop budget (sharp.glsl loopLimitReached) or max steps ran out
  int steps;
  float drift;
  int interfaces;
  int tir;
  // kAov: the first interface met (core/contract/march_types.h FirstInterface): its point, unit
  // normal facing the ray's origin, and scene object (−1 unknown: smoothed interfaces).
  bool hit;
  vec3 hitPoint;
  vec3 hitNormal;
  int hitObject;
};

vec3 axisAt(vec3 x) { return axisField(x).xyz; }

// Derivatives of (x, w) with respect to ray arc length s.
//  o-mode (docs/design.md §2, isotropic form): dx/ds = w/n, dw/ds = ∇n on the shell |w| = n.
//  e-mode (Hamiltonian H = ½(pᵀM_e p − 1), w = p): eModeRates (field.glsl) divided by |M p| to
//    step in arc length. Where there is no axis the e-mode is the o-mode.
// `dispersive`: set where a sample saw dispersion (sampleIndex), as in every helper below.
void deriv(vec3 x, vec3 w, int mode, inout bool dispersive, out vec3 dx, out vec3 dw) {
  vec4 o = sampleIndex(x, 0, dispersive);
  vec4 af = mode == 1 ? axisField(x) : vec4(0.0);
  if (!hasAxis(af.xyz)) {
    // Isotropic Hamiltonian M = I/n² in ray arc length: dx/ds = w/|w|, dw/ds = |w|∇n/n. On the
    // shell |w| = n this is dx/ds = w/n, dw/ds = ∇n; off it the ray still moves at unit speed and
    // |w|/n is an invariant of the flow, and it is the e-mode's equation with n_o = n_e.
    float lw = length(w);
    dx = w * (1.0 / lw);  // one division, not three
    dw = o.yzw * (lw / o.x);
    return;
  }
  vec3 Mp, dp;
  eModeRates(w, af, o, sampleIndex(x, 1, dispersive), Mp, dp);
  float L = length(Mp);
  dx = Mp / L;
  dw = dp / L;
}

// Ray direction of mode `mode` for wave vector w at x.
vec3 rayDirection(vec3 x, vec3 w, int mode, inout bool dispersive) {
  if (mode == 0) return normalize(w);
  vec3 a = axisAt(x);
  if (!hasAxis(a)) return normalize(w);
  return normalize(applyM(w, a, sampleIndex(x, 0, dispersive).x, sampleIndex(x, 1, dispersive).x));
}

// Attenuation per unit ray length of `mode` at x for wave vector w (band values or the value at λ);
// the e-mode's is pleochroic (attenuationE, field.glsl).
vec3 attenuationAt(vec3 x, vec3 w, int mode, inout bool dispersive) {
  vec3 so = sigmaOf(sampleMedium(x, 0).xyz);
  if (mode == 0) return so;
  vec3 a = axisAt(x);
  if (!hasAxis(a)) return so;
  vec3 se = sigmaOf(sampleMedium(x, 1).xyz);
  return attenuationE(so, se, w, a, sampleIndex(x, 0, dispersive).x, sampleIndex(x, 1, dispersive).x);
}

// ---- The march, stage by stage (the same stages, under the same names, as ReferenceMarcher's in
// core/reference/reference_marcher.cpp; docs/twins.md) ----

// The state of one march between its stages.
struct MarchState {
  vec3 x;        // position (mm)
  vec3 w;        // wave vector (|w| = n for the o-mode)
  vec4 nn;       // (n_o, ∇n_o) at x
  vec3 T;        // throughput
  vec3 L;        // radiance gathered so far
  bool stopped;  // at an opaque surface
  int region;    // sharp march: the boundary-field region the ray is in
  // The interface layer being crossed: where it opened, w before it, Σ∇n·ds over it, its peak
  // (|∇n|·h)² (layerGradient2).
  bool inLayer;
  float peak2;
  vec3 wBefore;
  vec3 gAcc;
  vec3 xOpen;
  vec3 xPeak;  // kAov: where the layer's |∇n|·h peaked so far
  // Full transport (P.transport; core/contract/march_types.h Transport): the seed of the march's
  // choices, the uniforms drawn so far, and the reflections followed.
  uint seed;
  uint draws;
  int reflections;
  int firstChoice;  // PathRecord.firstChoice
  bool split;       // the first choice was met and split
};

// The march's state before its first step: at x with wave vector w, nothing gathered, the
// choices seeded for the record's pixel sample and `mode`.
MarchState startState(vec3 x, vec3 w, int mode, PathRecord rec) {
  MarchState S;
  S.x = x;
  S.w = w;
  S.nn = vec4(0.0);
  S.T = vec3(1.0);
  S.L = vec3(0.0);
  S.stopped = false;
  S.region = 0;
  S.inLayer = false;
  S.peak2 = 0.0;
  S.wBefore = w;
  S.gAcc = vec3(0.0);
  S.xOpen = x;
  S.xPeak = x;
  S.seed = transportSeed(rec.pixel, rec.sampleIndex, mode);
  S.draws = 0u;
  S.reflections = 0;
  S.firstChoice = rec.firstChoice;
  S.split = false;
  return S;
}

// How a march makes its path's first Fresnel choice (core/contract/march_types.h FirstChoice): a
// view sample splits it, marching the transmitted branch at weight 1 − R and, where that path met
// a choice, the reflected one at weight R (view.comp marchModes).
const int kChoiceDrawn = 0;
const int kChoiceTransmit = 1;
const int kChoiceReflect = 2;

// Full transport (P.transport.x), while the path has followed fewer than P.transport.y
// reflections: true (the path reflects, counted) with probability Rf, else false (it refracts),
// in both cases at its whole weight (Russian roulette with the Fresnel weights; the CPU twin's
// RayMarch::followReflection). The first choice, where split, is the march's branch at its weight.
bool followReflection(inout MarchState S, float Rf) {
  if (P.transport.x == 0 || S.reflections >= P.transport.y) return false;
  bool first = S.draws == 0u;
  bool reflects = transportUniform(S.seed, S.draws) < Rf;
  S.draws++;
  if (first && S.firstChoice != kChoiceDrawn) {
    S.split = true;
    reflects = S.firstChoice == kChoiceReflect;
    S.T *= reflects ? Rf : 1.0 - Rf;
  }
  if (reflects) S.reflections++;
  return reflects;
}

// Mode conversion's second draw (sharp.glsl convertAtFace; the CPU twin's RayMarch::
// convertAtFace): path mode 0 with probability p0, else 1, the next uniform of the path's stream.
int drawMode(inout MarchState S, float p0) {
  bool zero = transportUniform(S.seed, S.draws) < p0;
  S.draws++;
  return zero ? 0 : 1;
}

// Whether a crossing weighs the path by 1 − R and looks its external reflection up in the
// environment (the single transmitted path): transport single, or past the reflection limit.
bool singlePathWeights(MarchState S) { return P.transport.x == 0 || S.reflections >= P.transport.y; }

// What an integration step leaves for the stages after it.
struct StepEnd {
  vec3 x0, w0;  // the step's start
  vec4 ne;      // (n_e, ∇n_e) at the step's end (the o-mode's where isotropic)
  vec3 aHere;   // optic axis there (e-mode)
  bool eHere;   // the e-mode in a crystal there
  vec3 gradN;   // the gradient the layer normal accumulates
};

const int kStepNone = 0;   // not homogeneous here: integrate
const int kStepTaken = 1;  // a straight step was taken
const int kStepStop = 2;   // the march ends (opaque surface, or out of the volume)

// Homogeneous region (skip distance D ≥ 2 voxels): one straight, exact step of (D − 1.5)·h along
// the ray direction, with the emission and attenuation integrated in closed form.
int straightStep(inout MarchState S, inout MarchResult R, inout PathRecord rec, int mode) {
  vec4 em = vec4(0.0);
  if (!S.inLayer && !hasFlag(EIKON_F_NO_SKIP)) em = imageLoad(emissionImg, voxelAt(S.x));
  if (em.w < 2.0) return kStepNone;
  const vec3 bmin = P.grid_origin.xyz, bmax = P.grid_origin.xyz + P.grid_extent.xyz;
  const float h = P.grid_origin.w;
  vec3 dir = rayDirection(S.x, S.w, mode, rec.dispersive);
  float tb0, tb1;
  boxHit(S.x, dir, bmin, bmax, tb0, tb1);
  float tExit = max(tb1, 0.0);
  float len = (em.w - 1.5) * h;
  // A lit scattering medium is homogeneous but its light is not: sample the light every voxel.
  bool scattering = hasFlag(EIKON_F_LIT) && hasFlag(EIKON_F_SCATTER) && dot(sampleScatter(S.x).xyz, vec3(1.0)) > 0.0;
  if (scattering) len = min(len, h);
  bool leaving = len >= tExit;
  len = min(len, tExit);
  if (hasFlag(EIKON_F_OPACITY) && sampleMedium(S.x, mode).w >= 0.5) {
    S.L += surfaceWeighted(rec, S.T, em.xyz / sampleMedium(S.x, mode).w, diffuseSurface(S.x, mode));
    S.stopped = true;
    return kStepStop;
  }
  if (hasFlag(EIKON_F_EMISSION) || hasFlag(EIKON_F_ATTENUATION)) {
    vec3 sig = hasFlag(EIKON_F_ATTENUATION) ? attenuationAt(S.x, S.w, mode, rec.dispersive) : vec3(0.0);
    vec3 e = colourOf(em.xyz);
    // In-scatter with the light at the middle of this straight step, constant over it.
    if (scattering) e += inScatter(S.x + 0.5 * len * dir, dir, sig);
    if (any(notEqual(sig, vec3(0.0))) || any(notEqual(e, vec3(0.0)))) rec.dispersive = true;
    vec3 att = exp(-sig * len);
    // ∫₀^len T e^{−σs} e ds = T e (1 − e^{−σ len})/σ  (→ T e len as σ → 0)
    S.L += S.T * mix(e * len, e * (1.0 - att) / max(sig, vec3(1e-30)), greaterThan(sig, vec3(1e-6)));
    S.T *= att;
  }
  R.opl += dot(S.w, dir) * len;  // ∫ p·dx
  S.x += dir * len;
  return leaving ? kStepStop : kStepTaken;
}

// One integration step of the ray equation (Euler, midpoint or RK4), then the fields at its end,
// the optical path and (o-mode) the drift of the invariant |w| = n.
StepEnd integrateStep(inout MarchState S, inout MarchResult R, inout bool dispersive, int mode) {
  const float ds = P.march.x * P.grid_origin.w;
  const int integrator = kIntegrator == -1 ? int(P.march.w) : kIntegrator;
  StepEnd E;
  E.x0 = S.x;
  E.w0 = S.w;
  float n0 = S.nn.x;
  vec3 k1x, k1w, k2x, k2w, k3x, k3w, k4x, k4w;
  deriv(S.x, S.w, mode, dispersive, k1x, k1w);
  if (integrator == EIKON_INT_EULER) {
    S.x += ds * k1x;
    S.w += ds * k1w;
  } else if (integrator == EIKON_INT_MIDPOINT) {
    deriv(S.x + 0.5 * ds * k1x, S.w + 0.5 * ds * k1w, mode, dispersive, k2x, k2w);
    S.x += ds * k2x;
    S.w += ds * k2w;
  } else {
    deriv(S.x + 0.5 * ds * k1x, S.w + 0.5 * ds * k1w, mode, dispersive, k2x, k2w);
    deriv(S.x + 0.5 * ds * k2x, S.w + 0.5 * ds * k2w, mode, dispersive, k3x, k3w);
    deriv(S.x + ds * k3x, S.w + ds * k3w, mode, dispersive, k4x, k4w);
    S.x += ds / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
    S.w += ds / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
  }
  S.nn = sampleIndex(S.x, 0, dispersive);
  E.gradN = S.nn.yzw;
  E.aHere = mode == 1 ? axisAt(S.x) : vec3(0.0);
  E.eHere = mode == 1 && hasAxis(E.aHere);
  E.ne = E.eHere ? sampleIndex(S.x, 1, dispersive) : S.nn;
  if (mode == 0) {
    R.drift = max(R.drift, abs(length(S.w) - S.nn.x));
    R.opl += 0.5 * (n0 + S.nn.x) * ds;
  } else {
    R.opl += 0.5 * dot(E.w0 + S.w, S.x - E.x0);
    if (E.eHere) E.gradN = 0.5 * (S.nn.yzw + E.ne.yzw);
  }
  return E;
}

// Emission, attenuation and in-scatter at the step's midpoint (only sampled where the scene has
// any); true if the step ended on an opaque surface.
bool mediumAlongStep(inout MarchState S, inout PathRecord rec, StepEnd E, int mode) {
  const float ds = P.march.x * P.grid_origin.w;
  vec3 xm = 0.5 * (E.x0 + S.x);
  if (hasFlag(EIKON_F_EMISSION)) {
    vec3 e = sampleEmission(xm);
    if (any(notEqual(e, vec3(0.0)))) rec.dispersive = true;  // λ-dependent (wavelength sharing)
    S.L += S.T * colourOf(e) * ds;
  }
  if (hasFlag(EIKON_F_ATTENUATION)) {
    vec3 sig = attenuationAt(xm, 0.5 * (E.w0 + S.w), mode, rec.dispersive);
    if (any(notEqual(sig, vec3(0.0)))) rec.dispersive = true;
    if (hasFlag(EIKON_F_LIT) && hasFlag(EIKON_F_SCATTER)) S.L += S.T * inScatter(xm, normalize(S.x - E.x0), sig) * ds;
    S.T *= exp(-sig * ds);
  }
  if (hasFlag(EIKON_F_OPACITY) && sampleMedium(S.x, mode).w >= 0.5) {
    // Surface emission: the emission field over the coverage (opacity ≥ 0.5 here), as the albedo.
    S.L += surfaceWeighted(rec, S.T, sampleEmission(S.x) / sampleMedium(S.x, mode).w, diffuseSurface(S.x, mode));
    S.stopped = true;
    return true;
  }
  return false;
}

// Back on the constraint surface H = 0 (|w| = n for the o-mode, wᵀM_e w = 1 for the e-mode)
// along the layer normal N: the tangential part of w is what the interface conserves (Snell).
// The stored central-difference gradient is not exactly the derivative of the trilinear n, which
// makes H drift by ~1e-4 across a sharp layer. Only for thin layers (interfaces no thicker than
// 12 voxels along their normal), never across gradient-index bodies; skipped if the normal part
// would change much.
void projectOnShell(inout MarchState S, StepEnd E, vec3 N) {
  float wn = dot(S.w, N);
  vec3 wt = S.w - wn * N;
  if (!E.eHere) {
    float rem = S.nn.x * S.nn.x - dot(wt, wt);
    if (rem > 0.25 * wn * wn) S.w = wt + sign(wn) * sqrt(rem) * N;
  } else {
    // (wt + λN)ᵀ M (wt + λN) = 1: qa λ² + 2 qb λ + qc = 0, root nearest the current wn.
    vec3 MN = applyM(N, E.aHere, S.nn.x, E.ne.x);
    float qa = dot(N, MN), qb = dot(wt, MN), qc = dot(wt, applyM(wt, E.aHere, S.nn.x, E.ne.x)) - 1.0;
    float disc = qb * qb - qa * qc;
    if (disc > 0.0) {
      float l1 = (-qb + sqrt(disc)) / qa, l2 = (-qb - sqrt(disc)) / qa;
      float lam = abs(l1 - wn) < abs(l2 - wn) ? l1 : l2;
      if (abs(lam - wn) < 0.5 * abs(wn)) S.w = wt + lam * N;
    }
  }
}

// Fresnel at a crossed layer of normal N (transmitted fraction 1 − R, with the full unpolarised
// equations, and an external reflection that samples the environment), or a total internal
// reflection, which the ODE produced by itself (no Fresnel loss).
void fresnelAtLayer(inout MarchState S, inout MarchResult R, inout PathRecord rec, vec3 N, int mode) {
  vec3 dIn = normalize(S.wBefore), dOut = normalize(S.w);
  float ci = dot(dIn, N), co = dot(dOut, N);
  float n1 = length(S.wBefore), n2 = length(S.w);
  if (ci * co > 0.0) {
    // Which side is the crystal? The end of the layer with the larger birefringence (the
    // axis field itself is dilated into the air around crystals).
    float bOut = abs(sampleIndex(S.x, 1, rec.dispersive).x - sampleIndex(S.x, 0, rec.dispersive).x);
    float bIn = abs(sampleIndex(S.xOpen, 1, rec.dispersive).x - sampleIndex(S.xOpen, 0, rec.dispersive).x);
    bool outCrystal = bOut >= bIn;
    vec3 a = axisAt(outCrystal ? S.x : S.xOpen);
    float wsw = sWeight(outCrystal ? dOut : dIn, a, N, dIn, mode);
    vec2 rsp = fresnelRsRp(abs(ci), n1, n2);
    float Rf = hasFlag(EIKON_F_UNIAXIAL) ? wsw * rsp.x + (1.0 - wsw) * rsp.y : 0.5 * (rsp.x + rsp.y);
    R.interfaces++;
    if (followReflection(S, Rf)) {
      // Back to where the layer opened, on the incident side, with the mirrored wave vector; a
      // crystal's e-wave put back on its shell there (the layer's own normal N).
      S.x = S.xOpen;
      S.nn = sampleIndex(S.x, 0, rec.dispersive);
      S.w = reflect(S.wBefore, N);
      StepEnd E;
      E.aHere = mode == 1 ? axisAt(S.x) : vec3(0.0);
      E.eHere = mode == 1 && hasAxis(E.aHere);
      E.ne = E.eHere ? sampleIndex(S.x, 1, rec.dispersive) : S.nn;
      projectOnShell(S, E, N);
      return;
    }
    if (!singlePathWeights(S)) return;
    if (n2 > n1) S.L += environmentWeighted(rec, S.T * Rf, reflect(dIn, N));
    S.T *= 1.0 - Rf;
  } else {
    R.tir++;
  }
}

// (|∇n|·h)² at the step's end, the quantity that opens and closes layers (squared: no square root
// per step; it is compared with the squared thresholds).
float layerGradient2(MarchState S, StepEnd E) {
  const float h = P.grid_origin.w;
  return max(dot(S.nn.yzw, S.nn.yzw), dot(E.ne.yzw, E.ne.yzw)) * (h * h);
}

const float kLayerOpen = 1e-6;  // |∇n|·h above which a layer opens
const float kLayerOpen2 = kLayerOpen * kLayerOpen;

// Whether layerStep would open or close a layer here (otherwise it only accumulates, as
// layerAccumulate does).
bool layerEvent(MarchState S, StepEnd E) {
  float g2 = layerGradient2(S, E);
  return S.inLayer ? g2 <= kLayerOpen2 : g2 > kLayerOpen2;
}

// layerStep where it neither opens nor closes a layer.
void layerAccumulate(inout MarchState S, StepEnd E) {
  if (!S.inLayer) return;
  S.gAcc += E.gradN * (P.march.x * P.grid_origin.w);
  float g2 = layerGradient2(S, E);
  if (kAov && g2 > S.peak2) S.xPeak = S.x;
  S.peak2 = max(S.peak2, g2);
}

// Interface bookkeeping: a layer opens where |∇n|·h rises above 1e-6 and closes where it falls
// back; a closed layer whose peak exceeded march.y was an interface (projectOnShell, fresnelAtLayer).
void layerStep(inout MarchState S, inout MarchResult R, inout PathRecord rec, StepEnd E, int mode) {
  const float h = P.grid_origin.w, ds = P.march.x * h;
  // The thresholds squared, as layerGradient2 (a negative march.y stays below every peak).
  const float thrLow2 = kLayerOpen2, thrIface2 = P.march.y * abs(P.march.y);
  float g2 = layerGradient2(S, E);
  if (!S.inLayer && g2 > thrLow2) {
    S.inLayer = true;
    S.wBefore = E.w0;
    S.gAcc = vec3(0.0);
    S.peak2 = 0.0;
    S.xOpen = E.x0;
  }
  if (!S.inLayer) return;
  S.gAcc += E.gradN * ds;
  if (kAov && g2 > S.peak2) S.xPeak = S.x;
  S.peak2 = max(S.peak2, g2);
  if (!(g2 <= thrLow2)) return;
  S.inLayer = false;
  vec3 N = dot(S.gAcc, S.gAcc) > 0.0 ? normalize(S.gAcc) : vec3(0.0);
  if (kAov && !R.hit && S.peak2 > thrIface2 && dot(N, N) > 0.0) {
    R.hit = true;
    R.hitPoint = S.xPeak;
    R.hitNormal = dot(N, S.wBefore) > 0.0 ? -N : N;
    R.hitObject = -1;
  }
  if (dot(N, N) > 0.0 && abs(dot(S.x - S.xOpen, N)) <= 12.0 * h) projectOnShell(S, E, N);
  if (S.peak2 > thrIface2 && !hasFlag(EIKON_F_NO_FRESNEL) && dot(N, N) > 0.0) fresnelAtLayer(S, R, rec, N, mode);
}

// Whether x is outside the volume box (clipToVolume's test).
bool outsideVolume(vec3 x) {
  return any(lessThan(x, P.grid_origin.xyz)) ||
         any(greaterThan(x, P.grid_origin.xyz + P.grid_extent.xyz));
}

// Left the volume? The ray is straight outside (fields clamp to the uniform edge voxels): cut the
// step at the boundary, with w there (linear within the step), not at the overshoot.
bool clipToVolume(inout MarchState S, inout MarchResult R, StepEnd E) {
  const vec3 bmin = P.grid_origin.xyz, bmax = P.grid_origin.xyz + P.grid_extent.xyz;
  if (!any(lessThan(S.x, bmin)) && !any(greaterThan(S.x, bmax))) return false;
  vec3 dd = normalize(S.x - E.x0);
  float a0, a1;
  boxHit(E.x0, dd, bmin, bmax, a0, a1);
  float stepLen = length(S.x - E.x0);
  float keep = clamp(max(a1, 0.0) / max(stepLen, 1e-30), 0.0, 1.0);
  R.opl -= (1.0 - keep) * 0.5 * dot(E.w0 + S.w, S.x - E.x0);
  S.x = E.x0 + (S.x - E.x0) * keep;
  S.w = mix(E.w0, S.w, keep);
  return true;
}

// Both marches start here: R initialised, and the ray either misses the volume (R is the
// environment seen along d; false) or enters it at o + t0·d, t0 ≥ 0 (true).
bool enterVolume(vec3 o, vec3 d, inout PathRecord rec, out MarchResult R, out float t0) {
  R.split = false;
  R.radiance = vec3(0.0);
  R.throughput = vec3(1.0);
  R.opl = 0.0;
  R.left = true;
  R.cut = false;
  R.steps = 0;
  R.drift = 0.0;
  R.interfaces = 0;
  R.tir = 0;
  R.exit_point = o;
  R.exit_dir = d;
  R.wave_normal = d;
  R.hit = false;
  R.hitPoint = vec3(0.0);
  R.hitNormal = vec3(0.0);
  R.hitObject = -1;
  const vec3 bmin = P.grid_origin.xyz, bmax = P.grid_origin.xyz + P.grid_extent.xyz;
  float t1;
  if (!boxHit(o, d, bmin, bmax, t0, t1)) {
    R.radiance = environmentWeighted(rec, vec3(1.0), d);
    return false;
  }
  t0 = max(t0, 0.0);
  return true;
}

#include "sharp.glsl"

// kSharpMarch (with EIKON_F_SHARP): the pipeline holds one of the two marches, which halves what
// lavapipe compiles. rec: the caller's record of the path (PathRecord), carried on.
MarchResult march(vec3 o, vec3 d, int mode, inout PathRecord rec) {
  if (!hasFlag(EIKON_F_TWO_MODES)) mode = 0;  // always so; as a constant it folds the e-mode away
  if (kSharpMarch) return marchSharp(o, d, mode, rec);
  MarchResult R;
  float t0;
  if (!enterVolume(o, d, rec, R, t0)) return R;
  R.opl = P.march.z * t0;  // the ambient index
  vec4 nn = sampleIndex(o + d * t0, 0, rec.dispersive);
  MarchState S = startState(o + d * t0, nn.x * d, mode, rec);  // the volume's faces are isotropic (air): p = n d
  S.nn = nn;
  const int maxSteps = P.limits.x;
  int steps = 0;
  // Per step: straightStep, integrateStep, mediumAlongStep, layerStep, clipToVolume. lavapipe runs
  // a loop's whole body for all lanes while any lane goes on, so the steps where layerStep only
  // accumulates and clipToVolume does nothing run in an inner loop, and the rare events (a layer
  // opens or closes, the ray leaves the volume) leave it for the full stages, once per event.
  while (steps < maxSteps) {
    StepEnd E;
    bool event = false;
    for (; steps < maxSteps; ++steps) {
      const int straight = straightStep(S, R, rec, mode);
      if (straight == kStepStop) break;
      if (straight == kStepTaken) continue;
      E = integrateStep(S, R, rec.dispersive, mode);
      if (mediumAlongStep(S, rec, E, mode)) break;
      if (layerEvent(S, E) || outsideVolume(S.x)) {
        event = true;
        break;
      }
      layerAccumulate(S, E);
    }
    if (!event) break;
    layerStep(S, R, rec, E, mode);
    if (clipToVolume(S, R, E)) break;
    ++steps;
  }
  // Cut short: by the driver's loop budget (lavapipe ends every loop once a group has run out of
  // it, so the march stops early without a sign: sharp.glsl loopLimitReached tells), or out of
  // steps. Either way the sample lacks the light it would have reached, and is counted.
  R.cut = loopLimitReached() || (!S.stopped && steps >= maxSteps);
  R.steps = steps;
  R.exit_point = S.x;
  R.exit_dir = rayDirection(S.x, S.w, mode, rec.dispersive);
  R.wave_normal = normalize(S.w);
  R.left = !S.stopped && !R.cut;
  if (R.left) S.L += environmentWeighted(rec, S.T, R.exit_dir);
  R.radiance = S.L;
  R.throughput = S.T;
  R.split = S.split;
  return R;
}

#endif
