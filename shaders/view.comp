#version 450
// View renderer: one thread per pixel and one pass per dispatch: pixel sample P.pass.x (jittered
// when spp > 1) at wavelengths [P.pass.y, P.pass.y + P.pass.z) of its N stratified ones (spectral
// mode, CIE 1931 → linear sRGB), or at all N by hero wavelength sampling (EIKON_PASS_HERO) or at
// the fixed wavelength (RGB mode, RGB attenuation). Uniaxial scenes march the o- and e-modes, each
// carrying half of the unpolarised radiance, or one of them at the whole of it (the pass's modes,
// EIKON_PASS_MODES_SHIFT: 1 o only, 2 e only; RenderSettings::modes, core/contract/march_types.h).
// The bits of P.pass.w are named in eikon_shared.h (EIKON_PASS_*); main chooses the strategy
// from them and the flags: renderRgbSample, or renderSpectralSample with the stratified* or hero*
// stages (the CPU twin's rgbSample, stratifiedSampleXyz, heroSampleXyz). Output: this
// pass's share of the pixel's linear sRGB radiance (the host sums the passes and divides by spp),
// w = its steps, or −(steps + 1) when a march of the pass ran out of the driver's loop budget.
//
// Why passes: lavapipe gives each SIMD group of invocations one budget of 65535 loop passes, all
// loops together, and silently ends every loop when it is spent (docs/view-renderer.md). A pixel
// that marched every sample and wavelength in one invocation spent it 16–32 times over in a
// spectral crystal; one pass marches one wavelength (both modes), or all N where wavelength
// sharing replaces the marches of the others by table lookups.
#extension GL_GOOGLE_include_directive : require
#include "eikon_shared.h"

layout(local_size_x = EIKON_WG_X, local_size_y = EIKON_WG_Y) in;

// RGB mode marches at P.wavelength.x only: the media's indices there come from the host
// (sharp.glsl mediumIndex).
#define EIKON_INDEX_AT_RENDER_WAVELENGTH (!hasFlag(EIKON_F_SPECTRAL))
#include "march.glsl"

layout(std430, binding = EIKON_B_OUTPUT) writeonly buffer OutBuf { vec4 pixels[]; };
// Sharing across passes (EIKON_PASS_SHARED; main below): per pixel of the image, 1 where the
// pixel sample's first pass added every wavelength.
layout(std430, binding = EIKON_B_SHARED_PATHS) buffer SharedPathsBuf { uint sharedPaths[]; };

vec3 cmf(float lambda_nm) {
  float t = lambda_nm - 360.0;
  if (t < 0.0 || t > 470.0) return vec3(0.0);
  int i = min(int(floor(t)), 469);
  float f = t - float(i);
  return mix(tables[EIKON_CMF_OFFSET + i].xyz, tables[EIKON_CMF_OFFSET + i + 1].xyz, f);
}

// Layers (EIKON_PASS_LAYERS; core/contract/render_layers.h): after the band's pixels, per pixel
// `layerStride` vec4s hold, per mode kept apart (2 with EIKON_PASS_LAYER_MODES, else 1), one value
// per channel (the N wavelength bins in spectral mode, r, g, b in RGB mode). A pass writes the bins it
// marches; the host reads those.
int layerChannels() { return hasFlag(EIKON_F_SPECTRAL) ? P.limits.z : 3; }
int layerModes() { return (P.pass.w & EIKON_PASS_LAYER_MODES) != 0 ? 2 : 1; }
int layerStride() { return (layerChannels() * layerModes() + 3) / 4; }
void layerWrite(int bandPixel, int mode, int channel, float v) {
  int i = min(mode, layerModes() - 1) * layerChannels() + channel;
  pixels[P.image.x * P.image.w + bandPixel * layerStride() + i / 4][i % 4] = v;
}

// The AOV layer (kAov; core/contract/render_layers.h): after the band's pixels and layers, two vec4s
// per pixel: (first interface point, its object or −1), (its unit normal facing the eye, zero
// where the pass's first march met no interface; the march steps of all the pass's marches).
// Every pass writes both; the host takes the geometry from the pixel's first pass (sample 0, its
// first wavelength, the o-mode) and adds up the steps.
void aovWrite(int bandPixel, vec4 pointObject, vec3 normal, float steps) {
  int layers = (P.pass.w & EIKON_PASS_LAYERS) != 0 ? layerStride() : 0;
  int base = P.image.x * P.image.w * (1 + layers) + 2 * bandPixel;
  pixels[base] = pointObject;
  pixels[base + 1] = vec4(normal, steps);
}

// Hero wavelength sampling after the march (heroAdd): the lookups recorded before the path's first
// dispersive event at all N wavelengths λ_j = 380 + ((k_h + j) mod N + u)·400/N, as CIE XYZ; with
// layers, each λ_j's radiance per mode in its bin, the hero's own (after divergence) N times.
vec3 heroWavelengthsXyz(PathRecord rec, int N, int kh, float uh, int heroCount0, float heroMode[2],
                        int bandPixel) {
  const bool layers = (P.pass.w & EIKON_PASS_LAYERS) != 0;
  const float width = 400.0 / float(N);
  vec3 xyz = vec3(0.0);
  for (int j = 0; j < N && (rec.count > 0 || layers); ++j) {
    float lj = 380.0 + (float((kh + j) % N) + uh) * width;
    setWavelength(lj * 1e-3, true);
    vec2 rad = vec2(0.0);  // per mode (records before heroCount0 are the o-mode's)
    for (int i = 0; i < kRecordMax; ++i)  // a constant count: unrolled (the loop budget)
      if (i < rec.count) rad[i < heroCount0 ? 0 : 1] += rec.entries[i].w * rgbToSpectrum(rec.entries[i].xyz);
    xyz += (rad.x + rad.y) * cmf(lj) * width;
    if (layers) {
      if (j == 0) rad += float(N) * vec2(heroMode[0], heroMode[1]);
      int bin = (kh + j) % N;
      if (layerModes() == 2) {
        layerWrite(bandPixel, 0, bin, rad.x);
        layerWrite(bandPixel, 1, bin, rad.y);
      } else {
        layerWrite(bandPixel, 0, bin, rad.x + rad.y);
      }
    }
  }
  return xyz;
}

// The camera ray of pixel (px, py), sample s (jittered when spp > 1).
vec3 cameraRay(int px, int py, int s, uint pixelIndex) {
  vec2 jitter = vec2(0.5);
  if (P.limits.y > 1) {
    uint hs = pcg_hash(pixelIndex * 9781u + uint(s) * 6271u + 17u);
    jitter = vec2(float(hs & 0xffffu), float(hs >> 16u)) / 65536.0;
  }
  float u = ((float(px) + jitter.x) / float(P.image.x) * 2.0 - 1.0) * P.cam_pos.w * P.cam_forward.w;
  float v = (1.0 - (float(py) + jitter.y) / float(P.image.y) * 2.0) * P.cam_pos.w;
  return normalize(P.cam_forward.xyz + u * P.cam_right.xyz + v * P.cam_up.xyz);
}

// ---- The pixel sample's sum and its marches, shared by every strategy ----

// What the pass adds for its pixel sample (main writes it): linear sRGB (RGB mode) or CIE XYZ
// (spectral modes), the steps (each march's divided by the wavelengths of the pixel sample it
// stands for), whether a march was cut, and the AOV layer's notes (kAov: the pass's first march's
// first interface, the steps of all its marches).
struct SampleSum {
  vec3 rgb;
  vec3 xyz;
  float steps;
  bool cut;
  vec4 aovPoint;
  vec3 aovNormal;
  float aovSteps;
  bool aovFirst;
};

SampleSum emptySum() {
  SampleSum acc;
  acc.rgb = vec3(0.0);
  acc.xyz = vec3(0.0);
  acc.steps = 0.0;
  acc.cut = false;
  acc.aovPoint = vec4(0.0, 0.0, 0.0, -1.0);
  acc.aovNormal = vec3(0.0);
  acc.aovSteps = 0.0;
  acc.aovFirst = true;
  return acc;
}

// The modes a pass marches, [m0, m1): both, each carrying half of the unpolarised light
// (modeWeight ½), or the one selected at the whole of it (march_types.h modeRange; the pass's
// EIKON_PASS_MODES_SHIFT bits). Isotropic scenes: the one mode.
struct ModeSpan {
  int m0, m1;
  float modeWeight;
};

ModeSpan passModes() {
  const int modes = hasFlag(EIKON_F_TWO_MODES) ? 2 : 1;
  const int selected = (P.pass.w >> EIKON_PASS_MODES_SHIFT) & EIKON_PASS_MODES_MASK;
  ModeSpan m;
  m.m0 = modes == 2 && selected == 2 ? 1 : 0;
  m.m1 = modes == 2 && selected == 1 ? 1 : modes;
  m.modeWeight = m.m1 - m.m0 == 2 ? 0.5 : 1.0;
  return m;
}

// The pass's modes along d at the current wavelength (setWavelength), each march's radiance
// times its share in radMode[mode], their sum returned. The march's one call site in a pipeline
// (lavapipe compiles every inlined copy of the march): called once by renderRgbSample and once by
// renderSpectralSample, of which the specialised flags keep one.
// stepDivisor: the wavelengths a march's steps are shared by (N for one of N stratified
// wavelengths, else 1). hero: the record restarts per mode, counted in heroCount0 after the o-mode.
vec3 marchModes(vec3 d, ModeSpan m, float stepDivisor, bool hero, inout PathRecord rec,
                inout SampleSum acc, out vec3 radMode[2], out int heroCount0) {
  const int weightDependent = EIKON_F_ATTENUATION | EIKON_F_EMISSION | EIKON_F_OPACITY;
  vec3 rad = vec3(0.0);
  radMode = vec3[2](vec3(0.0), vec3(0.0));
  heroCount0 = 0;
  // Per mode, full transport splits the path's first Fresnel choice (march.glsl kChoice*): the
  // transmitted branch, then, where it met a choice, the reflected one; one march call site.
  // P.transport.z = 0 (MarchSettings::split_first_choice false) draws it instead.
  const bool split = P.transport.x != 0 && P.transport.z != 0;
  int mode = m.m0, branch = split ? kChoiceTransmit : kChoiceDrawn;
  while (mode < m.m1) {
    if (hero) rec.dispersive = hasFlag(weightDependent);
    rec.firstChoice = branch;
    MarchResult r = march(P.cam_pos.xyz, d, mode, rec);
    vec3 part = m.modeWeight * r.radiance;
    rad += part;
    radMode[mode] += part;
    bool nextMode = branch != kChoiceTransmit || !r.split;
    branch = nextMode ? (split ? kChoiceTransmit : kChoiceDrawn) : kChoiceReflect;
    if (hero && mode == 0 && nextMode) heroCount0 = rec.count;
    acc.steps += float(r.steps) / stepDivisor;
    acc.cut = acc.cut || r.cut;
    if (kAov) {
      acc.aovSteps += float(r.steps);
      if (acc.aovFirst && r.hit) {
        acc.aovPoint = vec4(r.hitPoint, float(r.hitObject));
        acc.aovNormal = r.hitNormal;
      }
      acc.aovFirst = false;
    }
    if (nextMode) ++mode;
  }
  return rad;
}

// Per-channel layers of one marched wavelength (spectral: bin k) or of r, g, b (RGB mode).
void layersOfModes(int bandPixel, int k, vec3 rad, vec3 radMode[2]) {
  for (int m = 0; m < 2; ++m) {
    if (m >= layerModes()) break;
    vec3 v = layerModes() == 2 ? radMode[m] : rad;
    if (hasFlag(EIKON_F_SPECTRAL)) layerWrite(bandPixel, m, k, v.x);
    else for (int c = 0; c < 3; ++c) layerWrite(bandPixel, m, c, v[c]);
  }
}

// ---- The strategies (the pass bits EIKON_PASS_*; main chooses) ----

// RGB mode: one march per mode at the fixed wavelength P.wavelength.x, RGB attenuation.
void renderRgbSample(vec3 d, uint pixelIndex, int s, int bandPixel, inout SampleSum acc) {
  setWavelength(P.wavelength.x, false);
  PathRecord rec = sampleRecord(pixelIndex, s);
  vec3 radMode[2];
  int unused;
  vec3 rad = marchModes(d, passModes(), 1.0, false, rec, acc, radMode, unused);
  acc.rgb += rad;
  if ((P.pass.w & EIKON_PASS_LAYERS) != 0) layersOfModes(bandPixel, 0, rad, radMode);
}

// A spectral pass's wavelengths: bins [k0, k1) of N, 400/N nm wide, each jittered by u(k).
struct SpectralSpan {
  int N, k0, k1;
  float width;
  uint seed;  // stratified: u(k) from pcg_hash(seed + k)
  float uh;   // hero: the one jitter shared by all N
  uint pixel;  // the pixel sample (its records' sampleRecord)
  int sampleIndex;
};

SpectralSpan spectralSpan(int s, uint pixelIndex) {
  SpectralSpan w;
  w.N = P.limits.z;
  w.k0 = P.pass.y;
  w.k1 = min(P.pass.y + P.pass.z, w.N);
  w.width = 400.0 / float(w.N);
  w.seed = pcg_hash(pixelIndex + pcg_hash(uint(s)));
  w.uh = 0.0;
  w.pixel = pixelIndex;
  w.sampleIndex = s;
  return w;
}

// Bin k's wavelength (nm), set for the march.
float setBinWavelength(SpectralSpan w, int k, bool hero) {
  float uk = hero ? w.uh : float(pcg_hash(w.seed + uint(k)) >> 8u) * (1.0 / 16777216.0);
  float lambda = 380.0 + (float(k) + uk) * w.width;
  setWavelength(lambda * 1e-3, true);
  return lambda;
}

// Wavelengths rendered from the record (PathRecord) instead of marched: Σ weight·S(λ, rgb) over
// entries [i0, i1) at the current wavelength.
float recordedRadiance(PathRecord rec, int i0, int i1) {
  float rad = 0.0;
  for (int i = 0; i < kRecordMax; ++i)  // a constant count: unrolled (the loop budget)
    if (i >= i0 && i < i1) rad += rec.entries[i].w * rgbToSpectrum(rec.entries[i].xyz);
  return rad;
}

// The spectral strategies share one wavelength loop (renderSpectralSample), so that the pipeline
// holds one march (marchModes), and differ in the stages around it: stratified* and hero*.
//
// Stratified spectral (no EIKON_PASS_HERO): the pass's wavelengths [P.pass.y, P.pass.y +
// P.pass.z), one march per mode each, with wavelength sharing (march.glsl PathRecord). Within one
// pass: where nothing but the index can depend on λ the host makes a pass all N wavelengths, and
// the first one's record gives the others. Across passes (EIKON_PASS_SHARED: crystals,
// attenuating, emitting or opaque scenes; view_renderer.cpp): the pixel sample's first pass
// (k0 = 0, told to cover all N) marches λ_0 with the record on; where nothing on the path turned
// out to depend on λ it adds the other wavelengths from the record and notes it in sharedPaths,
// and the sample's later passes skip the pixel (main); elsewhere it stops after λ_0, as a pass of
// one wavelength does.

// The record for marching bin k: on for the pass's first wavelength where it may be shared.
PathRecord stratifiedRecord(int k, SpectralSpan w, bool crossShare) {
  const int lambdaDependent = EIKON_F_ATTENUATION | EIKON_F_EMISSION | EIKON_F_OPACITY | EIKON_F_TWO_MODES;
  PathRecord rec = sampleRecord(w.pixel, w.sampleIndex);
  rec.record = (!hasFlag(lambdaDependent) || crossShare) && k == w.k0;
  return rec;
}

// Bin k from the record instead of a march: the records of every mode marched, each carrying its
// share (modeWeight) of the light.
void stratifiedFromRecord(PathRecord rec, int k, float lambda, SpectralSpan w, float modeWeight,
                          int bandPixel, inout SampleSum acc) {
  float rad = recordedRadiance(rec, 0, rec.count) * modeWeight;
  acc.xyz += rad * cmf(lambda) * w.width;
  if ((P.pass.w & EIKON_PASS_LAYERS) != 0) layerWrite(bandPixel, 0, k, rad);
}

// Bin k marched: its radiance, and whether its record gives the other wavelengths (both modes
// recorded: a crystal's paths are one path where they meet no crystal).
bool stratifiedAdd(inout PathRecord rec, int k, float lambda, SpectralSpan w, vec3 rad,
                   vec3 radMode[2], int bandPixel, inout SampleSum acc) {
  bool reuse = rec.record && !rec.dispersive && !rec.overflow;
  rec.record = false;
  acc.xyz += rad.x * cmf(lambda) * w.width;
  if ((P.pass.w & EIKON_PASS_LAYERS) != 0) layersOfModes(bandPixel, k, rad, radMode);
  return reuse;
}

// Hero wavelength sampling (EIKON_PASS_HERO; docs/spectra.md, Wilkie et al. 2014): λ_j = 380 +
// ((k_h + j) mod N + u)·400/N, one shared jitter u, the hero's stratum k_h cycling over the
// samples (core/spectrum/wavelength_sampling.h heroWavelengths). One march at the hero (both
// modes); its lookups before the path's first dispersive event are recorded (march.glsl
// PathRecord) and valid at every λ_j (the stratified estimator, heroWavelengthsXyz); after it only
// the hero can have made the path, so the hero's own radiance counts N times. With λ-dependent
// weights on the path (attenuation, emission, opaque surfaces) the hero carries everything from
// the start.

// The span of the one march, [k_h, k_h + 1) with the shared jitter, and its record.
void heroBegin(int s, uint pixelIndex, float modeWeight, inout SpectralSpan w, out PathRecord rec) {
  uint offset = ((pcg_hash(pixelIndex ^ 0xa511e9b3u) >> 8u) * uint(w.N)) >> 24u;
  w.k0 = int((offset + uint(s)) % uint(w.N));
  w.k1 = w.k0 + 1;
  w.uh = float(pcg_hash(w.seed) >> 8u) * (1.0 / 16777216.0);
  rec = sampleRecord(w.pixel, w.sampleIndex);
  rec.hero = true;
  rec.weight = modeWeight;
}

// The hero's own radiance, N times, then every wavelength from the record (heroWavelengthsXyz).
void heroAdd(PathRecord rec, float lambda, SpectralSpan w, vec3 rad, vec3 radMode[2], int heroCount0,
             int bandPixel, inout SampleSum acc) {
  acc.xyz += float(w.N) * rad.x * cmf(lambda) * w.width;
  float heroMode[2] = float[2](radMode[0].x, radMode[1].x);  // each mode's own (after divergence)
  acc.xyz += heroWavelengthsXyz(rec, w.N, w.k0, w.uh, heroCount0, heroMode, bandPixel);
}

// A spectral pass of pixel sample s along d: the stratified or hero strategy's wavelengths, one
// march per mode at each (marchModes) or the record's values.
void renderSpectralSample(vec3 d, int s, bool hero, bool crossShare, uint pixelIndex, int bandPixel,
                          inout SampleSum acc) {
  SpectralSpan w = spectralSpan(s, pixelIndex);
  const ModeSpan m = passModes();
  PathRecord rec = noRecord();
  if (hero) heroBegin(s, pixelIndex, m.modeWeight, w, rec);
  bool reuse = false;  // stratified: the first wavelength's record gives the others
  for (int k = w.k0; k < w.k1; ++k) {
    float lambda = setBinWavelength(w, k, hero);
    if (crossShare && k > w.k0 && !reuse) break;  // a pass of one wavelength after all
    if (reuse) {
      stratifiedFromRecord(rec, k, lambda, w, m.modeWeight, bandPixel, acc);
      continue;
    }
    if (!hero) rec = stratifiedRecord(k, w, crossShare);
    vec3 radMode[2];
    int heroCount0;  // hero: records made by the o-mode's march
    vec3 rad = marchModes(d, m, hero ? 1.0 : float(w.N), hero, rec, acc, radMode, heroCount0);
    if (hero) heroAdd(rec, lambda, w, rad, radMode, heroCount0, bandPixel, acc);
    else reuse = stratifiedAdd(rec, k, lambda, w, rad, radMode, bandPixel, acc);
  }
  if (crossShare && w.k0 == 0) sharedPaths[pixelIndex] = reuse ? 1u : 0u;
}

// ---- main: the pixel, the pass's strategy, the output ----

void main() {
  loadParams();
  // llvmpipe runs a workgroup 8 invocations at a time (one SIMD vector, an 8-pixel row of the
  // 8×8 group): each vector takes a 4×2 tile instead, whose rays are more alike (neighbours in
  // both directions), so fewer lanes idle while the longest ray of the vector marches on.
  const uint l = gl_LocalInvocationIndex, c = l >> 3u, j = l & 7u;
  uvec2 gid = gl_WorkGroupID.xy * uvec2(EIKON_WG_X, EIKON_WG_Y) +
              uvec2((c & 1u) * 4u + (j & 3u), (c >> 1u) * 2u + (j >> 2u));
  int W = P.image.x, H = P.image.y;
  int px = int(gid.x), py = P.image.z + int(gid.y);
  if (px >= W || int(gid.y) >= P.image.w || py >= H) return;
  uint pixelIndex = uint(py * W + px);
  const int bandPixel = int(gid.y) * W + px;
  const int s = P.pass.x;
  const bool hero = hasFlag(EIKON_F_SPECTRAL) && (P.pass.w & EIKON_PASS_HERO) != 0;
  const bool crossShare =
      hasFlag(EIKON_F_SPECTRAL) && !hero && (P.pass.w & EIKON_PASS_SHARED) != 0;
  // A later pass of a pixel sample whose first pass added every wavelength (stratifiedAdd).
  if (crossShare && P.pass.y > 0 && sharedPaths[pixelIndex] != 0u) {
    pixels[bandPixel] = vec4(0.0);
    if (kAov) aovWrite(bandPixel, vec4(0.0, 0.0, 0.0, -1.0), vec3(0.0), 0.0);
    return;
  }
  vec3 d = cameraRay(px, py, s, pixelIndex);
  SampleSum acc = emptySum();
  if (!hasFlag(EIKON_F_SPECTRAL)) {
    renderRgbSample(d, pixelIndex, s, bandPixel, acc);
  } else {
    renderSpectralSample(d, s, hero, crossShare, pixelIndex, bandPixel, acc);
    mat3 M = mat3(tables[EIKON_MATRIX_OFFSET].xyz, tables[EIKON_MATRIX_OFFSET + 1].xyz,
                  tables[EIKON_MATRIX_OFFSET + 2].xyz);
    acc.rgb += acc.xyz * M;  // rows stored: rgb_i = dot(row_i, xyz)
  }
  pixels[bandPixel] = vec4(acc.rgb, acc.cut ? -(acc.steps + 1.0) : acc.steps);
  if (kAov) aovWrite(bandPixel, acc.aovPoint, acc.aovNormal, acc.aovSteps);
}
