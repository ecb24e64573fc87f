#version 450
// Exclusive prefix sum of uints (the wavefront's patch-count scan; see docs/light-simulator.md).
// Work-efficient (Blelloch) scan of one block of EIKON_SCAN_BLOCK = 2·EIKON_SCAN_WG elements in
// shared memory: up-sweep (reduce) then down-sweep, 2·B adds per block. A list longer than one
// block is scanned level by level by the host (GpuScan / GpuWavefront): pass 0 scans every block
// of a level in place and writes each block's total to the next level's region (or, for the one
// block of the top level, to the total slot); the next level is scanned the same way; pass 1 then
// adds each scanned block total to its block's elements, top level down. All levels live in one
// buffer at offsets given by the push constants, so one descriptor set serves every level.
#extension GL_GOOGLE_include_directive : require
#include "eikon_shared.h"

layout(local_size_x = EIKON_SCAN_WG) in;
layout(push_constant) uniform PushBlock { ScanPush pc; };
layout(std430, binding = 0) buffer Data { uint data[]; };

shared uint t[EIKON_SCAN_BLOCK];

void main() {
  const uint lid = gl_LocalInvocationID.x, blk = gl_WorkGroupID.x;
  const uint base = pc.control.x, n = pc.control.y, sums = pc.control.z;
  const uint i0 = blk * EIKON_SCAN_BLOCK + lid, i1 = i0 + EIKON_SCAN_WG;
  if (pc.control.w == 1u) {
    const uint add = data[sums + blk];
    if (i0 < n) data[base + i0] += add;
    if (i1 < n) data[base + i1] += add;
    return;
  }
  t[lid] = i0 < n ? data[base + i0] : 0u;
  t[lid + EIKON_SCAN_WG] = i1 < n ? data[base + i1] : 0u;
  uint offset = 1u;
  for (uint d = EIKON_SCAN_BLOCK / 2; d > 0u; d >>= 1) {
    memoryBarrierShared();
    barrier();
    if (lid < d) {
      const uint ai = offset * (2u * lid + 1u) - 1u, bi = offset * (2u * lid + 2u) - 1u;
      t[bi] += t[ai];
    }
    offset <<= 1;
  }
  memoryBarrierShared();
  barrier();
  if (lid == 0u) {
    data[sums + blk] = t[EIKON_SCAN_BLOCK - 1];
    t[EIKON_SCAN_BLOCK - 1] = 0u;
  }
  for (uint d = 1u; d < EIKON_SCAN_BLOCK; d <<= 1) {
    offset >>= 1;
    memoryBarrierShared();
    barrier();
    if (lid < d) {
      const uint ai = offset * (2u * lid + 1u) - 1u, bi = offset * (2u * lid + 2u) - 1u;
      const uint a = t[ai];
      t[ai] = t[bi];
      t[bi] += a;
    }
  }
  memoryBarrierShared();
  barrier();
  if (i0 < n) data[base + i0] = t[lid];
  if (i1 < n) data[base + i1] = t[lid + EIKON_SCAN_WG];
}
