#version 450
// View renderer: one thread per pixel and one pass per dispatch: pixel sample P.pass.x (jittered
// when spp > 1) at wavelengths [P.pass.y, P.pass.y + P.pass.z) of its N stratified ones (spectral
// mode, CIE 1931 → linear sRGB) or at the fixed wavelength (RGB mode, RGB attenuation). Uniaxial
// scenes march the o- and e-modes, each carrying half of the unpolarised radiance. Output: this
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

#include "march.glsl"

layout(std430, binding = EIKON_B_OUTPUT) writeonly buffer OutBuf { vec4 pixels[]; };

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

void main() {
  loadParams();
  uvec2 gid = gl_GlobalInvocationID.xy;
  int W = P.image.x, H = P.image.y;
  int px = int(gid.x), py = P.image.z + int(gid.y);
  if (px >= W || int(gid.y) >= P.image.w || py >= H) return;
  uint pixelIndex = uint(py * W + px);
  int spp = P.limits.y;
  vec3 sum = vec3(0.0);
  float steps = 0.0;
  bool cut = false;
  {
    int s = P.pass.x;
    vec2 jitter = vec2(0.5);
    if (spp > 1) {
      uint hs = pcg_hash(pixelIndex * 9781u + uint(s) * 6271u + 17u);
      jitter = vec2(float(hs & 0xffffu), float(hs >> 16u)) / 65536.0;
    }
    float u = ((float(px) + jitter.x) / float(W) * 2.0 - 1.0) * P.cam_pos.w * P.cam_forward.w;
    float v = (1.0 - (float(py) + jitter.y) / float(H) * 2.0) * P.cam_pos.w;
    vec3 d = normalize(P.cam_forward.xyz + u * P.cam_right.xyz + v * P.cam_up.xyz);
    // One call site of march() (lavapipe compiles every inlined copy of the march): the RGB mode
    // is one "wavelength" of radiance triplets, and the modes of a crystal are a loop.
    bool spectral = hasFlag(EIKON_F_SPECTRAL);
    int N = spectral ? P.limits.z : 1;
    int k0 = spectral ? P.pass.y : 0, k1 = spectral ? min(P.pass.y + P.pass.z, N) : 1;
    int modes = hasFlag(EIKON_F_UNIAXIAL) ? 2 : 1;  // unpolarised: each mode carries 1/modes
    uint seed = pcg_hash(pixelIndex + pcg_hash(uint(s)));
    vec3 xyz = vec3(0.0);
    // Wavelength sharing (march.glsl): only where nothing but the index can depend on λ, and only
    // within one pass (the host makes a pass all N wavelengths when the scene allows sharing).
    const int lambdaDependent = EIKON_F_ATTENUATION | EIKON_F_EMISSION | EIKON_F_OPACITY | EIKON_F_UNIAXIAL;
    bool share = spectral && !hasFlag(lambdaDependent);
    bool reuse = false;
    for (int k = k0; k < k1; ++k) {
      float lambda = 0.0;
      if (spectral) {
        float uk = float(pcg_hash(seed + uint(k)) >> 8u) * (1.0 / 16777216.0);
        lambda = 380.0 + (float(k) + uk) * (400.0 / float(N));
        setWavelength(lambda * 1e-3, true);
      } else {
        setWavelength(P.wavelength.x, false);
      }
      if (reuse) {
        float rad = 0.0;
        for (int j = 0; j < gNumRecorded; ++j) rad += gRecorded[j].w * environment(gRecorded[j].xyz).x;
        xyz += rad * cmf(lambda) * (400.0 / float(N));
        continue;
      }
      vec3 rad = vec3(0.0);
      for (int mode = 0; mode < modes; ++mode) {
        if (mode == 0) {
          gRecord = share && k == k0;
          gNumRecorded = 0;
          gRecordOverflow = false;
          gDispersiveHit = false;
        }
        MarchResult r = march(P.cam_pos.xyz, d, mode);
        if (mode == 0) {
          reuse = gRecord && !gDispersiveHit && !gRecordOverflow;
          gRecord = false;
        }
        rad += modes == 2 ? 0.5 * r.radiance : r.radiance;
        steps += float(r.steps) / float(N);
        cut = cut || r.cut;
      }
      if (spectral) xyz += rad.x * cmf(lambda) * (400.0 / float(N));
      else sum += rad;
    }
    if (spectral) {
      mat3 M = mat3(tables[EIKON_MATRIX_OFFSET].xyz, tables[EIKON_MATRIX_OFFSET + 1].xyz,
                    tables[EIKON_MATRIX_OFFSET + 2].xyz);
      sum += xyz * M;  // rows stored: rgb_i = dot(row_i, xyz)
    }
  }
  pixels[int(gid.y) * W + px] = vec4(sum, cut ? -(steps + 1.0) : steps);
}
