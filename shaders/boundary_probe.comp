#version 450
// Probe kernel of the sharp-boundary functions (shaders/boundary.glsl): one thread per query,
// evaluating boundaryPhi, boundaryRegion, locateCrossing and the analytic shape functions where
// the CPU twin (core/volume/boundary.h, core/scene/shapes.h) is evaluated by the tests.
#extension GL_GOOGLE_include_directive : require
#include "eikon_shared.h"

layout(local_size_x = EIKON_TRACE_WG) in;

layout(std430, binding = EIKON_B_PARAMS) readonly buffer ParamsBuf { ViewParams P; };
layout(binding = EIKON_B_REGION, r32ui) readonly uniform uimage3D regionImg;
layout(binding = EIKON_B_BOUNDARY_DIST, r32f) readonly uniform image3D boundaryDist;
layout(std430, binding = EIKON_B_SHAPES) readonly buffer ShapeBuf { vec4 shapeTable[]; };
layout(std430, binding = EIKON_B_BOUNDARY_QUERIES) readonly buffer QueryBuf { BoundaryQuery queries[]; };
layout(std430, binding = EIKON_B_OUTPUT) writeonly buffer AnswerBuf { BoundaryAnswer answers[]; };

#include "boundary.glsl"

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= uint(P.image.x)) return;
  BoundaryQuery q = queries[i];
  BoundaryAnswer o;
  vec3 grad;
  o.phi.x = boundaryPhi(q.a.xyz, int(q.a.w), grad);
  o.phi.yzw = grad;
  // P.march.x: the bisection tolerance (voxels) of locateCrossing.
  BoundaryCrossing c = locateCrossing(q.a.xyz, q.b.xyz, P.march.x, q.b.w > 0.5);
  o.regions = ivec4(boundaryRegion(q.a.xyz), c.found ? 1 : 0, c.from, c.to);
  o.crossing = vec4(c.point, c.t);
  o.normal = vec4(c.normal, float(gMeshPasses));
  int s = int(q.s.x) - 1;
  o.shape = s >= 0 ? vec4(shapeSignedDistance(s, q.a.xyz), shapeDistanceGradient(s, q.a.xyz))
                   : vec4(0.0);
  answers[i] = o;
}
