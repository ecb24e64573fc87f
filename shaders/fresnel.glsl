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

// Mode conversion's D-projection (sharp.glsl convertAtFace): the reflected field of an incident
// wave with s and p components (a_s, a_p) is r_s a_s ŝ + r_p a_p p̂_r, p̂ = ŝ × k̂ on every wave
// (Born & Wolf §1.5.2's signs: at normal incidence r_p = −r_s and p̂_r = −p̂_i, the same field).
// These return (|r_s|², |r_p|², Re r_s r_p*), the share of a direction D being
// |r_s|² X² + |r_p|² Y² + 2 Re(r_s r_p*) X Y with X = a_s ŝ·D, Y = a_p p̂·D; beyond the critical
// angle |r_s| = |r_p| = 1 with the phases δ_s = −2 atan(n₂κ / n₁cos i), δ_p = −2 atan(n₁κ /
// n₂cos i), κ = √(sin²θ_t − 1) (B&W §1.5.4).
vec3 fresnelReflectedMix(float ci, float n1, float n2) {
  float eta = n1 / n2;
  float st2 = eta * eta * max(0.0, 1.0 - ci * ci);
  if (st2 >= 1.0) {
    float k = sqrt(st2 - 1.0);
    float ds = -2.0 * atan(n2 * k, n1 * ci), dp = -2.0 * atan(n1 * k, n2 * ci);
    return vec3(1.0, 1.0, cos(ds - dp));
  }
  float ct = sqrt(1.0 - st2);
  float rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
  float rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
  return vec3(rs * rs, rp * rp, rs * rp);
}

// The transmitted field's (T_s, T_p, √(T_s T_p) sign(t_s t_p)): the powers of the s and p waves
// (t² n₂cos θ_t / n₁cos i) and their cross term, as fresnelReflectedMix's for the field
// t_s a_s ŝ + t_p a_p p̂_t (below the critical angle only).
vec3 fresnelTransmittedMix(float ci, float n1, float n2) {
  float eta = n1 / n2;
  float st2 = eta * eta * max(0.0, 1.0 - ci * ci);
  if (st2 >= 1.0) return vec3(0.0);
  float ct = sqrt(1.0 - st2);
  float ts = 2.0 * n1 * ci / (n1 * ci + n2 * ct), tp = 2.0 * n1 * ci / (n2 * ci + n1 * ct);
  return (n2 * ct / max(n1 * ci, 1e-30)) * vec3(ts * ts, tp * tp, ts * tp);
}

#endif  // EIKON_FRESNEL_GLSL
