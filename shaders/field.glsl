// The field/medium layer of the GPU twin: how a kernel reads the voxelised VolumeSet and the
// per-point physics of a medium (docs/design.md §2), written once for every kernel that marches
// through it (march.glsl for view.comp and trace.comp, wavefront.comp). Its CPU twin is
// core/reference/field.{h,cpp} (the sampling: VolumeField, core/volume/field.cpp): the same
// functions under the same names in double precision, sharing no code with this file
// (docs/twins.md).
//
// The including kernel declares, before `#include "field.glsl"`:
//   P                 its parameter block, with grid_origin (xyz: bounds_min, w: voxel edge h) and
//                     grid_dims (xyz: voxels per axis, w: EIKON_F_* flags);
//   idxOA, idxOB, idxOC, idxEA, idxEB, idxEC   the Cauchy coefficient images A, B, C of the o- and
//                     e-mode (each texel (value, ∂/∂x, ∂/∂y, ∂/∂z));
//   mediumO, mediumE  (σ at 612, 549, 465 nm, opacity) of the o- and e-mode;
//   axisImg           the optic-axis image (uniform axis with w = 0, or a radial centre, w = −1);
// and defines the macros
//   EIKON_FIELD_INV_H      1/h;
//   EIKON_FIELD_LAMBDA_UM  the wavelength (µm), EIKON_FIELD_IL2 / EIKON_FIELD_IL4 its 1/λ², 1/λ⁴;
//   EIKON_FIELD_HAS_AXIS   an expression, false where the kernel binds no optic axis;
//   EIKON_FIELD_FLAGS      optional: the EIKON_F_* flags hasFlag tests (default P.grid_dims.w).
//                          march.glsl makes them a specialization constant: lavapipe runs both
//                          sides of every branch (masked SIMD), so only code that a constant
//                          removes costs nothing (docs/performance.md).
#ifndef EIKON_FIELD_GLSL
#define EIKON_FIELD_GLSL

#ifndef EIKON_FIELD_FLAGS
#define EIKON_FIELD_FLAGS P.grid_dims.w
#endif

// A macro, not a function: with a specialization constant for EIKON_FIELD_FLAGS every test is a
// constant expression at its use, which the host's SPIR-V passes fold and whose dead branches
// they remove before the driver sees the module (core/vk/specialise.h); a function call hid the
// constant from them.
#define hasFlag(f) ((EIKON_FIELD_FLAGS & (f)) != 0)

// ---- Sampling: cell-centred trilinear stencil, clamped to the edge voxels ----

struct Stencil {
  ivec3 i0;
  ivec3 i1;
  vec3 f;
};

Stencil stencilAt(vec3 x) {
  vec3 g = (x - P.grid_origin.xyz) * EIKON_FIELD_INV_H - 0.5;
  vec3 fl = floor(g);
  Stencil s;
  s.f = g - fl;
  ivec3 i = ivec3(fl);
  ivec3 dmax = P.grid_dims.xyz - 1;
  s.i0 = clamp(i, ivec3(0), dmax);
  s.i1 = clamp(i + 1, ivec3(0), dmax);
  return s;
}

// Trilinear value of image img over stencil s (a macro: GLSL cannot pass images to functions).
#define TRI(img, s)                                                                              \
  mix(mix(mix(imageLoad(img, s.i0), imageLoad(img, ivec3(s.i1.x, s.i0.y, s.i0.z)), s.f.x),      \
          mix(imageLoad(img, ivec3(s.i0.x, s.i1.y, s.i0.z)), imageLoad(img, ivec3(s.i1.x, s.i1.y, s.i0.z)), s.f.x), \
          s.f.y),                                                                                \
      mix(mix(imageLoad(img, ivec3(s.i0.x, s.i0.y, s.i1.z)), imageLoad(img, ivec3(s.i1.x, s.i0.y, s.i1.z)), s.f.x), \
          mix(imageLoad(img, ivec3(s.i0.x, s.i1.y, s.i1.z)), imageLoad(img, s.i1), s.f.x), s.f.y), \
      s.f.z)

// The voxel holding x (nearest, clamped): where the axis and the skip distance are read.
ivec3 voxelAt(vec3 x) {
  return clamp(ivec3(floor((x - P.grid_origin.xyz) * EIKON_FIELD_INV_H)), ivec3(0), P.grid_dims.xyz - 1);
}

// (n, ∂n/∂x, ∂n/∂y, ∂n/∂z) of mode 0 (o) or 1 (e) at x and the kernel's wavelength:
// A + B/λ² + C/λ⁴ (docs/design.md §2, Dispersion). Sets `dispersive` where the sampled B or C is
// non-zero (march.glsl's wavelength sharing: the path met dispersion).
// Where the kernel binds no optic axis the e-mode images are the o-mode's, so mode 1 reads
// those (one branch fewer for a kernel specialised without crystals).
vec4 sampleIndex(vec3 x, int mode, inout bool dispersive) {
  Stencil s = stencilAt(x);
  vec4 a;
  if (mode == 0 || !(EIKON_FIELD_HAS_AXIS)) {
    a = TRI(idxOA, s);
    if (hasFlag(EIKON_F_DISPERSIVE)) {
      vec4 b = TRI(idxOB, s), c = TRI(idxOC, s);
      if (any(notEqual(b, vec4(0.0))) || any(notEqual(c, vec4(0.0)))) dispersive = true;
      a += b * EIKON_FIELD_IL2 + c * EIKON_FIELD_IL4;
    }
  } else {
    a = TRI(idxEA, s);
    if (hasFlag(EIKON_F_DISPERSIVE)) {
      vec4 b = TRI(idxEB, s), c = TRI(idxEC, s);
      if (any(notEqual(b, vec4(0.0))) || any(notEqual(c, vec4(0.0)))) dispersive = true;
      a += b * EIKON_FIELD_IL2 + c * EIKON_FIELD_IL4;
    }
  }
  return a;
}

// The same where nothing notes dispersion (wavefront.comp).
vec4 sampleIndex(vec3 x, int mode) {
  bool unused = false;
  return sampleIndex(x, mode, unused);
}

// (σ_r, σ_g, σ_b band values per mm, opacity) of the o-mode at x: a function of its own, so that
// a kernel that reads only the o-mode's keeps no read of mediumE (the host specialises without
// inlining, so a constant mode argument does not fold sampleMedium's test).
vec4 sampleMediumO(vec3 x) { return TRI(mediumO, stencilAt(x)); }

// The same of mode 0 (o) or 1 (e) at x (one stencil for either image).
vec4 sampleMedium(vec3 x, int mode) {
  Stencil s = stencilAt(x);
  if (mode == 0 || !(EIKON_FIELD_HAS_AXIS)) return TRI(mediumO, s);
  return TRI(mediumE, s);
}

// Band values (σ at 612, 549, 465 nm) → value at the wavelength, linear between, constant beyond.
float bandAt(vec3 rgb) {
  float l = EIKON_FIELD_LAMBDA_UM * 1000.0;
  if (l <= 465.0) return rgb.b;
  if (l >= 612.0) return rgb.r;
  if (l <= 549.0) return rgb.b + (rgb.g - rgb.b) * (l - 465.0) / (549.0 - 465.0);
  return rgb.g + (rgb.r - rgb.g) * (l - 549.0) / (612.0 - 549.0);
}

// ---- The optic axis and the e-mode (docs/design.md §2, One Hamiltonian for both modes) ----

// Optic axis at x: xyz = unit axis (zero where there is no crystal), w = 1/r for a radial field
// about a centre c (a = (x − c)/r, r = |x − c|), else 0. The texel of the nearest voxel holds either
// the uniform axis (w = 0) or the centre (w = −1).
vec4 axisField(vec3 x) {
  if (!(EIKON_FIELD_HAS_AXIS)) return vec4(0.0);
  vec4 t = imageLoad(axisImg, voxelAt(x));
  if (t.w > -0.5) return vec4(t.xyz, 0.0);
  vec3 d = x - t.xyz;
  float r = length(d);
  return r > 1e-6 ? vec4(d / r, 1.0 / r) : vec4(0.0, 0.0, 1.0, 0.0);
}

// A crystal is where the axis is set (it is zero, not merely short, elsewhere).
bool hasAxis(vec3 a) { return dot(a, a) >= 0.25; }

// The e-mode's inverse dielectric-like matrix M_e = aaᵀ/n_o² + (I − aaᵀ)/n_e² applied to p.
vec3 applyM(vec3 p, vec3 a, float no, float ne) {
  float pa = dot(p, a);
  return a * pa / (no * no) + (p - a * pa) / (ne * ne);
}

// The e-mode's Hamiltonian rates H = ½(pᵀM_e p − 1) for wave vector p, axis field af (axisField),
// o = (n_o, ∇n_o), e = (n_e, ∇n_e): Mp = dx/dτ = M_e p and
//   dp = dp/dτ = −½ pᵀ(∂M_e/∂x)p = (p·a)²/n_o³ ∇n_o + (|p|² − (p·a)²)/n_e³ ∇n_e
// minus, for a radial axis field (∂a/∂x = (I − aaᵀ)/r), (p·a)(1/n_o² − 1/n_e²)(p − (p·a)a)/r.
void eModeRates(vec3 p, vec4 af, vec4 o, vec4 e, out vec3 Mp, out vec3 dp) {
  vec3 a = af.xyz;
  float pa = dot(p, a), p2 = dot(p, p);
  Mp = applyM(p, a, o.x, e.x);
  dp = (pa * pa / (o.x * o.x * o.x)) * o.yzw + ((p2 - pa * pa) / (e.x * e.x * e.x)) * e.yzw;
  if (af.w > 0.0) dp -= pa * (1.0 / (o.x * o.x) - 1.0 / (e.x * e.x)) * (p - pa * a) * af.w;
}

// The wave vector along the unit wave normal s on the e-mode's shell pᵀM_e p = 1.
vec3 onShellE(vec3 s, vec3 a, float no, float ne) { return s * inversesqrt(dot(s, applyM(s, a, no, ne))); }

// e-mode attenuation per unit ray length for wave vector w (pleochroism, docs/design.md §2):
// σ(θ) = n(θ)³[σ_o cos²θ/n_o³ + σ_e sin²θ/n_e³] per unit wave-normal length, first order in the
// extinction, times cos ρ = ŝ·t̂ for the length along the ray (t̂ ∥ M_e w).
vec3 attenuationE(vec3 so, vec3 se, vec3 w, vec3 a, float no, float ne) {
  vec3 s = normalize(w);
  float c = dot(s, a), c2 = c * c, s2 = 1.0 - c2;
  float inv_n2 = c2 / (no * no) + s2 / (ne * ne);
  float n = inversesqrt(inv_n2);
  vec3 t = normalize(applyM(w, a, no, ne));
  return n * n * n * (so * c2 / (no * no * no) + se * s2 / (ne * ne * ne)) * dot(s, t);
}

#endif
