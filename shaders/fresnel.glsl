// The Fresnel factors of the GPU twins (anisotropic/fresnel.h on the CPU): the s and p reflectances of
// an isotropic interface and the D-projection weight of a crystal mode between them (the
// APPROXIMATE split of anisotropic/fresnel.h, uniaxialEntryApprox / uniaxialExitApprox). Included by
// march.glsl (the view march) and wavefront.comp (the light simulator's sharp interfaces).
#ifndef EIKON_FRESNEL_GLSL
#define EIKON_FRESNEL_GLSL

// Fresnel amplitude reflectances squared (Rs, Rp) for a wave going from index n1 into n2 with
// cos θ_i = ci ≥ 0 (Born & Wolf §1.5.2); (1, 1) beyond the critical angle.
vec2 fresnelRsRp(float ci, float n1, float n2) {
  float eta = n1 / n2;
  float st2 = eta * eta * max(0.0, 1.0 - ci * ci);
  if (st2 >= 1.0) return vec2(1.0);
  float ct = sqrt(1.0 - st2);
  float rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
  float rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
  return vec2(rs * rs, rp * rp);
}

// Fresnel (Rs, Rp) weights of a mode at an interface: the share of its D field along the
// s-polarisation direction (normal to the plane of incidence). Isotropic or degenerate: ½/½,
// which makes ½(T_o + T_e) the unpolarised transmittance.
float sWeight(vec3 s_crystal, vec3 a, vec3 N, vec3 dIn, int mode) {
  vec3 es = cross(N, dIn);
  if (dot(a, a) < 0.25 || dot(es, es) < 1e-12) return 0.5;
  vec3 Do = cross(s_crystal, a);
  if (dot(Do, Do) < 1e-12) return 0.5;  // wave normal along the axis: no split
  Do = normalize(Do);
  es = normalize(es);
  float wo = dot(Do, es) * dot(Do, es);
  return mode == 0 ? wo : 1.0 - wo;
}

#endif  // EIKON_FRESNEL_GLSL
