#version 450
// The polarised trace of the GPU twin (docs/polarisation.md): the twin of
// core/reference/polarised_trace.cpp under the same names (Tracer::run, segment, cross,
// applySheets, recombine), in single precision. One invocation follows one ray forwards through
// the sharp march's regions, splitting it into o and e branches at crystal faces (a bounded ray
// tree: EIKON_POL_MAX_* in eikon_shared.h), and reports the Stokes vector of every beam leaving
// the scene for the ray's input Stokes vector.
//
// Where it differs from the CPU twin, on purpose:
//   * crystal faces use the D-projection split (fresnel.glsl's idea, with amplitudes): each
//     outgoing mode takes the Born & Wolf s and p amplitudes of an isotropic interface of its own
//     index n(θ), projected on the mode's field direction; the CPU solves Maxwell's 4×4 boundary
//     problem. The two agree at normal incidence and where the modes are pure s and p (a c-cut
//     plate), and differ by a few 1e-3 in power at oblique incidence otherwise. A biaxial
//     crystal's fast (mode 0) and slow (mode 1) waves come from sharp.glsl's solveBiaxialMode and
//     take the same split with their own index and unit D (the eigenvector of ε⁻¹ ⊥ the wave
//     normal); the CPU solves the Booker quartic and the 4×4 problem (tensor_interface.h).
//     Reflection off a crystal face splits the incident field over the far side's two modes and
//     reflects each part with its own index (crystalReflection: exact at normal incidence);
//   * float32 phases: each branch carries its optical path RELATIVE to the input ray's wavefront,
//     Σ (p − p_in)·Δx over its straight pieces, so the numbers summed are (n − n_ambient) × the
//     thickness crossed, not the whole path; two branches' difference (the o−e retardation) is
//     then a difference of small numbers (~0.1 nm per mm of crystal), and the recombination phase
//     is reduced to a fraction of a wave before its cosine is taken;
//   * the two recombination tests (coherence length and width) are the CPU's; directions are
//     grouped by the chord |t₁ − t₂| instead of acos(t₁·t₂) (acos loses float precision near 0).
// Frames and conventions are the CPU's (Mitsuba 3's): input in stokesBasis(ray direction), each
// beam in stokesBasis(its direction), S3 > 0 right circular with e^{−iωt}.
#extension GL_GOOGLE_include_directive : require
#include "eikon_shared.h"

// Eight rays per workgroup, one per invocation: lavapipe runs them as one 8-wide SIMD group, and
// its loop budget (65535 passes, shared by the group) is spent by the group's longest ray rather
// than by the sum of the eight (a group runs each loop until its last lane is done); a ray cut by
// the budget is reported (loopLimitReached sets `truncated`), never returned silently short.
layout(local_size_x = EIKON_POL_GROUP) in;

#include "march.glsl"
#include "fresnel.glsl"
#include "sharp.glsl"

layout(std430, binding = EIKON_B_RAYS) readonly buffer RayBuf { PolarisedRay rays[]; };
layout(std430, binding = EIKON_B_OUTPUT) writeonly buffer ResultBuf { PolarisedResult results[]; };
layout(std430, binding = EIKON_B_SHEETS) readonly buffer SheetBuf { vec4 sheets[]; };

const float kFarMm = 1e9;  // "to infinity": sheets beyond the volume
const float kGrazeCos = 1e-6;  // a ray this close to a face's plane runs along it (cross)

// ---- Complex numbers (vec2) and complex 3-vectors ----

vec2 cmul(vec2 a, vec2 b) { return vec2(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x); }
vec2 cdiv(vec2 a, vec2 b) { return cmul(a, vec2(b.x, -b.y)) / dot(b, b); }

struct CV {
  vec3 re;
  vec3 im;
};

vec2 cvDot(CV v, vec3 a) { return vec2(dot(v.re, a), dot(v.im, a)); }
CV cvScale(vec2 c, vec3 e) { return CV(c.x * e, c.y * e); }
CV cvAdd(CV a, CV b) { return CV(a.re + b.re, a.im + b.im); }
CV cvMul(vec2 c, CV v) { return CV(c.x * v.re - c.y * v.im, c.x * v.im + c.y * v.re); }
float cvNorm2(CV v) { return dot(v.re, v.re) + dot(v.im, v.im); }

// Mitsuba 3's stokes_basis (anisotropic/polarization.cpp stokesBasis): the Stokes reference direction
// of a unit forward direction.
vec3 stokesBasis(vec3 n) {
  float sgn = n.z >= 0.0 ? 1.0 : -1.0, a = -1.0 / (sgn + n.z), b = n.x * n.y * a;
  return vec3(1.0 + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
}

// ---- The ray tree ----

// One path of the o/e ray tree (the CPU's Branch): position, wave vector, ray, region and mode,
// the power-normalised fields for the input basis states x̂_in (G0) and ŷ_in (G1), the optical
// path relative to the input wavefront (header), and the crystal modes met (bits, e = 1).
struct Branch {
  vec3 x;
  vec3 p;
  vec3 ray;
  int region;
  int mode;
  CV G0;
  CV G1;
  float opl;
  int modes;
  int nmodes;
  int events;
  int choices;  // reflect-or-transmit choices made (P.pass.w > 0): the uniform's index k
  int side;     // of the split first choice: 0 none, 1 transmitted, 2 reflected (recombine)
};

// The ray tree of the invocation's one ray (the CPU's Tracer): the branches waiting, the leaves,
// whether it was cut short, the region refused (+1) and the input wave vector. Globals, not a
// struct passed inout: the stack and the leaves are arrays of Branch indexed at run time, which
// llvmpipe keeps in memory and would copy whole at every call that took them inout (the
// polarised render ran ~1.6× slower so, on lavapipe).
Branch gStack[EIKON_POL_MAX_STACK];
int gTop = 0;
Branch gLeaves[EIKON_POL_MAX_LEAVES];
int gLeafCount = 0;
bool gTruncated = false;
int gUnsupported = 0;
vec3 gPin;  // the input wave vector n_ambient·d
uint gSeed;  // the ray's seed (its direction.w's bits): Transport::Full's choices

void push(Branch b) {
  if (gTop >= EIKON_POL_MAX_STACK) {
    gTruncated = true;
    return;
  }
  gStack[gTop++] = b;
}

int sheetCount() { return min(int(sheets[0].x), EIKON_POL_MAX_SHEETS); }

// An ideal dichroic sheet absorbs the field along its absorbing direction normal × axis
// (projected ⊥ the wave normal) and transmits the rest; sheets on [x, x + dir·len], nearest first.
void applySheets(inout Branch b, vec3 x, vec3 dir, float len) {
  int n = sheetCount();
  vec3 k = normalize(b.p);
  float last = 0.0;
  for (int done = 0; done < n; ++done) {  // selection by distance: the next sheet beyond `last`
    float best = 3.0e38;
    int which = -1;
    for (int s = 0; s < n; ++s) {
      vec4 c = sheets[1 + 3 * s], nm = sheets[2 + 3 * s], ax = sheets[3 + 3 * s];
      float dn = dot(dir, nm.xyz);
      if (abs(dn) < 1e-15) continue;
      float t = dot(c.xyz - x, nm.xyz) / dn;
      if (!(t > last && t <= len && t < best)) continue;
      vec3 r = x + t * dir - c.xyz;
      if (abs(dot(r, ax.xyz)) <= 0.5 * c.w && abs(dot(r, cross(nm.xyz, ax.xyz))) <= 0.5 * nm.w) {
        best = t;
        which = s;
      }
    }
    if (which < 0) break;
    last = best;
    vec3 a = cross(sheets[2 + 3 * which].xyz, sheets[3 + 3 * which].xyz);
    a -= dot(a, k) * k;
    if (length(a) < 1e-6) continue;  // grazing: the absorbing direction is along k
    a = normalize(a);
    b.G0 = cvAdd(b.G0, cvScale(-cvDot(b.G0, a), a));
    b.G1 = cvAdd(b.G1, cvScale(-cvDot(b.G1, a), a));
  }
}

// A straight piece of length len along b.ray in b's region: sheets, the relative optical path
// (p − p_in)·Δx and the pleochroic amplitude exp(−½σL), σ per unit ray length.
void segment(inout Branch b, float len) {
  applySheets(b, b.x, b.ray, len);
  b.opl += dot(b.p - gPin, b.ray) * len;
  int r = b.region;
  float sigma = regionSigmaAt(r, 0);
  vec4 af = regionAxisField(r, b.x);
  if (mediumUniaxial(r) && b.mode == 1 && hasAxis(af.xyz))
    sigma = attenuationE(vec3(sigma), vec3(regionSigmaAt(r, 1)), b.p, af.xyz,
                         regionIndex(r, 0, b.x), regionIndex(r, 1, b.x))
                .x;
  if (mediumBiaxial(r)) {  // trichroic: σ_α, σ_β, σ_γ (regionSigmaAt 0, 2, 1) of the mode's D
    bool dispersive = false;
    Biaxial B = biaxialOf(r, dispersive);
    sigma = biaxialAttenuation(B, vec3(sigma), vec3(regionSigmaAt(r, 2)), vec3(regionSigmaAt(r, 1)),
                               b.p, biaxialWave(B, b.p, b.mode))
                .x;
  }
  if (sigma > 0.0) {
    float f = exp(-0.5 * sigma * len);
    b.G0 = cvMul(vec2(f, 0.0), b.G0);
    b.G1 = cvMul(vec2(f, 0.0), b.G1);
  }
  b.x += b.ray * len;
}

// Born & Wolf's complex amplitudes n1 → n2 at cos i = ci; beyond the critical angle
// cos t = +i√((n1/n2)² sin²i − 1) (anisotropic/polarization.cpp fresnelAmplitudes). xy: (r_s, r_p)
// as two complex numbers, zw: the power-normalised (t̃_s, t̃_p).
void fresnelAmplitudes(float ci, float n1, float n2, out vec2 rs, out vec2 rp, out vec2 ts,
                       out vec2 tp) {
  float st2 = (n1 / n2) * (n1 / n2) * max(0.0, 1.0 - ci * ci);
  bool total = st2 > 1.0;
  vec2 ct = total ? vec2(0.0, sqrt(st2 - 1.0)) : vec2(sqrt(1.0 - st2), 0.0);
  vec2 a = vec2(n1 * ci, 0.0), b = n2 * ct, c = vec2(n2 * ci, 0.0), d = n1 * ct;
  rs = cdiv(a - b, a + b);
  rp = cdiv(c - d, c + d);
  float f = total ? 0.0 : sqrt(n2 * ct.x / (n1 * ci));
  ts = f * cdiv(2.0 * a, a + b);
  tp = f * cdiv(2.0 * a, c + d);
}

// The unit D direction of a crystal mode (the D-projection of fresnel.glsl's sWeight): o along
// s × a, e in the principal plane ⊥ s; where s ∥ a the modes are degenerate and follow ŝ. The
// field carried in a crystal is the mode's amplitude along it (⊥ the wave normal, so that a
// normal-incidence exit returns all of it, as the exact solve does).
vec3 modeField(int mode, vec3 s, vec3 a, vec3 sHat) {
  vec3 o = cross(s, a);
  o = length(o) < 1e-6 ? sHat : normalize(o);
  return mode == 0 ? o : normalize(cross(o, s));
}

// One outgoing wave w of an interface: its field from the incident (E_s, E_p) with the amplitudes
// (cs, cp), in the (ŝ, p̂ = k̂ × ŝ) frame of the wave or projected on its crystal mode (a biaxial
// mode's unit D where D ≠ 0, else the uniaxial modeField).
Branch outgoing(Branch b, ModeWave w, int mode, bool crystal, vec3 a, vec3 D, vec3 sHat, vec2 cs,
                vec2 cp, vec2 es0, vec2 ep0, vec2 es1, vec2 ep1) {
  Branch nb = b;
  vec3 pw = cross(w.s, sHat);
  CV f0 = cvAdd(cvScale(cmul(cs, es0), sHat), cvScale(cmul(cp, ep0), pw));
  CV f1 = cvAdd(cvScale(cmul(cs, es1), sHat), cvScale(cmul(cp, ep1), pw));
  if (crystal) {
    vec3 e = dot(D, D) > 0.25 ? D : modeField(mode, w.s, a, sHat);
    f0 = cvScale(cvDot(f0, e), e);
    f1 = cvScale(cvDot(f1, e), e);
  }
  nb.G0 = f0;
  nb.G1 = f1;
  nb.p = w.n * w.s;
  nb.ray = w.t;
  nb.mode = mode;
  return nb;
}

// What one crossing's outgoing waves share: the incident (ŝ, p̂) frame and field components, cos i,
// the incident and the far side's ordinary index, each side's crystal axis (zero: isotropic or
// biaxial), whether each side is a crystal (uniaxial or biaxial), the biaxial modes' unit D
// (zero elsewhere: the uniaxial modeField applies) and the far side's transmitted waves.
struct Incidence {
  vec3 sHat;
  vec2 es0, ep0, es1, ep1;
  float ci, nIn, noB;
  vec3 aA, aB;
  bool uA, uB;
  vec3 dA0, dA1, dB0, dB1;
  ModeWave wt0, wt1;
};

// The reflected amplitudes off a crystal's face (B a crystal), in the D-projection: the incident
// field splits over B's two transmitted modes k (their unit fields e_k, as components (a_k, b_k)
// along ŝ and the mode's p̂), and each part reflects with the s and p amplitudes of an isotropic
// interface of that mode's own index n_k (uniaxial: n_o and the e-wave's n(θ); biaxial: n_fast,
// n_slow): E_r = Σ_k (a_k E_s + b_k E_p)(r_s,k a_k ŝ + r_p,k b_k p̂_r). Exact at normal incidence
// and where the modes are pure s and p; with one index for both modes a quartz face reflected
// 6e-4 of the power wrongly. Where a mode of B is evanescent: one isotropic interface of B's n_o.
bool crystalReflection(Incidence I, vec3 pw, float scale, out CV f0, out CV f1) {
  f0 = CV(vec3(0.0), vec3(0.0));
  f1 = f0;
  if (!I.uB || !I.wt0.exists || !I.wt1.exists) return false;
  for (int k = 0; k < 2; ++k) {
    ModeWave t = k == 0 ? I.wt0 : I.wt1;
    vec3 d = k == 0 ? I.dB0 : I.dB1;
    vec3 e = dot(d, d) > 0.25 ? d : modeField(k, t.s, I.aB, I.sHat);
    vec2 ab = vec2(dot(e, I.sHat), dot(e, cross(t.s, I.sHat)));
    if (dot(ab, ab) < 1e-12) continue;
    ab = normalize(ab);
    vec2 rs, rp, ts, tp;
    fresnelAmplitudes(I.ci, I.nIn, t.n, rs, rp, ts, tp);
    vec2 c0 = ab.x * I.es0 + ab.y * I.ep0, c1 = ab.x * I.es1 + ab.y * I.ep1;
    vec2 s = scale * ab.x * rs, p = scale * ab.y * rp;
    f0 = cvAdd(f0, cvAdd(cvScale(cmul(c0, s), I.sHat), cvScale(cmul(c0, p), pw)));
    f1 = cvAdd(f1, cvAdd(cvScale(cmul(c1, s), I.sHat), cvScale(cmul(c1, p), pw)));
  }
  return true;
}

// The outgoing wave w (mode k) of a crossing, reflected or transmitted, its fields scaled.
Branch wave(Branch b, ModeWave w, int k, bool reflect, Incidence I, float scale) {
  vec3 D = reflect ? (k == 0 ? I.dA0 : I.dA1) : (k == 0 ? I.dB0 : I.dB1);
  CV f0, f1;
  if (reflect && crystalReflection(I, cross(w.s, I.sHat), scale, f0, f1)) {
    // Its fields in A's frame: the isotropic outgoing() with unit amplitudes on (E_s, E_p) of f.
    vec3 pw = cross(w.s, I.sHat);
    return outgoing(b, w, k, I.uA, I.aA, D, I.sHat, vec2(1, 0), vec2(1, 0), cvDot(f0, I.sHat),
                    cvDot(f0, pw), cvDot(f1, I.sHat), cvDot(f1, pw));
  }
  vec2 rs, rp, ts, tp;
  fresnelAmplitudes(I.ci, I.nIn, reflect ? I.noB : w.n, rs, rp, ts, tp);
  Branch nb = outgoing(b, w, k, reflect ? I.uA : I.uB, reflect ? I.aA : I.aB, D, I.sHat,
                       scale * (reflect ? rs : ts), scale * (reflect ? rp : tp), I.es0, I.ep0,
                       I.es1, I.ep1);
  return nb;
}

// The power of the waves w (both input basis states together).
float wavesPower(Branch b, ModeWave w[2], bool reflect, Incidence I) {
  float sum = 0.0;
  for (int k = 0; k < 2; ++k) {
    if (!w[k].exists) continue;
    Branch nb = wave(b, w[k], k, reflect, I, 1.0);
    sum += cvNorm2(nb.G0) + cvNorm2(nb.G1);
  }
  return sum;
}

// The interface (the CPU's Tracer::cross): the branch goes on as the transmitted beam(s) (the o
// and e modes into a crystal), or the reflected one(s) (both modes in a crystal) on total internal
// reflection, where asked (reflect_at), or, with Transport::Full (P.pass.w: the choices a branch
// may make), where its random choice takes them: the reflection with probability p = the
// reflected share of the branch's power (both basis states), the chosen fields scaled by 1/√p or
// 1/√(1 − p). The path's first choice, where split (P.transport.z), is no draw: the reflected and
// the transmitted waves both go on, with their exact fields, each marked with its side.
void cross(Branch b, BoundaryCrossing c) {
  int A = b.region, B = c.to;
  if (mediumOpaque(B)) return;  // absorbed: nothing of this branch leaves
  vec3 x = c.point;
  vec4 afA = regionAxisField(A, x), afB = regionAxisField(B, x);
  bool bA = mediumBiaxial(A), bB = mediumBiaxial(B);  // false unless EIKON_F_BIAXIAL
  // Equal biaxial media also share their principal axes (sharp.glsl crossInterface's sameTensor).
  bool sameTensor = !(bA || bB) || (mediumRow(A, 7).xyz == mediumRow(B, 7).xyz &&
                                    mediumRow(A, 20).xyz == mediumRow(B, 20).xyz);
  if (mediumRow(A, 10).w == mediumRow(B, 10).w && afA.xyz == afB.xyz && sameTensor) {
    b.region = B;
    push(b);
    return;
  }
  Incidence I;
  I.uA = hasAxis(afA.xyz) || bA;
  I.uB = hasAxis(afB.xyz) || bB;
  I.dA0 = I.dA1 = I.dB0 = I.dB1 = vec3(0.0);
  bool dispersive = false;
  Biaxial BA, BB;
  if (bA) BA = biaxialOf(A, dispersive);
  if (bB) BB = biaxialOf(B, dispersive);
  I.aA = afA.xyz;
  I.aB = afB.xyz;
  float noA = regionIndex(A, 0, x), neA = regionIndex(A, 1, x);
  I.noB = regionIndex(B, 0, x);
  float neB = regionIndex(B, 1, x);
  I.nIn = length(b.p);
  vec3 s = b.p / I.nIn;
  vec3 m = orientNormal(c.normal, b.ray);
  // Along the face (the CPU's kGrazeCos): not a crossing; the Fresnel factor √(n₂cos t/(n₁cos i))
  // divides by cos i = 0 there (NaN). The branch goes on in its own medium, one event spent.
  if (min(abs(dot(s, m)), abs(dot(normalize(b.ray), m))) < kGrazeCos) {
    b.events++;
    push(b);
    return;
  }
  vec3 pt = b.p - dot(b.p, m) * m;
  ModeWave wt[2], wr[2];
  if (bB) {
    wt[0] = solveBiaxialMode(pt, m, BB, 0, true, I.dB0);
    wt[1] = solveBiaxialMode(pt, m, BB, 1, true, I.dB1);
  } else {
    for (int k = 0; k < 2; ++k) wt[k] = solveInterfaceMode(pt, m, k == 1, I.aB, I.noB, neB, true);
  }
  if (!I.uB) wt[1].exists = false;
  I.wt0 = wt[0];
  I.wt1 = wt[1];
  int mask = int(sheets[0].w);
  bool asked = b.events < 24 && ((mask >> b.events) & 1) != 0;
  bool reflect = asked || !(wt[0].exists || wt[1].exists);
  bool choose = !reflect && b.choices < P.pass.w;
  if (reflect || choose) {
    if (bA) {
      wr[0] = solveBiaxialMode(pt, m, BA, 0, false, I.dA0);
      wr[1] = solveBiaxialMode(pt, m, BA, 1, false, I.dA1);
    } else {
      for (int k = 0; k < 2; ++k) wr[k] = solveInterfaceMode(pt, m, k == 1, I.aA, noA, neA, false);
    }
    if (!I.uA) wr[1].exists = false;
  }
  I.sHat = cross(s, m);
  if (length(I.sHat) < 1e-6) I.sHat = stokesBasis(s);  // normal incidence: any ŝ ⊥ s
  I.sHat = normalize(I.sHat);
  vec3 pIn = cross(s, I.sHat);
  I.es0 = cvDot(b.G0, I.sHat);
  I.ep0 = cvDot(b.G0, pIn);
  I.es1 = cvDot(b.G1, I.sHat);
  I.ep1 = cvDot(b.G1, pIn);
  I.ci = min(1.0, abs(dot(s, m)));
  float scale = 1.0;
  bool split = false;
  if (choose) {
    float pr = wavesPower(b, wr, true, I), pw = pr + wavesPower(b, wt, false, I);
    if (pw > 0.0) {
      float p = pr / pw;
      split = b.choices == 0 && P.transport.z != 0;
      reflect = !split && transportUniform(gSeed, uint(b.choices)) < p;  // march.glsl
      if (!split) scale = inversesqrt(reflect ? p : 1.0 - p);
      b.choices++;
    }
  }
  // Split: the reflected waves, then the transmitted; else the chosen pair.
  for (int j = reflect || split ? 0 : 2; j < (reflect ? 2 : 4); ++j) {
    bool refl = j < 2;
    int k = j & 1;
    ModeWave w = refl ? wr[k] : wt[k];
    if (!w.exists) continue;
    Branch nb = wave(b, w, k, refl, I, scale);
    if (cvNorm2(nb.G0) + cvNorm2(nb.G1) < 1e-12) continue;
    nb.region = refl ? A : B;
    nb.x = x;
    nb.events = b.events + 1;
    if (split) nb.side = refl ? 2 : 1;
    if ((refl ? I.uA : I.uB) && nb.nmodes < 15) {
      nb.modes |= k << nb.nmodes;
      nb.nmodes++;
    }
    push(nb);
  }
}

// Follow the branches on the stack to their exits (Tracer::run), at most EIKON_POL_MAX_PIECES
// straight pieces in all; `maxEvents`, `maxLeaves` as PolarisedTraceSettings.
void run(int maxEvents, int maxLeaves) {
  const vec3 bmin = P.grid_origin.xyz, bmax = P.grid_origin.xyz + P.grid_extent.xyz;
  for (int piece = 0; piece < EIKON_POL_MAX_PIECES && gTop > 0; ++piece) {
    Branch b = gStack[--gTop];
    if (b.events > maxEvents || gLeafCount + gTop + 1 > maxLeaves) {
      gTruncated = true;
      continue;
    }
    if (mediumOpaque(b.region)) continue;
    if (!mediumHomogeneous(b.region)) {  // refused, as the CPU's mediumOf
      gUnsupported = b.region + 1;
      continue;
    }
    float t0, t1;
    boxHit(b.x, b.ray, bmin, bmax, t0, t1);
    float len = max(t1, 0.0);
    BoundaryCrossing c = nextCrossing(b.x, b.x + b.ray * len, b.region);
    if (c.found) len *= c.t;
    segment(b, len);
    if (!c.found) {  // out of the volume: straight on, through any sheets beyond it
      applySheets(b, b.x, b.ray, kFarMm);
      gLeaves[gLeafCount++] = b;
    } else {
      b.x = c.point;
      cross(b, c);
    }
    if (loopLimitReached()) {
      gTruncated = true;
      break;
    }
  }
  if (gTop > 0) gTruncated = true;
}

// Stokes vector out of a Jones matrix J (columns: the responses to x̂_in, ŷ_in) for the input
// Stokes vector S: the coherency matrix J C Jᴴ, C = ½[[S0 + S1, S2 + iS3], [S2 − iS3, S0 − S1]]
// (C_xy = ⟨E_x E_y*⟩), equal to the CPU's muellerOf(J)·S.
vec4 stokesOut(vec2 J[4], vec4 S) {  // J = (xx, xy, yx, yy) = (row, col)
  vec2 C[4] = vec2[4](vec2(0.5 * (S.x + S.y), 0.0), vec2(0.5 * S.z, 0.5 * S.w),
                      vec2(0.5 * S.z, -0.5 * S.w), vec2(0.5 * (S.x - S.y), 0.0));
  vec2 K[4];  // J C
  for (int r = 0; r < 2; ++r)
    for (int q = 0; q < 2; ++q)
      K[2 * r + q] = cmul(J[2 * r], C[q]) + cmul(J[2 * r + 1], C[2 + q]);
  vec2 D[4];  // (J C) Jᴴ
  for (int r = 0; r < 2; ++r)
    for (int q = 0; q < 2; ++q) {
      vec2 j0 = J[2 * q], j1 = J[2 * q + 1];
      D[2 * r + q] = cmul(K[2 * r], vec2(j0.x, -j0.y)) + cmul(K[2 * r + 1], vec2(j1.x, -j1.y));
    }
  return vec4(D[0].x + D[3].x, D[0].x - D[3].x, 2.0 * D[1].x, 2.0 * D[1].y);
}

// The leaves leaving along leaf `first`'s direction, recombined (the CPU's recombine): coherent
// groups (Jones matrices added with their phases on a common wavefront, the phase from the
// relative optical paths) added as Stokes vectors. `taken` marks the leaves used.
PolarisedBeamOut recombine(int first, inout int taken, vec4 S, float lambdaMm, float angle,
                           float width, float length_) {
  PolarisedBeamOut beam;
  Branch f = gLeaves[first];
  vec3 dir = normalize(f.ray), fx = stokesBasis(dir), fy = cross(dir, fx);
  float chord = 2.0 * sin(0.5 * angle);
  int inDir = 0;  // the leaves of this direction
  for (int j = first; j < gLeafCount; ++j)
    if ((taken & (1 << j)) == 0 && length(normalize(gLeaves[j].ray) - dir) <= chord)
      inDir |= 1 << j;
  taken |= inDir;
  vec4 stokes = vec4(0.0);
  int branches = 0, groups = 0;
  ivec4 codes = ivec4(-1);
  for (int r = first; r < gLeafCount; ++r) {
    if ((inDir & (1 << r)) == 0) continue;
    Branch ref = gLeaves[r];
    vec2 J[4] = vec2[4](vec2(0.0), vec2(0.0), vec2(0.0), vec2(0.0));
    for (int j = r; j < gLeafCount; ++j) {
      if ((inDir & (1 << j)) == 0) continue;
      Branch b = gLeaves[j];
      vec3 sep = b.x - ref.x;
      float lateral = length(sep - dot(sep, dir) * dir);
      // Δ(S − p·x) with S = opl + p_in·(x − x_start): the path difference on a common wavefront.
      float opd = (b.opl - ref.opl) + dot(gPin - b.p, sep);
      // The two sides of a split first choice are two estimates, added as such (incoherently).
      if (b.side != ref.side || lateral > width || abs(opd) > length_) continue;
      inDir &= ~(1 << j);
      float waves = opd / lambdaMm;
      float ph = 2.0 * kPi * (waves - round(waves));
      vec2 e = vec2(cos(ph), sin(ph));
      J[0] += cmul(e, cvDot(b.G0, fx));
      J[1] += cmul(e, cvDot(b.G1, fx));
      J[2] += cmul(e, cvDot(b.G0, fy));
      J[3] += cmul(e, cvDot(b.G1, fy));
      if (branches < EIKON_POL_MAX_GROUPED) codes[branches] = (b.nmodes << 16) | b.modes;
      branches++;
    }
    if (P.pass.z != 0)  // renders: the Mueller matrix's first row (S0 out per input basis state)
      stokes += vec4(stokesOut(J, vec4(1, 0, 0, 0)).x, stokesOut(J, vec4(0, 1, 0, 0)).x,
                     stokesOut(J, vec4(0, 0, 1, 0)).x, stokesOut(J, vec4(0, 0, 0, 1)).x);
    else
      stokes += stokesOut(J, S);
    groups++;
  }
  beam.exit_point = vec4(f.x, float(branches));
  beam.direction = vec4(dir, float(groups));
  beam.frame_x = vec4(fx, 0.0);
  beam.stokes = stokes;
  beam.modes = codes;
  return beam;
}

void main() {
  loadParams();
  uint i = gl_GlobalInvocationID.x;
  if (i >= uint(P.image.x)) return;
  PolarisedRay ray = rays[i];
  setWavelength(ray.origin.w, true);
  vec3 d = normalize(ray.direction.xyz), o = ray.origin.xyz;
  gPin = P.march.z * d;
  vec3 xin = stokesBasis(d);
  Branch b;
  b.x = o;
  b.p = gPin;
  b.ray = d;
  b.region = 0;
  b.mode = 0;
  b.G0 = CV(xin, vec3(0.0));
  b.G1 = CV(cross(d, xin), vec3(0.0));
  b.opl = 0.0;
  b.modes = 0;
  b.nmodes = 0;
  b.events = 0;
  b.choices = 0;
  b.side = 0;
  gSeed = floatBitsToUint(ray.direction.w);
  PolarisedResult res;
  res.head = ivec4(0);
  float t0, t1;
  if (!boxHit(o, d, P.grid_origin.xyz, P.grid_origin.xyz + P.grid_extent.xyz, t0, t1) ||
      t1 < max(t0, 0.0)) {
    applySheets(b, o, d, kFarMm);
    gLeaves[gLeafCount++] = b;
  } else {
    t0 = max(t0, 0.0);
    applySheets(b, o, d, t0);
    b.x = o + d * t0;
    b.region = regionAt(b.x);  // on the shapes on the exact path, else the field's
    if (b.region != 0) res.head.w = 1;
    else {
      push(b);
      run(min(int(P.pass.x), EIKON_POL_MAX_EVENTS), min(int(P.pass.y), EIKON_POL_MAX_LEAVES));
    }
  }
  float lambdaMm = ray.origin.w * 1e-3, bw = sheets[0].y, angle = sheets[0].z;
  float width = lambdaMm / angle, length_ = lambdaMm * lambdaMm / (bw * 1e-6);
  int taken = 0, beams = 0;
  for (int j = 0; j < gLeafCount && beams < EIKON_POL_MAX_BEAMS; ++j) {
    if ((taken & (1 << j)) != 0) continue;
    res.beams[beams++] = recombine(j, taken, ray.stokes, lambdaMm, angle, width, length_);
  }
  if (taken != (1 << gLeafCount) - 1) gTruncated = true;  // more directions than beams
  res.head.x = beams;
  res.head.y = gTruncated ? 1 : 0;
  res.head.z = gUnsupported;
  for (int k = beams; k < EIKON_POL_MAX_BEAMS; ++k) {
    res.beams[k].exit_point = vec4(0.0);
    res.beams[k].direction = vec4(0.0);
    res.beams[k].frame_x = vec4(0.0);
    res.beams[k].stokes = vec4(0.0);
    res.beams[k].modes = ivec4(-1);
  }
  results[i] = res;
}
