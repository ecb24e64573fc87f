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
#include <stdexcept>
#include <thread>

#include "core/light/seeding.h"

namespace eikon {
namespace {

// Attenuation band at λ from the (612, 549, 465) nm band values (same rule as the marcher).
double sigmaAt(const glm::dvec3& rgb, double l) {
  if (l <= 465.0) return rgb.b;
  if (l >= 612.0) return rgb.r;
  if (l <= 549.0) return rgb.b + (rgb.g - rgb.b) * (l - 465.0) / (549.0 - 465.0);
  return rgb.g + (rgb.r - rgb.g) * (l - 549.0) / (612.0 - 549.0);
}

// Patch geometry shared with the seeding (core/light/seeding.h).
using light::applyM;
using light::centre;
using light::hasAxis;
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
  double* acc = nullptr;         ///< Σ flux·Δs / h³ (W/mm²), per voxel
  double* best = nullptr;        ///< highest patch irradiance (W/mm²), per voxel
  glm::dvec3* dirAcc = nullptr;  ///< Σ (flux·Δs / h³)·direction, per voxel
  std::vector<double> accOwn, bestOwn;  ///< storage of acc and best for chunks c ≥ 1
  std::vector<glm::dvec3> dirOwn;       ///< storage of dirAcc for chunks c ≥ 1
  WavefrontStats st;                    ///< this chunk's counts and flux sums over the run
  std::vector<Patch> out[2];  ///< out[step parity]: the step's children and survivors
  std::vector<Patch>* next = nullptr;  ///< the running step's out[]
  std::vector<Patch> done, work;  ///< the step's patches at max_steps; emit()'s stack
  /// Threads > 1: the step's surviving patches before emission, and the chunk's kill count when
  /// each survived, to redo the emission serially if the patch budget binds.
  std::vector<Patch> surv;
  std::vector<size_t> survKills;
  /// Live count while the step runs: absolute when emitting against the budget (one chunk, or the
  /// serial redo), else relative to the chunk's start (−1 per kill, +3 per split).
  long long live = 0;
  long long maxAfterSplit = LLONG_MIN;  ///< highest `live` right after a split in this step
  size_t kills = 0, splits = 0, refused = 0;  ///< this step's
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

}  // namespace

glm::dvec3 WavefrontSimulator::onShell(const glm::dvec3& x, const glm::dvec3& s) const {
  return onModeShell(field_, s_.mode, il2_, il4_, x, s);
}

WavefrontSimulator::WavefrontSimulator(const Field& field, const Grid& splat_grid, const WavefrontSettings& settings)
    : field_(field), grid_(splat_grid), s_(checkedWavefrontSettings(settings, splat_grid)) {
  const double l_um = s_.wavelength_nm * 1e-3;
  il2_ = 1.0 / (l_um * l_um);
  il4_ = il2_ * il2_;
}

std::vector<Patch> WavefrontSimulator::seed(const Light& light) const {
  return seedWavefront(field_, grid_, s_, light);
}

WavefrontResult WavefrontSimulator::run(const Light& light) const {
  WavefrontResult res;
  WavefrontStats& st = res.stats;
  const glm::dvec3 lo = field_.boundsMin(), hi = field_.boundsMax();
  const double h = grid_.h, h3 = h * h * h, dt = s_.dt;
  const double maxEdge = s_.split_span_voxels * h;
  std::vector<double> acc(grid_.count(), 0.0), best(grid_.count(), 0.0);
  std::vector<glm::dvec3> dirAcc(grid_.count(), glm::dvec3(0.0));
  // Default: every core, at most 8 (each thread after the first keeps its own splat volumes,
  // 40 B per voxel: 56 MB at 128×85×128).
  const int nChunks = s_.threads > 0 ? s_.threads : int(std::clamp(std::thread::hardware_concurrency(), 1u, 8u));
  std::vector<Chunk> chunks(static_cast<size_t>(nChunks));
  for (size_t c = 0; c < chunks.size(); ++c) {
    Chunk& ch = chunks[c];
    if (c > 0) {
      ch.accOwn.assign(grid_.count(), 0.0);
      ch.bestOwn.assign(grid_.count(), 0.0);
      ch.dirOwn.assign(grid_.count(), glm::dvec3(0.0));
    }
    ch.acc = c > 0 ? ch.accOwn.data() : acc.data();
    ch.best = c > 0 ? ch.bestOwn.data() : best.data();
    ch.dirAcc = c > 0 ? ch.dirOwn.data() : dirAcc.data();
  }

  std::vector<Patch> cur = seed(light);
  st.seeded = cur.size();
  for (Patch& p : cur) {
    st.flux_emitted += p.energy;
    const glm::dvec3 c = centre(p);
    p.entered = inside(c, lo, hi);
    if (s_.probe_axis >= 0) p.probe_side = c[s_.probe_axis] >= s_.probe_position ? 1 : -1;
  }
  long long live = (long long)cur.size();  // patches alive (moving or at max_steps)
  st.max_live = cur.size();

  const bool eMode = s_.mode == 1;
  auto deriv = [&](const glm::dvec3& x, const glm::dvec3& w, glm::dvec3& dx, glm::dvec3& dw) {
    double n;
    glm::dvec3 g;
    field_.index(x, il2_, il4_, n, g);
    if (eMode) {
      // e-mode Hamiltonian H = ½(pᵀM_e p − 1) in constant time (wavefront.h): the same terms as
      // deriv() in reference_marcher.cpp / march.glsl, not divided by |M_e p|.
      const glm::dvec4 af = field_.axisField(x);
      const glm::dvec3 a(af);
      if (hasAxis(a)) {
        double ne;
        glm::dvec3 ge;
        field_.indexE(x, il2_, il4_, ne, ge);
        const double pa = glm::dot(w, a), p2 = glm::dot(w, w);
        dx = applyM(w, a, n, ne);
        dw = (pa * pa / (n * n * n)) * g + ((p2 - pa * pa) / (ne * ne * ne)) * ge;
        if (af.w > 0.0) dw -= pa * (1.0 / (n * n) - 1.0 / (ne * ne)) * (w - pa * a) * af.w;
        return;
      }
    }
    dx = w / (n * n);
    dw = g / n;
  };
  // e-mode attenuation per unit ray length at x for wave vector w: the pleochroic
  // σ(θ) = n(θ)³[σ_o cos²θ/n_o³ + σ_e sin²θ/n_e³] times cos ρ = ŝ·t̂ (attenuationAt in march.glsl
  // and reference_marcher.cpp), at the simulator's wavelength.
  auto sigmaE = [&](const glm::dvec3& x, const glm::dvec3& w) {
    const double so = sigmaAt(glm::dvec3(field_.medium(x)), s_.wavelength_nm);
    const glm::dvec3 a = field_.axis(x);
    if (!hasAxis(a) || !(glm::dot(w, w) > 0)) return so;
    const double se = sigmaAt(glm::dvec3(field_.mediumE(x)), s_.wavelength_nm);
    double no, ne;
    glm::dvec3 g;
    field_.index(x, il2_, il4_, no, g);
    field_.indexE(x, il2_, il4_, ne, g);
    const glm::dvec3 sn = glm::normalize(w);
    const double c = glm::dot(sn, a), c2 = c * c, s2 = 1.0 - c2;
    const double n = 1.0 / std::sqrt(c2 / (no * no) + s2 / (ne * ne));
    const glm::dvec3 t = glm::normalize(applyM(w, a, no, ne));
    return n * n * n * (so * c2 / (no * no * no) + se * s2 / (ne * ne * ne)) * glm::dot(sn, t);
  };
  auto rk4 = [&](glm::dvec3& x, glm::dvec3& w) {
    glm::dvec3 k1x, k1w, k2x, k2w, k3x, k3w, k4x, k4w;
    deriv(x, w, k1x, k1w);
    deriv(x + 0.5 * dt * k1x, w + 0.5 * dt * k1w, k2x, k2w);
    deriv(x + 0.5 * dt * k2x, w + 0.5 * dt * k2w, k3x, k3w);
    deriv(x + dt * k3x, w + dt * k3w, k4x, k4w);
    x += dt / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
    w += dt / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
  };
  auto splat = [&](Chunk& ch, const glm::dvec3& m, double fluxDs, double irr, const glm::dvec3& dir) {
    int idx[3];
    for (int a = 0; a < 3; ++a) {
      double f = std::floor((m[a] - grid_.origin[a]) / h);
      if (!(f >= 0 && f < grid_.dims[size_t(a)])) return;
      idx[a] = int(f);
    }
    const size_t v = grid_.index(idx[0], idx[1], idx[2]);
    ch.acc[v] += fluxDs / h3;
    ch.dirAcc[v] += (fluxDs / h3) * dir;
    ch.best[v] = std::max(ch.best[v], irr);
  };
  // Straight-step splat: the centre's straight path c0 + s·u, s ∈ [0, L] (u unit), deposits into
  // every voxel it crosses flux(s)·len/h³, with len the length of the piece inside the voxel and
  // flux(s) = E0·exp(−σs) at the piece's midpoint (the sum over pieces is the single steps' sum of
  // flux_mid·Δs up to where within a voxel it falls). HighestEnergy sees flux(s)/area(s), the
  // patch area at that point: area(τ) = |½ (A + τB) × (C + τD)| with τ = s/ds1 time steps
  // (A, C the diagonals at the start, B, D their change per step). A voxel walk (Amanatides & Woo
  // 1987) over the part of the segment inside the grid; the same walk as splatSegment in
  // wavefront.comp.
  auto splatSegment = [&](Chunk& ch, const glm::dvec3& c0, const glm::dvec3& u, double L, double E0, double sigma,
                          const glm::dvec3& dir, double ds1, const glm::dvec3 diag[4]) {
    double sA = 0.0, sB = L;
    for (int a = 0; a < 3; ++a) {
      const double g0 = grid_.origin[a], g1 = grid_.origin[a] + grid_.dims[size_t(a)] * h;
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
      const double ga = (c0[a] + sA * u[a] - grid_.origin[a]) / h;
      i[a] = std::clamp(int(std::floor(ga)), 0, grid_.dims[size_t(a)] - 1);
      if (u[a] > 0) {
        stepI[a] = 1, tDelta[a] = h / u[a];
        tNext[a] = (grid_.origin[a] + (i[a] + 1) * h - c0[a]) / u[a];
      } else if (u[a] < 0) {
        stepI[a] = -1, tDelta[a] = -h / u[a];
        tNext[a] = (grid_.origin[a] + i[a] * h - c0[a]) / u[a];
      } else {
        stepI[a] = 0, tDelta[a] = 0, tNext[a] = 1e300;
      }
    }
    double sCur = sA;
    const int guard = grid_.dims[0] + grid_.dims[1] + grid_.dims[2] + 3;
    for (int it = 0; it < guard; ++it) {
      const int a = tNext[0] <= tNext[1] ? (tNext[0] <= tNext[2] ? 0 : 2) : (tNext[1] <= tNext[2] ? 1 : 2);
      const double sEnd = std::min(tNext[a], sB);
      if (sEnd > sCur) {
        const double sm = 0.5 * (sCur + sEnd), flux = E0 * std::exp(-sigma * sm), val = flux * (sEnd - sCur) / h3;
        const double tau = ds1 > 0 ? sm / ds1 : 0.0;
        const double area = 0.5 * glm::length(glm::cross(diag[0] + tau * diag[1], diag[2] + tau * diag[3]));
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
  };
  // How many time steps p may take at once along straight lines (0: none, take an RK4 step), and
  // the corners' constant velocities dx/dt. Conditions (docs/light-simulator.md, "Straight
  // steps"): the centre and all corners lie in voxels of skip distance D ≥ 2, the centre's voxel is
  // not opaque, no radial axis field (e-mode), and a centre outside the bounds is headed for them.
  // k then keeps every point within (D − 1.5)·h of where it starts (so it, and the trilinear
  // stencils along its path, stay inside its homogeneous region: the straight line is the exact
  // solution there), stays within max_steps − steps and, when σ > 0, ends at the first step whose
  // flux is below the energy threshold; finally it is cut at the first step j at which single
  // steps would act: an edge longer than maxEdge (split), an orientation flip (caustic), the
  // centre leaving (after having been inside, or its ray missing the bounds).
  auto straightSteps = [&](const Patch& p, glm::dvec3 v[4]) -> int {
    if (!s_.skip_empty) return 0;
    const glm::dvec3 c0 = centre(p);
    double Dmin = field_.skipDistance(c0);
    if (Dmin < 2.0) return 0;
    double D[4];
    for (int k = 0; k < 4; ++k) {
      D[k] = field_.skipDistance(p.x[size_t(k)]);
      if (D[k] < 2.0) return 0;
    }
    if (field_.medium(c0).w >= 0.5) return 0;
    const glm::dvec3 wm = meanW(p);
    const double wl = glm::length(wm);
    if (!(wl > 0)) return 0;
    const bool in0 = inside(c0, lo, hi);
    if (!in0 && (p.entered || !rayHitsBox(c0, wm / wl, lo, hi))) return 0;
    glm::dvec3 vc(0.0);
    for (int k = 0; k < 4; ++k) {
      if (eMode && field_.axisField(p.x[size_t(k)]).w > 0.0) return 0;  // radial axis: a varies
      glm::dvec3 dw;
      deriv(p.x[size_t(k)], p.w[size_t(k)], v[k], dw);
      vc += 0.25 * v[k];
    }
    double kmax = double(s_.max_steps - p.steps);
    auto capBy = [&](double Dv, const glm::dvec3& vel) {
      const double sp = glm::length(vel) * dt;
      if (sp > 0) kmax = std::min(kmax, std::floor((Dv - 1.5) * h / sp));
    };
    capBy(Dmin, vc);
    for (int k = 0; k < 4; ++k) capBy(D[k], v[k]);
    // Energy: a patch already below the threshold (a child of a split) is killed after its next
    // step; otherwise the first step at which exp(−σ·j·ds1) takes it below.
    const double ds1 = glm::length(vc) * dt, thr = s_.min_energy_fraction * p.seed_energy;
    if (p.energy < thr) {
      kmax = std::min(kmax, 1.0);
    } else if (ds1 > 0) {
      const glm::dvec3 m = c0 + 0.5 * dt * vc;
      const double sigma = eMode ? sigmaE(m, wm) : sigmaAt(glm::dvec3(field_.medium(m)), s_.wavelength_nm);
      if (sigma > 0 && thr > 0) kmax = std::min(kmax, std::floor(std::log(p.energy / thr) / (sigma * ds1)) + 1.0);
    }
    if (kmax < 1.0) return 0;
    const int K = int(kmax);
    bool entered = p.entered || in0;
    for (int j = 1; j <= K; ++j) {
      glm::dvec3 x[4];
      for (int k = 0; k < 4; ++k) x[k] = p.x[size_t(k)] + (double(j) * dt) * v[k];
      double e = 0;
      for (int k = 0; k < 4; ++k) e = std::max(e, glm::length(x[(k + 1) % 4] - x[k]));
      const double o = glm::dot(0.5 * glm::cross(x[2] - x[0], x[3] - x[1]), wm);
      const glm::dvec3 c = 0.25 * (x[0] + x[1] + x[2] + x[3]);
      bool stop = e > maxEdge || (o > 0 && p.orientation < 0) || (o < 0 && p.orientation > 0);
      if (inside(c, lo, hi))
        entered = true;
      else if (entered || !rayHitsBox(c, wm / wl, lo, hi))
        stop = true;
      if (stop) return j;
    }
    return K;
  };
  // Split p (repeatedly) until no edge exceeds maxEdge or the patch budget is spent: a split is
  // refused when it would take ch.live above `budget` (LLONG_MAX: never; see the step loop).
  auto emit = [&](Chunk& ch, const Patch& p0, long long budget) {
    std::vector<Patch>& work = ch.work;
    work.clear();
    work.push_back(p0);
    while (!work.empty()) {
      Patch p = work.back();
      work.pop_back();
      double e = 0;
      for (int k = 0; k < 4; ++k) e = std::max(e, glm::length(p.x[size_t((k + 1) % 4)] - p.x[size_t(k)]));
      if (e <= maxEdge) {
        ch.next->push_back(p);
        continue;
      }
      if (ch.live + 3 > budget) {
        ++ch.refused;
        ch.next->push_back(p);
        continue;
      }
      ch.live += 3;
      ++ch.splits;
      ch.maxAfterSplit = std::max(ch.maxAfterSplit, ch.live);
      // 3×3 lattice of bilinear points; the parent's own corners are kept exactly.
      glm::dvec3 X[3][3], W[3][3];
      for (int b = 0; b < 3; ++b)
        for (int a = 0; a < 3; ++a) {
          const double fa = 0.5 * a, fb = 0.5 * b;
          X[b][a] = (1 - fa) * (1 - fb) * p.x[0] + fa * (1 - fb) * p.x[1] + fa * fb * p.x[2] + (1 - fa) * fb * p.x[3];
          glm::dvec3 w = (1 - fa) * (1 - fb) * p.w[0] + fa * (1 - fb) * p.w[1] + fa * fb * p.w[2] + (1 - fa) * fb * p.w[3];
          if ((a == 1 || b == 1)) {
            if (eMode) {
              w = onShell(X[b][a], glm::normalize(w));  // back onto the mode's shell pᵀMp = 1
            } else {
              double n;
              glm::dvec3 g;
              field_.index(X[b][a], il2_, il4_, n, g);
              w = glm::normalize(w) * n;
            }
          }
          W[b][a] = w;
        }
      X[0][0] = p.x[0], X[0][2] = p.x[1], X[2][2] = p.x[2], X[2][0] = p.x[3];
      W[0][0] = p.w[0], W[0][2] = p.w[1], W[2][2] = p.w[2], W[2][0] = p.w[3];
      for (int cb = 0; cb < 2; ++cb)
        for (int ca = 0; ca < 2; ++ca) {
          Patch c = p;
          const int pa[4] = {ca, ca + 1, ca + 1, ca}, pb[4] = {cb, cb, cb + 1, cb + 1};
          for (int k = 0; k < 4; ++k) {
            c.x[size_t(k)] = X[pb[k]][pa[k]];
            c.w[size_t(k)] = W[pb[k]][pa[k]];
          }
          c.energy = 0.25 * p.energy;  // equal parameter area: a quarter of the parent's ray tubes
          c.area0 = 0.25 * p.area0;
          work.push_back(c);
        }
    }
  };

  // A patch ends: it leaves the live set; note its flux if it never got past the probe plane.
  auto ended = [&](Chunk& ch, const Patch& p) {
    ++ch.kills;
    --ch.live;
    if (s_.probe_axis >= 0 && p.probe_side < 0) ch.st.flux_ended_before_probe += p.energy;
  };

  // One patch's step (the single-threaded loop body): advance, splat, count, end it or emit it
  // (split against `budget`) into *ch.next. keep: also record it in ch.surv before emission.
  auto advance = [&](Chunk& ch, Patch p, long long budget, bool keep) {
    if (p.steps >= s_.max_steps) {
      ch.done.push_back(p);
      return;
    }
    const glm::dvec3 c0 = centre(p), wm0 = eMode ? meanW(p) : glm::dvec3(0.0);
    glm::dvec3 vel[4], diag[4];
    const int kStraight = straightSteps(p, vel);
    if (kStraight > 0) {
      // Straight step: k time steps along straight lines; w is unchanged (∇n = 0). diag: the
      // diagonals at the start and their change per time step (the area along the path).
      diag[0] = p.x[2] - p.x[0], diag[1] = dt * (vel[2] - vel[0]);
      diag[2] = p.x[3] - p.x[1], diag[3] = dt * (vel[3] - vel[1]);
      const double T = double(kStraight) * dt;
      for (int k = 0; k < 4; ++k) p.x[size_t(k)] += T * vel[k];
      p.steps += kStraight;
      ++ch.st.straight_steps;
      ch.st.straight_time_steps += size_t(kStraight);
    } else {
      for (int k = 0; k < 4; ++k) rk4(p.x[size_t(k)], p.w[size_t(k)]);
      ++p.steps;
    }
    ch.st.steps = std::max(ch.st.steps, p.steps);
    const glm::dvec3 c1 = centre(p), m = 0.5 * (c0 + c1);
    const double ds = glm::length(c1 - c0);
    const glm::dvec4 med = field_.medium(m);
    const double sigma = eMode ? sigmaE(m, 0.5 * (wm0 + meanW(p))) : sigmaAt(glm::dvec3(med), s_.wavelength_nm);
    const double E0 = p.energy;
    const double att = std::exp(-sigma * ds), fluxMid = p.energy * std::exp(-0.5 * sigma * ds);
    ch.st.flux_absorbed += p.energy * (1.0 - att);
    p.energy *= att;
    p.transmittance *= att;
    const glm::dvec3 va = vectorArea(p);
    const double area = glm::length(va);
    const glm::dvec3 wm = meanW(p);
    const double wl = glm::length(wm);
    // Propagation direction: ŵ for the o-mode; for the e-mode the energy direction, which is
    // that of the centre's motion over the step (M_e p, not p, in a crystal).
    const glm::dvec3 dir = eMode ? (ds > 0 ? (c1 - c0) / ds : glm::dvec3(0.0)) : (wl > 0 ? wm / wl : glm::dvec3(0.0));
    if (kStraight > 0) {
      if (ds > 0) splatSegment(ch, c0, (c1 - c0) / ds, ds, E0, sigma, dir, ds / kStraight, diag);
    } else {
      splat(ch, m, fluxMid * ds, area > 0 ? fluxMid / area : 0.0, dir);
    }
    if (s_.probe_axis >= 0) {
      const int side = c1[s_.probe_axis] >= s_.probe_position ? 1 : -1;
      if (side != p.probe_side) {
        const int ax = s_.probe_axis;
        const double span = c1[ax] - c0[ax];
        const double f = span != 0 ? std::clamp((s_.probe_position - c0[ax]) / span, 0.0, 1.0) : 0.5;
        // The flux where the centre crosses: mid-step for an RK4 step, at the crossing point
        // for a straight step (exact along its attenuated path).
        const double fx = kStraight > 0 ? E0 * std::exp(-sigma * f * ds) : fluxMid;
        ch.st.flux_probe += side * fx;
        ch.st.probe_centroid += side * fx * (c0 + f * (c1 - c0));
        if (ds > 0) ch.st.probe_direction += side * fx * (c1 - c0) / ds;
      }
      p.probe_side = side;
    }
    // Kills, each accounted by reason.
    if (med.w >= 0.5) {
      ++ch.st.kills_opaque;
      ch.st.flux_absorbed += p.energy;
      ended(ch, p);
      return;
    }
    if (inside(c1, lo, hi)) {
      p.entered = true;
    } else if (p.entered || !(wl > 0) || !rayHitsBox(c1, wm / wl, lo, hi)) {
      ++ch.st.kills_left;
      ch.st.flux_left += p.energy;
      ended(ch, p);
      return;
    }
    const double o = glm::dot(va, wm);
    if (s_.pass_caustics && ((o > 0 && p.orientation < 0) || (o < 0 && p.orientation > 0))) {
      p.orientation = -p.orientation;  // through the focal line; the next flip is the next caustic
      ++ch.st.caustic_crossings;
    } else if ((o > 0 && p.orientation < 0) || (o < 0 && p.orientation > 0)) {
      ++ch.st.kills_caustic;
      ch.st.flux_caustic += p.energy;
      ch.st.caustic_centroid += p.energy * c1;
      ended(ch, p);
      return;
    }
    if (p.energy < s_.min_energy_fraction * p.seed_energy) {
      ++ch.st.kills_energy;
      ch.st.flux_energy += p.energy;
      ended(ch, p);
      return;
    }
    if (keep) {
      ch.surv.push_back(p);
      ch.survKills.push_back(ch.kills);
    }
    emit(ch, p, budget);
  };

  // Patches that have used up max_steps stay live (and counted in `live`) but move no further.
  // Each step cuts its list into T = nChunks contiguous chunks (Chunk). With one chunk the budget is
  // checked against the running live count, as always. With T > 1 the chunks emit without a
  // budget, each tracking its live count relative to its start; single-threaded emission would
  // have refused a split iff some chunk c, starting at L_c = L0 + Σ_{c' < c} (3·splits − kills),
  // reaches L_c + maxAfterSplit > max_patches. Then the step's emission is redone serially from
  // the recorded survivors, in list order against the running count. Either way the counts,
  // `next` and `done` are those of the single-threaded loop.
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
      ch.kills = ch.splits = ch.refused = 0;
      ch.live = nChunks == 1 ? L0 : 0;
      ch.maxAfterSplit = LLONG_MIN;
      const long long budget = nChunks == 1 ? maxPatches : LLONG_MAX;
      const size_t b = n * size_t(c) / size_t(nChunks), e = n * size_t(c + 1) / size_t(nChunks);
      size_t at = 0;  // list index of the current segment's first patch
      for (const std::vector<Patch>* seg : in) {
        const size_t i0 = std::max(b, at), i1 = std::min(e, at + seg->size());
        for (size_t i = i0; i < i1; ++i) advance(ch, (*seg)[i - at], budget, nChunks > 1);
        at += seg->size();
        if (at >= e) break;
      }
    };
    if (pool && n >= kMinPatchesPerChunk * size_t(nChunks)) {
      pool->go(step);
    } else {
      for (int c = 0; c < nChunks; ++c) step(c);
    }
    if (nChunks == 1) {
      live = chunks[0].live;
      if (chunks[0].splits > 0) st.max_live = std::max(st.max_live, size_t(chunks[0].maxAfterSplit));
    } else {
      bool fits = true;
      long long Lc = L0;
      size_t peak = 0;
      for (const Chunk& ch : chunks) {
        if (ch.splits > 0) {
          const long long top = Lc + ch.maxAfterSplit;
          fits = fits && top <= maxPatches;
          peak = std::max(peak, size_t(top));
        }
        Lc += 3 * (long long)ch.splits - (long long)ch.kills;
      }
      if (fits) {
        live = Lc;
        st.max_live = std::max(st.max_live, peak);
      } else {
        // The budget binds in this step: emit again in list order, kills interleaved as they fell.
        live = L0;
        for (Chunk& ch : chunks) {
          ch.out[ping].clear();
          ch.splits = ch.refused = 0;
          ch.maxAfterSplit = LLONG_MIN;
          size_t seen = 0;
          for (size_t i = 0; i < ch.surv.size(); ++i) {
            live -= (long long)(ch.survKills[i] - seen);
            seen = ch.survKills[i];
            ch.live = live;
            emit(ch, ch.surv[i], maxPatches);
            live = ch.live;
          }
          live -= (long long)(ch.kills - seen);
          if (ch.splits > 0) st.max_live = std::max(st.max_live, size_t(ch.maxAfterSplit));
        }
      }
    }
    for (Chunk& ch : chunks) {
      ch.st.splits += ch.splits;
      ch.st.splits_refused += ch.refused;
      done.insert(done.end(), ch.done.begin(), ch.done.end());
    }
    st.max_live = std::max(st.max_live, size_t(live));
    ping = 1 - ping;
    ++step_count;
    if (s_.progress) {
      double flux_ended = 0.0;
      for (const Chunk& ch : chunks)
        flux_ended +=
            ch.st.flux_left + ch.st.flux_caustic + ch.st.flux_energy + ch.st.flux_absorbed;
      s_.progress(wavefrontRunFraction(step_count, dt, grid_.extent, flux_ended, st.flux_emitted));
    }
  }
  pool.reset();
  if (s_.progress) s_.progress(1.0);  // every patch has ended (or reached max_steps)
  // Reduce the chunks in chunk order (one chunk: its sums unchanged, as 0 + x = x).
  for (const Chunk& ch : chunks) {
    const WavefrontStats& a = ch.st;
    st.steps = std::max(st.steps, a.steps);
    st.straight_steps += a.straight_steps;
    st.straight_time_steps += a.straight_time_steps;
    st.splits += a.splits;
    st.splits_refused += a.splits_refused;
    st.kills_left += a.kills_left;
    st.kills_caustic += a.kills_caustic;
    st.kills_energy += a.kills_energy;
    st.kills_opaque += a.kills_opaque;
    st.flux_left += a.flux_left;
    st.flux_caustic += a.flux_caustic;
    st.flux_energy += a.flux_energy;
    st.flux_absorbed += a.flux_absorbed;
    st.flux_probe += a.flux_probe;
    st.flux_ended_before_probe += a.flux_ended_before_probe;
    st.caustic_crossings += a.caustic_crossings;
    st.caustic_centroid += a.caustic_centroid;
    st.probe_centroid += a.probe_centroid;
    st.probe_direction += a.probe_direction;
  }
  for (size_t c = 1; c < chunks.size(); ++c) {
    Chunk& ch = chunks[c];
    for (size_t v = 0; v < grid_.count(); ++v) {
      acc[v] += ch.acc[v];
      best[v] = std::max(best[v], ch.best[v]);
      dirAcc[v] += ch.dirAcc[v];
    }
    std::vector<double>().swap(ch.accOwn);
    std::vector<double>().swap(ch.bestOwn);
    std::vector<glm::dvec3>().swap(ch.dirOwn);
  }
  cur.swap(done);
  if (st.flux_caustic > 0) st.caustic_centroid /= st.flux_caustic;
  if (st.flux_probe != 0) {
    st.probe_centroid /= st.flux_probe;
    st.probe_direction /= st.flux_probe;
  }
  st.live_at_end = cur.size();
  for (const Patch& p : cur) {
    st.flux_live_at_end += p.energy;
    if (s_.probe_axis >= 0 && p.probe_side < 0) st.flux_ended_before_probe += p.energy;
  }

  res.irradiance.resize(grid_.count());
  res.direction.resize(grid_.count());
  const bool highest = s_.splat == WavefrontSettings::Splat::HighestEnergy;
  for (size_t v = 0; v < grid_.count(); ++v) {
    res.irradiance[v] = float(highest ? best[v] : acc[v]);
    const glm::dvec3 d = acc[v] > 0 ? dirAcc[v] / acc[v] : glm::dvec3(0.0);
    res.direction[v] = glm::vec4(glm::vec3(d), float(acc[v]));
  }
  return res;
}

}  // namespace eikon
