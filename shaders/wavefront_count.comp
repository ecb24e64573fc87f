#version 450
// Count passes of the light simulator's list rebuild (see wavefront.comp and
// docs/light-simulator.md): per patch of the source list, its number of outputs (0 dead or out of
// steps, 1 kept, 2 split into halves or itself and its reflected copy, 4 split into quarters or
// torn into pencils; one level) into
// scan[i], and in the COUNT and BUDGET
// passes the workgroup's kill statistics and probe-plane sums reduced in shared memory (a tree of
// EIKON_WAVE_WG lanes, float sums) into tally[workgroup], which the host adds in double. A separate
// shader from wavefront.comp so that the propagation shader carries no barrier (llvmpipe
// implements barriers with coroutines).
#extension GL_GOOGLE_include_directive : require
#include "eikon_shared.h"

layout(local_size_x = EIKON_WAVE_WG) in;

layout(std430, binding = EIKON_WB_PARAMS) readonly buffer ParamsBuf { WaveParams P; };
layout(std430, binding = EIKON_WB_PATCHES) readonly buffer PatchBuf { WavePatch patchesA[]; };
layout(std430, binding = EIKON_WB_PATCHES_B) readonly buffer PatchBufB { WavePatch patchesB[]; };
layout(std430, binding = EIKON_WB_SCAN) buffer ScanBuf { uint scan[]; };
layout(std430, binding = EIKON_WB_TALLY) writeonly buffer TallyBuf { WaveTally tally[]; };
layout(push_constant) uniform PushBlock { WavePush pc; };

WavePatch loadPatch(uint i) {
  if ((pc.control.w & 1u) != 0u) return patchesB[i];
  return patchesA[i];
}

shared vec4 sFluxA[EIKON_WAVE_WG], sFluxB[EIKON_WAVE_WG], sCentroid[EIKON_WAVE_WG];
shared vec4 sProbePos[EIKON_WAVE_WG], sProbeDir[EIKON_WAVE_WG];
shared uvec4 sCountA[EIKON_WAVE_WG], sCountB[EIKON_WAVE_WG], sCountC[EIKON_WAVE_WG];

void countPass(uint id, uint lid, uint mode) {
  vec4 fa = vec4(0.0), fb = vec4(0.0), cen = vec4(0.0), ppos = vec4(0.0), pdir = vec4(0.0);
  uvec4 ca = uvec4(0u), cb = uvec4(0u), cc = uvec4(0u);
  if (id < pc.control.x) {
    WavePatch p = loadPatch(id);
    const float e = p.flux.x;
    uint keep = 0u;
    bool wantSplit = false;
    switch (p.state.x) {
      case EIKON_PATCH_ALIVE:
        if (p.state.w >= P.control.z) {
          fb.y = e;  // out of steps: ends live
          cb.x = 1u;
        } else {
          keep = 1u;
        }
        break;
      case EIKON_PATCH_SPLIT:
        keep = 1u;
        wantSplit = true;
        break;
      case EIKON_PATCH_HALVE_U:  // two halves: ranked as a split request
      case EIKON_PATCH_HALVE_V:
        keep = 1u;
        wantSplit = true;
        cc.y = 1u;
        break;
      case EIKON_PATCH_TORN:  // four pencils: counted as a split
        keep = 1u;
        wantSplit = true;
        cen.w = 1.0;
        break;
      case EIKON_PATCH_REFLECT:  // itself and its reflected copy: ranked as a split request
        keep = 1u;
        wantSplit = true;
        cc.x = 1u;
        break;
      case EIKON_PATCH_LEFT:
        fa.x = e;
        ca.x = 1u;
        break;
      case EIKON_PATCH_CAUSTIC:
        fa.y = e;
        ca.y = 1u;
        cen.xyz = e * 0.25 * (p.x[0].xyz + p.x[1].xyz + p.x[2].xyz + p.x[3].xyz);
        break;
      case EIKON_PATCH_ENERGY:
        fa.z = e;
        ca.z = 1u;
        break;
      default:  // EIKON_PATCH_OPAQUE: the flux is absorbed
        fa.w = e;
        ca.w = 1u;
    }
    fb.x = p.flux.w;
    ppos = vec4(p.x[0].w, p.x[1].w, p.x[2].w, p.x[3].w);  // probe sums of the last propagation
    pdir = vec4(p.w[0].w, p.w[1].w, p.w[2].w, p.w[3].w);  // w: flux reflected (sharp interfaces)
    cb.y = wantSplit ? 1u : 0u;
    cb.z = keep;
    cb.w = uint(max(p.state.w, 0));
    const uint grown = cc.x != 0u || cc.y != 0u ? 2u : 4u;
    uint c = wantSplit ? grown : keep;
    if (mode == EIKON_WM_COUNT_SPLITS) c = wantSplit ? 1u : 0u;
    if (mode == EIKON_WM_COUNT_BUDGET && wantSplit) {
      const bool granted = scan[id] < pc.control.z;
      c = granted ? grown : 1u;
      if (!granted) cen.w = 0.0, cc.xy = uvec2(0u);  // refused: the patch goes on whole
    }
    scan[id] = c;
  }
  // The COUNT pass tallies every patch; the BUDGET pass tallies again so that the host reads the
  // tears granted (caustic_sum.w), not those asked for. Uniform: the push constant.
  if (mode == EIKON_WM_COUNT_SPLITS) return;
  sFluxA[lid] = fa;
  sFluxB[lid] = fb;
  sCentroid[lid] = cen;
  sProbePos[lid] = ppos;
  sProbeDir[lid] = pdir;
  sCountA[lid] = ca;
  sCountB[lid] = cb;
  sCountC[lid] = cc;
  for (uint s = EIKON_WAVE_WG / 2; s > 0u; s >>= 1) {
    memoryBarrierShared();
    barrier();
    if (lid < s) {
      sFluxA[lid] += sFluxA[lid + s];
      sFluxB[lid] += sFluxB[lid + s];
      sCentroid[lid] += sCentroid[lid + s];
      sProbePos[lid] += sProbePos[lid + s];
      sProbeDir[lid] += sProbeDir[lid + s];
      sCountA[lid] += sCountA[lid + s];
      sCountC[lid] += sCountC[lid + s];
      const uvec4 o = sCountB[lid + s];
      sCountB[lid] = uvec4(sCountB[lid].xyz + o.xyz, max(sCountB[lid].w, o.w));
    }
  }
  memoryBarrierShared();
  barrier();
  if (lid == 0u) {
    WaveTally t;
    t.flux_a = sFluxA[0];
    t.flux_b = sFluxB[0];
    t.caustic_sum = sCentroid[0];
    t.count_a = sCountA[0];
    t.count_b = sCountB[0];
    t.probe_pos = sProbePos[0];
    t.probe_dir = sProbeDir[0];
    t.count_c = sCountC[0];
    tally[gl_WorkGroupID.x] = t;
  }
}

void main() { countPass(gl_GlobalInvocationID.x, gl_LocalInvocationID.x, pc.control.y); }
