#version 450
// View renderer: one thread per pixel and one pass per dispatch: pixel sample P.pass.x (jittered
// when spp > 1) at wavelengths [P.pass.y, P.pass.y + P.pass.z) of its N stratified ones (spectral
// mode, CIE 1931 → linear sRGB), or at all N by hero wavelength sampling (EIKON_PASS_HERO) or at
// the fixed wavelength (RGB mode, RGB attenuation). Uniaxial scenes march the o- and e-modes, each
// carrying half of the unpolarised radiance, or one of them at the whole of it (the pass's modes,
// EIKON_PASS_MODES_SHIFT: 1 o only, 2 e only; RenderSettings::modes, core/contract/march_types.h).
// The bits of P.pass.w are named in eikon_shared.h (EIKON_PASS_*). Output: this
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

uint pcg_hash(uint v) {
  uint state = v * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

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

// Hero wavelength sampling after the march (main): the lookups recorded before the path's first
// dispersive event at all N wavelengths λ_j = 380 + ((k_h + j) mod N + u)·400/N, as CIE XYZ; with
// layers, each λ_j's radiance per mode in its bin, the hero's own (after divergence) N times.
vec3 heroWavelengthsXyz(int N, int kh, float uh, int heroCount0, float heroMode[2], bool layers,
                        int bandPixel) {
  const float width = 400.0 / float(N);
  vec3 xyz = vec3(0.0);
  for (int j = 0; j < N && (gNumRecorded > 0 || layers); ++j) {
    float lj = 380.0 + (float((kh + j) % N) + uh) * width;
    setWavelength(lj * 1e-3, true);
    vec2 rad = vec2(0.0);  // per mode (records before heroCount0 are the o-mode's)
    for (int i = 0; i < 6; ++i)  // a constant count: unrolled (the loop budget)
      if (i < gNumRecorded) rad[i < heroCount0 ? 0 : 1] += gRecorded[i].w * rgbToSpectrum(gRecorded[i].xyz);
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
  int spp = P.limits.y;
  vec3 sum = vec3(0.0);
  float steps = 0.0;
  bool cut = false;
  vec4 aovPoint = vec4(0.0, 0.0, 0.0, -1.0);  // kAov: the first march's first interface
  vec3 aovNormal = vec3(0.0);
  float aovSteps = 0.0;
  bool aovFirst = true;
  {
    int s = P.pass.x;
    vec3 d = cameraRay(px, py, s, pixelIndex);
    // One call site of march() (lavapipe compiles every inlined copy of the march): the RGB mode
    // is one "wavelength" of radiance triplets, and the modes of a crystal are a loop.
    bool spectral = hasFlag(EIKON_F_SPECTRAL);
    int N = spectral ? P.limits.z : 1;
    int k0 = spectral ? P.pass.y : 0, k1 = spectral ? min(P.pass.y + P.pass.z, N) : 1;
    // The modes marched, [m0, m1): both, each carrying half of the unpolarised light, or the one
    // selected at the whole of it (march_types.h modeRange). Isotropic scenes: the one mode.
    const int modes = hasFlag(EIKON_F_UNIAXIAL) ? 2 : 1;
    const int selected = (P.pass.w >> EIKON_PASS_MODES_SHIFT) & EIKON_PASS_MODES_MASK;
    const int m0 = modes == 2 && selected == 2 ? 1 : 0;
    const int m1 = modes == 2 && selected == 1 ? 1 : modes;
    const float modeWeight = m1 - m0 == 2 ? 0.5 : 1.0;
    uint seed = pcg_hash(pixelIndex + pcg_hash(uint(s)));
    vec3 xyz = vec3(0.0);
    // Wavelength sharing (march.glsl) within one pass: where nothing but the index can depend on λ
    // the host makes a pass all N wavelengths; elsewhere the sharing across passes below.
    const int lambdaDependent = EIKON_F_ATTENUATION | EIKON_F_EMISSION | EIKON_F_OPACITY | EIKON_F_UNIAXIAL;
    // Sharing across passes (EIKON_PASS_SHARED, stratified renders whose passes march one
    // wavelength each: crystals, attenuating, emitting or opaque scenes; view_renderer.cpp). The pixel
    // sample's first pass (k0 = 0, told to cover all N) marches λ_0 with the record on; where
    // nothing on the path turned out to depend on λ it adds the other wavelengths from the record
    // and notes it in sharedPaths, and the sample's later passes skip the pixel; elsewhere it
    // stops after λ_0, as a pass of one wavelength does, and the later passes march as before.
    const bool crossShare =
        spectral && (P.pass.w & EIKON_PASS_HERO) == 0 && (P.pass.w & EIKON_PASS_SHARED) != 0;
    if (crossShare && k0 > 0 && sharedPaths[pixelIndex] != 0u) {
      pixels[int(gid.y) * W + px] = vec4(0.0);
      if (kAov) aovWrite(int(gid.y) * W + px, vec4(0.0, 0.0, 0.0, -1.0), vec3(0.0), 0.0);
      return;
    }
    bool share = spectral && (!hasFlag(lambdaDependent) || crossShare);
    bool reuse = false;
    // Hero wavelength sampling (EIKON_PASS_HERO; docs/spectra.md, Wilkie et al. 2014): λ_j = 380 +
    // ((k_h + j) mod N + u)·400/N, one shared jitter u, the hero's stratum k_h cycling over the
    // samples (core/spectrum/wavelength_sampling.h heroWavelengths). One march at the hero (both
    // modes) in the loop below; its lookups before the path's first dispersive event are recorded
    // (march.glsl) and valid at every λ_j (the stratified estimator, evaluated after the loop);
    // after it only the hero can have made the path, so the hero's own radiance counts N times.
    // With λ-dependent weights on the path (attenuation, emission, opaque surfaces) the hero
    // carries everything from the start.
    const bool hero = spectral && (P.pass.w & EIKON_PASS_HERO) != 0;
    const bool layers = (P.pass.w & EIKON_PASS_LAYERS) != 0;
    const int bandPixel = int(gid.y) * W + px;
    int heroCount0 = 0;                // hero: records made by the o-mode's march
    float heroMode[2] = float[2](0.0, 0.0);  // hero: each mode's own radiance (after divergence)
    const float width = 400.0 / float(N);
    const int weightDependent = EIKON_F_ATTENUATION | EIKON_F_EMISSION | EIKON_F_OPACITY;
    int kh = 0;
    float uh = 0.0;
    if (hero) {
      uint offset = ((pcg_hash(pixelIndex ^ 0xa511e9b3u) >> 8u) * uint(N)) >> 24u;
      kh = int((offset + uint(s)) % uint(N));
      uh = float(pcg_hash(seed) >> 8u) * (1.0 / 16777216.0);
      k0 = kh;
      k1 = kh + 1;
      gHero = true;
      gNumRecorded = 0;
      gRecordWeight = modeWeight;
    }
    for (int k = k0; k < k1; ++k) {
      float lambda = 0.0;
      if (spectral) {
        float uk = hero ? uh : float(pcg_hash(seed + uint(k)) >> 8u) * (1.0 / 16777216.0);
        lambda = 380.0 + (float(k) + uk) * width;
        setWavelength(lambda * 1e-3, true);
      } else {
        setWavelength(P.wavelength.x, false);
      }
      if (crossShare && k > k0 && !reuse) break;  // a pass of one wavelength after all
      if (reuse) {
        // The records of every mode marched, each carrying its share (modeWeight) of the light.
        float rad = 0.0;
        for (int j = 0; j < gNumRecorded; ++j) rad += gRecorded[j].w * rgbToSpectrum(gRecorded[j].xyz);
        rad *= modeWeight;
        xyz += rad * cmf(lambda) * width;
        if (layers) layerWrite(bandPixel, 0, k, rad);
        continue;
      }
      vec3 rad = vec3(0.0);
      vec3 radMode[2] = vec3[2](vec3(0.0), vec3(0.0));
      for (int mode = m0; mode < m1; ++mode) {
        if (mode == m0 && !hero) {
          gRecord = share && k == k0;
          gNumRecorded = 0;
          gRecordOverflow = false;
          gDispersiveHit = false;
        }
        if (hero) gDispersiveHit = hasFlag(weightDependent);
        MarchResult r = march(P.cam_pos.xyz, d, mode);
        if (mode == m1 - 1 && !hero) {  // both modes recorded (a crystal's paths are one path
          reuse = gRecord && !gDispersiveHit && !gRecordOverflow;  // where they meet no crystal)
          gRecord = false;
        }
        vec3 part = modeWeight * r.radiance;
        rad += part;
        radMode[mode] = part;
        if (hero && mode == 0) heroCount0 = gNumRecorded;
        steps += float(r.steps) / float(hero ? 1 : N);
        cut = cut || r.cut;
        if (kAov) {
          aovSteps += float(r.steps);
          if (aovFirst && r.hit) {
            aovPoint = vec4(r.hitPoint, float(r.hitObject));
            aovNormal = r.hitNormal;
          }
          aovFirst = false;
        }
      }
      if (spectral) xyz += (hero ? float(N) : 1.0) * rad.x * cmf(lambda) * width;
      else sum += rad;
      if (hero) {
        heroMode[0] = radMode[0].x;
        heroMode[1] = radMode[1].x;
      } else if (layers) {
        for (int m = 0; m < 2; ++m) {
          if (m >= layerModes()) break;
          vec3 v = layerModes() == 2 ? radMode[m] : rad;
          if (spectral) layerWrite(bandPixel, m, k, v.x);
          else for (int c = 0; c < 3; ++c) layerWrite(bandPixel, m, c, v[c]);
        }
      }
    }
    if (crossShare && k0 == 0) sharedPaths[pixelIndex] = reuse ? 1u : 0u;
    if (hero) {
      gHero = false;
      xyz += heroWavelengthsXyz(N, kh, uh, heroCount0, heroMode, layers, bandPixel);
    }
    if (spectral) {
      mat3 M = mat3(tables[EIKON_MATRIX_OFFSET].xyz, tables[EIKON_MATRIX_OFFSET + 1].xyz,
                    tables[EIKON_MATRIX_OFFSET + 2].xyz);
      sum += xyz * M;  // rows stored: rgb_i = dot(row_i, xyz)
    }
  }
  pixels[int(gid.y) * W + px] = vec4(sum, cut ? -(steps + 1.0) : steps);
  if (kAov) aovWrite(int(gid.y) * W + px, aovPoint, aovNormal, aovSteps);
}
