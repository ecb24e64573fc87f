#version 450
// Trace kernel: one thread per ray (and mode), reporting exit point, direction, optical path and
// transmittance at the ray's wavelength (eikon trace; GPU-vs-CPU tests).
#extension GL_GOOGLE_include_directive : require
#include "eikon_shared.h"

layout(local_size_x = EIKON_TRACE_WG) in;

#include "march.glsl"

layout(std430, binding = EIKON_B_RAYS) readonly buffer RayBuf { TraceRay rays[]; };
layout(std430, binding = EIKON_B_OUTPUT) writeonly buffer ResultBuf { TraceResult results[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= uint(P.image.x)) return;
  TraceRay ray = rays[i];
  setWavelength(ray.origin.w, true);
  MarchResult r = march(ray.origin.xyz, normalize(ray.direction.xyz), 0);
  TraceResult out_;
  out_.exit_point = vec4(r.exit_point, r.left ? 1.0 : 0.0);
  out_.exit_direction = vec4(r.exit_dir, r.opl);
  out_.wave_normal = vec4(r.exit_dir, r.throughput.x);
  out_.stats = vec4(float(r.steps), r.drift, float(r.interfaces), float(r.tir));
  results[i] = out_;
}
