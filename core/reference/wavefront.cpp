// CPU reference of the light simulator: see wavefront.h for the method and the units.
#include "core/reference/wavefront.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>

#include "anisotropic/fresnel.h"
#include "anisotropic/interface.h"
#include "anisotropic/tensor_interface.h"
#include "anisotropic/tensor_medium.h"
#include "anisotropic/units.h"
#include "core/light/seeding.h"
#include "core/light/sharp_skip.h"
#include "core/reference/field.h"

namespace eikon {
namespace {

// Patch geometry shared with the seeding (core/light/seeding.h).
using light::centre;
using light::inside;
using light::meanW;
using light::rayHitsBox;
using light::vectorArea;

/// One chunk of a run (WavefrontSettings::threads): chunk c advances slice c of every step's
/// list, n·c/T ≤ i < n·(c + 1)/T (n patches, T chunks), always on the same thread. It splats into
/// its own volumes and counts into its own statistics over the whole run (reduced in chunk order
/// at the end), and writes the step's outputs (children and survivors in list order, patches
/// that reached max_steps); the next step's list is the chunks' outputs in chunk order, read in
/// place (out[] alternates between steps). Chunk 0 splats into the result's volumes, so one chunk
/// is exactly the single-threaded loop. Aligned: chunks are written concurrently, and a shared
/// cache line would bounce between cores.
struct alignas(64) Chunk {
  double* acc = nullptr;                ///< Σ flux·Δs / h³ (W/mm²), per voxel
  double* best = nullptr;               ///< highest patch irradiance (W/mm²), per voxel
  glm::dvec3* dirAcc = nullptr;         ///< Σ (flux·Δs / h³)·direction, per voxel
  std::vector<double> accOwn, bestOwn;  ///< storage of acc and best for chunks c ≥ 1
  std::vector<glm::dvec3> dirOwn;       ///< storage of dirAcc for chunks c ≥ 1
  WavefrontStats st;                    ///< this chunk's counts and flux sums over the run
  std::vector<Patch> out[2];            ///< out[step parity]: the step's children and survivors
  std::vector<Patch>* next = nullptr;   ///< the running step's out[]
  std::vector<Patch> done, work;        ///< the step's patches at max_steps; emit()'s stack
  /// Threads > 1: the step's surviving patches before emission, and the chunk's kill count when
  /// each survived, to redo the emission serially if the patch budget binds.
  std::vector<Patch> surv;
  std::vector<size_t> survKills;
  /// Live count while the step runs: absolute when emitting against the budget (one chunk, or the
  /// serial redo), else relative to the chunk's start (−1 per kill, +3 per split into quarters,
  /// +1 per split into halves or reflected copy).
  long long live = 0;
  long long maxAfterSplit = LLONG_MIN;  ///< highest `live` right after a split in this step
  size_t kills = 0, splits = 0, halvings = 0, refused = 0, tears = 0, reflections = 0;  ///< step's
  /// Patches this step added to the live count by splits and reflected copies.
  long long grown() const { return 3 * (long long)splits + (long long)(halvings + reflections); }
  bool anyGrowth() const { return splits + halvings + reflections > 0; }
};

/// Worker threads for one WavefrontSimulator::run, created once: go(f) calls f(c) for chunk c on
/// worker c (c = 1 … T − 1) and f(0) on the calling thread, and returns when all have returned
/// (rethrowing the first exception). The fixed assignment keeps each chunk's state on one core.
class ChunkPool {
 public:
  explicit ChunkPool(int chunks) {
    for (int c = 1; c < chunks; ++c) workers_.emplace_back([this, c] { work(c); });
  }
  ~ChunkPool() {
    {
      std::lock_guard<std::mutex> lock(m_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : workers_) t.join();
  }
  ChunkPool(const ChunkPool&) = delete;
  ChunkPool& operator=(const ChunkPool&) = delete;

  void go(const std::function<void(int)>& f) {
    {
      std::lock_guard<std::mutex> lock(m_);
      f_ = &f;
      pending_ = workers_.size();
      ++generation_;
    }
    wake_.notify_all();
    std::exception_ptr mine;
    try {
      f(0);
    } catch (...) {
      mine = std::current_exception();
    }
    std::unique_lock<std::mutex> lock(m_);
    done_.wait(lock, [&] { return pending_ == 0; });
    f_ = nullptr;
    std::exception_ptr theirs = error_;
    error_ = nullptr;
    if (mine) std::rethrow_exception(mine);
    if (theirs) std::rethrow_exception(theirs);
  }

 private:
  void work(int c) {
    unsigned long long seen = 0;
    for (;;) {
      const std::function<void(int)>* f;
      {
        std::unique_lock<std::mutex> lock(m_);
        wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
        if (stop_) return;
        seen = generation_;
        f = f_;
      }
      std::exception_ptr e;
      try {
        (*f)(c);
      } catch (...) {
        e = std::current_exception();
      }
      std::lock_guard<std::mutex> lock(m_);
      if (e && !error_) error_ = e;
      if (--pending_ == 0) done_.notify_one();
    }
  }

  std::vector<std::thread> workers_;
  std::mutex m_;
  std::condition_variable wake_, done_;
  const std::function<void(int)>* f_ = nullptr;
  size_t pending_ = 0;
  unsigned long long generation_ = 0;
  bool stop_ = false;
  std::exception_ptr error_;
};

/// Steps with fewer patches than this per chunk run their chunks one after another on the calling
/// thread (the same chunks, so the same results): waking the workers would cost more.
constexpr size_t kMinPatchesPerChunk = 64;
/// A straight step ends this far (voxels) before the boundary a corner would meet (straightClear;
/// wavefront.comp has the same): well above the GPU twin's float rounding of a position.
constexpr double kStraightMarginVoxels = 1e-3;

/// What a patch's step leaves for the stages after it (wavefront.comp's PatchStep).
struct PatchStep {
  int kStraight = 0;            ///< time steps taken along straight lines (0: one RK4 step)
  glm::dvec3 c0{0.0}, c1{0.0};  ///< the centre before and after
  glm::dvec3 wm0{0.0};          ///< the mean w before (e-mode)
  glm::dvec3 diag[4];  ///< straight step: the diagonals at the start and their change per time step
  glm::dvec3 vc{0.0};  ///< straight step: the centre's velocity (the mean of the corners')
  double ds = 0.0;     ///< |c1 − c0|
  double sigma = 0.0;  ///< attenuation at the step's midpoint
  double E0 = 0.0;     ///< flux before the step
  double fluxMid = 0.0;  ///< flux at the step's middle
  // Sharp interfaces: the factors of the corners' crossings over the step, each the product over
  // the four corners of a fourth root (Fresnel transmission; attenuation exp(−σ·length)).
  double fresnel = 1.0;
  double attenuation = 1.0;
  /// Reflected copies: the product over the pending corners that reflected in this step of T^¼
  /// (the transmission their twins' corners took): shadow·(1 − gain) is reflected into the patch.
  double gain = 1.0;
};

/// The per-patch physics of one WavefrontSimulator::run: the functions and stages of
/// shaders/wavefront.comp under the same names, in double precision (docs/twins.md). Const: the
/// chunks call it concurrently, each with its own Chunk.
class PatchStepper {
 public:
  PatchStepper(const Field& f, const Grid& grid, const WavefrontSettings& s, double il2, double il4,
               const SharpInterfaces* sharp)
      : f_(f),
        grid_(grid),
        s_(s),
        il2_(il2),
        il4_(il4),
        lo_(f.boundsMin()),
        hi_(f.boundsMax()),
        h_(grid.h),
        h3_(grid.h * grid.h * grid.h),
        dt_(s.dt),
        maxEdge_(s.split_span_voxels * grid.h),
        eMode_(s.mode == 1),
        sharp_(sharp && sharp->active() ? sharp : nullptr),
        onShapes_(sharp_ && sharp_->boundary->regionsOnShapes()) {
    if (!sharp_) return;
    for (const WavefrontMedium& m : sharp_->media) {
      tensors_.push_back(m.biaxial ? std::optional<TensorMedium>(tensorOfMedium(m)) : std::nullopt);
      walk_ = walk_ || m.biaxial;
    }
  }

  /// Sharp interfaces: the region a seed corner starts in and its wave vector along s on that
  /// region's shell (the run's seeds are moved onto the media's shells with it).
  int regionAt(const glm::dvec3& x) const { return eikon::regionAt(*sharp_->boundary, x); }
  glm::dvec3 mediumShell(int region, const glm::dvec3& s) const;

  /// One patch's step (propagate in wavefront.comp): advance, splat, count, end it or emit it
  /// (split against `budget`) into *ch.next. keep: also record it in ch.surv before emission.
  void advance(Chunk& ch, Patch p, long long budget, bool keep) const;
  /// Split p (repeatedly) until no edge exceeds the split span or the patch budget is spent: a
  /// split is refused when it would take ch.live above `budget` (LLONG_MAX: never).
  void emit(Chunk& ch, const Patch& p0, long long budget) const;
  /// The ways a patch splits (splitWays): bits, kSplitU | kSplitV = quarters.
  static constexpr int kSplitNone = 0, kSplitU = 1, kSplitV = 2, kSplitQuarters = 3;

 private:
  glm::dvec4 sampleIndex(const glm::dvec3& x, int mode) const {
    return field::sampleIndex(f_, x, il2_, il4_, mode);
  }
  double bandAt(const glm::dvec3& rgb) const { return field::bandAt(rgb, s_.wavelength_nm); }
  glm::dvec3 onShell(const glm::dvec3& x, const glm::dvec3& s) const;
  void deriv(const glm::dvec3& x, const glm::dvec3& w, glm::dvec3& dx, glm::dvec3& dw) const;
  double sigmaE(const glm::dvec3& x, const glm::dvec3& w) const;
  void rk4(glm::dvec3& x, glm::dvec3& w) const;
  void splatAt(Chunk& ch, const glm::dvec3& m, double fluxDs, double irr,
               const glm::dvec3& dir) const;
  void splatSegment(Chunk& ch, const glm::dvec3& c0, const glm::dvec3& u, double L, double E0,
                    double sigma, const glm::dvec3& dir, double ds1,
                    const glm::dvec3 diag[4]) const;
  int straightSteps(const Patch& p, glm::dvec3 v[4], double& sigma1) const;
  double skipAt(const glm::dvec3& x) const;
  size_t sharpVoxel(const glm::dvec3& x) const;
  enum class Along { OneRegion, SameMotion, Others };
  Along regionsAlong(const glm::dvec3& a, const glm::dvec3& b, int r) const;
  bool sameMotion(int r, int q) const;
  // The stages of a step.
  PatchStep moveStep(Chunk& ch, Patch& p) const;
  glm::dvec4 attenuateStep(Chunk& ch, Patch& p, PatchStep& st) const;
  glm::dvec3 splatStep(Chunk& ch, const PatchStep& st, const Patch& p) const;
  void probeStep(Chunk& ch, const PatchStep& st, Patch& p) const;
  bool endOfStep(Chunk& ch, Patch& p, const PatchStep& st, const glm::dvec4& med) const;
  void ended(Chunk& ch, const Patch& p) const;
  // Sharp interfaces.
  const WavefrontMedium& mediumOf(int region) const { return sharp_->media[size_t(region)]; }
  // Biaxial regions: the medium's tensor, the run's mode (fast or slow) for wave vector w, the
  // run's outgoing root in a region, the same mode's mirror wave, the Maxwell share at a face.
  static TensorMedium tensorOfMedium(const WavefrontMedium& m);
  const TensorMedium& tensorOf(int region) const { return *tensors_[size_t(region)]; }
  TensorMode biaxialMode(int region, const glm::dvec3& w) const;
  ModeWave modeRoot(int region, const glm::dvec3& p_t, const glm::dvec3& m, bool transmitted) const;
  ModeWave mirrorWave(int region, const glm::dvec3& w, const glm::dvec3& N) const;
  double biaxialTransmission(int from, int to, const glm::dvec3& w, const glm::dvec3& N,
                             const ModeWave& out) const;
  glm::dvec3 mediumVelocity(int region, const glm::dvec3& w) const;
  double mediumSigma(int region, const glm::dvec3& w) const;
  void sharpCorner(Chunk& ch, Patch& p, int k, double T, PatchStep& st) const;
  bool crossInterface(const BoundaryCrossing& c, Patch& p, int k, double& transmission,
                      double& gain) const;
  bool spawnsReflection(const Patch& p) const {
    return sharp_ && p.generation < s_.max_reflection_generations && !p.armed && p.pending == 0u &&
           !straddles(p);
  }
  /// The flux a patch holds or will hold: its own and what its pending corners will reflect in.
  static double fluxAhead(const Patch& p) { return p.energy + p.shadow; }
  bool straddles(const Patch& p) const;
  bool torn(const Patch& p) const;
  /// How p splits (wavefront.comp splitWays): kSplitNone when no edge exceeds the split span;
  /// kSplitU (two halves across the u edges 0→1 and 3→2) or kSplitV (across 1→2 and 0→3) when only
  /// one pair of opposite edges does; kSplitQuarters when both do (or always, with
  /// WavefrontSettings::split_halves off). A patch fanned along one direction (light grazing a
  /// smoothed interface) thus doubles its patches per generation rather than quadrupling them.
  int splitWays(const Patch& p) const {
    auto len = [&](size_t a, size_t b) { return glm::length(p.x[b] - p.x[a]); };
    const bool u = std::max(len(0, 1), len(3, 2)) > maxEdge_;
    const bool v = std::max(len(1, 2), len(0, 3)) > maxEdge_;
    if (!s_.split_halves) return u || v ? kSplitQuarters : kSplitNone;
    return (u ? kSplitU : kSplitNone) | (v ? kSplitV : kSplitNone);
  }
  /// Whether p may be split `ways`: only while its children (halves or quarters) keep at least the
  /// energy threshold (min_energy_fraction of its seed's flux). A patch due a split it may not make
  /// ends as a kill by energy (endOfStep), as its children would have after one step each; a child
  /// of a split that would need another is stepped once first (emit). Near grazing incidence on a
  /// smoothed interface a stretched patch split until then made thousands of such children per
  /// seed (wavefront.comp mayBeSplit).
  bool mayBeSplit(const Patch& p, int ways) const {
    const double share = ways == kSplitQuarters ? 0.25 : 0.5;
    return share * fluxAhead(p) >= s_.min_energy_fraction * p.seed_energy;
  }
  double straightClear(const glm::dvec3& x, const glm::dvec3& v, int r) const;
  void splitInto(const Patch& p, int ways, std::vector<Patch>& out) const;

  const Field& f_;
  const Grid& grid_;
  const WavefrontSettings& s_;
  double il2_, il4_;
  glm::dvec3 lo_, hi_;
  double h_, h3_, dt_, maxEdge_;
  bool eMode_;
  const SharpInterfaces* sharp_;  ///< null: the smoothed path
  /// The boundary field's regions are on the shapes (BoundaryField::regionsOnShapes): crossings
  /// by crossingOutOf (sharpCorner), once per run rather than per corner step.
  bool onShapes_ = false;
  /// Sharp interfaces: tensors_[r], region r's tensor where its medium is biaxial.
  std::vector<std::optional<TensorMedium>> tensors_;
  /// The energy leaves a corner along its ray, not w (the e-mode, or a biaxial region): the splat
  /// direction is the centre's motion.
  bool walk_ = eMode_;
};

// The skip distance at x (voxels): the sharp path's own (SharpInterfaces::skip, on the boundary
// field's grid, looked up as VolumeField::skipDistance does) when it has them, else the field's.
double PatchStepper::skipAt(const glm::dvec3& x) const {
  if (!sharp_ || sharp_->skip.empty()) return f_.skipDistance(x);
  return double(sharp_->skip[sharpVoxel(x)]);
}

// The voxel of the boundary field's grid that holds x, clamped (as VolumeField::skipDistance).
size_t PatchStepper::sharpVoxel(const glm::dvec3& x) const {
  const Grid& g = sharp_->boundary->grid;
  int i[3];
  for (int a = 0; a < 3; ++a)
    i[a] = std::clamp(int(std::floor((x[a] - g.origin[a]) / g.h)), 0, g.dims[size_t(a)] - 1);
  return g.index(i[0], i[1], i[2]);
}

// Wave vector along the unit direction s at x on the simulated mode's shell (wavefront.comp
// onShell): the seeding's (core/light/seeding.h), which both twins share.
glm::dvec3 PatchStepper::onShell(const glm::dvec3& x, const glm::dvec3& s) const {
  return onModeShell(f_, s_.mode, il2_, il4_, x, s);
}

// Constant-time rates (wavefront.h): dx/dt = w/n², dw/dt = ∇n/n; in a crystal of the e-mode the
// Hamiltonian's, field::eModeRates (not divided by |M_e p|, unlike the marcher's arc length).
void PatchStepper::deriv(const glm::dvec3& x, const glm::dvec3& w, glm::dvec3& dx,
                         glm::dvec3& dw) const {
  const glm::dvec4 o = sampleIndex(x, 0);
  if (eMode_) {
    const glm::dvec4 af = f_.axisField(x);
    if (field::hasAxis(glm::dvec3(af))) {
      field::eModeRates(w, af, o, sampleIndex(x, 1), dx, dw);
      return;
    }
  }
  dx = w / (o.x * o.x);
  dw = glm::dvec3(o.y, o.z, o.w) / o.x;
}

// e-mode attenuation per unit ray length at x for wave vector w (field::attenuationE), at the
// simulator's wavelength; the o-mode σ where there is no axis.
double PatchStepper::sigmaE(const glm::dvec3& x, const glm::dvec3& w) const {
  const double so = bandAt(glm::dvec3(f_.medium(x)));
  const glm::dvec3 a = f_.axis(x);
  if (!field::hasAxis(a) || !(glm::dot(w, w) > 0)) return so;
  const double se = bandAt(glm::dvec3(f_.mediumE(x)));
  return field::attenuationE(glm::dvec3(so), glm::dvec3(se), w, a, sampleIndex(x, 0).x,
                             sampleIndex(x, 1).x)
      .x;
}

void PatchStepper::rk4(glm::dvec3& x, glm::dvec3& w) const {
  const double dt = dt_;
  glm::dvec3 k1x, k1w, k2x, k2w, k3x, k3w, k4x, k4w;
  deriv(x, w, k1x, k1w);
  deriv(x + 0.5 * dt * k1x, w + 0.5 * dt * k1w, k2x, k2w);
  deriv(x + 0.5 * dt * k2x, w + 0.5 * dt * k2w, k3x, k3w);
  deriv(x + dt * k3x, w + dt * k3w, k4x, k4w);
  x += dt / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
  w += dt / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
}

// Sharp interfaces: the wave vector along the unit direction s on the shell of region r's medium
// (|w| = n; the e-mode in a crystal: sᵀM_e s scaled to 1), and the constant-time velocity there
// (w/n², or M_e w), as deriv() has them in a constant field.
glm::dvec3 PatchStepper::mediumShell(int region, const glm::dvec3& s) const {
  const WavefrontMedium& m = mediumOf(region);
  if (m.biaxial) return tensorOf(region).indices(s)[size_t(eMode_ ? 1 : 0)] * s;
  if (eMode_ && m.n_e > 0.0) return s / std::sqrt(glm::dot(s, mediumVelocity(region, s)));
  return m.n * s;
}

glm::dvec3 PatchStepper::mediumVelocity(int region, const glm::dvec3& w) const {
  const WavefrontMedium& m = mediumOf(region);
  if (m.biaxial) {  // the energy velocity t̂/(p·t̂): the mode's ray, p·v = 1 as on every shell
    const glm::dvec3 t = biaxialMode(region, w).t;
    return t / glm::dot(w, t);
  }
  if (eMode_ && m.n_e > 0.0) {
    const double pa = glm::dot(w, m.axis);
    return pa / (m.n * m.n) * m.axis + (w - pa * m.axis) / (m.n_e * m.n_e);
  }
  return w / (m.n * m.n);
}

// Attenuation per unit ray length in region r for wave vector w: σ_o, or in a crystal of the
// e-mode the pleochroic σ(θ)·cos ρ of field::attenuationE (as sigmaE on the smoothed path).
double PatchStepper::mediumSigma(int region, const glm::dvec3& w) const {
  const WavefrontMedium& m = mediumOf(region);
  if (m.biaxial) {  // trichroism, first order in the principal σ's, per unit ray length
    if (m.sigma == 0.0 && m.sigma_beta == 0.0 && m.sigma_e == 0.0) return 0.0;
    const TensorMode md = biaxialMode(region, w);
    return tensorOf(region).attenuation(md.D, md.n) * glm::dot(glm::normalize(w), md.t);
  }
  if (!eMode_ || !(m.n_e > 0.0) || (m.sigma == 0.0 && m.sigma_e == 0.0)) return m.sigma;
  return field::attenuationE(glm::dvec3(m.sigma), glm::dvec3(m.sigma_e), w, m.axis, m.n, m.n_e).x;
}

// A biaxial medium's dielectric tensor with its principal attenuations (σ_α, σ_β, σ_γ).
TensorMedium PatchStepper::tensorOfMedium(const WavefrontMedium& m) {
  return TensorMedium(m.n, m.n_beta, m.n_e, m.alpha_axis, m.axis,
                      glm::dvec3(m.sigma, m.sigma_beta, m.sigma_e));
}

// The run's mode of a biaxial region for wave vector w (its wave normal): fast (mode 0), slow (1).
TensorMode PatchStepper::biaxialMode(int region, const glm::dvec3& w) const {
  return tensorOf(region).modes(glm::normalize(w))[eMode_ ? WaveMode::Slow : WaveMode::Fast];
}

// The outgoing wave of the run's mode in `region` with tangential wave vector p_t, on the side +m
// (transmitted) or −m (reflected), m unit along the incident ray (the view march's outgoingMode):
// a biaxial region's root of the mode's dispersion relation (outgoingWaves: the propagating waves
// in order fast, slow; where only one propagates, it is the mode whose index it has), a uniaxial
// one's o or e root (solveUniaxialMode), an isotropic one's Snell root. None: exists = false.
ModeWave PatchStepper::modeRoot(int region, const glm::dvec3& p_t, const glm::dvec3& m,
                                bool transmitted) const {
  const WavefrontMedium& M = mediumOf(region);
  const int mode = eMode_ ? 1 : 0;
  ModeWave out;
  if (M.biaxial) {
    const TensorMedium& t = tensorOf(region);
    return outgoingModeWave(t, outgoingWaves(t, p_t, m, transmitted), mode);
  }
  if (M.n_e > 0.0)
    return solveUniaxialMode(p_t, m, Uniaxial(M.n, M.n_e, M.axis),
                             eMode_ ? Mode::Extraordinary : Mode::Ordinary, transmitted);
  const double rem = M.n * M.n - glm::dot(p_t, p_t);
  if (!(rem > 0.0)) return out;
  out.exists = true;
  out.q = (transmitted ? 1.0 : -1.0) * std::sqrt(rem);
  out.n = M.n;
  out.s = glm::normalize(p_t + out.q * m);
  out.t = out.s;
  return out;
}

// The mirror wave of the run's mode in a biaxial region at a face of normal N (total internal
// reflection, or a reflected copy's corner): the same mode's reflected root.
ModeWave PatchStepper::mirrorWave(int region, const glm::dvec3& w, const glm::dvec3& N) const {
  const glm::dvec3 m = glm::dot(mediumVelocity(region, w), N) >= 0 ? N : -N;
  return modeRoot(region, w - glm::dot(w, m) * m, m, false);
}

// The transmission of the run's mode through a face with a biaxial side, `out` the outgoing wave
// (anisotropic/tensor_interface.h, the exact Maxwell powers). Isotropic → crystal: the mode's
// share of unpolarised light, the mean over the s and p incident waves, doubled because a mode's
// run carries half the light (the sum of the two); crystal → isotropic: the incident mode's
// transmitted power; crystal → crystal: the phase-matched wave of the same mode, no loss. An
// interface the solver refuses (energy along the face: grazing) transmits nothing.
double PatchStepper::biaxialTransmission(int from, int to, const glm::dvec3& w, const glm::dvec3& N,
                                         const ModeWave& out) const {
  const WavefrontMedium &a = mediumOf(from), &b = mediumOf(to);
  const bool crystalA = a.biaxial || a.n_e > 0.0, crystalB = b.biaxial || b.n_e > 0.0;
  if (crystalA && crystalB) return 1.0;
  try {
    if (crystalA)
      return solveTensorInterface(tensorOf(from), eMode_ ? WaveMode::Slow : WaveMode::Fast,
                                  glm::normalize(w), N, TensorMedium::isotropic(b.n))
          .transmittedPower();
    const glm::dvec3 m = glm::dot(w, N) >= 0 ? N : -N, pt = w - glm::dot(w, m) * m;
    const TensorMedium near = TensorMedium::isotropic(a.n);
    double T = 0.0;
    for (const maxwell::Wave& in : maxwell::isotropicWaves(pt, m, a.n, true)) {
      const TensorInterfaceSolution sol = solveTensorInterface(near, in, N, tensorOf(to));
      const OutgoingWave* mine = nullptr;  // the transmitted wave that is `out`
      double gap = 0.0;
      for (const OutgoingWave& o : sol.transmitted) {
        const double d = glm::length(o.n * o.s - out.p());
        if (o.propagating && (!mine || d < gap)) mine = &o, gap = d;
      }
      if (mine) T += mine->power;
    }
    return T;
  } catch (const std::exception&) {
    return 0.0;
  }
}

// Corner k at the crossing c (p.x[k] its point, p.w[k] the incident wave vector): the exact laws
// of anisotropic/ between the media of c.from and c.to (docs/light-simulator.md, "Sharp
// interfaces"). Isotropic ↔ isotropic: Snell and the unpolarised Fresnel T = 1 − R; into a crystal:
// the run's mode (o by Snell with n_o, e by the closed form of the e-wave normal) with the exact
// Maxwell share of the unpolarised power, doubled because a mode's run carries half the light; out
// of a crystal: the exact exit transmission of the mode; crystal → crystal: the phase-matched wave
// of the same mode, no loss. A biaxial side (docs/light-simulator.md, "Biaxial crystals"): the
// mode's roots (modeRoot) and Maxwell shares (biaxialTransmission) by the same rules. Where the
// outgoing wave does not exist, total internal reflection: the mirror (same mode), no loss, the
// corner's mirror bit flips and it stays in its region. Equal media, or an opaque one entered: only
// the region changes. Multiplies `transmission` by T; true if the corner was turned. A pending
// corner of a reflected copy (Patch::pending) takes the reflected wave where its twin's corner goes
// through (the mirror: reflectIsotropic, reflectInsideUniaxial of the same mode, as total internal
// reflection), stays in its region and multiplies `gain` by the T its twin's corner took instead.
bool PatchStepper::crossInterface(const BoundaryCrossing& c, Patch& p, int k, double& transmission,
                                  double& gain) const {
  const WavefrontMedium &a = mediumOf(c.from), &b = mediumOf(c.to);
  glm::dvec3 N = glm::length(c.normal) > 0 ? c.normal : c.field_normal;
  const bool same = a.biaxial || b.biaxial
                        ? a.biaxial && b.biaxial && a.n == b.n && a.n_beta == b.n_beta &&
                              a.n_e == b.n_e && a.axis == b.axis && a.alpha_axis == b.alpha_axis
                        : a.n == b.n && a.n_e == b.n_e && (a.n_e == 0.0 || a.axis == b.axis);
  const bool reflects = (p.pending >> k) & 1u;
  p.pending &= ~(1u << k);
  ++p.events[size_t(k)];  // every region change or mirror is an event (torn)
  if (c.face >= 0)
    p.faces[size_t(k)] = faceDigest(p.faces[size_t(k)], std::max(c.from, c.to), c.face);
  if (same || b.opaque || !(glm::length(N) > 0)) {
    p.region[size_t(k)] = c.to;
    return false;
  }
  glm::dvec3& w = p.w[size_t(k)];
  const glm::dvec3 s = glm::normalize(w);
  const Mode mode = eMode_ ? Mode::Extraordinary : Mode::Ordinary;
  const bool inA = a.n_e > 0.0 && !a.biaxial, inB = b.n_e > 0.0 && !b.biaxial;
  ModeWave out;
  double T = 1.0;
  bool mirror = false;
  if (a.biaxial || b.biaxial) {  // the mode's root beyond the face, m̂ along the incident ray
    const glm::dvec3 m = glm::dot(mediumVelocity(c.from, w), N) >= 0 ? N : -N;
    const glm::dvec3 pt = w - glm::dot(w, m) * m;
    out = modeRoot(c.to, pt, m, true);
    if (out.exists) T = biaxialTransmission(c.from, c.to, w, N, out);
    if (!out.exists) out = modeRoot(c.from, pt, m, false), mirror = true;
  } else if (!inA && !inB) {
    out = refractIsotropic(s, N, a.n, b.n);
    if (out.exists) T = 1.0 - fresnelReflectance(std::abs(glm::dot(s, N)), a.n, b.n).R;
  } else if (!inA) {
    const Uniaxial X(b.n, b.n_e, b.axis);
    const ModePair pair = refractIntoUniaxial(s, N, a.n, X);
    out = eMode_ ? pair.e : pair.o;
    if (out.exists) {
      const ModeSplit sp = uniaxialEntryExact(s, N, a.n, X);
      T = 2.0 * (eMode_ ? sp.e : sp.o);
    }
  } else if (!inB) {
    const Uniaxial X(a.n, a.n_e, a.axis);
    out = refractOutOfUniaxial(X, mode, s, N, b.n);
    if (out.exists)
      T = uniaxialExitExact(X, mode, s, N, b.n).transmitted;
    else
      out = reflectInsideUniaxial(X, mode, s, N), mirror = true;
  } else {
    const Uniaxial A(a.n, a.n_e, a.axis), B(b.n, b.n_e, b.axis);
    const glm::dvec3 m = glm::dot(mediumVelocity(c.from, w), N) >= 0 ? N : -N;
    const glm::dvec3 pt = w - glm::dot(w, m) * m;
    out = solveUniaxialMode(pt, m, B, mode, true);
    if (!out.exists || reflects) out = solveUniaxialMode(pt, m, A, mode, false), mirror = true;
  }
  if (reflects && out.exists && !mirror) {  // a reflected copy's corner: the mirror, gain T
    gain *= T;
    out = ModeWave{};
  }
  if (!out.exists && !mirror) {
    // Total internal reflection into an isotropic medium, or a crystal mode that cannot enter.
    out = a.biaxial ? mirrorWave(c.from, w, N)
          : inA     ? reflectInsideUniaxial(Uniaxial(a.n, a.n_e, a.axis), mode, s, N)
                    : reflectIsotropic(s, N, a.n);
    mirror = true;
  }
  if (!out.exists) {  // degenerate (grazing): go on unturned
    p.region[size_t(k)] = c.to;
    return false;
  }
  w = out.p();
  if (mirror) {
    p.mirrored ^= 1u << k;
  } else {
    p.region[size_t(k)] = c.to;
    transmission *= T;
  }
  return true;
}

// Sharp interfaces: corner k moves for the time T through homogeneous media, straight in its
// region's medium up to the first boundary (locateCrossing, refined on the exact shape), turned
// there (crossInterface) and on for the rest of T. Its share of the patch's factors: (T_F)^¼ of
// each transmission, exp(−σ·length/4) of the attenuation along its path.
void PatchStepper::sharpCorner(Chunk& ch, Patch& p, int k, double T, PatchStep& st) const {
  const BoundaryField& bf = *sharp_->boundary;
  glm::dvec3& x = p.x[size_t(k)];
  double absorb = 0.0, trans = 1.0, gain = 1.0;
  for (int guard = 0; T > 0.0; ++guard) {
    const int r = p.region[size_t(k)];
    const glm::dvec3 d = T * mediumVelocity(r, p.w[size_t(k)]);
    const double len = glm::length(d);
    // No boundary can lie on the corner's way when it moves at most (D − 1.5)·h from a voxel of
    // skip distance D (the argument of straight steps; the sharp path's D counts region changes
    // only) or when every boundary-field cell it touches lies in its region: locateCrossing would
    // find none, so it is not called (most corners near a surface are such corners).
    // Where the regions are on the shapes (BoundaryField::regionsOnShapes) the crossing is the
    // shapes' own (crossingOutOf, the view march's; the GPU twin's nextCrossing), and the voxels'
    // regions along the way say nothing about it: only the skip distance is a bound there.
    const bool onShapes = onShapes_;
    const Along along = guard == 0 && s_.skip_empty
                            ? (len <= (skipAt(x) - 1.5) * h_ ? Along::OneRegion
                               : onShapes                    ? Along::Others
                                                             : regionsAlong(x, x + d, r))
                            : Along::Others;
    if (along == Along::OneRegion) {
      absorb += mediumSigma(r, p.w[size_t(k)]) * len;
      x += d;
      break;
    }
    // Only regions whose media move a corner as r's does (an opaque floor of the ambient's
    // index): where the crossing lies changes the corner's end point by round-off only, so the
    // trilinear field's zero is taken without the refinement on the exact shape.
    LocateOptions opt;
    opt.analytic = along != Along::SameMotion;
    BoundaryCrossing c = guard >= 16 ? BoundaryCrossing{}
                         : onShapes  ? crossingOutOf(bf, x, x + d, r)
                                     : locateCrossing(bf, x, x + d, opt);
    if (!onShapes && c.found && c.from != r && c.to == r) {
      // The trilinear field's zero lies just past the exact surface where the corner was turned
      // (curved faces: by up to 3h²/8r): not a new boundary, so go on past it.
      const double t = std::min(1.0, c.t + 1e-6 * h_ / std::max(len, 1e-300));
      absorb += mediumSigma(r, p.w[size_t(k)]) * t * len;
      x += t * d;
      T *= 1.0 - t;
      continue;
    }
    if (!c.found) {
      absorb += mediumSigma(r, p.w[size_t(k)]) * len;
      x += d;
      break;
    }
    absorb += mediumSigma(r, p.w[size_t(k)]) * c.t * len;
    x = c.point;
    T *= 1.0 - c.t;
    c.from = r;  // the corner's own region, whatever the field says at its start
    if (crossInterface(c, p, k, trans, gain)) ++ch.st.interface_events;
  }
  if (trans != 1.0) st.fresnel *= std::pow(trans, 0.25);  // pow(1, ¼) = 1 exactly
  if (gain != 1.0) st.gain *= std::pow(gain, 0.25);
  if (absorb != 0.0) st.attenuation *= std::exp(-0.25 * absorb);
}

// Sharp interfaces: the corners lie in different regions, or only some have been mirrored. Such a
// patch is being torn by a boundary: it is not split (a new corner would mix the sides) and its
// orientation is not tested for a caustic until all four are on one side.
bool PatchStepper::straddles(const Patch& p) const {
  const bool oneRegion =
      p.region[1] == p.region[0] && p.region[2] == p.region[0] && p.region[3] == p.region[0];
  return !oneRegion || (p.mirrored != 0u && p.mirrored != 15u) ||
         (p.pending != 0u && p.pending != 15u);
}

// Sharp interfaces: the corners met different boundaries, or one boundary with different outcomes
// (one refracted where another was totally reflected). While one boundary sweeps over a coherent
// patch the corners' event counts differ by at most one and corners of equal count share region
// and mirror; a torn patch breaks that. Its corners are exact rays but its interior is not a ray
// tube: a split would interpolate across the tear (a fan of rays that exist nowhere) and, held
// together, its centre splats between corners that may be far apart.
// How far (mm) a corner at x moving along v goes in region r before it meets the region's boundary
// (crossingOutOf over the bounds' diagonal), less kStraightMarginVoxels (the GPU twin's float
// positions stay on this side of it); the diagonal if it meets none.
double PatchStepper::straightClear(const glm::dvec3& x, const glm::dvec3& v, int r) const {
  const double L = glm::length(hi_ - lo_);
  const BoundaryCrossing c = crossingOutOf(*sharp_->boundary, x, x + L * glm::normalize(v), r);
  return c.found ? c.t * L - kStraightMarginVoxels * h_ : L;
}

bool PatchStepper::torn(const Patch& p) const {
  const auto [lo, hi] = std::minmax_element(p.events.begin(), p.events.end());
  if (*hi - *lo > 1) return true;
  for (size_t a = 0; a < 4; ++a)
    for (size_t b = a + 1; b < 4; ++b)
      if (p.events[a] == p.events[b] &&
          (p.region[a] != p.region[b] || ((p.mirrored >> a) & 1u) != ((p.mirrored >> b) & 1u) ||
           p.faces[a] != p.faces[b]))
        return true;
  return false;
}

void PatchStepper::splatAt(Chunk& ch, const glm::dvec3& m, double fluxDs, double irr,
                           const glm::dvec3& dir) const {
  int idx[3];
  for (int a = 0; a < 3; ++a) {
    double f = std::floor((m[a] - grid_.origin[a]) / h_);
    if (!(f >= 0 && f < grid_.dims[size_t(a)])) return;
    idx[a] = int(f);
  }
  const size_t v = grid_.index(idx[0], idx[1], idx[2]);
  ch.acc[v] += fluxDs / h3_;
  ch.dirAcc[v] += (fluxDs / h3_) * dir;
  ch.best[v] = std::max(ch.best[v], irr);
}

void PatchStepper::splatSegment(Chunk& ch, const glm::dvec3& c0, const glm::dvec3& u, double L,
                                double E0, double sigma, const glm::dvec3& dir, double ds1,
                                const glm::dvec3 diag[4]) const {
  double sA = 0.0, sB = L;
  for (int a = 0; a < 3; ++a) {
    const double g0 = grid_.origin[a], g1 = grid_.origin[a] + grid_.dims[size_t(a)] * h_;
    if (u[a] == 0.0) {
      if (c0[a] < g0 || c0[a] >= g1) return;
      continue;
    }
    double t0 = (g0 - c0[a]) / u[a], t1 = (g1 - c0[a]) / u[a];
    if (t0 > t1) std::swap(t0, t1);
    sA = std::max(sA, t0);
    sB = std::min(sB, t1);
  }
  if (!(sA < sB)) return;
  int i[3], stepI[3];
  double tNext[3], tDelta[3];
  for (int a = 0; a < 3; ++a) {
    const double ga = (c0[a] + sA * u[a] - grid_.origin[a]) / h_;
    i[a] = std::clamp(int(std::floor(ga)), 0, grid_.dims[size_t(a)] - 1);
    if (u[a] > 0) {
      stepI[a] = 1, tDelta[a] = h_ / u[a];
      tNext[a] = (grid_.origin[a] + (i[a] + 1) * h_ - c0[a]) / u[a];
    } else if (u[a] < 0) {
      stepI[a] = -1, tDelta[a] = -h_ / u[a];
      tNext[a] = (grid_.origin[a] + i[a] * h_ - c0[a]) / u[a];
    } else {
      stepI[a] = 0, tDelta[a] = 0, tNext[a] = 1e300;
    }
  }
  double sCur = sA;
  const int guard = grid_.dims[0] + grid_.dims[1] + grid_.dims[2] + 3;
  for (int it = 0; it < guard; ++it) {
    const int a =
        tNext[0] <= tNext[1] ? (tNext[0] <= tNext[2] ? 0 : 2) : (tNext[1] <= tNext[2] ? 1 : 2);
    const double sEnd = std::min(tNext[a], sB);
    if (sEnd > sCur) {
      const double sm = 0.5 * (sCur + sEnd), flux = E0 * std::exp(-sigma * sm),
                   val = flux * (sEnd - sCur) / h3_;
      const double tau = ds1 > 0 ? sm / ds1 : 0.0;
      const double area =
          0.5 * glm::length(glm::cross(diag[0] + tau * diag[1], diag[2] + tau * diag[3]));
      const size_t v = grid_.index(i[0], i[1], i[2]);
      ch.acc[v] += val;
      ch.dirAcc[v] += val * dir;
      ch.best[v] = std::max(ch.best[v], area > 0 ? flux / area : 0.0);
      sCur = sEnd;
    }
    if (sCur >= sB) break;
    i[a] += stepI[a];
    if (i[a] < 0 || i[a] >= grid_.dims[size_t(a)]) break;
    tNext[a] += tDelta[a];
  }
}

// Sharp interfaces: the regions of every voxel of every trilinear cell of the boundary field that
// the segment [a, b] touches. OneRegion: all are r, so locateCrossing would find no crossing on
// it (its cells have no other region: φ_r > 0 throughout). SameMotion: the others' media have
// r's indices, axis and attenuation (sameMotion). The cells of the points u (voxel coordinates)
// have corners L(u) and L(u) + 1 per axis, L(u) = clamp(⌊u⌋, 0, n − 2) (boundary.cpp cellAt),
// monotone in u: so the voxels L(min) … L(max) + 1 per axis hold them all.
PatchStepper::Along PatchStepper::regionsAlong(const glm::dvec3& a, const glm::dvec3& b,
                                               int r) const {
  const BoundaryField& bf = *sharp_->boundary;
  const Grid& g = bf.grid;
  int lo[3], hi[3];
  for (int ax = 0; ax < 3; ++ax) {
    const int n = g.dims[size_t(ax)];
    const double ua = (a[ax] - g.origin[ax]) / g.h - 0.5, ub = (b[ax] - g.origin[ax]) / g.h - 0.5;
    if (!(std::isfinite(ua) && std::isfinite(ub))) return Along::Others;
    const auto L = [n](double u) {
      return n < 2 ? 0 : int(std::clamp(std::floor(u), 0.0, n - 2.0));
    };
    lo[ax] = L(std::min(ua, ub));
    hi[ax] = std::min(L(std::max(ua, ub)) + 1, n - 1);
  }
  Along along = Along::OneRegion;
  for (int k = lo[2]; k <= hi[2]; ++k)
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int i = lo[0]; i <= hi[0]; ++i) {
        const int q = int(bf.region[g.index(i, j, k)]);
        if (q == r) continue;
        if (!sameMotion(r, q)) return Along::Others;
        along = Along::SameMotion;
      }
  return along;
}

// Whether a corner moves and is attenuated in region q's medium exactly as in r's (the same n,
// n_e, optic axis of a crystal, σ_o, σ_e; opacity aside): crossInterface then only changes the
// corner's region id.
bool PatchStepper::sameMotion(int r, int q) const {
  const WavefrontMedium &a = mediumOf(r), &b = mediumOf(q);
  if (a.biaxial || b.biaxial)
    return a.biaxial == b.biaxial && a.n == b.n && a.n_beta == b.n_beta && a.n_e == b.n_e &&
           a.axis == b.axis && a.alpha_axis == b.alpha_axis && a.sigma == b.sigma &&
           a.sigma_beta == b.sigma_beta && a.sigma_e == b.sigma_e;
  return a.n == b.n && a.n_e == b.n_e && (a.n_e == 0.0 || a.axis == b.axis) && a.sigma == b.sigma &&
         a.sigma_e == b.sigma_e;
}

// How many time steps p may take at once along straight lines (0: none, take an RK4 step), and
// the corners' constant velocities dx/dt. Conditions (docs/light-simulator.md, "Straight
// steps"): the centre and all corners lie in voxels of skip distance D ≥ 2, the centre's voxel is
// not opaque, no radial axis field (e-mode), and a centre outside the bounds is headed for them.
// k then keeps every point within (D − 1.5)·h of where it starts (so it, and the trilinear
// stencils along its path, stay inside its homogeneous region: the straight line is the exact
// solution there), stays within max_steps − steps and, when σ > 0, ends at the first step whose
// flux is below the energy threshold; finally it is cut at the first step j at which single
// steps would act: an edge longer than the split span (split), an orientation flip (caustic), the
// centre leaving (after having been inside, or its ray missing the bounds). Sharp interfaces
// (docs/light-simulator.md, "Sharp interfaces"): also for a patch that is not torn and whose
// region is not opaque, at its medium's velocities; sigma1 is then the step's attenuation per
// unit of the centre's path (its corners' exp(−¼ Σ σ·length), as sharpCorner takes it).
int PatchStepper::straightSteps(const Patch& p, glm::dvec3 v[4], double& sigma1) const {
  if (!s_.skip_empty) return 0;
  // Sharp interfaces: all four corners in one region on one side of every mirror (a torn patch
  // takes single steps), moving at that medium's constant velocity.
  if (sharp_ && (straddles(p) || mediumOf(p.region[0]).opaque)) return 0;
  const glm::dvec3 c0 = centre(p);
  // Sharp interfaces: the centre reads no field but the opacity, which the loop below tests at
  // every time step's midpoint as single steps would, so only the corners need skip distances.
  const double Dmin = sharp_ ? 0.0 : skipAt(c0);
  if (!sharp_ && Dmin < 2.0) return 0;
  double D[4];
  // Sharp, with crossings found on the shapes or their planes (no walk): each corner's way to its
  // region's boundary is searched exactly (straightClear), so a corner near a surface, whose skip
  // distance is below 2, may still go straight up to it.
  const bool exact = sharp_ && s_.straight_to_boundary &&
                     (sharp_->boundary->convex_apart || sharp_->boundary->exact);
  for (int k = 0; k < 4; ++k) {
    D[k] = skipAt(p.x[size_t(k)]);
    if (D[k] < 2.0 && !exact) return 0;
  }
  if (f_.medium(c0).w >= 0.5) return 0;
  const glm::dvec3 wm = meanW(p);
  const double wl = glm::length(wm);
  if (!(wl > 0)) return 0;
  const bool in0 = inside(c0, lo_, hi_);
  if (!in0 && (p.entered || !rayHitsBox(c0, wm / wl, lo_, hi_))) return 0;
  glm::dvec3 vc(0.0);
  double absorb1 = 0.0;  // sharp: Σ σ·length of the corners over one time step
  for (int k = 0; k < 4; ++k) {
    if (sharp_) {
      v[k] = mediumVelocity(p.region[0], p.w[size_t(k)]);
      absorb1 += mediumSigma(p.region[0], p.w[size_t(k)]) * glm::length(v[k]) * dt_;
    } else {
      if (eMode_ && f_.axisField(p.x[size_t(k)]).w > 0.0) return 0;  // radial axis: a varies
      glm::dvec3 dw;
      deriv(p.x[size_t(k)], p.w[size_t(k)], v[k], dw);
    }
    vc += 0.25 * v[k];
  }
  double kmax = double(s_.max_steps - p.steps);
  auto capBy = [&](double Dv, const glm::dvec3& vel) {
    const double sp = glm::length(vel) * dt_;
    if (sp > 0) kmax = std::min(kmax, std::floor((Dv - 1.5) * h_ / sp));
  };
  if (!sharp_) capBy(Dmin, vc);
  for (int k = 0; k < 4; ++k) {
    const double sp = glm::length(v[k]) * dt_;
    if (!(sp > 0)) continue;
    double kk = std::floor((D[k] - 1.5) * h_ / sp);
    if (exact) kk = std::max(kk, std::floor(straightClear(p.x[size_t(k)], v[k], p.region[0]) / sp));
    kmax = std::min(kmax, kk);
  }
  // Energy: a patch already below the threshold (a child of a split) is killed after its next
  // step; otherwise the first step at which exp(−σ·j·ds1) takes it below.
  // Sharp interfaces: a single step's factor is exp(−¼ Σ σ·length) over the corners (sharpCorner),
  // the same each step; sigma1 = −log of it per unit of the centre's path.
  const double ds1 = glm::length(vc) * dt_, thr = s_.min_energy_fraction * p.seed_energy;
  sigma1 = 0.0;
  const double flux = fluxAhead(p);
  if (flux < thr) {
    kmax = std::min(kmax, 1.0);
  } else if (ds1 > 0) {
    const glm::dvec3 m = c0 + 0.5 * dt_ * vc;
    const double sigma = sharp_   ? 0.25 * absorb1 / ds1
                         : eMode_ ? sigmaE(m, wm)
                                  : bandAt(glm::dvec3(f_.medium(m)));
    if (sigma > 0 && thr > 0)
      kmax = std::min(kmax, std::floor(std::log(flux / thr) / (sigma * ds1)) + 1.0);
  }
  if (sharp_ && ds1 > 0) sigma1 = 0.25 * absorb1 / ds1;
  if (kmax < 1.0) return 0;
  const int K = int(kmax);
  // A mirror reverses the orientation (endOfStep).
  const int orientation = sharp_ && p.mirrored != 0u ? -p.orientation : p.orientation;
  bool entered = p.entered || in0;
  // Sharp: how far the centre may go before its opacity can reach 0.5 (opacitySkipDistances; c0
  // is not opaque, so within that distance it is below 0.5 throughout).
  const double opacitySafe = sharp_ && !sharp_->opacity_skip.empty()
                                 ? (double(sharp_->opacity_skip[sharpVoxel(c0)]) - 1.5) * h_
                                 : -1.0;
  const double vcl = glm::length(vc);
  for (int j = 1; j <= K; ++j) {
    glm::dvec3 x[4];
    for (int k = 0; k < 4; ++k) x[k] = p.x[size_t(k)] + (double(j) * dt_) * v[k];
    double e = 0;
    for (int k = 0; k < 4; ++k) e = std::max(e, glm::length(x[(k + 1) % 4] - x[k]));
    const double o = glm::dot(0.5 * glm::cross(x[2] - x[0], x[3] - x[1]), wm);
    const glm::dvec3 c = 0.25 * (x[0] + x[1] + x[2] + x[3]);
    bool stop = e > maxEdge_ || (o > 0 && orientation < 0) || (o < 0 && orientation > 0);
    if (inside(c, lo_, hi_))
      entered = true;
    else if (entered || !rayHitsBox(c, wm / wl, lo_, hi_))
      stop = true;
    // Sharp: the opacity kill at the step's midpoint (attenuateStep reads it at the same point).
    if (sharp_ && (double(j) - 0.5) * dt_ * vcl > opacitySafe &&
        f_.medium(c0 + (double(j) - 0.5) * dt_ * vc).w >= 0.5)
      stop = true;
    if (stop) return j;
  }
  return K;
}

// Split p (repeatedly) until no edge exceeds maxEdge_ or the patch budget is spent: a split is
// refused when it would take ch.live above `budget` (LLONG_MAX: never; see the step loop).
void PatchStepper::emit(Chunk& ch, const Patch& p0, long long budget) const {
  // One patch becomes four (quarters or a tear's pencils) or two (halves) unless that takes
  // ch.live over budget: then p goes on whole (refused).
  auto grant = [&](const Patch& p, int ways) {
    const long long more = ways == kSplitQuarters ? 3 : 1;
    if (ch.live + more > budget) {
      ++ch.refused;
      ch.next->push_back(p);
      return false;
    }
    ch.live += more;
    ++(ways == kSplitQuarters ? ch.splits : ch.halvings);
    ch.maxAfterSplit = std::max(ch.maxAfterSplit, ch.live);
    return true;
  };
  if (p0.spawn) {
    // A reflected copy (advance): the patch, armed, and its copy, both from the state before the
    // step; one patch more unless that takes ch.live over budget (then the patch goes on alone and
    // its reflected power is dropped at the crossing).
    Patch orig = p0;
    orig.spawn = false;
    orig.armed = true;
    if (ch.live + 1 > budget) {
      ++ch.refused;
      ch.next->push_back(orig);
      return;
    }
    ++ch.live;
    ++ch.reflections;
    ch.maxAfterSplit = std::max(ch.maxAfterSplit, ch.live);
    Patch copy = orig;
    copy.armed = false;
    copy.generation = orig.generation + 1;
    copy.pending = 15u;
    copy.shadow = orig.energy;
    copy.energy = 0.0;
    ch.next->push_back(orig);
    ch.next->push_back(copy);
    return;
  }
  if (sharp_ && torn(p0)) {
    if (!grant(p0, kSplitQuarters)) return;
    ++ch.tears;
    // Four pencils, one per corner: all four corners on the corner's ray (zero width: a pencil
    // never splits, deposits its flux along its ray and has no irradiance of its own).
    for (size_t k = 0; k < 4; ++k) {
      Patch c = p0;
      c.x.fill(p0.x[k]);
      c.w.fill(p0.w[k]);
      c.region.fill(p0.region[k]);
      c.events.fill(p0.events[k]);
      c.faces.fill(p0.faces[k]);
      c.mirrored = ((p0.mirrored >> k) & 1u) ? 15u : 0u;
      c.pending = ((p0.pending >> k) & 1u) ? 15u : 0u;
      c.shadow = 0.25 * p0.shadow;
      c.energy = 0.25 * p0.energy;
      c.area0 = 0.25 * p0.area0;
      ch.next->push_back(c);
    }
    return;
  }
  // Most patches need no split: emitted as they are, without the work stack's copies.
  if (splitWays(p0) == kSplitNone || (sharp_ && straddles(p0))) {
    ch.next->push_back(p0);
    return;
  }
  std::vector<Patch>& work = ch.work;
  work.clear();
  work.push_back(p0);
  while (!work.empty()) {
    const Patch p = work.back();
    work.pop_back();
    const int ways = splitWays(p);
    if (ways == kSplitNone || (sharp_ && straddles(p)) || !mayBeSplit(p, ways)) {
      ch.next->push_back(p);
      continue;
    }
    if (!grant(p, ways)) continue;
    splitInto(p, ways, work);
  }
}

// The children of p split `ways` (wavefront.comp scatter), pushed onto `out`: on the bilinear 3×3
// lattice of p's parameters (only its points the children use), the parent's own corners kept
// exactly and each new point's w put back onto the shell; quarters of the lattice, or halves
// across the u (or v) edges, each with an equal share of the parameter area and so of the flux.
void PatchStepper::splitInto(const Patch& p, int ways, std::vector<Patch>& out) const {
  glm::dvec3 X[3][3], W[3][3];
  for (int b = 0; b < 3; ++b)
    for (int a = 0; a < 3; ++a) {
      if ((ways == kSplitU && b == 1) || (ways == kSplitV && a == 1)) continue;  // not used
      const double fa = 0.5 * a, fb = 0.5 * b;
      X[b][a] = (1 - fa) * (1 - fb) * p.x[0] + fa * (1 - fb) * p.x[1] + fa * fb * p.x[2] +
                (1 - fa) * fb * p.x[3];
      glm::dvec3 w = (1 - fa) * (1 - fb) * p.w[0] + fa * (1 - fb) * p.w[1] + fa * fb * p.w[2] +
                     (1 - fa) * fb * p.w[3];
      if ((a == 1 || b == 1) && sharp_)
        w = mediumShell(p.region[0], glm::normalize(w));  // the region's medium's shell
      else if (a == 1 || b == 1)
        w = onShell(X[b][a], glm::normalize(w));  // back onto the mode's shell
      W[b][a] = w;
    }
  X[0][0] = p.x[0], X[0][2] = p.x[1], X[2][2] = p.x[2], X[2][0] = p.x[3];
  W[0][0] = p.w[0], W[0][2] = p.w[1], W[2][2] = p.w[2], W[2][0] = p.w[3];
  const int n = ways == kSplitQuarters ? 4 : 2;
  const double share = 1.0 / n;  // equal parameter areas: that share of the parent's ray tubes
  for (int i = 0; i < n; ++i) {
    // The child's parameter ranges [a0, a1] × [b0, b1] on the lattice.
    const int a0 = ways == kSplitV ? 0 : (ways == kSplitU ? i : i & 1);
    const int a1 = ways == kSplitV ? 2 : a0 + 1;
    const int b0 = ways == kSplitU ? 0 : (ways == kSplitV ? i : i >> 1);
    const int b1 = ways == kSplitU ? 2 : b0 + 1;
    Patch c = p;
    const int pa[4] = {a0, a1, a1, a0}, pb[4] = {b0, b0, b1, b1};
    for (int k = 0; k < 4; ++k) {
      c.x[size_t(k)] = X[pb[k]][pa[k]];
      c.w[size_t(k)] = W[pb[k]][pa[k]];
    }
    c.energy = share * p.energy;
    c.shadow = share * p.shadow;
    c.area0 = share * p.area0;
    out.push_back(c);
  }
}

// Advance the corners by one RK4 time step, or by k time steps along straight lines (w is then
// unchanged: ∇n = 0), and count the time steps (wavefront.comp moveStep).
PatchStep PatchStepper::moveStep(Chunk& ch, Patch& p) const {
  PatchStep st;
  st.c0 = centre(p);
  st.wm0 = eMode_ ? meanW(p) : glm::dvec3(0.0);
  glm::dvec3 vel[4];
  double sigma1 = 0.0;
  st.kStraight = straightSteps(p, vel, sigma1);
  if (sharp_ && st.kStraight == 0) {
    for (int k = 0; k < 4; ++k) sharpCorner(ch, p, k, dt_, st);
    ++p.steps;
  } else if (st.kStraight > 0) {
    // diag: the diagonals at the start and their change per time step (the area along the path).
    st.diag[0] = p.x[2] - p.x[0], st.diag[1] = dt_ * (vel[2] - vel[0]);
    st.diag[2] = p.x[3] - p.x[1], st.diag[3] = dt_ * (vel[3] - vel[1]);
    for (int k = 0; k < 4; ++k) st.vc += 0.25 * vel[k];  // as straightSteps sums it
    const double T = double(st.kStraight) * dt_;
    for (int k = 0; k < 4; ++k) p.x[size_t(k)] += T * vel[k];
    // Sharp: no boundary on the way (no Fresnel), the corners' attenuation over the path.
    if (sharp_) st.attenuation = std::exp(-sigma1 * glm::length(centre(p) - st.c0));
    p.steps += st.kStraight;
    ++ch.st.straight_steps;
    ch.st.straight_time_steps += size_t(st.kStraight);
  } else {
    for (int k = 0; k < 4; ++k) rk4(p.x[size_t(k)], p.w[size_t(k)]);
    ++p.steps;
  }
  ch.st.steps = std::max(ch.st.steps, p.steps);
  st.c1 = centre(p);
  st.ds = glm::length(st.c1 - st.c0);
  return st;
}

// flux ← flux·exp(−σΔs), σ at the midpoint of the centre's path; returns the medium there
// (wavefront.comp attenuateStep).
glm::dvec4 PatchStepper::attenuateStep(Chunk& ch, Patch& p, PatchStep& st) const {
  // Sharp straight steps: the medium (for the opacity kill) at the midpoint of the last time
  // step, where single steps would have read it (straightSteps stops there when it is opaque).
  const glm::dvec3 m = sharp_ && st.kStraight > 0
                           ? st.c0 + (double(st.kStraight) - 0.5) * dt_ * st.vc
                           : 0.5 * (st.c0 + st.c1);
  const glm::dvec4 med = f_.medium(m);
  if (sharp_) {
    // The corners' Fresnel losses, then their attenuation; σ: the mean over the centre's path.
    ch.st.flux_reflected += p.energy * (1.0 - st.fresnel);
    p.energy *= st.fresnel;
    // A reflected copy: what its pending corners reflected in this step, taken from the flux the
    // crossing dropped; once all four have reflected the rest of the shadow is the transmitted
    // twin's and not this patch's.
    const double gained = p.shadow * (1.0 - st.gain);
    p.energy += gained;
    ch.st.flux_reflected -= gained;
    p.shadow = p.pending != 0u ? p.shadow - gained : 0.0;
    st.sigma = st.ds > 0 ? -std::log(st.attenuation) / st.ds : 0.0;
  } else {
    st.sigma = eMode_ ? sigmaE(m, 0.5 * (st.wm0 + meanW(p))) : bandAt(glm::dvec3(med));
  }
  st.E0 = p.energy;
  const double att = sharp_ ? st.attenuation : std::exp(-st.sigma * st.ds);
  st.fluxMid = p.energy * (sharp_ ? std::sqrt(att) : std::exp(-0.5 * st.sigma * st.ds));
  ch.st.flux_absorbed += p.energy * (1.0 - att);
  p.energy *= att;
  p.shadow *= att;
  p.transmittance *= att;
  return med;
}

// Splat the step: along the straight path (splatSegment) or at the midpoint (splatAt). Returns
// the propagation direction: ŵ for the o-mode; for the e-mode the energy direction, that of the
// centre's motion over the step (M_e p, not p, in a crystal) (wavefront.comp splatStep).
glm::dvec3 PatchStepper::splatStep(Chunk& ch, const PatchStep& st, const Patch& p) const {
  const double area = glm::length(vectorArea(p));
  const glm::dvec3 wm = meanW(p);
  const double wl = glm::length(wm);
  const glm::dvec3 dir = walk_ ? (st.ds > 0 ? (st.c1 - st.c0) / st.ds : glm::dvec3(0.0))
                               : (wl > 0 ? wm / wl : glm::dvec3(0.0));
  if (st.kStraight > 0) {
    if (st.ds > 0)
      splatSegment(ch, st.c0, (st.c1 - st.c0) / st.ds, st.ds, st.E0, st.sigma, dir,
                   st.ds / st.kStraight, st.diag);
  } else {
    splatAt(ch, 0.5 * (st.c0 + st.c1), st.fluxMid * st.ds, area > 0 ? st.fluxMid / area : 0.0, dir);
  }
  return dir;
}

// The probe plane: the net flux, centroid and direction of the centres crossing it
// (wavefront.comp probeStep).
void PatchStepper::probeStep(Chunk& ch, const PatchStep& st, Patch& p) const {
  if (s_.probe_axis < 0) return;
  const int ax = s_.probe_axis;
  const int side = st.c1[ax] >= s_.probe_position ? 1 : -1;
  if (side != p.probe_side) {
    const double span = st.c1[ax] - st.c0[ax];
    const double f = span != 0 ? std::clamp((s_.probe_position - st.c0[ax]) / span, 0.0, 1.0) : 0.5;
    // The flux where the centre crosses: mid-step for an RK4 step, at the crossing point for a
    // straight step (exact along its attenuated path).
    const double fx = st.kStraight > 0 ? st.E0 * std::exp(-st.sigma * f * st.ds) : st.fluxMid;
    ch.st.flux_probe += side * fx;
    ch.st.probe_centroid += side * fx * (st.c0 + f * (st.c1 - st.c0));
    if (st.ds > 0) ch.st.probe_direction += side * fx * (st.c1 - st.c0) / st.ds;
  }
  p.probe_side = side;
}

// A patch ends: it leaves the live set; note its flux if it never got past the probe plane.
void PatchStepper::ended(Chunk& ch, const Patch& p) const {
  ++ch.kills;
  --ch.live;
  if (s_.probe_axis >= 0 && p.probe_side < 0) ch.st.flux_ended_before_probe += p.energy;
}

// The kills, each accounted by reason, in wavefront.comp's order (endOfStep): opaque, left,
// caustic (or passed through), energy. True if the patch ended.
bool PatchStepper::endOfStep(Chunk& ch, Patch& p, const PatchStep& st,
                             const glm::dvec4& med) const {
  if (med.w >= 0.5) {
    ++ch.st.kills_opaque;
    ch.st.flux_absorbed += p.energy;
    ended(ch, p);
    return true;
  }
  const glm::dvec3 wm = meanW(p);
  const double wl = glm::length(wm);
  if (inside(st.c1, lo_, hi_)) {
    p.entered = true;
  } else if (p.entered || !(wl > 0) || !rayHitsBox(st.c1, wm / wl, lo_, hi_)) {
    ++ch.st.kills_left;
    ch.st.flux_left += p.energy;
    ended(ch, p);
    return true;
  }
  const double o = glm::dot(vectorArea(p), wm);
  // Sharp interfaces: a mirror reverses the orientation; a patch torn by a boundary is not tested.
  const int orient = sharp_ && p.mirrored != 0u ? -p.orientation : p.orientation;
  const bool flip = (o > 0 && orient < 0) || (o < 0 && orient > 0);
  if (sharp_ && straddles(p)) {
    // no caustic test while the corners are on different sides
  } else if (s_.pass_caustics && flip) {
    p.orientation = -p.orientation;  // through the focal line; the next flip is the next caustic
    ++ch.st.caustic_crossings;
  } else if (flip) {
    ++ch.st.kills_caustic;
    ch.st.flux_caustic += p.energy;
    ch.st.caustic_centroid += p.energy * st.c1;
    ended(ch, p);
    return true;
  }
  // Energy: below the threshold, or due a split whose children would be (mayBeSplit).
  const int ways = sharp_ && straddles(p) ? kSplitNone : splitWays(p);
  if (fluxAhead(p) < s_.min_energy_fraction * p.seed_energy ||
      (ways != kSplitNone && !mayBeSplit(p, ways))) {
    ++ch.st.kills_energy;
    ch.st.flux_energy += p.energy;
    ended(ch, p);
    return true;
  }
  return false;
}

void PatchStepper::advance(Chunk& ch, Patch p, long long budget, bool keep) const {
  if (p.steps >= s_.max_steps) {
    ch.done.push_back(p);
    return;
  }
  // Reflected wavefronts: a step of a whole patch that takes a Fresnel loss at a crossing is
  // undone; the patch and its reflected copy (emit) then both take it from the state before (the
  // copy's corners meet the interface where the patch's do, with the same T, and turn back there).
  const bool mayReflect = spawnsReflection(p);
  Patch before;
  size_t events0 = 0;
  if (mayReflect) before = p, events0 = ch.st.interface_events;
  PatchStep st = moveStep(ch, p);
  p.armed = false;
  if (mayReflect && st.kStraight == 0 && st.fresnel < 1.0) {
    ch.st.interface_events = events0;
    before.spawn = true;
    if (keep) {
      ch.surv.push_back(before);
      ch.survKills.push_back(ch.kills);
    }
    emit(ch, before, budget);
    return;
  }
  const glm::dvec4 med = attenuateStep(ch, p, st);
  splatStep(ch, st, p);
  probeStep(ch, st, p);
  if (endOfStep(ch, p, st, med)) return;
  if (keep) {
    ch.surv.push_back(p);
    ch.survKills.push_back(ch.kills);
  }
  emit(ch, p, budget);
}

/// The chunks of a run; chunk 0 splats into the result's volumes acc, best, dirAcc, the others into
/// their own (reduced at the end, reduceChunks).
std::vector<Chunk> makeChunks(int nChunks, size_t voxels, std::vector<double>& acc,
                              std::vector<double>& best, std::vector<glm::dvec3>& dirAcc) {
  std::vector<Chunk> chunks(static_cast<size_t>(nChunks));
  for (size_t c = 0; c < chunks.size(); ++c) {
    Chunk& ch = chunks[c];
    if (c > 0) {
      ch.accOwn.assign(voxels, 0.0);
      ch.bestOwn.assign(voxels, 0.0);
      ch.dirOwn.assign(voxels, glm::dvec3(0.0));
    }
    ch.acc = c > 0 ? ch.accOwn.data() : acc.data();
    ch.best = c > 0 ? ch.bestOwn.data() : best.data();
    ch.dirAcc = c > 0 ? ch.dirOwn.data() : dirAcc.data();
  }
  return chunks;
}

/// After the chunks of a step ran: the live count, with the patch budget applied as the
/// single-threaded loop would have (see the step loop in WavefrontSimulator::run). L0: the live
/// count before the step; out[ping]: the step's outputs. Returns the live count after the step.
long long settleStep(std::vector<Chunk>& chunks, const PatchStepper& stepper, long long L0,
                     long long maxPatches, int ping, WavefrontStats& st) {
  if (chunks.size() == 1) {
    if (chunks[0].anyGrowth()) st.max_live = std::max(st.max_live, size_t(chunks[0].maxAfterSplit));
    return chunks[0].live;
  }
  bool fits = true;
  long long Lc = L0;
  size_t peak = 0;
  for (const Chunk& ch : chunks) {
    if (ch.anyGrowth()) {
      const long long top = Lc + ch.maxAfterSplit;
      fits = fits && top <= maxPatches;
      peak = std::max(peak, size_t(top));
    }
    Lc += ch.grown() - (long long)ch.kills;
  }
  if (fits) {
    st.max_live = std::max(st.max_live, peak);
    return Lc;
  }
  // The budget binds in this step: emit again in list order, kills interleaved as they fell.
  long long live = L0;
  for (Chunk& ch : chunks) {
    ch.out[ping].clear();
    ch.splits = ch.halvings = ch.refused = ch.tears = ch.reflections = 0;
    ch.maxAfterSplit = LLONG_MIN;
    size_t seen = 0;
    for (size_t i = 0; i < ch.surv.size(); ++i) {
      live -= (long long)(ch.survKills[i] - seen);
      seen = ch.survKills[i];
      ch.live = live;
      stepper.emit(ch, ch.surv[i], maxPatches);
      live = ch.live;
    }
    live -= (long long)(ch.kills - seen);
    if (ch.anyGrowth()) st.max_live = std::max(st.max_live, size_t(ch.maxAfterSplit));
  }
  return live;
}

/// Reduce the chunks in chunk order (one chunk: its sums unchanged, as 0 + x = x): statistics into
/// st, the splat volumes of chunks c ≥ 1 into chunk 0's (acc, best, dirAcc), freeing theirs.
void reduceChunks(std::vector<Chunk>& chunks, WavefrontStats& st, std::vector<double>& acc,
                  std::vector<double>& best, std::vector<glm::dvec3>& dirAcc) {
  for (const Chunk& ch : chunks) {
    const WavefrontStats& a = ch.st;
    st.steps = std::max(st.steps, a.steps);
    st.straight_steps += a.straight_steps;
    st.straight_time_steps += a.straight_time_steps;
    st.splits += a.splits;
    st.halvings += a.halvings;
    st.splits_refused += a.splits_refused;
    st.tears += a.tears;
    st.reflections += a.reflections;
    st.kills_left += a.kills_left;
    st.kills_caustic += a.kills_caustic;
    st.kills_energy += a.kills_energy;
    st.kills_opaque += a.kills_opaque;
    st.flux_left += a.flux_left;
    st.flux_caustic += a.flux_caustic;
    st.flux_energy += a.flux_energy;
    st.flux_absorbed += a.flux_absorbed;
    st.flux_reflected += a.flux_reflected;
    st.interface_events += a.interface_events;
    st.flux_probe += a.flux_probe;
    st.flux_ended_before_probe += a.flux_ended_before_probe;
    st.caustic_crossings += a.caustic_crossings;
    st.caustic_centroid += a.caustic_centroid;
    st.probe_centroid += a.probe_centroid;
    st.probe_direction += a.probe_direction;
  }
  for (size_t c = 1; c < chunks.size(); ++c) {
    Chunk& ch = chunks[c];
    for (size_t v = 0; v < acc.size(); ++v) {
      acc[v] += ch.acc[v];
      best[v] = std::max(best[v], ch.best[v]);
      dirAcc[v] += ch.dirAcc[v];
    }
    std::vector<double>().swap(ch.accOwn);
    std::vector<double>().swap(ch.bestOwn);
    std::vector<glm::dvec3>().swap(ch.dirOwn);
  }
}

/// The run's result: the final statistics (centroids, the patches still live at max_steps) and
/// the volumes (Accumulate: acc; HighestEnergy: best; the mean direction from dirAcc).
WavefrontResult finishResult(WavefrontResult res, const std::vector<Patch>& done,
                             const WavefrontSettings& s, const std::vector<double>& acc,
                             const std::vector<double>& best,
                             const std::vector<glm::dvec3>& dirAcc) {
  WavefrontStats& st = res.stats;
  if (st.flux_caustic > 0) st.caustic_centroid /= st.flux_caustic;
  if (st.flux_probe != 0) {
    st.probe_centroid /= st.flux_probe;
    st.probe_direction /= st.flux_probe;
  }
  st.live_at_end = done.size();
  for (const Patch& p : done) {
    st.flux_live_at_end += p.energy;
    if (s.probe_axis >= 0 && p.probe_side < 0) st.flux_ended_before_probe += p.energy;
  }
  res.irradiance.resize(acc.size());
  res.direction.resize(acc.size());
  const bool highest = s.splat == WavefrontSettings::Splat::HighestEnergy;
  for (size_t v = 0; v < acc.size(); ++v) {
    res.irradiance[v] = float(highest ? best[v] : acc[v]);
    const glm::dvec3 d = acc[v] > 0 ? dirAcc[v] / acc[v] : glm::dvec3(0.0);
    res.direction[v] = glm::vec4(glm::vec3(d), float(acc[v]));
  }
  return res;
}

}  // namespace

glm::dvec3 WavefrontSimulator::onShell(const glm::dvec3& x, const glm::dvec3& s) const {
  return onModeShell(field_, s_.mode, il2_, il4_, x, s);
}

bool SharpInterfaces::active() const {
  if (!boundary || boundary->empty() || media.size() < boundary->shapes.size() + 1) return false;
  return std::all_of(media.begin(), media.end(),
                     [](const WavefrontMedium& m) { return m.homogeneous; });
}

SharpInterfaces sharpInterfacesFor(const VolumeSet& volume, double wavelength_nm, bool with_skip) {
  SharpInterfaces si;
  if (volume.boundary.empty() || volume.media.empty()) return si;
  si.boundary = &volume.boundary;
  for (const MediumRecord& r : volume.media.regions) {
    WavefrontMedium m;
    m.n = mediumIndex(r.n_o, wavelength_nm);
    if (r.biaxial) {  // n_α ≤ n_β ≤ n_γ kept at every wavelength (as the view march's tensorOf)
      m.biaxial = true;
      m.n_e = std::max(mediumIndex(r.n_e, wavelength_nm), m.n);
      m.n_beta = std::clamp(mediumIndex(r.n_beta, wavelength_nm), m.n, m.n_e);
      m.axis = r.axis;
      m.alpha_axis = r.alpha_axis;
      m.sigma_beta = mediumSigmaAt(r, 2, wavelength_nm);
    } else if (r.uniaxial && !r.radial_axis) {
      m.n_e = mediumIndex(r.n_e, wavelength_nm);
      m.axis = r.axis;
    }
    m.sigma = mediumSigmaAt(r, 0, wavelength_nm);
    m.sigma_e = mediumSigmaAt(r, 1, wavelength_nm);
    m.homogeneous = r.homogeneous;
    m.opaque = r.opaque();
    si.media.push_back(m);
  }
  if (with_skip) si.skip = sharpSkipDistances(volume);
  if (!si.skip.empty()) si.opacity_skip = opacitySkipDistances(volume);  // the same grid
  return si;
}

WavefrontSimulator::WavefrontSimulator(const Field& field, const Grid& splat_grid,
                                       const WavefrontSettings& settings)
    : field_(field), grid_(splat_grid), s_(checkedWavefrontSettings(settings, splat_grid)) {
  const double l_um = micrometresFromNanometres(s_.wavelength_nm);
  il2_ = 1.0 / (l_um * l_um);
  il4_ = il2_ * il2_;
}

WavefrontSimulator::WavefrontSimulator(const Field& field, const Grid& splat_grid,
                                       const WavefrontSettings& settings,
                                       const SharpInterfaces& sharp)
    : WavefrontSimulator(field, splat_grid, settings) {
  if (sharp.active()) sharp_ = &sharp;
  const bool biaxial = std::any_of(sharp.media.begin(), sharp.media.end(),
                                   [](const WavefrontMedium& m) { return m.biaxial; });
  if (biaxial && !sharp_)
    throw std::invalid_argument(
        "wavefront: a biaxial crystal needs the sharp path (the boundary field and a homogeneous "
        "medium in every region); the smoothed field has no biaxial law");
}

std::vector<Patch> WavefrontSimulator::seed(const Light& light) const {
  return seedWavefront(field_, grid_, s_, light);
}

WavefrontResult WavefrontSimulator::run(const Light& light) const {
  WavefrontResult res;
  WavefrontStats& st = res.stats;
  const glm::dvec3 lo = field_.boundsMin(), hi = field_.boundsMax();
  std::vector<double> acc(grid_.count(), 0.0), best(grid_.count(), 0.0);
  std::vector<glm::dvec3> dirAcc(grid_.count(), glm::dvec3(0.0));
  // Default: every core, at most 8 (each thread after the first keeps its own splat volumes,
  // 40 B per voxel: 56 MB at 128×85×128).
  const int nChunks =
      s_.threads > 0 ? s_.threads : int(std::clamp(std::thread::hardware_concurrency(), 1u, 8u));
  std::vector<Chunk> chunks = makeChunks(nChunks, grid_.count(), acc, best, dirAcc);

  std::vector<Patch> cur = seed(light);
  st.seeded = cur.size();
  const PatchStepper stepper(field_, grid_, s_, il2_, il4_, sharp_);
  for (Patch& p : cur) {
    if (sharp_)  // each corner in its region, on that medium's shell along its launch direction
      for (size_t k = 0; k < 4; ++k) {
        p.region[k] = stepper.regionAt(p.x[k]);
        p.w[k] = stepper.mediumShell(p.region[k], glm::normalize(p.w[k]));
      }
    st.flux_emitted += p.energy;
    const glm::dvec3 c = centre(p);
    p.entered = inside(c, lo, hi);
    if (s_.probe_axis >= 0) p.probe_side = c[s_.probe_axis] >= s_.probe_position ? 1 : -1;
  }
  long long live = (long long)cur.size();  // patches alive (moving or at max_steps)
  st.max_live = cur.size();

  // Patches that have used up max_steps stay live (and counted in `live`) but move no further.
  // Each step cuts its list into T = nChunks contiguous chunks (Chunk). With one chunk the budget
  // is checked against the running live count, as always. With T > 1 the chunks emit without a
  // budget, each tracking its live count relative to its start; single-threaded emission would
  // have refused a split iff some chunk c, starting at L_c = L0 + Σ_{c' < c} (grown − kills),
  // reaches L_c + maxAfterSplit > max_patches. Then the step's emission is redone serially from
  // the recorded survivors, in list order against the running count (settleStep). Either way the
  // counts, `next` and `done` are those of the single-threaded loop.
  std::vector<Patch> done;
  std::unique_ptr<ChunkPool> pool;
  if (nChunks > 1) pool = std::make_unique<ChunkPool>(nChunks);
  const long long maxPatches = s_.max_patches;
  // The step's list: the concatenation of the chunks' out[1 − ping] (the seeds: chunk 0's).
  int ping = 0;
  chunks[0].out[1].swap(cur);
  std::vector<const std::vector<Patch>*> in(chunks.size());
  long long step_count = 0;
  for (;;) {
    size_t n = 0;
    for (size_t c = 0; c < chunks.size(); ++c) {
      in[c] = &chunks[c].out[1 - ping];
      n += in[c]->size();
    }
    if (n == 0) break;
    const long long L0 = live;
    const std::function<void(int)> step = [&](int c) {
      Chunk& ch = chunks[size_t(c)];
      ch.next = &ch.out[ping];
      ch.next->clear();
      ch.done.clear();
      ch.surv.clear();
      ch.survKills.clear();
      ch.kills = ch.splits = ch.halvings = ch.refused = ch.tears = ch.reflections = 0;
      ch.live = nChunks == 1 ? L0 : 0;
      ch.maxAfterSplit = LLONG_MIN;
      const long long budget = nChunks == 1 ? maxPatches : LLONG_MAX;
      const size_t b = n * size_t(c) / size_t(nChunks), e = n * size_t(c + 1) / size_t(nChunks);
      size_t at = 0;  // list index of the current segment's first patch
      for (const std::vector<Patch>* seg : in) {
        const size_t i0 = std::max(b, at), i1 = std::min(e, at + seg->size());
        for (size_t i = i0; i < i1; ++i) stepper.advance(ch, (*seg)[i - at], budget, nChunks > 1);
        at += seg->size();
        if (at >= e) break;
      }
    };
    if (pool && n >= kMinPatchesPerChunk * size_t(nChunks)) {
      pool->go(step);
    } else {
      for (int c = 0; c < nChunks; ++c) step(c);
    }
    live = settleStep(chunks, stepper, L0, maxPatches, ping, st);
    for (Chunk& ch : chunks) {
      ch.st.splits += ch.splits;
      ch.st.halvings += ch.halvings;
      ch.st.splits_refused += ch.refused;
      ch.st.tears += ch.tears;
      ch.st.reflections += ch.reflections;
      done.insert(done.end(), ch.done.begin(), ch.done.end());
    }
    st.max_live = std::max(st.max_live, size_t(live));
    ping = 1 - ping;
    ++step_count;
    if (s_.progress) {
      double flux_ended = 0.0;
      for (const Chunk& ch : chunks)
        flux_ended += ch.st.flux_left + ch.st.flux_caustic + ch.st.flux_energy +
                      ch.st.flux_absorbed + ch.st.flux_reflected;
      s_.progress(
          wavefrontRunFraction(step_count, s_.dt, grid_.extent, flux_ended, st.flux_emitted));
    }
  }
  pool.reset();
  if (s_.progress) s_.progress(1.0);  // every patch has ended (or reached max_steps)
  reduceChunks(chunks, st, acc, best, dirAcc);
  return finishResult(std::move(res), done, s_, acc, best, dirAcc);
}

}  // namespace eikon
