#version 450
// Trace kernel: one thread per ray (and mode), reporting exit point, direction, optical path and
// transmittance at the ray's wavelength (eikon trace; GPU-vs-CPU tests).
#extension GL_GOOGLE_include_directive : require
#include "eikon_shared.h"

layout(local_size_x = EIKON_TRACE_WG) in;

#include "march.glsl"

layout(std430, binding = EIKON_B_RAYS) readonly buffer RayBuf { TraceRay rays[]; };
layout(std430, binding = EIKON_B_OUTPUT) writeonly buffer ResultBuf { TraceResult results[]; };

TraceResult pack(MarchResult r) {
  TraceResult o;
  o.exit_point = vec4(r.exit_point, r.left ? 1.0 : 0.0);
  o.exit_direction = vec4(r.exit_dir, r.opl);
  o.wave_normal = vec4(r.wave_normal, r.throughput.x);
  o.stats = vec4(float(r.steps), r.drift, float(r.interfaces), float(r.tir));
  return o;
}

// results[2i] is the o-mode of ray i, results[2i + 1] its e-mode (identical where isotropic).
void main() {
  loadParams();
  uint i = gl_GlobalInvocationID.x;
  if (i >= uint(P.image.x)) return;
  TraceRay ray = rays[i];
  setWavelength(ray.origin.w, true);
  vec3 d = normalize(ray.direction.xyz);
  // One call site of march() (lavapipe compiles every inlined copy): the modes are a loop.
  int modes = hasFlag(EIKON_F_TWO_MODES) ? 2 : 1;
  for (int mode = 0; mode < modes; ++mode) {
    PathRecord rec = noRecord();  // nothing is evaluated at other wavelengths
    TraceResult o = pack(march(ray.origin.xyz, d, mode, rec));
    results[2 * i + mode] = o;
    if (modes == 1) results[2 * i + 1] = o;
  }
}
