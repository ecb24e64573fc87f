// The eikonal march shared by view.comp and trace.comp (GPU twin of core/reference/reference_marcher.cpp).
//
// Ray equation with the spatial arc parameter s (docs/design.md §2; Ihrke et al. 2007 eq. 3):
//   dx/ds = w / n(x),   dw/ds = ∇n(x),   w = n·dx/ds, invariant |w| = n.
// Integrated with a fixed step ds = march.x · h by Euler, midpoint (RK2) or classical RK4; inside
// homogeneous regions (skip distance D ≥ 2 voxels) the ray crosses (D − 1.5)·h in one straight
// step, exact because every field is constant there. Interfaces are the layers where |∇n|·h
// rises above 1e-6: on leaving a layer whose peak exceeded march.y, the ray either crossed it
// (Fresnel: transmitted fraction 1 − R with the full unpolarised equations, and an external
// reflection that samples the environment) or was turned back by total internal reflection, which
// the ODE produces by itself (no Fresnel loss).
#ifndef EIKON_MARCH_GLSL
#define EIKON_MARCH_GLSL

layout(std430, binding = EIKON_B_PARAMS) readonly buffer ParamsBuf { ViewParams P; };
layout(binding = EIKON_B_INDEX_O_A, rgba32f) readonly uniform image3D idxOA;
layout(binding = EIKON_B_INDEX_O_B, rgba32f) readonly uniform image3D idxOB;
layout(binding = EIKON_B_INDEX_O_C, rgba32f) readonly uniform image3D idxOC;
layout(binding = EIKON_B_INDEX_E_A, rgba32f) readonly uniform image3D idxEA;
layout(binding = EIKON_B_INDEX_E_B, rgba32f) readonly uniform image3D idxEB;
layout(binding = EIKON_B_INDEX_E_C, rgba32f) readonly uniform image3D idxEC;
layout(binding = EIKON_B_MEDIUM_O, rgba32f) readonly uniform image3D mediumO;
layout(binding = EIKON_B_MEDIUM_E, rgba32f) readonly uniform image3D mediumE;
layout(binding = EIKON_B_EMISSION, rgba32f) readonly uniform image3D emissionImg;
layout(binding = EIKON_B_AXIS, rgba32f) readonly uniform image3D axisImg;
layout(binding = EIKON_B_SCATTER, rgba32f) readonly uniform image3D scatterImg;
layout(binding = EIKON_B_LIGHT_FLUENCE, rgba32f) readonly uniform image3D lightFluenceImg;
layout(binding = EIKON_B_LIGHT_FLUX, rgba32f) readonly uniform image3D lightFluxImg;
layout(std430, binding = EIKON_B_ENV_IMAGE) readonly buffer EnvBuf { vec4 envTexels[]; };
layout(std430, binding = EIKON_B_TABLES) readonly buffer TableBuf { vec4 tables[]; };

const float kPi = 3.14159265358979323846;

// Per-wavelength state set before a march.
float gLambdaUm = 0.5876;
float gIl2 = 1.0 / (0.5876 * 0.5876);
float gIl4 = gIl2 * gIl2;
bool gScalar = false;  // spectral/trace: radiance and attenuation at gLambdaUm, carried in .x (broadcast)

void setWavelength(float lambda_um, bool scalar) {
  gLambdaUm = lambda_um;
  gIl2 = 1.0 / (lambda_um * lambda_um);
  gIl4 = gIl2 * gIl2;
  gScalar = scalar;
}

bool hasFlag(int f) { return (P.grid_dims.w & f) != 0; }

struct Stencil {
  ivec3 i0;
  ivec3 i1;
  vec3 f;
};

Stencil stencilAt(vec3 x) {
  vec3 g = (x - P.grid_origin.xyz) * P.grid_extent.w - 0.5;
  vec3 fl = floor(g);
  Stencil s;
  s.f = g - fl;
  ivec3 i = ivec3(fl);
  ivec3 dmax = P.grid_dims.xyz - 1;
  s.i0 = clamp(i, ivec3(0), dmax);
  s.i1 = clamp(i + 1, ivec3(0), dmax);
  return s;
}

#define TRI(img, s)                                                                              \
  mix(mix(mix(imageLoad(img, s.i0), imageLoad(img, ivec3(s.i1.x, s.i0.y, s.i0.z)), s.f.x),      \
          mix(imageLoad(img, ivec3(s.i0.x, s.i1.y, s.i0.z)), imageLoad(img, ivec3(s.i1.x, s.i1.y, s.i0.z)), s.f.x), \
          s.f.y),                                                                                \
      mix(mix(imageLoad(img, ivec3(s.i0.x, s.i0.y, s.i1.z)), imageLoad(img, ivec3(s.i1.x, s.i0.y, s.i1.z)), s.f.x), \
          mix(imageLoad(img, ivec3(s.i0.x, s.i1.y, s.i1.z)), imageLoad(img, s.i1), s.f.x), s.f.y), \
      s.f.z)

// (n, ∂n/∂x, ∂n/∂y, ∂n/∂z) at x for the current wavelength; mode 0 = o, 1 = e.
// Wavelength sharing (view.comp, spectral mode): while marching the first wavelength of a pixel
// sample, note whether any sample saw dispersion (B or C ≠ 0) and record every environment lookup
// as (direction, weight). If none did, and nothing else depends on λ (no attenuation, emission,
// opacity or crystal), the path and every weight are the same at all wavelengths: the others are
// Σ weight·S_env(λ, direction), without marching.
bool gDispersiveHit = false;
bool gRecord = false;
bool gRecordOverflow = false;
int gNumRecorded = 0;
vec4 gRecorded[6];

vec4 sampleIndex(vec3 x, int mode) {
  Stencil s = stencilAt(x);
  vec4 a;
  if (mode == 0) {
    a = TRI(idxOA, s);
    if (hasFlag(EIKON_F_DISPERSIVE)) {
      vec4 b = TRI(idxOB, s), c = TRI(idxOC, s);
      if (any(notEqual(b, vec4(0.0))) || any(notEqual(c, vec4(0.0)))) gDispersiveHit = true;
      a += b * gIl2 + c * gIl4;
    }
  } else {
    a = TRI(idxEA, s);
    if (hasFlag(EIKON_F_DISPERSIVE)) {
      vec4 b = TRI(idxEB, s), c = TRI(idxEC, s);
      if (any(notEqual(b, vec4(0.0))) || any(notEqual(c, vec4(0.0)))) gDispersiveHit = true;
      a += b * gIl2 + c * gIl4;
    }
  }
  return a;
}

vec4 sampleMedium(vec3 x, int mode) {
  Stencil s = stencilAt(x);
  return mode == 0 ? TRI(mediumO, s) : TRI(mediumE, s);
}

vec3 sampleEmission(vec3 x) {
  Stencil s = stencilAt(x);
  return TRI(emissionImg, s).xyz;
}

// (albedo_r, albedo_g, albedo_b, g); zero where nothing scatters.
vec4 sampleScatter(vec3 x) {
  if (!hasFlag(EIKON_F_SCATTER)) return vec4(0.0);
  Stencil s = stencilAt(x);
  return TRI(scatterImg, s);
}

// Band values (σ at 612, 549, 465 nm) → value at gLambdaUm, linear between, constant beyond.
float bandAt(vec3 rgb) {
  float l = gLambdaUm * 1000.0;
  if (l <= 465.0) return rgb.b;
  if (l >= 612.0) return rgb.r;
  if (l <= 549.0) return rgb.b + (rgb.g - rgb.b) * (l - 465.0) / (549.0 - 465.0);
  return rgb.g + (rgb.r - rgb.g) * (l - 549.0) / (612.0 - 549.0);
}

// Linear sRGB colour → smooth spectrum value at gLambdaUm (core/spectrum/rgb_to_spectrum.h).
float rgbToSpectrum(vec3 rgb) {
  float t = clamp((gLambdaUm * 1000.0 - 380.0) / 5.0, 0.0, 80.0);
  int i = min(int(floor(t)), 79);
  float f = t - float(i);
  vec3 b = mix(tables[EIKON_BASIS_OFFSET + i].xyz, tables[EIKON_BASIS_OFFSET + i + 1].xyz, f);
  return max(rgb.g + (rgb.r - rgb.g) * b.x + (rgb.b - rgb.g) * b.z, 0.0);
}

// Attenuation and colours in the current mode: RGB triplets, or the value at λ broadcast.
vec3 sigmaOf(vec3 bands) { return gScalar ? vec3(bandAt(bands)) : bands; }
vec3 colourOf(vec3 rgb) { return gScalar ? vec3(rgbToSpectrum(rgb)) : rgb; }

// Environment radiance in direction d (unit). Same formulas as Environment::lookup (scene.cpp).
vec3 environment(vec3 d);

// Environment radiance times a throughput weight, recorded for wavelength sharing.
vec3 environmentWeighted(vec3 weight, vec3 d) {
  if (gRecord) {
    if (gNumRecorded < 6) gRecorded[gNumRecorded++] = vec4(d, weight.x);
    else gRecordOverflow = true;
  }
  return weight * environment(d);
}

vec3 environment(vec3 d) {
  float u = atan(d.x, -d.z) / (2.0 * kPi) + 0.5;
  float v = acos(clamp(d.y, -1.0, 1.0)) / kPi;
  int type = int(P.env.x);
  vec3 c;
  if (type == EIKON_ENV_CONSTANT) {
    c = P.env_a.xyz;
  } else if (type == EIKON_ENV_CHECKER) {
    float sq = P.env.y;
    int iu = int(floor(u * 2.0 * sq)), iv = int(floor(v * sq));
    c = ((iu + iv) & 1) != 0 ? P.env_b.xyz : P.env_a.xyz;
  } else {
    int W = P.env_size.x, H = P.env_size.y;
    float fx = u * float(W) - 0.5, fy = v * float(H) - 0.5;
    int x0 = int(floor(fx)), y0 = int(floor(fy));
    float tx = fx - float(x0), ty = fy - float(y0);
    int xa = ((x0 % W) + W) % W, xb = (((x0 + 1) % W) + W) % W;
    int ya = clamp(y0, 0, H - 1), yb = clamp(y0 + 1, 0, H - 1);
    c = mix(mix(envTexels[ya * W + xa].xyz, envTexels[ya * W + xb].xyz, tx),
            mix(envTexels[yb * W + xa].xyz, envTexels[yb * W + xb].xyz, tx), ty);
  }
  return colourOf(c * P.env.z);
}

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

// Light from the light simulator (docs/design.md §2 image formation, Tevs eq. 5.10; docs/light-simulator.md).
// φ (fluence rate, W/mm², linear sRGB) and the net flux vector F of its luminance φ_Y, trilinear.
// Henyey–Greenstein phase function of cos θ (θ between the light's and the scattered direction).
float phaseHG(float cosTheta, float g) {
  float d = 1.0 + g * g - 2.0 * g * cosTheta;
  return (1.0 - g * g) / (4.0 * kPi * d * sqrt(d));
}

// Radiance scattered towards the eye per unit length at x, for a ray travelling along d, before
// multiplying by the path transmittance: σ_s·p·φ with σ_s = albedo·σ_t. The light in a voxel is
// one mean direction m = F/φ_Y with |m| ≤ 1 (1 for a single collimated beam): the phase function
// is |m|·p_HG(m̂·(−d)) + (1 − |m|)/4π, i.e. the part of the light that does not share the mean
// direction is treated as isotropic.
vec3 inScatter(vec3 x, vec3 d, vec3 sigmaT) {
  vec4 sc = sampleScatter(x);
  if (sc.x + sc.y + sc.z <= 0.0) return vec3(0.0);
  Stencil s = stencilAt(x);
  vec4 phi = TRI(lightFluenceImg, s);
  if (phi.w <= 0.0) return vec3(0.0);
  vec3 m = TRI(lightFluxImg, s).xyz / phi.w;
  float lm = min(length(m), 1.0);
  float p = (1.0 - lm) / (4.0 * kPi);
  if (lm > 1e-6) p += lm * phaseHG(dot(normalize(m), -d), sc.w);
  return sigmaOf(sc.xyz) * sigmaT * colourOf(phi.xyz) * p;
}

// Radiance of a diffuse (Lambertian) opaque surface hit at x: albedo·E/π with E = φ·max(0, −m·N),
// the irradiance on the surface of outward normal N from the light volumes sampled 1.5 voxels
// outside the surface (clear of the opaque voxels, where nothing is splatted). N is the
// normalised −∇opacity by central differences of the trilinear opacity.
vec3 diffuseSurface(vec3 x, int mode) {
  // The albedo field is composited with the object's coverage, like the opacity: at the stop
  // point (opacity ≥ 0.5) the surface's own albedo is their ratio.
  if (!hasFlag(EIKON_F_LIT)) return vec3(0.0);
  vec4 sc = sampleScatter(x) / max(sampleMedium(x, mode).w, 0.5);
  if (sc.x + sc.y + sc.z <= 0.0) return vec3(0.0);
  float h = P.grid_origin.w;
  vec3 g = vec3(sampleMedium(x + vec3(h, 0, 0), mode).w - sampleMedium(x - vec3(h, 0, 0), mode).w,
                sampleMedium(x + vec3(0, h, 0), mode).w - sampleMedium(x - vec3(0, h, 0), mode).w,
                sampleMedium(x + vec3(0, 0, h), mode).w - sampleMedium(x - vec3(0, 0, h), mode).w);
  if (dot(g, g) <= 0.0) return vec3(0.0);
  vec3 N = -normalize(g);
  Stencil s = stencilAt(x + 1.5 * h * N);
  vec4 phi = TRI(lightFluenceImg, s);
  if (phi.w <= 0.0) return vec3(0.0);
  float cosFactor = max(0.0, -dot(TRI(lightFluxImg, s).xyz, N)) / phi.w;
  return sigmaOf(sc.xyz) * colourOf(phi.xyz) * (cosFactor / kPi);
}

// Ray–box slab test; returns false if the line misses. t0 ≤ t1.
bool boxHit(vec3 o, vec3 d, vec3 bmin, vec3 bmax, out float t0, out float t1) {
  vec3 inv = 1.0 / mix(d, vec3(1e-30), equal(d, vec3(0.0)));
  vec3 ta = (bmin - o) * inv, tb = (bmax - o) * inv;
  vec3 lo = min(ta, tb), hi = max(ta, tb);
  t0 = max(max(lo.x, lo.y), lo.z);
  t1 = min(min(hi.x, hi.y), hi.z);
  return t1 >= max(t0, 0.0);
}

struct MarchResult {
  vec3 radiance;
  vec3 exit_point;
  vec3 exit_dir;     // ray (energy) direction
  vec3 wave_normal;
  vec3 throughput;
  float opl;
  bool left;
  int steps;
  float drift;
  int interfaces;
  int tir;
};

// Optic axis at x: xyz = unit axis (zero where there is no crystal), w = 1/r for a radial field
// about a centre c (a = (x − c)/r, r = |x − c|), else 0. The texel of the nearest voxel holds either
// the uniform axis (w = 0) or the centre (w = −1).
vec4 axisField(vec3 x) {
  if (!hasFlag(EIKON_F_UNIAXIAL)) return vec4(0.0);
  ivec3 vi = clamp(ivec3(floor((x - P.grid_origin.xyz) * P.grid_extent.w)), ivec3(0), P.grid_dims.xyz - 1);
  vec4 t = imageLoad(axisImg, vi);
  if (t.w > -0.5) return vec4(t.xyz, 0.0);
  vec3 d = x - t.xyz;
  float r = length(d);
  return r > 1e-6 ? vec4(d / r, 1.0 / r) : vec4(0.0, 0.0, 1.0, 0.0);
}
vec3 axisAt(vec3 x) { return axisField(x).xyz; }

// The e-mode's inverse dielectric-like matrix M_e = aaᵀ/n_o² + (I − aaᵀ)/n_e² applied to p.
vec3 applyM(vec3 p, vec3 a, float no, float ne) {
  float pa = dot(p, a);
  return a * pa / (no * no) + (p - a * pa) / (ne * ne);
}

// Derivatives of (x, w) with respect to ray arc length s.
//  o-mode (docs/design.md §2, isotropic form): dx/ds = w/n, dw/ds = ∇n on the shell |w| = n.
//  e-mode (Hamiltonian H = ½(pᵀM_e p − 1), w = p): dx/dτ = M p,
//    dp/dτ = −½ pᵀ(∂M/∂x)p = (p·a)²/n_o³ ∇n_o + (|p|² − (p·a)²)/n_e³ ∇n_e (+ the axis term of a
//    radial field, below),
//    divided by |M p| to step in arc length. Where there is no axis the e-mode is the o-mode.
void deriv(vec3 x, vec3 w, int mode, out vec3 dx, out vec3 dw) {
  vec4 o = sampleIndex(x, 0);
  vec4 af = mode == 1 ? axisField(x) : vec4(0.0);
  vec3 a = af.xyz;
  if (dot(a, a) < 0.25) {
    // Isotropic Hamiltonian M = I/n² in ray arc length: dx/ds = w/|w|, dw/ds = |w|∇n/n. On the
    // shell |w| = n this is dx/ds = w/n, dw/ds = ∇n; off it the ray still moves at unit speed and
    // |w|/n is an invariant of the flow, and it is the e-mode's equation with n_o = n_e.
    float lw = length(w);
    dx = w / lw;
    dw = o.yzw * (lw / o.x);
    return;
  }
  vec4 e = sampleIndex(x, 1);
  float pa = dot(w, a), p2 = dot(w, w);
  vec3 Mp = applyM(w, a, o.x, e.x);
  vec3 dp = (pa * pa / (o.x * o.x * o.x)) * o.yzw + ((p2 - pa * pa) / (e.x * e.x * e.x)) * e.yzw;
  // A varying axis adds −½ ∂(pᵀMp)/∂x from ∂a/∂x = (I − aaᵀ)/r (radial field):
  // −(p·a)(1/n_o² − 1/n_e²)(p − (p·a)a)/r.
  if (af.w > 0.0) dp -= pa * (1.0 / (o.x * o.x) - 1.0 / (e.x * e.x)) * (w - pa * a) * af.w;
  float L = length(Mp);
  dx = Mp / L;
  dw = dp / L;
}

// Ray direction of mode `mode` for wave vector w at x.
vec3 rayDirection(vec3 x, vec3 w, int mode) {
  if (mode == 0) return normalize(w);
  vec3 a = axisAt(x);
  if (dot(a, a) < 0.25) return normalize(w);
  return normalize(applyM(w, a, sampleIndex(x, 0).x, sampleIndex(x, 1).x));
}

// Attenuation per unit ray length of `mode` at x for wave vector w (band values or the value at λ).
// e-mode: σ(θ) = n(θ)³[σ_o cos²θ/n_o³ + σ_e sin²θ/n_e³] per unit wave-normal length (docs/design.md §2,
// first order in the extinction), times cos ρ = s·t for the length along the ray.
vec3 attenuationAt(vec3 x, vec3 w, int mode) {
  vec3 so = sigmaOf(sampleMedium(x, 0).xyz);
  if (mode == 0) return so;
  vec3 a = axisAt(x);
  if (dot(a, a) < 0.25) return so;
  vec3 se = sigmaOf(sampleMedium(x, 1).xyz);
  float no = sampleIndex(x, 0).x, ne = sampleIndex(x, 1).x;
  vec3 s = normalize(w);
  float c = dot(s, a), c2 = c * c, s2 = 1.0 - c2;
  float inv_n2 = c2 / (no * no) + s2 / (ne * ne);
  float n = inversesqrt(inv_n2);
  vec3 t = normalize(applyM(w, a, no, ne));
  return n * n * n * (so * c2 / (no * no * no) + se * s2 / (ne * ne * ne)) * dot(s, t);
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

MarchResult march(vec3 o, vec3 d, int mode) {
  MarchResult R;
  R.radiance = vec3(0.0);
  R.throughput = vec3(1.0);
  R.opl = 0.0;
  R.left = true;
  R.steps = 0;
  R.drift = 0.0;
  R.interfaces = 0;
  R.tir = 0;
  const vec3 bmin = P.grid_origin.xyz, bmax = P.grid_origin.xyz + P.grid_extent.xyz;
  const float h = P.grid_origin.w;
  const float ambient = P.march.z;
  float t0, t1;
  if (!boxHit(o, d, bmin, bmax, t0, t1)) {
    R.radiance = environmentWeighted(vec3(1.0), d);
    R.exit_point = o;
    R.exit_dir = d;
    R.wave_normal = d;
    return R;
  }
  t0 = max(t0, 0.0);
  vec3 x = o + d * t0;
  R.opl = ambient * t0;
  vec4 nn = sampleIndex(x, 0);
  vec3 w = nn.x * d;  // the volume's faces are isotropic (air): p = n d
  const float ds = P.march.x * h;
  const int integrator = int(P.march.w);
  const float thrLow = 1e-6, thrIface = P.march.y;
  bool inLayer = false;
  float peak = 0.0;
  vec3 wBefore = w, gAcc = vec3(0.0), xOpen = x;
  vec3 T = vec3(1.0), L = vec3(0.0);
  bool stopped = false;
  const int maxSteps = P.limits.x;
  int steps = 0;
  for (; steps < maxSteps; ++steps) {
    // Homogeneous region: one straight, exact step along the ray direction.
    vec4 em = vec4(0.0);
    if (!inLayer && !hasFlag(EIKON_F_NO_SKIP))
      em = imageLoad(emissionImg, clamp(ivec3(floor((x - P.grid_origin.xyz) * P.grid_extent.w)), ivec3(0), P.grid_dims.xyz - 1));
    if (em.w >= 2.0) {
      vec3 dir = rayDirection(x, w, mode);
      float tb0, tb1;
      boxHit(x, dir, bmin, bmax, tb0, tb1);
      float tExit = max(tb1, 0.0);
      float len = (em.w - 1.5) * h;
      // A lit scattering medium is homogeneous but its light is not: sample the light every voxel.
      bool scattering = hasFlag(EIKON_F_LIT) && hasFlag(EIKON_F_SCATTER) && dot(sampleScatter(x).xyz, vec3(1.0)) > 0.0;
      if (scattering) len = min(len, h);
      bool leaving = len >= tExit;
      len = min(len, tExit);
      if (hasFlag(EIKON_F_OPACITY) && sampleMedium(x, mode).w >= 0.5) {
        L += T * (colourOf(em.xyz) / sampleMedium(x, mode).w + diffuseSurface(x, mode));
        stopped = true;
        break;
      }
      if (hasFlag(EIKON_F_EMISSION) || hasFlag(EIKON_F_ATTENUATION)) {
        vec3 sig = hasFlag(EIKON_F_ATTENUATION) ? attenuationAt(x, w, mode) : vec3(0.0);
        vec3 e = colourOf(em.xyz);
        // In-scatter with the light at the middle of this straight step, constant over it.
        if (scattering) e += inScatter(x + 0.5 * len * dir, dir, sig);
        vec3 att = exp(-sig * len);
        // ∫₀^len T e^{−σs} e ds = T e (1 − e^{−σ len})/σ  (→ T e len as σ → 0)
        L += T * mix(e * len, e * (1.0 - att) / max(sig, vec3(1e-30)), greaterThan(sig, vec3(1e-6)));
        T *= att;
      }
      R.opl += dot(w, dir) * len;  // ∫ p·dx
      x += dir * len;
      if (leaving) break;
      continue;
    }
    // One integration step of the ray equation.
    vec3 x0 = x, w0 = w;
    float n0 = nn.x;
    vec3 k1x, k1w, k2x, k2w, k3x, k3w, k4x, k4w;
    deriv(x, w, mode, k1x, k1w);
    if (integrator == EIKON_INT_EULER) {
      x += ds * k1x;
      w += ds * k1w;
    } else if (integrator == EIKON_INT_MIDPOINT) {
      deriv(x + 0.5 * ds * k1x, w + 0.5 * ds * k1w, mode, k2x, k2w);
      x += ds * k2x;
      w += ds * k2w;
    } else {
      deriv(x + 0.5 * ds * k1x, w + 0.5 * ds * k1w, mode, k2x, k2w);
      deriv(x + 0.5 * ds * k2x, w + 0.5 * ds * k2w, mode, k3x, k3w);
      deriv(x + ds * k3x, w + ds * k3w, mode, k4x, k4w);
      x += ds / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
      w += ds / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
    }
    nn = sampleIndex(x, 0);
    vec3 gradN = nn.yzw;
    vec3 aHere = mode == 1 ? axisAt(x) : vec3(0.0);
    bool eHere = mode == 1 && dot(aHere, aHere) >= 0.25;
    vec4 ne = eHere ? sampleIndex(x, 1) : nn;
    if (mode == 0) {
      R.drift = max(R.drift, abs(length(w) - nn.x));
      R.opl += 0.5 * (n0 + nn.x) * ds;
    } else {
      R.opl += 0.5 * dot(w0 + w, x - x0);
      if (eHere) gradN = 0.5 * (nn.yzw + ne.yzw);
    }
    // Medium at the step midpoint (only sampled where the scene has any).
    vec3 xm = 0.5 * (x0 + x);
    if (hasFlag(EIKON_F_EMISSION)) L += T * colourOf(sampleEmission(xm)) * ds;
    if (hasFlag(EIKON_F_ATTENUATION)) {
      vec3 sig = attenuationAt(xm, 0.5 * (w0 + w), mode);
      if (hasFlag(EIKON_F_LIT) && hasFlag(EIKON_F_SCATTER)) L += T * inScatter(xm, normalize(x - x0), sig) * ds;
      T *= exp(-sig * ds);
    }
    if (hasFlag(EIKON_F_OPACITY) && sampleMedium(x, mode).w >= 0.5) {
      // Surface emission: the emission field over the coverage (opacity ≥ 0.5 here), as the albedo.
      L += T * (colourOf(sampleEmission(x)) / sampleMedium(x, mode).w + diffuseSurface(x, mode));
      stopped = true;
      break;
    }
    // Interface bookkeeping.
    float g = max(length(nn.yzw), length(ne.yzw)) * h;
    if (!inLayer && g > thrLow) {
      inLayer = true;
      wBefore = w0;
      gAcc = vec3(0.0);
      peak = 0.0;
      xOpen = x0;
    }
    if (inLayer) {
      gAcc += gradN * ds;
      peak = max(peak, g);
      if (g <= thrLow) {
        inLayer = false;
        vec3 N = dot(gAcc, gAcc) > 0.0 ? normalize(gAcc) : vec3(0.0);
        if (dot(N, N) > 0.0 && abs(dot(x - xOpen, N)) <= 12.0 * h) {
          // Back on the constraint surface H = 0 (|w| = n for the o-mode, wᵀM_e w = 1 for the
          // e-mode) along the layer normal: the tangential part of w is what the interface
          // conserves (Snell). The stored central-difference gradient is not exactly the
          // derivative of the trilinear n, which makes H drift by ~1e-4 across a sharp layer.
          // Only for thin layers (interfaces no thicker than 12 voxels along their normal),
          // never across gradient-index bodies; skipped if the normal part would change much.
          float wn = dot(w, N);
          vec3 wt = w - wn * N;
          if (!eHere) {
            float rem = nn.x * nn.x - dot(wt, wt);
            if (rem > 0.25 * wn * wn) w = wt + sign(wn) * sqrt(rem) * N;
          } else {
            // (wt + λN)ᵀ M (wt + λN) = 1: qa λ² + 2 qb λ + qc = 0, root nearest the current wn.
            vec3 MN = applyM(N, aHere, nn.x, ne.x);
            float qa = dot(N, MN), qb = dot(wt, MN), qc = dot(wt, applyM(wt, aHere, nn.x, ne.x)) - 1.0;
            float disc = qb * qb - qa * qc;
            if (disc > 0.0) {
              float l1 = (-qb + sqrt(disc)) / qa, l2 = (-qb - sqrt(disc)) / qa;
              float lam = abs(l1 - wn) < abs(l2 - wn) ? l1 : l2;
              if (abs(lam - wn) < 0.5 * abs(wn)) w = wt + lam * N;
            }
          }
        }
        if (peak > thrIface && !hasFlag(EIKON_F_NO_FRESNEL) && dot(N, N) > 0.0) {
          vec3 dIn = normalize(wBefore), dOut = normalize(w);
          float ci = dot(dIn, N), co = dot(dOut, N);
          float n1 = length(wBefore), n2 = length(w);
          if (ci * co > 0.0) {
            // Which side is the crystal? The end of the layer with the larger birefringence (the
            // axis field itself is dilated into the air around crystals).
            float bOut = abs(sampleIndex(x, 1).x - sampleIndex(x, 0).x);
            float bIn = abs(sampleIndex(xOpen, 1).x - sampleIndex(xOpen, 0).x);
            bool outCrystal = bOut >= bIn;
            vec3 a = axisAt(outCrystal ? x : xOpen);
            float wsw = sWeight(outCrystal ? dOut : dIn, a, N, dIn, mode);
            vec2 rsp = fresnelRsRp(abs(ci), n1, n2);
            float Rf = hasFlag(EIKON_F_UNIAXIAL) ? wsw * rsp.x + (1.0 - wsw) * rsp.y : 0.5 * (rsp.x + rsp.y);
            if (n2 > n1) L += environmentWeighted(T * Rf, reflect(dIn, N));
            T *= 1.0 - Rf;
            R.interfaces++;
          } else {
            R.tir++;
          }
        }
      }
    }
    // Left the volume? The ray is straight outside (fields clamp to the uniform edge voxels).
    if (any(lessThan(x, bmin)) || any(greaterThan(x, bmax))) {
      vec3 dd = normalize(x - x0);
      float a0, a1;
      boxHit(x0, dd, bmin, bmax, a0, a1);
      float stepLen = length(x - x0);
      float keep = clamp(max(a1, 0.0) / max(stepLen, 1e-30), 0.0, 1.0);
      R.opl -= (1.0 - keep) * 0.5 * dot(w0 + w, x - x0);
      x = x0 + (x - x0) * keep;
      // w at the boundary, not at the overshoot (linear within the step).
      w = mix(w0, w, keep);
      break;
    }
  }
  R.steps = steps;
  R.exit_point = x;
  R.exit_dir = rayDirection(x, w, mode);
  R.wave_normal = normalize(w);
  R.left = !stopped && steps < maxSteps;
  if (R.left) L += environmentWeighted(T, R.exit_dir);
  R.radiance = L;
  R.throughput = T;
  return R;
}

#endif
