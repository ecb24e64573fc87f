#include "core/reference/reference_marcher.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "anisotropic/fresnel.h"
#include "anisotropic/interface.h"
#include "anisotropic/tensor_interface.h"
#include "anisotropic/tensor_medium.h"
#include "anisotropic/units.h"
#include "core/contract/render_layers.h"
#include "core/reference/field.h"
#include "core/spectrum/cie1931.h"
#include "core/spectrum/color.h"
#include "core/spectrum/rgb_to_spectrum.h"
#include "core/spectrum/wavelength_sampling.h"
#include "core/volume/boundary.h"
#include "core/volume/media.h"

namespace eikon {
namespace {
bool boxHit(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& bmin,
            const glm::dvec3& bmax, double& t0, double& t1) {
  t0 = -1e300;
  t1 = 1e300;
  for (int a = 0; a < 3; ++a) {
    double inv = 1.0 / (d[a] == 0.0 ? 1e-30 : d[a]);
    double ta = (bmin[a] - o[a]) * inv, tb = (bmax[a] - o[a]) * inv;
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  return t1 >= std::max(t0, 0.0);
}

/// The outward normal of the side of the box by which the line o + t·d leaves it: the axis whose
/// exit parameter is boxHit's t1 (sharp.glsl volumeSide).
glm::dvec3 volumeSide(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& bmin,
                      const glm::dvec3& bmax) {
  glm::dvec3 hi;
  for (int a = 0; a < 3; ++a) {
    const double inv = 1.0 / (d[a] == 0.0 ? 1e-30 : d[a]);
    hi[a] = std::max((bmin[a] - o[a]) * inv, (bmax[a] - o[a]) * inv);
  }
  const int k = hi.x <= hi.y && hi.x <= hi.z ? 0 : (hi.y <= hi.z ? 1 : 2);
  glm::dvec3 n(0.0);
  n[k] = d[k] < 0.0 ? -1.0 : 1.0;
  return n;
}

void validate(const MarchSettings& m) { checkMarchSettings(m); }

}  // namespace

/// Hero wavelength sampling (view.comp, march.glsl PathRecord): the environment lookups of a hero
/// march made before its path met anything dispersive, as (linear sRGB radiance, weight), valid at
/// every wavelength of the pixel sample; after that (or once full) lookups are the hero's alone.
struct HeroRecord {
  static constexpr int kMax = 6;
  bool diverged = false;
  int count = 0;
  double weight = 1.0;  ///< the mode's share (½ each in a crystal)
  std::array<glm::dvec4, kMax> entries{};
};

// ------------------------------------------------------------------ ReferenceMarcher
namespace {

/// What one march returns (march.glsl's MarchResult).
struct MarchResult {
  glm::dvec3 radiance{0.0}, throughput{1.0}, exit_point{0.0}, exit_dir{0.0}, wave_normal{0.0};
  double opl = 0.0, drift = 0.0;
  bool left = true;
  bool ran_out = false;  ///< ended by max_steps alone (march.glsl's cut, RenderImage::cut_samples)
  int steps = 0, interfaces = 0, tir = 0;
  int reflections = 0;    ///< Fresnel reflections followed (Transport::Full)
  bool split = false;     ///< the first Fresnel choice was met and split (FirstChoice)
  long long fetches = 0;  ///< volume-field reads (CountedField)
  FirstInterface first;   ///< the first interface met (the AOV layer)
};

/// The state of one march between its stages (march.glsl's MarchState).
struct MarchState {
  glm::dvec3 x{0.0}, w{0.0};  ///< position (mm), wave vector
  glm::dvec4 nn{0.0};         ///< (n_o, ∇n_o) at x
  glm::dvec3 T{1.0}, L{0.0};  ///< throughput, radiance gathered so far
  bool stopped = false;       ///< at an opaque surface
  int region = 0;             ///< sharp march: the boundary-field region the ray is in
  /// The interface layer being crossed: where it opened, w before it, Σ∇n·ds over it, its peak.
  bool inLayer = false;
  double peak = 0.0;
  glm::dvec3 wBefore{0.0}, gAcc{0.0}, xOpen{0.0};
  glm::dvec3 xPeak{0.0};    ///< where the layer's |∇n|·h peaked so far (the AOV layer)
  std::uint32_t draws = 0;  ///< Transport::Full: the uniforms drawn so far (transportUniform's k)
};

/// What an integration step leaves for the stages after it (march.glsl's StepEnd).
struct StepEnd {
  glm::dvec3 x0{0.0}, w0{0.0};  ///< the step's start
  glm::dvec4 ne{0.0};           ///< (n_e, ∇n_e) at the step's end (the o-mode's where isotropic)
  glm::dvec3 aHere{0.0};        ///< optic axis there (e-mode)
  bool eHere = false;           ///< the e-mode in a crystal there
  glm::dvec3 gradN{0.0};        ///< the gradient the layer normal accumulates
};

/// One event of a path the light tree marches (ReferenceMarcher::lightTree): a split, where it
/// reflected or refracted as its script said, or a total internal reflection.
struct TreeStep {
  bool tir = false, reflected = false;
  double Rf = 1.0;                    ///< the split's Fresnel reflectance (tir: 1)
  glm::dvec3 point{0.0}, dirIn{0.0};  ///< where, and the ray direction arriving
  glm::dvec3 dir{0.0}, wave{0.0};     ///< the ray direction and wave normal leaving
  double T = 1.0, opl = 0.0;          ///< attenuation and optical path so far
  int region = 0;                     ///< the region leaving (the sharp march)
};

/// The light tree's choices for one march: the splits' reflect (true) / refract (false) in order,
/// refraction past its end, and the events the march met.
struct ChoiceScript {
  const std::vector<bool>* choices = nullptr;
  size_t splits = 0;
  std::vector<TreeStep> steps;
};

enum class Straight { None, Taken, Stop };
/// How a stage of the sharp march ended: still inside its region, at a boundary crossing, or
/// out of the volume.
enum class SharpEvent { Go, Cross, Leave };

/// The field as one march reads it, every read of the volumes counted (bench/view_bench.cpp
/// reports fetches per ray): a trilinear sample of the index, medium, emission, axis, scatter or
/// light volume, a nearest-voxel read (skipDistance), and (RayMarch::nextCrossing) each
/// boundary-field cell locateCrossing evaluates. A counter per ray, no atomics.
class CountedField {
 public:
  explicit CountedField(const Field& f) : f_(f) {}
  /// The field without counting a read (hero sampling's dispersion test, not a march's read).
  const Field& uncounted() const { return f_; }
  const Field& read() const {  // a read of the volumes through the returned field
    ++fetches;
    return f_;
  }
  glm::dvec4 medium(const glm::dvec3& x) const { return read().medium(x); }
  glm::dvec4 mediumE(const glm::dvec3& x) const { return read().mediumE(x); }
  glm::dvec3 emission(const glm::dvec3& x) const { return read().emission(x); }
  glm::dvec4 scatter(const glm::dvec3& x) const { return read().scatter(x); }
  glm::dvec4 lightFluence(const glm::dvec3& x) const { return read().lightFluence(x); }
  glm::dvec3 lightFlux(const glm::dvec3& x) const { return read().lightFlux(x); }
  glm::dvec3 axis(const glm::dvec3& x) const { return read().axis(x); }
  glm::dvec4 axisField(const glm::dvec3& x) const { return read().axisField(x); }
  double skipDistance(const glm::dvec3& x) const { return read().skipDistance(x); }
  double ambientIndex() const { return f_.ambientIndex(); }
  bool uniaxial() const { return f_.uniaxial(); }
  mutable long long fetches = 0;

 private:
  const Field& f_;
};

/// One march of ReferenceMarcher: the ray's constants and the functions and stages of
/// shaders/march.glsl under the same names, in double precision (docs/twins.md).
class RayMarch {
 public:
  RayMarch(const Field& f, const Environment& env, double lambda_nm, bool scalar,
           const MarchSettings& m, int mode, HeroRecord* hero = nullptr, std::uint32_t seed = 0,
           FirstChoice first = FirstChoice::Drawn)
      : hero_(hero),
        seed_(seed),
        first_(first),
        f_(f),
        env_(env),
        lambda_nm_(lambda_nm),
        scalar_(scalar),
        m_(m),
        mode_(mode),
        mode0_(mode),
        lit_(f.lit()),
        h_(f.cellSize()),
        ds_(m.step_voxels * f.cellSize()),
        bmin_(f.boundsMin()),
        bmax_(f.boundsMax()),
        bf_(f.boundary()),
        media_(f.media()) {
    const double l_um = micrometresFromNanometres(lambda_nm);
    il2_ = 1.0 / (l_um * l_um);
    il4_ = il2_ * il2_;
  }
  MarchResult march(const glm::dvec3& o, const glm::dvec3& d) const;
  /// The volume-field reads of this march so far (CountedField).
  long long fetches() const { return f_.fetches; }
  /// The light tree's march: followReflection takes the script's choices, and the events are
  /// recorded in it (ReferenceMarcher::lightTree).
  void setScript(ChoiceScript* script) { script_ = script; }
  /// Record the path's face events in a crystal (ReferenceMarcher::samplePath).
  void setEvents(std::vector<PathEvent>* events) { events_ = events; }
  /// Both marches start here: false (R = the environment along d) if the ray misses the volume,
  /// else true with the entry at o + t0·d, t0 ≥ 0.
  bool enterVolume(const glm::dvec3& o, const glm::dvec3& d, MarchResult& R, double& t0) const;

 private:
  glm::dvec3 colourOf(const glm::dvec3& rgb) const {
    return scalar_ ? glm::dvec3(spectrum::rgbToSpectrum(rgb, lambda_nm_)) : rgb;
  }
  glm::dvec3 sigmaOf(const glm::dvec3& b) const {
    return scalar_ ? glm::dvec3(field::bandAt(b, lambda_nm_)) : b;
  }
  /// σ of a sharp region's principal axis (mediumSigmaAt: its measured spectrum at λ where it has
  /// one) or its band values (march.glsl regionSigma).
  glm::dvec3 regionSigma(const MediumRecord& m, int axis) const {
    if (scalar_) return glm::dvec3(mediumSigmaAt(m, axis, lambda_nm_));
    return axis == 0 ? m.sigma_o : axis == 1 ? m.sigma_e : m.sigma_beta;
  }
  glm::dvec3 environment(const glm::dvec3& dir) const { return colourOf(env_.lookup(dir)); }
  /// weight × environment(dir), or, while a hero march has met nothing dispersive, recorded for
  /// all wavelengths and left out of the radiance (march.glsl environmentWeighted).
  glm::dvec3 environmentWeighted(const glm::dvec3& weight, const glm::dvec3& dir) const {
    if (hero_ && !hero_->diverged) {
      if (hero_->count < HeroRecord::kMax) {
        hero_->entries[size_t(hero_->count++)] =
            glm::dvec4(env_.lookup(dir), weight.x * hero_->weight);
        return glm::dvec3(0.0);
      }
      hero_->diverged = true;  // the record is full: from here on the hero's alone
    }
    return weight * environment(dir);
  }
  glm::dvec4 sampleIndex(const glm::dvec3& x, int mode) const {
    const glm::dvec4 n = field::sampleIndex(f_.read(), x, il2_, il4_, mode);
    // The GPU twin notes dispersion where the sampled B or C is non-zero: n differs from A.
    if (hero_ && !hero_->diverged && n != field::sampleIndex(f_.uncounted(), x, 0.0, 0.0, mode))
      hero_->diverged = true;
    return n;
  }
  glm::dvec3 axisAt(const glm::dvec3& x) const { return mode_ == 1 ? f_.axis(x) : glm::dvec3(0.0); }
  void deriv(const glm::dvec3& x, const glm::dvec3& w, glm::dvec3& dx, glm::dvec3& dw) const;
  glm::dvec3 rayDirection(const glm::dvec3& x, const glm::dvec3& w) const;
  glm::dvec3 attenuationAt(const glm::dvec3& x, const glm::dvec3& w) const;
  glm::dvec3 inScatter(const glm::dvec3& x, const glm::dvec3& dir, const glm::dvec3& sigmaT) const;
  glm::dvec3 diffuseSurface(const glm::dvec3& x) const;
  // The stages of a march.
  Straight straightStep(MarchState& S, MarchResult& R) const;
  StepEnd integrateStep(MarchState& S, MarchResult& R) const;
  bool mediumAlongStep(MarchState& S, const StepEnd& E) const;
  void projectOnShell(MarchState& S, const StepEnd& E, const glm::dvec3& N) const;
  void fresnelAtLayer(MarchState& S, MarchResult& R, const glm::dvec3& N) const;
  void layerStep(MarchState& S, MarchResult& R, const StepEnd& E) const;
  bool clipToVolume(MarchState& S, MarchResult& R, const StepEnd& E) const;
  // The stages of the sharp march (docs/view-renderer.md "Sharp interfaces: the march").
  MarchResult marchSharp(const glm::dvec3& o, const glm::dvec3& d) const;
  const MediumRecord& rec(int region) const { return media_->regions[size_t(region)]; }
  double regionIndex(int region, int mode, const glm::dvec3& x, glm::dvec3* grad = nullptr) const {
    const MediumRecord& m = rec(region);
    if (hero_ && m.grin_type == 0) noteDispersion(mode == 1 ? m.n_e : m.n_o);
    return mediumIndexAt(m, mode, lambda_nm_, x, grad);
  }
  /// A hero march has met dispersion (shaders/sharp.glsl mediumIndex: anything but a constant).
  void noteDispersion(const MediumDispersion& d) const {
    bool dispersive =
        d.kind != MediumDispersion::Kind::Constant && d.kind != MediumDispersion::Kind::Cauchy;
    for (int k = 1; k < std::min(d.terms, 6); ++k)  // Cauchy: any λ term
      dispersive =
          dispersive || (d.kind == MediumDispersion::Kind::Cauchy && d.coeff[size_t(k)] != 0.0);
    if (dispersive) hero_->diverged = true;
  }
  // Biaxial regions (docs/biaxial-optics.md "In the renderer"): the region's dielectric tensor
  // at the march's wavelength, and the stages' biaxial cases.
  TensorMedium tensorOf(int region) const;
  TensorMode modeOf(int region, const glm::dvec3& w) const;
  ModeWave outgoingMode(int region, const glm::dvec3& x, const glm::dvec3& p_t, const glm::dvec3& m,
                        bool transmitted) const;
  double biaxialSWeight(int from, int to, const glm::dvec3& x, const glm::dvec3& s,
                        const ModeWave& out, const glm::dvec3& N) const;
  void sharpEnter(MarchState& S, const glm::dvec3& x, const glm::dvec3& d) const;
  glm::dvec3 sharpDirection(const MarchState& S) const;
  BoundaryCrossing nextCrossing(const glm::dvec3& a, const glm::dvec3& b, int region) const;
  long long cellsOn(const glm::dvec3& a, const glm::dvec3& b) const;
  void absorbAlong(MarchState& S, const glm::dvec3& dir, double len) const;
  SharpEvent sharpSegment(MarchState& S, MarchResult& R, BoundaryCrossing& c) const;
  void sharpDeriv(int region, const glm::dvec3& x, const glm::dvec3& w, glm::dvec3& dx,
                  glm::dvec3& dw) const;
  void sharpRk4(int region, double ds, glm::dvec3& x, glm::dvec3& w, double& opl,
                glm::dvec3& tangent) const;
  void sharpLand(int region, const glm::dvec3& x0, const glm::dvec3& w0, double s, double ds,
                 const glm::dvec3& q, const glm::dvec3& N, glm::dvec3& x1, glm::dvec3& w1,
                 double& opl) const;
  SharpEvent sharpStep(MarchState& S, MarchResult& R, BoundaryCrossing& c) const;
  void crossInterface(MarchState& S, MarchResult& R, const BoundaryCrossing& c) const;
  void reflectInRegion(MarchState& S, const glm::dvec3& N) const;
  bool followReflection(MarchState& S, MarchResult& R, double Rf) const;
  void noteEvent(const MarchState& S, const MarchResult& R, bool tir, bool reflected,
                 double Rf) const;
  void noteAfter(const MarchState& S) const;

  // Mode conversion at the faces met inside a crystal (docs/view-renderer.md "Light transport").
  TensorMedium tensorAt(int region, const glm::dvec3& x) const;
  WaveMode waveModeOf(int region) const;
  int marchModeOf(int region, const TensorMedium& t, const std::array<OutgoingWave, 2>& w,
                  int k) const;
  bool convertAtFace(MarchState& S, MarchResult& R, const BoundaryCrossing& c) const;

  ChoiceScript* script_ = nullptr;
  std::vector<PathEvent>* events_ = nullptr;

  HeroRecord* hero_;
  std::uint32_t seed_;  ///< Transport::Full: transportSeed of the pixel sample and mode
  FirstChoice first_;   ///< Transport::Full: how the path's first Fresnel choice is made
  CountedField f_;
  const Environment& env_;
  double lambda_nm_, il2_ = 0.0, il4_ = 0.0;
  bool scalar_;
  const MarchSettings& m_;
  /// The mode the path is in now (0: o or fast, 1: e or slow): the march's mode until a face
  /// inside a crystal converts it (convertAtFace); mode0_ the march's own.
  mutable int mode_;
  int mode0_;
  bool lit_;
  double h_, ds_;
  glm::dvec3 bmin_, bmax_;
  const BoundaryField* bf_;  ///< non-null: the sharp march (with media_)
  const MediaTable* media_;
};

// Derivatives with respect to ray arc length; see shaders/march.glsl deriv().
void RayMarch::deriv(const glm::dvec3& x, const glm::dvec3& w, glm::dvec3& dx,
                     glm::dvec3& dw) const {
  const glm::dvec4 o = sampleIndex(x, 0);
  const glm::dvec4 af = mode_ == 1 ? f_.axisField(x) : glm::dvec4(0.0);
  if (mode_ == 0 || !field::hasAxis(glm::dvec3(af))) {  // M = I/n²: dx/ds = w/|w|, dw/ds = |w|∇n/n
    const double lw = glm::length(w);
    dx = w / lw;
    dw = glm::dvec3(o.y, o.z, o.w) * (lw / o.x);
    return;
  }
  glm::dvec3 Mp, dp;
  field::eModeRates(w, af, o, sampleIndex(x, 1), Mp, dp);
  const double L = glm::length(Mp);
  dx = Mp / L;
  dw = dp / L;
}

glm::dvec3 RayMarch::rayDirection(const glm::dvec3& x, const glm::dvec3& w) const {
  const glm::dvec3 a = axisAt(x);
  if (mode_ == 0 || !field::hasAxis(a)) return glm::normalize(w);
  return glm::normalize(field::applyM(w, a, sampleIndex(x, 0).x, sampleIndex(x, 1).x));
}

// Attenuation per unit ray length (e-mode: pleochroic σ(θ)·cos ρ, field::attenuationE).
glm::dvec3 RayMarch::attenuationAt(const glm::dvec3& x, const glm::dvec3& w) const {
  const glm::dvec3 so = sigmaOf(glm::dvec3(f_.medium(x)));
  const glm::dvec3 a = axisAt(x);
  if (mode_ == 0 || !field::hasAxis(a)) return so;
  const glm::dvec3 se = sigmaOf(glm::dvec3(f_.mediumE(x)));
  return field::attenuationE(so, se, w, a, sampleIndex(x, 0).x, sampleIndex(x, 1).x);
}

// Light from the light simulator: in-scatter σ_s·p·φ and diffuse surfaces albedo·E/π; the formulas
// and the mean-direction phase model are those of march.glsl inScatter/diffuseSurface.
double phaseHG(double cosTheta, double g) {
  const double dd = 1.0 + g * g - 2.0 * g * cosTheta;
  return (1.0 - g * g) / (4.0 * std::numbers::pi * dd * std::sqrt(dd));
}

glm::dvec3 RayMarch::inScatter(const glm::dvec3& x, const glm::dvec3& dir,
                               const glm::dvec3& sigmaT) const {
  const glm::dvec4 sc = f_.scatter(x);
  if (sc.x + sc.y + sc.z <= 0.0) return glm::dvec3(0.0);
  const glm::dvec4 phi = f_.lightFluence(x);
  if (phi.w <= 0.0) return glm::dvec3(0.0);
  const glm::dvec3 mdir = f_.lightFlux(x) / phi.w;
  const double lm = std::min(glm::length(mdir), 1.0);
  double p = (1.0 - lm) / (4.0 * std::numbers::pi);
  if (lm > 1e-6) p += lm * phaseHG(glm::dot(glm::normalize(mdir), -dir), sc.w);
  return sigmaOf(glm::dvec3(sc)) * sigmaT * colourOf(glm::dvec3(phi)) * p;
}

glm::dvec3 RayMarch::diffuseSurface(const glm::dvec3& x) const {
  // Albedo and opacity are both composited with the coverage: their ratio is the surface's albedo.
  if (!lit_) return glm::dvec3(0.0);
  auto opacity = [&](const glm::dvec3& y) { return field::sampleMedium(f_.read(), y, mode_).w; };
  const glm::dvec4 sc = f_.scatter(x) / std::max(opacity(x), 0.5);
  if (sc.x + sc.y + sc.z <= 0.0) return glm::dvec3(0.0);
  glm::dvec3 g;
  for (int a = 0; a < 3; ++a) {
    glm::dvec3 e(0.0);
    e[a] = h_;
    g[a] = opacity(x + e) - opacity(x - e);
  }
  if (glm::dot(g, g) <= 0.0) return glm::dvec3(0.0);
  const glm::dvec3 N = -glm::normalize(g);
  const glm::dvec3 xs = x + 1.5 * h_ * N;
  const glm::dvec4 phi = f_.lightFluence(xs);
  if (phi.w <= 0.0) return glm::dvec3(0.0);
  const double cosFactor = std::max(0.0, -glm::dot(f_.lightFlux(xs), N)) / phi.w;
  return sigmaOf(glm::dvec3(sc)) * colourOf(glm::dvec3(phi)) * (cosFactor / std::numbers::pi);
}

/// Fresnel (Rs, Rp) weights of a mode at an interface: the share of its D field along the
/// s-polarisation direction (march.glsl sWeight).
double sWeight(const glm::dvec3& s_crystal, const glm::dvec3& a, const glm::dvec3& N,
               const glm::dvec3& dIn, int md) {
  glm::dvec3 es = glm::cross(N, dIn);
  if (glm::dot(a, a) < 0.25 || glm::dot(es, es) < 1e-12) return 0.5;
  glm::dvec3 Do = glm::cross(s_crystal, a);
  if (glm::dot(Do, Do) < 1e-12) return 0.5;
  Do = glm::normalize(Do);
  es = glm::normalize(es);
  const double wo = glm::dot(Do, es) * glm::dot(Do, es);
  return md == 0 ? wo : 1.0 - wo;
}

// Homogeneous region: one straight, exact step (march.glsl straightStep).
Straight RayMarch::straightStep(MarchState& S, MarchResult& R) const {
  const double D = f_.skipDistance(S.x);
  if (S.inLayer || !(D >= 2.0) || !m_.skip_empty) return Straight::None;
  const glm::dvec3 dir = rayDirection(S.x, S.w);
  double tb0, tb1;
  boxHit(S.x, dir, bmin_, bmax_, tb0, tb1);
  const double tExit = std::max(tb1, 0.0);
  double len = (D - 1.5) * h_;
  // A lit scattering medium is homogeneous but its light is not: sample the light every voxel.
  const glm::dvec4 scHere = lit_ ? f_.scatter(S.x) : glm::dvec4(0.0);
  const bool scattering = scHere.x + scHere.y + scHere.z > 0.0;
  if (scattering) len = std::min(len, h_);
  const bool leaving = len >= tExit;
  len = std::min(len, tExit);
  const glm::dvec4 med = f_.medium(S.x);
  glm::dvec3 e = colourOf(f_.emission(S.x));
  if (med.w >= 0.5) {
    S.L += S.T * (e / med.w + diffuseSurface(S.x));
    S.stopped = true;
    return Straight::Stop;
  }
  const glm::dvec3 sig = attenuationAt(S.x, S.w);
  if (scattering) e += inScatter(S.x + 0.5 * len * dir, dir, sig);
  for (int c = 0; c < 3; ++c) {
    const double a = std::exp(-sig[c] * len);
    S.L[c] += S.T[c] * (sig[c] > 1e-6 ? e[c] * (1.0 - a) / sig[c] : e[c] * len);
    S.T[c] *= a;
  }
  R.opl += glm::dot(S.w, dir) * len;
  S.x += dir * len;
  return leaving ? Straight::Stop : Straight::Taken;
}

// One integration step and the fields at its end (march.glsl integrateStep).
StepEnd RayMarch::integrateStep(MarchState& S, MarchResult& R) const {
  const double ds = ds_;
  StepEnd E;
  E.x0 = S.x;
  E.w0 = S.w;
  const double n0 = S.nn.x;
  glm::dvec3 k1x, k1w, k2x, k2w, k3x, k3w, k4x, k4w;
  deriv(S.x, S.w, k1x, k1w);
  if (m_.integrator == Integrator::Euler) {
    S.x += ds * k1x;
    S.w += ds * k1w;
  } else if (m_.integrator == Integrator::Midpoint) {
    deriv(S.x + 0.5 * ds * k1x, S.w + 0.5 * ds * k1w, k2x, k2w);
    S.x += ds * k2x;
    S.w += ds * k2w;
  } else {
    deriv(S.x + 0.5 * ds * k1x, S.w + 0.5 * ds * k1w, k2x, k2w);
    deriv(S.x + 0.5 * ds * k2x, S.w + 0.5 * ds * k2w, k3x, k3w);
    deriv(S.x + ds * k3x, S.w + ds * k3w, k4x, k4w);
    S.x += ds / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
    S.w += ds / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
  }
  S.nn = sampleIndex(S.x, 0);
  const glm::dvec3 grad(S.nn.y, S.nn.z, S.nn.w);
  E.gradN = grad;
  E.aHere = axisAt(S.x);
  E.eHere = mode_ == 1 && field::hasAxis(E.aHere);
  E.ne = E.eHere ? sampleIndex(S.x, 1) : S.nn;
  if (mode_ == 0) {
    R.drift = std::max(R.drift, std::abs(glm::length(S.w) - S.nn.x));
    R.opl += 0.5 * (n0 + S.nn.x) * ds;
  } else {
    R.opl += 0.5 * glm::dot(E.w0 + S.w, S.x - E.x0);
    if (E.eHere) E.gradN = 0.5 * (grad + glm::dvec3(E.ne.y, E.ne.z, E.ne.w));
  }
  return E;
}

// Emission, attenuation and in-scatter at the step's midpoint; true at an opaque surface.
bool RayMarch::mediumAlongStep(MarchState& S, const StepEnd& E) const {
  const glm::dvec3 xm = 0.5 * (E.x0 + S.x);
  S.L += S.T * colourOf(f_.emission(xm)) * ds_;
  const glm::dvec3 sig = attenuationAt(xm, 0.5 * (E.w0 + S.w));
  if (lit_) S.L += S.T * inScatter(xm, glm::normalize(S.x - E.x0), sig) * ds_;
  S.T *= glm::exp(-sig * ds_);
  if (f_.medium(S.x).w >= 0.5) {
    // Surface emission: the emission field over the coverage (opacity ≥ 0.5 here), as the albedo.
    S.L += S.T * (colourOf(f_.emission(S.x)) / f_.medium(S.x).w + diffuseSurface(S.x));
    S.stopped = true;
    return true;
  }
  return false;
}

// Back onto H = 0 along the layer normal (see shaders/march.glsl projectOnShell).
void RayMarch::projectOnShell(MarchState& S, const StepEnd& E, const glm::dvec3& N) const {
  const double n = S.nn.x, ne = E.ne.x, wn = glm::dot(S.w, N);
  const glm::dvec3 wt = S.w - wn * N;
  if (!E.eHere) {
    const double rem = n * n - glm::dot(wt, wt);
    if (rem > 0.25 * wn * wn) S.w = wt + (wn < 0 ? -1.0 : 1.0) * std::sqrt(rem) * N;
    return;
  }
  const glm::dvec3 MN = field::applyM(N, E.aHere, n, ne);
  const double qa = glm::dot(N, MN), qb = glm::dot(wt, MN);
  const double qc = glm::dot(wt, field::applyM(wt, E.aHere, n, ne)) - 1.0;
  const double disc = qb * qb - qa * qc;
  if (disc > 0.0) {
    const double l1 = (-qb + std::sqrt(disc)) / qa, l2 = (-qb - std::sqrt(disc)) / qa;
    const double lam = std::abs(l1 - wn) < std::abs(l2 - wn) ? l1 : l2;
    if (std::abs(lam - wn) < 0.5 * std::abs(wn)) S.w = wt + lam * N;
  }
}

// Fresnel at a crossed layer, or a total internal reflection (march.glsl fresnelAtLayer); the
// reflectances are anisotropic/fresnel.h's.
void RayMarch::fresnelAtLayer(MarchState& S, MarchResult& R, const glm::dvec3& N) const {
  const glm::dvec3 dIn = glm::normalize(S.wBefore), dOut = glm::normalize(S.w);
  const double ci = glm::dot(dIn, N), co = glm::dot(dOut, N);
  const double n1 = glm::length(S.wBefore), n2 = glm::length(S.w);
  if (!(ci * co > 0.0)) {
    R.tir++;
    noteEvent(S, R, true, true, 1.0);
    return;
  }
  // The crystal side is the layer end with the larger birefringence (the axis field is dilated
  // into the air around crystals).
  const double bOut = std::abs(sampleIndex(S.x, 1).x - sampleIndex(S.x, 0).x);
  const double bIn = std::abs(sampleIndex(S.xOpen, 1).x - sampleIndex(S.xOpen, 0).x);
  const bool outCrystal = bOut >= bIn;
  const glm::dvec3 a = f_.axis(outCrystal ? S.x : S.xOpen);
  const double wsw = sWeight(outCrystal ? dOut : dIn, a, N, dIn, mode_);
  if (!(n1 > 0.0 && n2 > 0.0) || !std::isfinite(n1 + n2)) return;  // fresnelReflectance's domain
  const FresnelReflectance rsp = fresnelReflectance(std::abs(ci), n1, n2);
  const double Rf = f_.uniaxial() ? wsw * rsp.Rs + (1.0 - wsw) * rsp.Rp : 0.5 * (rsp.Rs + rsp.Rp);
  R.interfaces++;
  if (followReflection(S, R, Rf)) {
    // Back to where the layer opened, on the incident side, with the mirrored wave vector; a
    // crystal's e-wave put back on its shell there (the layer's own normal N).
    S.x = S.xOpen;
    S.nn = sampleIndex(S.x, 0);
    S.w = glm::reflect(S.wBefore, N);
    StepEnd E;
    E.aHere = axisAt(S.x);
    E.eHere = mode_ == 1 && field::hasAxis(E.aHere);
    E.ne = E.eHere ? sampleIndex(S.x, 1) : S.nn;
    projectOnShell(S, E, N);
    return;
  }
  if (m_.transport == Transport::Full && R.reflections < m_.max_reflections) return;
  if (n2 > n1) S.L += environmentWeighted(S.T * Rf, glm::reflect(dIn, N));
  S.T *= 1.0 - Rf;
}

// Transport::Full, while the path has followed fewer than max_reflections: true (the path
// reflects, counted) with probability Rf, else false (it refracts) — in both cases at its whole
// weight, the Fresnel weights being the probabilities (Russian roulette, unbiased). The path's
// first choice, where split (FirstChoice), is this march's branch at its weight instead.
bool RayMarch::followReflection(MarchState& S, MarchResult& R, double Rf) const {
  if (m_.transport != Transport::Full || R.reflections >= m_.max_reflections) return false;
  if (script_) {  // the light tree: the branch's scripted choice, the weights its own
    const size_t k = script_->splits++;
    const bool reflect = k < script_->choices->size() && (*script_->choices)[k];
    noteEvent(S, R, false, reflect, Rf);
    if (reflect) R.reflections++;
    return reflect;
  }
  const bool first = S.draws == 0;
  bool reflects = transportUniform(seed_, S.draws++) < Rf;
  if (first && first_ != FirstChoice::Drawn) {
    R.split = true;
    reflects = first_ == FirstChoice::Reflect;
    S.T *= reflects ? Rf : 1.0 - Rf;
  }
  if (reflects) R.reflections++;
  return reflects;
}

// The light tree's record of an event where it happens (the ray arriving), its leaving direction
// filled in by noteAfter once the crossing has been applied.
void RayMarch::noteEvent(const MarchState& S, const MarchResult& R, bool tir, bool reflected,
                         double Rf) const {
  if (!script_) return;
  TreeStep t;
  t.tir = tir;
  t.reflected = reflected;
  t.Rf = Rf;
  t.point = S.x;
  t.dirIn = bf_ && media_ ? sharpDirection(S) : rayDirection(S.x, S.w);
  t.T = S.T.x;
  t.opl = R.opl;
  t.dir = glm::dvec3(0.0);
  script_->steps.push_back(t);
}

void RayMarch::noteAfter(const MarchState& S) const {
  if (!script_ || script_->steps.empty() || script_->steps.back().dir != glm::dvec3(0.0)) return;
  TreeStep& t = script_->steps.back();
  t.dir = bf_ && media_ ? sharpDirection(S) : rayDirection(S.x, S.w);
  t.wave = glm::normalize(S.w);
  t.region = S.region;
}

// Interface bookkeeping (march.glsl layerStep).
void RayMarch::layerStep(MarchState& S, MarchResult& R, const StepEnd& E) const {
  const double thrLow = 1e-6;
  const double g = std::max(glm::length(glm::dvec3(S.nn.y, S.nn.z, S.nn.w)),
                            glm::length(glm::dvec3(E.ne.y, E.ne.z, E.ne.w))) *
                   h_;
  if (!S.inLayer && g > thrLow) {
    S.inLayer = true;
    S.wBefore = E.w0;
    S.gAcc = glm::dvec3(0.0);
    S.peak = 0.0;
    S.xOpen = E.x0;
  }
  if (!S.inLayer) return;
  S.gAcc += E.gradN * ds_;
  if (g > S.peak) S.xPeak = S.x;
  S.peak = std::max(S.peak, g);
  if (!(g <= thrLow)) return;
  S.inLayer = false;
  const glm::dvec3 N = glm::dot(S.gAcc, S.gAcc) > 0.0 ? glm::normalize(S.gAcc) : glm::dvec3(0.0);
  if (!R.first.hit && S.peak > m_.interface_threshold && glm::dot(N, N) > 0.0)
    R.first = {true, S.xPeak, glm::dot(N, S.wBefore) > 0.0 ? -N : N, -1};
  if (glm::dot(N, N) > 0.0 && std::abs(glm::dot(S.x - S.xOpen, N)) <= 12.0 * h_)
    projectOnShell(S, E, N);
  if (S.peak > m_.interface_threshold && m_.fresnel && glm::dot(N, N) > 0.0)
    fresnelAtLayer(S, R, N);
}

// Left the volume? Cut the step at the boundary (march.glsl clipToVolume).
bool RayMarch::clipToVolume(MarchState& S, MarchResult& R, const StepEnd& E) const {
  bool outside = false;
  for (int a = 0; a < 3; ++a) outside = outside || S.x[a] < bmin_[a] || S.x[a] > bmax_[a];
  if (!outside) return false;
  const glm::dvec3 dd = glm::normalize(S.x - E.x0);
  double a0, a1;
  boxHit(E.x0, dd, bmin_, bmax_, a0, a1);
  const double stepLen = glm::length(S.x - E.x0);
  const double keep = std::clamp(std::max(a1, 0.0) / std::max(stepLen, 1e-300), 0.0, 1.0);
  R.opl -= (1.0 - keep) * 0.5 * glm::dot(E.w0 + S.w, S.x - E.x0);
  S.x = E.x0 + (S.x - E.x0) * keep;
  S.w = glm::mix(E.w0, S.w, keep);
  return true;
}

bool RayMarch::enterVolume(const glm::dvec3& o, const glm::dvec3& d, MarchResult& R,
                           double& t0) const {
  R = MarchResult{};
  double t1;
  if (!boxHit(o, d, bmin_, bmax_, t0, t1)) {
    R.radiance = environmentWeighted(glm::dvec3(1.0), d);
    R.exit_point = o;
    R.exit_dir = d;
    R.wave_normal = d;
    return false;
  }
  t0 = std::max(t0, 0.0);
  return true;
}

MarchResult RayMarch::march(const glm::dvec3& o, const glm::dvec3& d) const {
  if (bf_ && media_) return marchSharp(o, d);
  MarchResult R;
  double t0;
  if (!enterVolume(o, d, R, t0)) return R;
  MarchState S;
  S.x = o + d * t0;
  R.opl = f_.ambientIndex() * t0;
  S.nn = sampleIndex(S.x, 0);
  S.w = S.nn.x * d;
  S.wBefore = S.w;
  S.xOpen = S.x;
  int steps = 0;
  for (; steps < m_.max_steps; ++steps) {
    const Straight straight = straightStep(S, R);
    if (straight == Straight::Stop) break;
    if (straight == Straight::Taken) continue;
    const StepEnd E = integrateStep(S, R);
    if (mediumAlongStep(S, E)) break;
    layerStep(S, R, E);
    noteAfter(S);
    if (clipToVolume(S, R, E)) break;
  }
  R.steps = steps;
  R.exit_point = S.x;
  R.exit_dir = rayDirection(S.x, S.w);
  R.wave_normal = glm::normalize(S.w);
  R.left = !S.stopped && steps < m_.max_steps;
  R.ran_out = !S.stopped && steps >= m_.max_steps;
  if (R.left) S.L += environmentWeighted(S.T, R.exit_dir);
  R.radiance = S.L;
  R.throughput = S.T;
  return R;
}

// ------------------------------------------------------------------ the sharp march
// Stages of the same names in shaders/sharp.glsl (docs/twins.md). The ray carries its region;
// homogeneous regions are crossed in one straight segment, varying ones (GRIN, radial axis) are
// integrated with RK4 on the region's own analytic medium, the optical path with it; every segment
// or step chord is tested with nextCrossing, a step that meets a face ends on it on its own path
// (sharpLand), and at a crossing the exact interface laws of anisotropic/ are applied.

// Box entry: the region there, and the wave vector of the mode in its medium along d.
void RayMarch::sharpEnter(MarchState& S, const glm::dvec3& x, const glm::dvec3& d) const {
  S.x = x;
  S.region = regionAt(*bf_, x);
  if (!bf_->exact) ++f_.fetches;  // the cell around x (exact: on the shapes, no cell)
  const MediumRecord& m = rec(S.region);
  if (m.biaxial) {  // the mode's index along d (box entry: p = n_m(d̂) d̂)
    S.w = tensorOf(S.region).indices(d)[size_t(mode_)] * d;
    return;
  }
  double n = regionIndex(S.region, 0, x);
  const glm::dvec4 af = mediumAxisField(m, x);
  if (mode_ == 1 && field::hasAxis(glm::dvec3(af)))
    n = Uniaxial(n, regionIndex(S.region, 1, x), glm::dvec3(af)).extraordinaryIndex(d);
  S.w = n * d;
}

// The ray (energy) direction in the ray's region: w/|w|, or M_e w for the e-mode in a crystal.
glm::dvec3 RayMarch::sharpDirection(const MarchState& S) const {
  if (rec(S.region).biaxial) return modeOf(S.region, S.w).t;
  const glm::dvec4 af = mediumAxisField(rec(S.region), S.x);
  if (mode_ == 0 || !field::hasAxis(glm::dvec3(af))) return glm::normalize(S.w);
  return glm::normalize(field::applyM(S.w, glm::dvec3(af), regionIndex(S.region, 0, S.x),
                                      regionIndex(S.region, 1, S.x)));
}

// The first crossing on [a, b] out of the ray's region by the one dispatch (crossingOutOf, as
// march.glsl's nextCrossing): the planes (convex_apart), the shapes (exact) or the walk (the
// sliver rule), counting the cells each search reads: convex_apart the field normal's cell;
// exact none; the walk the region at its start, the cells walked to the crossing, and (found)
// the cells past it and at it (the region entered, the field's normal).
BoundaryCrossing RayMarch::nextCrossing(const glm::dvec3& a, const glm::dvec3& b,
                                        int region) const {
  if (bf_->convex_apart) f_.fetches += 1;  // the cell of the field normal
  return crossingOutOf(*bf_, a, b, region, [&](const glm::dvec3& start, const BoundaryCrossing& c) {
    f_.fetches += 1 + cellsOn(start, c.found ? c.point : b) + (c.found ? 2 : 0);
  });
}

// The trilinear cells of the boundary field that [a, b] passes through, which locateCrossing
// walks in order: 1 + the voxel-centre planes crossed (boundary.cpp cellBreaks).
long long RayMarch::cellsOn(const glm::dvec3& a, const glm::dvec3& b) const {
  const Grid& g = bf_->grid;
  const glm::dvec3 ua = (a - g.origin) / g.h - 0.5, ub = (b - g.origin) / g.h - 0.5;
  long long n = 1;
  for (int k = 0; k < 3; ++k) {
    const double m0 = std::max(std::ceil(std::min(ua[k], ub[k])), 0.0);
    const double m1 = std::min(std::floor(std::max(ua[k], ub[k])), double(g.dims[size_t(k)] - 1));
    if (m1 >= m0) n += (long long)(m1 - m0) + 1;
  }
  return n;
}

// Emission, attenuation (exact: e^{−σ len}) and in-scatter along a straight piece in the ray's
// region (march.glsl absorbAlong).
void RayMarch::absorbAlong(MarchState& S, const glm::dvec3& dir, double len) const {
  const MediumRecord& m = rec(S.region);
  glm::dvec3 sig = regionSigma(m, 0);
  const glm::dvec4 af = mediumAxisField(m, S.x);
  if (m.biaxial) {  // trichroism: first order in the principal σ's, per unit ray length
    TensorMedium t = tensorOf(S.region);
    const glm::dvec3 s = glm::normalize(S.w);
    const TensorMode md = t.modes(s)[mode_ == 1 ? WaveMode::Slow : WaveMode::Fast];
    const glm::dvec3 sa = regionSigma(m, 0), sb = regionSigma(m, 2), sg = regionSigma(m, 1);
    for (int k = 0; k < 3; ++k) {
      t.sigma = glm::dvec3(sa[k], sb[k], sg[k]);
      sig[k] = t.attenuation(md.D, md.n) * glm::dot(s, md.t);
    }
  } else if (mode_ == 1 && field::hasAxis(glm::dvec3(af)))
    sig = field::attenuationE(sig, regionSigma(m, 1), S.w, glm::dvec3(af),
                              regionIndex(S.region, 0, S.x), regionIndex(S.region, 1, S.x));
  glm::dvec3 e = colourOf(m.emission);
  if (lit_ && m.albedo.x + m.albedo.y + m.albedo.z > 0.0)
    e += inScatter(S.x + 0.5 * len * dir, dir, sig);
  for (int c = 0; c < 3; ++c) {
    const double a = std::exp(-sig[c] * len);
    S.L[c] += S.T[c] * (sig[c] > 1e-6 ? e[c] * (1.0 - a) / sig[c] : e[c] * len);
    S.T[c] *= a;
  }
}

// Homogeneous region: one straight segment to the volume's exit (a voxel at a time in a lit
// scattering medium, so that in-scatter is sampled) or to the first crossing on it.
SharpEvent RayMarch::sharpSegment(MarchState& S, MarchResult& R, BoundaryCrossing& c) const {
  const MediumRecord& m = rec(S.region);
  const glm::dvec3 dir = sharpDirection(S);
  double tb0, tb1;
  boxHit(S.x, dir, bmin_, bmax_, tb0, tb1);
  double len = std::max(tb1, 0.0);
  bool leaving = true;
  if (lit_ && m.albedo.x + m.albedo.y + m.albedo.z > 0.0 && len > h_) {
    len = h_;
    leaving = false;
  }
  c = nextCrossing(S.x, S.x + dir * len, S.region);
  if (c.found) len *= c.t;
  absorbAlong(S, dir, len);
  R.opl += glm::dot(S.w, dir) * len;
  S.x = c.found ? c.point : S.x + dir * len;
  return c.found ? SharpEvent::Cross : leaving ? SharpEvent::Leave : SharpEvent::Go;
}

// The ray equation in a varying region from its own analytic medium (deriv's twin).
void RayMarch::sharpDeriv(int region, const glm::dvec3& x, const glm::dvec3& w, glm::dvec3& dx,
                          glm::dvec3& dw) const {
  glm::dvec3 g;
  const double n = regionIndex(region, 0, x, &g);
  const glm::dvec4 af = mode_ == 1 ? mediumAxisField(rec(region), x) : glm::dvec4(0.0);
  if (!field::hasAxis(glm::dvec3(af))) {
    const double lw = glm::length(w);
    dx = w / lw;
    dw = g * (lw / n);
    return;
  }
  glm::dvec3 ge;
  const double ne = regionIndex(region, 1, x, &ge);
  glm::dvec3 Mp, dp;
  field::eModeRates(w, af, glm::dvec4(n, g), glm::dvec4(ne, ge), Mp, dp);
  const double L = glm::length(Mp);
  dx = Mp / L;
  dw = dp / L;
}

// Classical RK4 on (x, w) and the optical path L with dL/ds = w·dx/ds (n for the o-mode, p·t for
// the e-mode): one more component of the same ODE, so L keeps the integrator's fourth order.
// `tangent` is the last stage's dx/ds (sharpLand's rate).
void RayMarch::sharpRk4(int region, double ds, glm::dvec3& x, glm::dvec3& w, double& opl,
                        glm::dvec3& tangent) const {
  glm::dvec3 k1x, k1w, k2x, k2w, k3x, k3w, k4x, k4w;
  sharpDeriv(region, x, w, k1x, k1w);
  const glm::dvec3 w2 = w + 0.5 * ds * k1w;
  sharpDeriv(region, x + 0.5 * ds * k1x, w2, k2x, k2w);
  const glm::dvec3 w3 = w + 0.5 * ds * k2w;
  sharpDeriv(region, x + 0.5 * ds * k2x, w3, k3x, k3w);
  const glm::dvec3 w4 = w + ds * k3w;
  sharpDeriv(region, x + ds * k3x, w4, k4x, k4w);
  const double l1 = glm::dot(w, k1x), l2 = glm::dot(w2, k2x), l3 = glm::dot(w3, k3x),
               l4 = glm::dot(w4, k4x);
  x += ds / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
  w += ds / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
  opl += ds / 6.0 * (l1 + 2.0 * l2 + 2.0 * l3 + l4);
  tangent = k4x;
}

// The RK4 step from (x0, w0) that ends on the plane through q with normal N (along the ray: the
// face crossed, or the volume's side), by Newton's method on its length s from the chord's guess:
// f(s) = (x(s) − q)·N, f'(s) ≈ tangent·N (the last stage's dx/ds, within O(s²) of the end's, so
// each pass cuts f by O((κs)²) or better, κ the ray's curvature), s kept in [0, ds]. A graze
// (tangent·N ≤ kLandMinRate) keeps the s it has. The end is then put on the plane (a move of the
// last residual, ~1e-16 of the coordinates), so x1, w1 and the step's optical path all belong to
// the one point of the integrator's path on the plane (a curved face's tangent plane at the
// chord's crossing: off the surface by O(κ²s⁴/R) for radius of curvature R).
void RayMarch::sharpLand(int region, const glm::dvec3& x0, const glm::dvec3& w0, double s,
                         double ds, const glm::dvec3& q, const glm::dvec3& N, glm::dvec3& x1,
                         glm::dvec3& w1, double& opl) const {
  constexpr int kLandPasses = 3;
  constexpr double kLandMinRate = 1e-3;
  for (int pass = 0;; ++pass) {
    glm::dvec3 tangent;
    x1 = x0, w1 = w0, opl = 0.0;
    sharpRk4(region, s, x1, w1, opl, tangent);
    const double rate = glm::dot(tangent, N);
    if (pass == kLandPasses || !(rate > kLandMinRate)) break;
    s = std::clamp(s - glm::dot(x1 - q, N) / rate, 0.0, ds);
  }
  x1 -= glm::dot(x1 - q, N) * N;
}

// Varying region: one RK4 step of ds; where its chord leaves the volume or crosses a face first,
// the step is shortened to the one that ends on that plane (sharpLand), so that x, w and the
// optical path belong to where it ends, and the crossing is that point of the path.
SharpEvent RayMarch::sharpStep(MarchState& S, MarchResult& R, BoundaryCrossing& c) const {
  const glm::dvec3 x0 = S.x, w0 = S.w;
  glm::dvec3 x1 = x0, w1 = w0, tangent;
  double opl = 0.0;
  sharpRk4(S.region, ds_, x1, w1, opl, tangent);
  double a0, a1;
  const glm::dvec3 chord = x1 - x0, dir = glm::normalize(chord);
  const bool out = !boxHit(x0, dir, bmin_, bmax_, a0, a1) || a1 < glm::length(chord);
  double keep = out ? std::clamp(std::max(a1, 0.0) / glm::length(chord), 0.0, 1.0) : 1.0;
  c = nextCrossing(x0, x0 + keep * chord, S.region);
  if (c.found) keep *= c.t;
  if (keep < 1.0) {
    const glm::dvec3 q = c.found ? c.point : x0 + keep * chord;
    const glm::dvec3 N = c.found ? c.normal : volumeSide(x0, dir, bmin_, bmax_);
    sharpLand(S.region, x0, w0, keep * ds_, ds_, q, N, x1, w1, opl);
    if (c.found) c.point = x1;
  }
  R.opl += opl;
  if (mode_ == 0)
    R.drift = std::max(R.drift, std::abs(glm::length(w1) - regionIndex(S.region, 0, x1)));
  S.x = 0.5 * (x0 + x1);
  S.w = 0.5 * (w0 + w1);
  absorbAlong(S, glm::normalize(x1 - x0 + 1e-300), glm::length(x1 - x0));
  S.x = x1;
  S.w = w1;
  return c.found ? SharpEvent::Cross : out ? SharpEvent::Leave : SharpEvent::Go;
}

// The exact laws at a crossing (anisotropic/interface.h, anisotropic/fresnel.h): Snell, or the o/e
// waves into / out of a crystal; TIR is a lossless mirror; otherwise the ray carries (1 − R) on and
// an external reflection adds R × environment(mirror direction), as the smoothed path does.
void RayMarch::crossInterface(MarchState& S, MarchResult& R, const BoundaryCrossing& c) const {
  const MediumRecord &A = rec(S.region), &B = rec(c.to);
  const glm::dvec3 x = S.x, N = c.normal, s = glm::normalize(S.w);
  const glm::dvec4 afA = mediumAxisField(A, x), afB = mediumAxisField(B, x);
  if (B.opaque() ||
      (A.medium == B.medium && A.grin_type == 0 && glm::dvec3(afA) == glm::dvec3(afB) &&
       A.axis == B.axis && A.alpha_axis == B.alpha_axis)) {
    S.region = c.to;  // equal media: nothing changes (an opaque one stops the ray next)
    return;
  }
  if (convertAtFace(S, R, c)) return;
  const Mode mode = mode_ == 1 ? Mode::Extraordinary : Mode::Ordinary;
  const double n1 = glm::length(S.w);
  ModeWave out;
  const bool biaxial = A.biaxial || B.biaxial;
  if (biaxial) {  // the mode's outgoing root beyond the face, m̂ along the incident ray
    const glm::dvec3 m = glm::dot(sharpDirection(S), N) >= 0.0 ? N : -N;
    out = outgoingMode(c.to, x, S.w - glm::dot(S.w, m) * m, m, true);
  } else if (!A.uniaxial && !B.uniaxial) {
    out = refractIsotropic(s, N, n1, regionIndex(c.to, 0, x));
  } else if (!A.uniaxial || B.uniaxial) {  // crystal → crystal: as if from an isotropic n1
    const Uniaxial cr(regionIndex(c.to, 0, x), regionIndex(c.to, 1, x), glm::dvec3(afB));
    const ModePair mp = refractIntoUniaxial(s, N, n1, cr);
    out = mode_ == 1 ? mp.e : mp.o;
  } else {
    const Uniaxial cr(regionIndex(S.region, 0, x), regionIndex(S.region, 1, x), glm::dvec3(afA));
    out = refractOutOfUniaxial(cr, mode, s, N, regionIndex(c.to, 0, x));
  }
  if (!out.exists) {  // total internal reflection: a mirror, no loss; the ray stays in A
    noteEvent(S, R, true, true, 1.0);
    reflectInRegion(S, N);
    R.tir++;
    return;
  }
  R.interfaces++;
  if (m_.fresnel) {
    const FresnelReflectance rsp = fresnelReflectance(std::abs(glm::dot(s, N)), n1, out.n);
    double Rf = 0.5 * (rsp.Rs + rsp.Rp);
    if (biaxial) {
      const double wsw = biaxialSWeight(S.region, c.to, x, s, out, N);
      Rf = wsw * rsp.Rs + (1.0 - wsw) * rsp.Rp;
    } else if (A.uniaxial || B.uniaxial) {
      const bool intoCrystal = B.uniaxial;
      const double wsw =
          sWeight(intoCrystal ? out.s : s, glm::dvec3(intoCrystal ? afB : afA), N, s, mode_);
      Rf = wsw * rsp.Rs + (1.0 - wsw) * rsp.Rp;
    }
    if (followReflection(S, R, Rf)) {  // the partial reflection, internal or external
      reflectInRegion(S, N);
      return;
    }
    if (m_.transport == Transport::Single || R.reflections >= m_.max_reflections) {
      if (out.n > n1) S.L += environmentWeighted(S.T * Rf, glm::reflect(s, N));
      S.T *= 1.0 - Rf;
    }
  }
  S.w = out.p();
  S.region = c.to;
}

// The mirror wave in the ray's own region (total internal reflection, or a partial reflection
// followed): in a crystal the reflected wave of the same mode (reflectInsideUniaxial), else w
// mirrored in the face.
void RayMarch::reflectInRegion(MarchState& S, const glm::dvec3& N) const {
  const MediumRecord& A = rec(S.region);
  if (A.biaxial) {  // the same mode's reflected root, m̂ along the incident ray
    const glm::dvec3 m = glm::dot(sharpDirection(S), N) >= 0.0 ? N : -N;
    const ModeWave r = outgoingMode(S.region, S.x, S.w - glm::dot(S.w, m) * m, m, false);
    S.w = r.exists ? r.p() : glm::reflect(S.w, N);
  } else if (A.uniaxial) {
    const glm::dvec3 s = glm::normalize(S.w);
    const glm::dvec4 afA = mediumAxisField(A, S.x);
    const Uniaxial cr(regionIndex(S.region, 0, S.x), regionIndex(S.region, 1, S.x),
                      glm::dvec3(afA));
    const ModeWave r =
        reflectInsideUniaxial(cr, mode_ == 1 ? Mode::Extraordinary : Mode::Ordinary, s, N);
    S.w = r.exists ? r.p() : glm::reflect(S.w, N);
  } else {
    S.w = glm::reflect(S.w, N);
  }
}

// The dielectric tensor of a biaxial region at the march's wavelength. A dispersion formula that
// lets n_beta leave [n_alpha, n_gamma] between the three wavelengths the scene checks is clamped
// back (the principal axes keep their names).
TensorMedium RayMarch::tensorOf(int region) const {
  const MediumRecord& m = rec(region);
  if (hero_) {
    noteDispersion(m.n_o);
    noteDispersion(m.n_beta);
    noteDispersion(m.n_e);
  }
  const double a = mediumIndex(m.n_o, lambda_nm_);
  const double g = std::max(mediumIndex(m.n_e, lambda_nm_), a);
  const double b = std::clamp(mediumIndex(m.n_beta, lambda_nm_), a, g);
  return TensorMedium(a, b, g, m.alpha_axis, m.axis);
}

// The march's mode (0 fast, 1 slow) of a biaxial region for wave vector w (its wave normal).
TensorMode RayMarch::modeOf(int region, const glm::dvec3& w) const {
  return tensorOf(region).modes(w)[mode_ == 1 ? WaveMode::Slow : WaveMode::Fast];
}

// The outgoing wave of the march's mode in `region` with tangential wave vector p_t, on the side
// +m (transmitted) or −m (reflected), m unit along the incident ray: a biaxial region's root of
// the mode's dispersion relation (anisotropic/tensor_interface.h, the propagating waves in order
// of increasing index: fast, slow), a uniaxial one's o or e root (solveUniaxialMode), an
// isotropic one's Snell root. No root: exists = false (evanescent).
ModeWave RayMarch::outgoingMode(int region, const glm::dvec3& x, const glm::dvec3& p_t,
                                const glm::dvec3& m, bool transmitted) const {
  const MediumRecord& M = rec(region);
  ModeWave out;
  if (M.biaxial) {
    const TensorMedium t = tensorOf(region);
    return outgoingModeWave(t, outgoingWaves(t, p_t, m, transmitted), mode_);
  }
  if (M.uniaxial) {
    const Uniaxial cr(regionIndex(region, 0, x), regionIndex(region, 1, x),
                      glm::dvec3(mediumAxisField(M, x)));
    return solveUniaxialMode(p_t, m, cr, mode_ == 1 ? Mode::Extraordinary : Mode::Ordinary,
                             transmitted);
  }
  const double n = regionIndex(region, 0, x), rem = n * n - glm::dot(p_t, p_t);
  if (!(rem > 0.0)) return out;
  out.exists = true;
  out.q = (transmitted ? 1.0 : -1.0) * std::sqrt(rem);
  out.n = n;
  out.s = glm::normalize(p_t + out.q * m);
  out.t = out.s;
  return out;
}

// The Fresnel weight at a face with a biaxial side (the scalar rule of sWeight): the share of the
// mode's unit D along the s direction N × ŝ_in, taken on the crystal side (B when B is
// anisotropic, else A) at that side's wave normal; a uniaxial crystal side keeps sWeight.
double RayMarch::biaxialSWeight(int from, int to, const glm::dvec3& x, const glm::dvec3& s,
                                const ModeWave& out, const glm::dvec3& N) const {
  const bool intoCrystal = rec(to).biaxial || rec(to).uniaxial;
  const int side = intoCrystal ? to : from;
  const MediumRecord& C = rec(side);
  const glm::dvec3 sc = intoCrystal ? out.s : s;
  if (!C.biaxial) return sWeight(sc, glm::dvec3(mediumAxisField(C, x)), N, s, mode_);
  glm::dvec3 es = glm::cross(N, s);
  if (glm::dot(es, es) < 1e-12) return 0.5;
  es = glm::normalize(es);
  const double ds = glm::dot(modeOf(side, sc).D, es);
  return ds * ds;
}

// The region's dielectric tensor at x and the march's wavelength (solveTensorInterface's medium):
// a biaxial region's tensorOf, a uniaxial one's (n_o, n_e, axis there), else isotropic n_o.
TensorMedium RayMarch::tensorAt(int region, const glm::dvec3& x) const {
  const MediumRecord& m = rec(region);
  if (m.biaxial) return tensorOf(region);
  const double no = regionIndex(region, 0, x);
  if (!m.uniaxial) return TensorMedium::isotropic(no);
  return TensorMedium::uniaxial(no, regionIndex(region, 1, x), glm::dvec3(mediumAxisField(m, x)));
}

// Whether a crystal's path mode (0: o or fast, 1: e or slow) and its wave index k (0 fast, 1
// slow; tensor_medium.h) are swapped: in a uniaxial crystal with n_e < n_o the o-wave is the slow
// one (TensorMedium::uniaxial: α = n_e along the axis, β = γ = n_o).
int modeSwap(const MediumRecord& m, const TensorMedium& t) {
  return m.uniaxial && !m.biaxial && t.n_beta != t.n_alpha ? 1 : 0;
}

// The path mode of outgoing wave k of a crystal region's pair `w` (solveTensorInterface's order:
// the propagating waves first, fast then slow): with both propagating, k itself; with one, the
// mode whose index along its wave normal is the wave's (as outgoingMode decides).
int RayMarch::marchModeOf(int region, const TensorMedium& t, const std::array<OutgoingWave, 2>& w,
                          int k) const {
  int fs = k;
  if (!(w[0].propagating && w[1].propagating)) {
    const std::array<double, 2> n = t.indices(w[size_t(k)].s);
    fs = std::abs(w[size_t(k)].n - n[0]) <= std::abs(w[size_t(k)].n - n[1]) ? 0 : 1;
  }
  return fs ^ modeSwap(rec(region), t);
}

// Mode conversion at a face met inside a crystal (Transport::Full; docs/view-renderer.md "Light
// transport"): the incident wave of the path's mode meets the face, and Maxwell's boundary
// conditions (solveTensorInterface, exact for any pair of media) give the power fraction of each
// outgoing propagating wave: reflected fast and slow (or o and e) in this crystal, transmitted
// ones beyond (one ray when the far side is isotropic: its s and p waves share the direction).
// The path chooses one wave with probability equal to its fraction, keeping its weight, in two
// draws of transportUniform: first reflection (probability R = Σ reflected) or transmission as
// followReflection (no draw when nothing is transmitted: total reflection), then, where the
// chosen side has two propagating waves into a crystal, the wave of mode 0 with probability
// P₀ / (P₀ + P₁) (one more draw, made whenever both propagate). The path continues in the chosen
// wave's mode, wave vector and ray. false: not a face inside a crystal, or no solution (grazing
// flow), and crossInterface applies the same-mode laws.
bool RayMarch::convertAtFace(MarchState& S, MarchResult& R, const BoundaryCrossing& c) const {
  const MediumRecord &A = rec(S.region), &B = rec(c.to);
  if (!(A.uniaxial || A.biaxial) || !m_.fresnel || m_.transport != Transport::Full || script_)
    return false;
  const glm::dvec3 x = S.x, N = c.normal, s = glm::normalize(S.w);
  TensorInterfaceSolution sol;
  TensorMedium near = TensorMedium::isotropic(1.0), far = near;
  try {
    near = tensorAt(S.region, x);
    far = tensorAt(c.to, x);
    if (near.symmetry() == Symmetry::Isotropic) return false;
    const WaveMode wm = (mode_ ^ modeSwap(A, near)) == 1 ? WaveMode::Slow : WaveMode::Fast;
    sol = solveTensorInterface(near, wm, s, N, far);
  } catch (const std::exception&) {
    return false;
  }
  const bool farCrystal = far.symmetry() != Symmetry::Isotropic;
  double Rt = 0.0, Tt = 0.0;
  for (int k = 0; k < 2; ++k) {
    if (sol.reflected[size_t(k)].propagating) Rt += sol.reflected[size_t(k)].power;
    if (sol.transmitted[size_t(k)].propagating) Tt += sol.transmitted[size_t(k)].power;
  }
  const bool transmits = sol.transmitted[0].propagating;
  const double Rf = transmits ? std::clamp(Rt / (Rt + Tt), 0.0, 1.0) : 1.0;
  bool reflects = true;
  if (!transmits) {
    R.tir++;
  } else {
    R.interfaces++;
    reflects = followReflection(S, R, Rf);
    if (!reflects && R.reflections >= m_.max_reflections) {
      if (sol.transmitted[0].n > glm::length(S.w))
        S.L += environmentWeighted(S.T * Rf, glm::reflect(s, N));
      S.T *= 1.0 - Rf;
    }
  }
  const std::array<OutgoingWave, 2>& w = reflects ? sol.reflected : sol.transmitted;
  const bool crystal = reflects || farCrystal;
  int k = 0;
  if (crystal && w[0].propagating && w[1].propagating) {
    const double p0 = w[0].power / std::max(w[0].power + w[1].power, 1e-300);
    // The draw picks path mode 0 with its share: wave k = 0 is mode 0 unless swapped.
    const int swap = modeSwap(reflects ? A : B, reflects ? near : far);
    const double pMode0 = swap ? 1.0 - p0 : p0;
    const int mode = transportUniform(seed_, S.draws++) < pMode0 ? 0 : 1;
    k = mode ^ swap;
  }
  const OutgoingWave& out = w[size_t(k)];
  if (!out.propagating) {  // no reflected wave (rounding at a graze): the mirror, as
                           // reflectInRegion
    S.w = glm::reflect(S.w, N);
    return true;
  }
  if (crystal) mode_ = marchModeOf(reflects ? S.region : c.to, reflects ? near : far, w, k);
  S.w = out.n * out.s;
  if (!reflects) S.region = c.to;
  return true;
}

MarchResult RayMarch::marchSharp(const glm::dvec3& o, const glm::dvec3& d) const {
  MarchResult R;
  double t0;
  if (!enterVolume(o, d, R, t0)) return R;
  MarchState S;
  mode_ = mode0_;
  sharpEnter(S, o + d * t0, d);
  R.opl = f_.ambientIndex() * t0;
  int steps = 0;
  for (; steps < m_.max_steps; ++steps) {
    const MediumRecord& m = rec(S.region);
    if (m.opaque()) {  // surface emission over the coverage, as the smoothed path
      S.L += S.T * (colourOf(m.emission) / m.opacity + diffuseSurface(S.x));
      S.stopped = true;
      break;
    }
    BoundaryCrossing c;
    const SharpEvent ev = m.homogeneous ? sharpSegment(S, R, c) : sharpStep(S, R, c);
    if (ev == SharpEvent::Cross && !R.first.hit)  // the AOV layer: the exact crossing
      R.first = {true, c.point, glm::dot(c.normal, S.w) > 0.0 ? -c.normal : c.normal,
                 std::max(c.from, c.to) - 1};
    if (ev == SharpEvent::Leave) break;
    if (ev == SharpEvent::Cross) {
      const int from = S.region, tir = R.tir;
      crossInterface(S, R, c);
      if (events_ && (rec(from).uniaxial || rec(from).biaxial))
        events_->push_back({c.point, S.region == from, R.tir > tir, mode_, S.region});
    }
    noteAfter(S);
  }
  R.steps = steps;
  R.exit_point = S.x;
  R.exit_dir = sharpDirection(S);
  R.wave_normal = glm::normalize(S.w);
  R.left = !S.stopped && steps < m_.max_steps;
  R.ran_out = !S.stopped && steps >= m_.max_steps;
  if (R.left) S.L += environmentWeighted(S.T, R.exit_dir);
  R.radiance = S.L;
  R.throughput = S.T;
  return R;
}

}  // namespace

struct ReferenceMarcher::Result : MarchResult {};

ReferenceMarcher::Result ReferenceMarcher::march(const glm::dvec3& o, const glm::dvec3& d,
                                                 double lambda_nm, bool scalar,
                                                 const MarchSettings& m, int mode, HeroRecord* hero,
                                                 uint32_t seed, FirstChoice first) const {
  Result r;
  const RayMarch rm(field_, env_, lambda_nm, scalar, m, mode, hero, seed, first);
  static_cast<MarchResult&>(r) = rm.march(o, d);
  r.fetches = rm.fetches();
  return r;
}

TraceOutcome ReferenceMarcher::trace(const TraceRequest& ray, const MarchSettings& m,
                                     int mode) const {
  validate(m);
  double len = glm::length(ray.direction);
  if (!(len > 0) || !std::isfinite(len))
    throw std::invalid_argument("trace direction must be a non-zero finite vector");
  if (!(ray.wavelength_nm > 0)) throw std::invalid_argument("trace wavelength must be > 0 nm");
  if (mode != 0 && mode != 1) throw std::invalid_argument("mode must be 0 (o) or 1 (e)");
  // The transmitted path (Transport::Single): its transmittance is the product of the crossings'.
  MarchSettings single = m;
  single.transport = Transport::Single;
  Result r = march(ray.origin, ray.direction / len, ray.wavelength_nm, true, single,
                   field_.uniaxial() ? mode : 0);
  TraceOutcome t;
  t.exit_point = r.exit_point;
  t.exit_direction = r.exit_dir;
  t.wave_normal = r.wave_normal;
  t.optical_path_mm = r.opl;
  t.transmittance = r.throughput.x;
  t.left_volume = r.left;
  t.steps = r.steps;
  t.invariant_drift = r.drift;
  t.interfaces = r.interfaces;
  t.total_internal_reflections = r.tir;
  return t;
}

std::vector<PathEvent> ReferenceMarcher::samplePath(const TraceRequest& ray, const MarchSettings& m,
                                                    int mode, uint32_t seed) const {
  validate(m);
  if (mode != 0 && mode != 1) throw std::invalid_argument("mode must be 0 (o) or 1 (e)");
  MarchSettings full = m;
  full.transport = Transport::Full;
  std::vector<PathEvent> events;
  RayMarch rm(field_, env_, ray.wavelength_nm, true, full, mode, nullptr, seed);
  rm.setEvents(&events);
  rm.march(ray.origin, glm::normalize(ray.direction));
  return events;
}

namespace {

/// Builds a light tree (ReferenceMarcher::lightTree). Each branch is one march of the ray with
/// the choices of its splits scripted (ChoiceScript): the reflections of the branches it descends
/// from, then refraction at every later split. Each later split spawns the reflected branch, whose
/// script is the same choices with that split reflected; it is marched in turn.
class TreeBuilder {
 public:
  using MarchFn = std::function<MarchResult(const std::vector<bool>&, std::vector<TreeStep>&)>;
  TreeBuilder(MarchFn march, const LightTreeSettings& s, LightTree& out)
      : march_(std::move(march)), s_(s), out_(out) {}
  void build(const glm::dvec3& entry, const glm::dvec3& d, double opl_entry);

 private:
  /// A branch being followed: its last node, the product of its Fresnel factors, its attenuation
  /// there, its depth, and the choices of its splits so far.
  struct Branch {
    int node = 0;
    double F = 1.0, T = 1.0;
    int depth = 0;
    std::vector<bool> script;
  };
  /// A reflected branch waiting for its march: the split's parent node, and its Fresnel product
  /// and depth after the reflection; its script ends with the reflection.
  struct Pending {
    std::vector<bool> script;
    int parent = 0;
    double F = 1.0;
    int depth = 0;
  };
  int add(LightTreeNode n) {
    n.id = int(out_.nodes.size());
    out_.nodes.push_back(n);
    return n.id;
  }
  int object(int region) const { return out_.sharp ? region - 1 : -1; }
  /// The node of a branch's event at step t: where t happened, with this event, weight and depth.
  LightTreeNode stepNode(int parent, TreeEvent event, const TreeStep& t, double weight,
                         int depth) const {
    LightTreeNode n;
    n.parent = parent;
    n.event = event;
    n.point = t.point;
    n.direction = t.dir;
    n.wave_normal = t.wave;
    n.weight = weight;
    n.fresnel_r = t.Rf;
    n.optical_path_mm = t.opl;
    n.object = object(t.region);
    n.depth = depth;
    return n;
  }
  bool cut(double w, int depth, const TreeStep& t, int parent);
  void follow(Branch b, const std::vector<TreeStep>& steps, size_t from, const MarchResult& end);
  void reflected(const Pending& p);

  MarchFn march_;
  const LightTreeSettings& s_;
  LightTree& out_;
  std::vector<Pending> pending_;
};

void TreeBuilder::build(const glm::dvec3& entry, const glm::dvec3& d, double opl_entry) {
  LightTreeNode root;
  root.event = TreeEvent::Enter;
  root.point = entry;
  root.direction = root.wave_normal = d;
  root.weight = 1.0;
  root.optical_path_mm = opl_entry;
  add(root);
  std::vector<TreeStep> steps;
  const MarchResult end = march_({}, steps);
  follow(Branch{}, steps, 0, end);
  while (!pending_.empty()) {
    const Pending p = std::move(pending_.back());
    pending_.pop_back();
    reflected(p);
  }
}

// A branch of weight w would take an event of depth `depth` at t: true (a cut leaf added) where
// the weight is below the threshold, the depth past the limit, or the tree full.
bool TreeBuilder::cut(double w, int depth, const TreeStep& t, int parent) {
  const TreeCut why = w < s_.min_weight                        ? TreeCut::Weight
                      : depth > s_.max_depth                   ? TreeCut::Depth
                      : int(out_.nodes.size()) >= s_.max_nodes ? TreeCut::Nodes
                                                               : TreeCut::None;
  if (why == TreeCut::None) return false;
  LightTreeNode n;
  n.parent = parent;
  n.event = TreeEvent::Cut;
  n.point = t.point;
  n.direction = n.wave_normal = t.dirIn;
  n.weight = w;
  n.fresnel_r = t.Rf;
  n.optical_path_mm = t.opl;
  n.object = out_.nodes[size_t(parent)].object;
  n.depth = depth - 1;
  n.cut = why;
  add(n);
  out_.cut += w;
  return true;
}

// The branch b from its march's event `from` on: each split's reflection is left for its own
// march (or cut), the refraction followed; the march's end is the branch's leaf.
void TreeBuilder::follow(Branch b, const std::vector<TreeStep>& steps, size_t from,
                         const MarchResult& end) {
  for (size_t k = from; k < steps.size(); ++k) {
    const TreeStep& t = steps[k];
    out_.absorbed += b.F * (b.T - t.T);
    b.T = t.T;
    if (!t.tir) {
      std::vector<bool> script = b.script;
      script.push_back(true);
      if (!cut(b.F * t.T * t.Rf, b.depth + 1, t, b.node))
        pending_.push_back({std::move(script), b.node, b.F * t.Rf, b.depth + 1});
      b.script.push_back(false);
      b.F *= 1.0 - t.Rf;
    }
    if (cut(b.F * t.T, b.depth + 1, t, b.node)) return;
    ++b.depth;
    b.node =
        add(stepNode(b.node, t.tir ? TreeEvent::Tir : TreeEvent::Refract, t, b.F * t.T, b.depth));
  }
  out_.absorbed += b.F * (b.T - end.throughput.x);
  LightTreeNode n;
  n.parent = b.node;
  n.event = end.left ? TreeEvent::Exit : end.ran_out ? TreeEvent::Cut : TreeEvent::Stop;
  n.cut = end.ran_out ? TreeCut::Steps : TreeCut::None;
  n.point = end.exit_point;
  n.direction = end.exit_dir;
  n.wave_normal = end.wave_normal;
  n.weight = b.F * end.throughput.x;
  n.optical_path_mm = end.opl;
  n.object = end.left ? -1 : out_.nodes[size_t(b.node)].object;
  n.depth = b.depth;
  add(n);
  (end.left ? out_.exit : end.ran_out ? out_.cut : out_.stopped) += n.weight;
}

// A reflected branch: its march repeats its ancestors' events (already in the tree) up to its
// last scripted split, where it reflects; from there it is followed as any branch.
void TreeBuilder::reflected(const Pending& p) {
  std::vector<TreeStep> steps;
  const MarchResult end = march_(p.script, steps);
  size_t j = 0, splits = 0;
  for (; j < steps.size(); ++j)
    if (!steps[j].tir && ++splits == p.script.size()) break;
  if (j == steps.size() || !steps[j].reflected)
    throw std::logic_error("light tree: a scripted reflection was not met again");
  const TreeStep& t = steps[j];
  const LightTreeNode n = stepNode(p.parent, TreeEvent::Reflect, t, p.F * t.T, p.depth);
  follow(Branch{add(n), p.F, t.T, p.depth, p.script}, steps, j + 1, end);
}

}  // namespace

LightTree ReferenceMarcher::lightTree(const TraceRequest& ray, const MarchSettings& m, int mode,
                                      const LightTreeSettings& tree) const {
  validate(m);
  checkLightTreeSettings(tree);
  const double len = glm::length(ray.direction);
  if (!(len > 0) || !std::isfinite(len))
    throw std::invalid_argument("trace direction must be a non-zero finite vector");
  if (!(ray.wavelength_nm > 0)) throw std::invalid_argument("trace wavelength must be > 0 nm");
  if (mode != 0 && mode != 1) throw std::invalid_argument("mode must be 0 (o) or 1 (e)");
  const glm::dvec3 d = ray.direction / len;
  LightTree out;
  out.uniaxial = field_.uniaxial();
  out.fast_slow = fastSlowModes(field_.media());
  out.mode = out.uniaxial ? mode : 0;
  out.sharp = field_.boundary() && field_.media();
  // Every split followed both ways: Full transport, its roulette replaced by the script, with no
  // limit on the reflections a branch follows (the tree's own limits cut it).
  MarchSettings full = m;
  full.transport = Transport::Full;
  full.max_reflections = std::numeric_limits<int>::max();
  auto march = [&](const std::vector<bool>& script, std::vector<TreeStep>& steps) {
    RayMarch rm(field_, env_, ray.wavelength_nm, true, full, out.mode);
    ChoiceScript cs;
    cs.choices = &script;
    rm.setScript(&cs);
    const MarchResult r = rm.march(ray.origin, d);
    steps = std::move(cs.steps);
    ++out.marches;
    return r;
  };
  double t0 = 0.0, t1 = 0.0;
  const bool hits = boxHit(ray.origin, d, field_.boundsMin(), field_.boundsMax(), t0, t1);
  t0 = hits ? std::max(t0, 0.0) : 0.0;
  TreeBuilder(march, tree, out).build(ray.origin + t0 * d, d, field_.ambientIndex() * t0);
  return out;
}

/// What the marches of one pixel sample add up to: steps and field reads as the mean per march
/// (divided by the wavelengths marched one by one), all steps taken (the AOV layer's steps), and
/// the first interface of the sample's first march.
struct ReferenceMarcher::SampleTally {
  double steps = 0.0, fetches = 0.0, marchSteps = 0.0;
  FirstInterface first;
  bool marched = false;
  bool ran_out = false;  ///< a march ran out of max_steps (the sample is cut short)
  void add(const Result& r, double share) {
    if (!marched) first = r.first;
    marched = true;
    ran_out = ran_out || r.ran_out;
    steps += double(r.steps) / share;
    fetches += double(r.fetches) / share;
    marchSteps += double(r.steps);
  }
};

ReferenceMarcher::Result ReferenceMarcher::marchSample(const glm::dvec3& o, const glm::dvec3& d,
                                                       double lambda_nm, bool scalar,
                                                       const MarchSettings& m, int mode,
                                                       HeroRecord* hero, uint32_t seed,
                                                       SampleTally& tally, double share) const {
  const bool split = m.transport == Transport::Full && m.split_first_choice;
  if (hero) hero->diverged = field_.weightsDependOnLambda();
  Result r = march(o, d, lambda_nm, scalar, m, mode, hero, seed,
                   split ? FirstChoice::Transmit : FirstChoice::Drawn);
  tally.add(r, share);
  if (!r.split) return r;
  if (hero) hero->diverged = field_.weightsDependOnLambda();
  const Result reflected =
      march(o, d, lambda_nm, scalar, m, mode, hero, seed, FirstChoice::Reflect);
  tally.add(reflected, share);
  r.radiance += reflected.radiance;
  return r;
}

glm::dvec3 ReferenceMarcher::heroSampleXyz(const glm::dvec3& o, const glm::dvec3& d, uint32_t pixel,
                                           uint32_t sample, const RenderSettings& s,
                                           SampleTally& tally, LayerSums* layers) const {
  // view.comp renderSpectralSample, hero: one march (per mode) at λ_0, its lookups before the
  // path's first dispersive event recorded for all N wavelengths, the rest the hero's alone,
  // counted N times.
  const auto n = uint32_t(s.wavelengths);
  const std::vector<double> lambdas = spectrum::heroWavelengths(pixel, sample, n);
  const int modes = field_.uniaxial() ? 2 : 1;
  const ModeRange mr = modeRange(s.modes, field_.uniaxial());
  HeroRecord rec;
  rec.weight = mr.weight;
  double heroMode[2] = {0.0, 0.0};  // each mode's own radiance after its path dispersed
  int count0 = 0;                   // records made by the o-mode's march
  for (int mode = mr.first; mode < mr.end; ++mode) {
    const Result r = marchSample(o, d, lambdas[0], true, s.march, mode, &rec,
                                 transportSeed(pixel, sample, mode), tally, 1.0);
    heroMode[mode] = rec.weight * r.radiance.x;
    if (mode == 0) count0 = rec.count;
  }
  glm::dvec3 xyz =
      double(n) * (heroMode[0] + heroMode[1]) * spectrum::sampleWeightXyz(lambdas[0], n);
  // The hero's bin (layers): λ_j lies in bin (k_h + j) mod N, k_h the hero's.
  const auto heroBin = uint32_t((lambdas[0] - spectrum::kVisibleMinNm) * n /
                                (spectrum::kVisibleMaxNm - spectrum::kVisibleMinNm));
  for (uint32_t j = 0; j < n; ++j) {
    const double l = lambdas[j];
    double rad[2] = {0.0, 0.0};
    for (int i = 0; i < rec.count; ++i) {
      const glm::dvec4& e = rec.entries[size_t(i)];
      rad[i < count0 ? 0 : 1] += e.w * spectrum::rgbToSpectrum(glm::dvec3(e), l);
    }
    if (rec.count > 0) xyz += (rad[0] + rad[1]) * spectrum::sampleWeightXyz(l, n);
    if (layers) {
      if (j == 0)
        for (int m = 0; m < 2; ++m) rad[m] += double(n) * heroMode[m];
      const int bin = int(std::min((heroBin + j) % n, n - 1));
      for (int m = 0; m < modes; ++m) layers->at(pixel, m)[bin] += rad[m];
    }
  }
  return xyz;
}

glm::dvec3 ReferenceMarcher::rgbSample(const glm::dvec3& eye, const glm::dvec3& d, uint32_t pixel,
                                       uint32_t sidx, const RenderSettings& s, SampleTally& tally,
                                       LayerSums* layers) const {
  // Unpolarised light: each mode carries half, or the one selected the whole (modeRange).
  const ModeRange mr = modeRange(s.modes, field_.uniaxial());
  glm::dvec3 rad(0.0);
  for (int mode = mr.first; mode < mr.end; ++mode) {
    const Result r = marchSample(eye, d, s.wavelength_nm, false, s.march, mode, nullptr,
                                 transportSeed(pixel, sidx, mode), tally, 1.0);
    const glm::dvec3 part = mr.weight * r.radiance;
    rad += part;
    if (layers)
      for (int c = 0; c < 3; ++c) layers->at(pixel, mode)[c] += part[c];
  }
  return rad;
}

glm::dvec3 ReferenceMarcher::stratifiedSampleXyz(const glm::dvec3& eye, const glm::dvec3& d,
                                                 uint32_t pixel, uint32_t sidx,
                                                 const RenderSettings& s, SampleTally& tally,
                                                 LayerSums* layers) const {
  // Unpolarised light: each mode carries half, or the one selected the whole (modeRange). Every
  // wavelength is marched: view.comp's wavelength sharing only skips marches whose results the
  // record already gives.
  const ModeRange mr = modeRange(s.modes, field_.uniaxial());
  const auto n = uint32_t(s.wavelengths);
  const std::vector<double> lambdas = spectrum::stratifiedWavelengths(pixel, sidx, n);
  glm::dvec3 xyz(0.0);
  for (size_t k = 0; k < lambdas.size(); ++k) {
    double rad = 0.0;
    for (int mode = mr.first; mode < mr.end; ++mode) {
      const Result r = marchSample(eye, d, lambdas[k], true, s.march, mode, nullptr,
                                   transportSeed(pixel, sidx, mode), tally, s.wavelengths);
      const double part = mr.weight * r.radiance.x;
      rad += part;
      if (layers) layers->at(pixel, mode)[k] += part;
    }
    xyz += rad * spectrum::sampleWeightXyz(lambdas[k], n);
  }
  return xyz;
}

glm::dvec3 ReferenceMarcher::sampleRgb(const glm::dvec3& eye, const glm::dvec3& d, uint32_t pixel,
                                       uint32_t sidx, const RenderSettings& s, bool hero,
                                       SampleTally& tally, LayerSums& layers) const {
  // The strategy, as view.comp's main chooses it from the pass bits.
  LayerSums* lp = layers.active() ? &layers : nullptr;
  if (s.wavelengths == 0) return rgbSample(eye, d, pixel, sidx, s, tally, lp);
  const glm::dmat3 M = spectrum::spectralToLinearSrgbMatrix();
  if (hero) return M * heroSampleXyz(eye, d, pixel, sidx, s, tally, lp);
  return M * stratifiedSampleXyz(eye, d, pixel, sidx, s, tally, lp);
}

RenderImage ReferenceMarcher::render(const Camera& cam, const RenderSettings& s,
                                     int threads) const {
  validate(s.march);
  if (int(s.modes) < 0 || int(s.modes) > 2)
    throw std::invalid_argument("modes must be both, o or e");
  RenderImage img;
  img.width = s.width > 0 ? s.width : cam.width;
  img.height = s.height > 0 ? s.height : cam.height;
  img.rgb.assign(size_t(img.width) * size_t(img.height) * 3, 0.0f);
  const glm::dvec3 fwd = glm::normalize(cam.look_at - cam.position);
  const glm::dvec3 right = glm::normalize(glm::cross(fwd, cam.up));
  const glm::dvec3 up = glm::cross(right, fwd);
  const double tanh = std::tan(0.5 * cam.fov_deg * std::numbers::pi / 180.0),
               aspect = double(img.width) / img.height;
  const bool hero = useHeroSampling(s.sampling, field_.weightsDependOnLambda());
  LayerSums layers(s, size_t(img.width) * size_t(img.height), field_.uniaxial());
  if (s.aov_layer) initAov(img);
  std::atomic<int> next{0}, rows_done{0};
  std::atomic<long long> total_steps{0}, total_fetches{0}, cut_samples{0};
  std::mutex progress_mutex;  // progress per row, one report at a time (skipped when busy)
  auto worker = [&] {
    long long local_steps = 0, local_fetches = 0;
    for (int y = next++; y < img.height; y = next++) {
      if (y > 0 && s.progress) {
        std::unique_lock<std::mutex> lock(progress_mutex, std::try_to_lock);
        if (lock.owns_lock()) s.progress(double(rows_done.load()) / img.height);
      }
      for (int x = 0; x < img.width; ++x) {
        uint32_t pixel = uint32_t(y * img.width + x);
        glm::dvec3 sum(0.0);
        double steps = 0, fetches = 0;
        for (int sidx = 0; sidx < s.spp; ++sidx) {
          double jx = 0.5, jy = 0.5;
          if (s.spp > 1) {
            uint32_t hs = spectrum::pcgHash(pixel * 9781u + uint32_t(sidx) * 6271u + 17u);
            jx = double(hs & 0xffffu) / 65536.0;
            jy = double(hs >> 16u) / 65536.0;
          }
          double u = ((x + jx) / img.width * 2.0 - 1.0) * tanh * aspect;
          double v = (1.0 - (y + jy) / img.height * 2.0) * tanh;
          glm::dvec3 d = glm::normalize(fwd + u * right + v * up);
          SampleTally tally;
          sum += sampleRgb(cam.position, d, pixel, uint32_t(sidx), s, hero, tally, layers);
          steps += tally.steps;
          fetches += tally.fetches;
          if (tally.ran_out) ++cut_samples;
          if (s.aov_layer) {
            if (sidx == 0) setAovGeometry(img, pixel, cam.position, tally.first);
            addAovSteps(img, pixel, tally.marchSteps);
          }
        }
        size_t o = (size_t(y) * size_t(img.width) + size_t(x)) * 3;
        for (int c = 0; c < 3; ++c) img.rgb[o + size_t(c)] = float(sum[c] / s.spp);
        local_steps += (long long)(steps / s.spp);
        local_fetches += (long long)(fetches / s.spp);
      }
      ++rows_done;
    }
    total_steps += local_steps;
    total_fetches += local_fetches;
  };
  int t = threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
  auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  for (int i = 0; i < t; ++i) pool.emplace_back(worker);
  for (auto& th : pool) th.join();
  if (s.progress) s.progress(1.0);
  layers.finish(img, s.spp);
  img.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  img.mean_steps = double(total_steps) / (double(img.width) * img.height);
  img.mean_fetches = double(total_fetches) / (double(img.width) * img.height);
  img.cut_samples = cut_samples;
  return img;
}

}  // namespace eikon
