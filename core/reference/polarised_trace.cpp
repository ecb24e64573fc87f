#include "core/reference/polarised_trace.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "anisotropic/tensor_interface.h"
#include "anisotropic/tensor_medium.h"
#include "core/reference/field.h"
#include "core/volume/boundary.h"
#include "core/volume/media.h"

namespace eikon {
namespace {

using maxwell::CV;
/// "To infinity": how far a ray leaving the volume is followed for polariser sheets (mm).
constexpr double kFarMm = 1e9;

bool boxHit(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& bmin,
            const glm::dvec3& bmax, double& t0, double& t1) {
  t0 = -1e300;
  t1 = 1e300;
  for (int a = 0; a < 3; ++a) {
    const double inv = 1.0 / (d[a] == 0.0 ? 1e-30 : d[a]);
    const double ta = (bmin[a] - o[a]) * inv, tb = (bmax[a] - o[a]) * inv;
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  return t1 >= std::max(t0, 0.0);
}

/// A ray whose ray direction or wave normal makes |cos| below this with a face's normal runs along
/// the face (a ray exactly in the plane of a wedge's side face): it does not cross it. The
/// interface solve divides by the normal flux (the transmitted power fraction √(flux_out/flux_in)),
/// which is zero there: such rays returned NaN Stokes vectors. The grazing limit of the exact
/// equations transmits nothing and reflects along the ray itself, so the branch simply goes on, in
/// its own medium. shaders/polarised_trace.comp uses the same constant.
constexpr double kGrazeCos = 1e-6;

bool grazes(const glm::dvec3& p, const glm::dvec3& ray, const glm::dvec3& normal) {
  return std::abs(glm::dot(glm::normalize(p), normal)) < kGrazeCos ||
         std::abs(glm::dot(glm::normalize(ray), normal)) < kGrazeCos;
}

/// One path of the o/e ray tree: where it is, its wave vector and ray, and the power-normalised
/// fields G[b] it carries for the input basis states b = x̂_in, ŷ_in (unit power each).
struct Branch {
  glm::dvec3 x{0.0}, p{0.0}, ray{0.0};
  int region = 0;
  Mode mode = Mode::Ordinary;  ///< in a biaxial region: Ordinary the fast mode, Extraordinary slow
  std::array<CV, 2> G{};
  double opl = 0.0;  ///< ∫p·dx from the origin (mm)
  std::string modes;
  int events = 0;
  int choices = 0;  ///< reflect-or-transmit choices made (Transport::Full): the uniform's index k
  /// The side of the path's split first choice it descends from: 0 none (not met, or drawn), 1
  /// the transmitted, 2 the reflected (FirstChoice). Only branches of one side add coherently.
  int side = 0;
};

double power(const Branch& b) {
  return maxwell::norm(b.G[0]) * maxwell::norm(b.G[0]) +
         maxwell::norm(b.G[1]) * maxwell::norm(b.G[1]);
}

class Tracer {
 public:
  Tracer(const Field& f, const std::vector<PolarizerSheet>& sheets, double lambda_nm,
         const PolarisedTraceSettings& s, std::uint32_t seed)
      : sheets_(sheets),
        lambda_(lambda_nm),
        s_(s),
        seed_(seed),
        bf_(f.boundary()),
        media_(f.media()),
        bmin_(f.boundsMin()),
        bmax_(f.boundsMax()) {}
  /// Follow `start` (inside the volume) to the exits of all its branches.
  void run(const Branch& start, std::vector<Branch>& exits, bool& truncated) const;
  /// Polariser sheets met on [x, x + dir·len] (nearest first), applied to b's fields.
  void applySheets(Branch& b, const glm::dvec3& x, const glm::dvec3& dir, double len) const;

 private:
  const MediumRecord& rec(int region) const { return media_->regions[size_t(region)]; }
  OpticalMedium mediumOf(int region, const glm::dvec3& x) const;
  TensorMedium tensorOf(int region, const glm::dvec3& x) const;
  InterfaceMap tensorMap(const Branch& b, const BoundaryCrossing& c) const;
  bool sameMedium(int a, int b) const;
  BoundaryCrossing nextCrossing(const glm::dvec3& a, const glm::dvec3& b, int region) const;
  void segment(Branch& b, double len) const;
  void cross(const Branch& b, const BoundaryCrossing& c, std::vector<Branch>& stack) const;

  const std::vector<PolarizerSheet>& sheets_;
  double lambda_;
  const PolarisedTraceSettings& s_;
  std::uint32_t seed_;
  const BoundaryField* bf_;
  const MediaTable* media_;
  glm::dvec3 bmin_, bmax_;
};

OpticalMedium Tracer::mediumOf(int region, const glm::dvec3& x) const {
  const MediumRecord& m = rec(region);
  if (!m.homogeneous)
    throw std::runtime_error("polarised trace: region " + std::to_string(region) +
                             " is a gradient-index or radial-axis medium, which the polarised "
                             "trace does not support yet");
  const double n_o = mediumIndexAt(m, 0, lambda_, x);
  if (!m.uniaxial) return OpticalMedium::isotropic(n_o);
  return OpticalMedium::uniaxial(
      Uniaxial(n_o, mediumIndexAt(m, 1, lambda_, x), glm::dvec3(mediumAxisField(m, x))));
}

// A region's dielectric tensor at the trace's wavelength (biaxial: n_α, n_β, n_γ with n_β clamped
// into [n_α, n_γ] as the scalar march's tensorOf; uniaxial and isotropic: their special cases).
TensorMedium Tracer::tensorOf(int region, const glm::dvec3& x) const {
  const MediumRecord& m = rec(region);
  const double a = mediumIndexAt(m, 0, lambda_, x);
  if (!m.biaxial) {
    if (!m.uniaxial) return TensorMedium::isotropic(a);
    return TensorMedium::uniaxial(a, mediumIndexAt(m, 1, lambda_, x),
                                  glm::dvec3(mediumAxisField(m, x)));
  }
  const double g = std::max(mediumIndexAt(m, 1, lambda_, x), a);
  const double b = std::clamp(mediumIndex(m.n_beta, lambda_), a, g);
  return TensorMedium(a, b, g, m.alpha_axis, m.axis);
}

bool Tracer::sameMedium(int a, int b) const {
  const MediumRecord &A = rec(a), &B = rec(b);
  return A.medium == B.medium && A.axis == B.axis && A.alpha_axis == B.alpha_axis &&
         !A.radial_axis && !B.radial_axis;
}

/// Which outgoing slot (0 the fast or ordinary mode, 1 the slow or extraordinary one) a
/// propagating wave of `t` with index n and wave normal s takes: the mode whose index it has.
/// A uniaxial medium names its modes o and e (the o-wave has n_o), a biaxial one fast and slow.
size_t modeSlot(const TensorMedium& t, const Uniaxial* uni, double n, const glm::dvec3& s) {
  if (uni)
    return std::abs(n - uni->n_o) <= std::abs(n - uni->index(Mode::Extraordinary, s)) ? 0 : 1;
  const std::array<double, 2> idx = t.indices(s);
  return std::abs(n - idx[0]) <= std::abs(n - idx[1]) ? 0 : 1;
}

// The exact interface map where either side is biaxial (anisotropic/tensor_interface.h: the
// Booker quartic of each side and Maxwell's boundary conditions, valid for any pair of media),
// in the form of interfaceMap's: the incident basis fields (an isotropic side's s and p waves,
// or the branch's crystal mode), and for each outgoing slot the power-normalised field per basis
// state, amplitude·√(flux_out/flux_in) times the wave's unit E. An isotropic side's two waves
// share one beam (slot 0 or 2); a crystal side's propagating waves take slot 0 (o or fast) and
// 1 (e or slow) by their index.
InterfaceMap Tracer::tensorMap(const Branch& b, const BoundaryCrossing& c) const {
  const TensorMedium from = tensorOf(b.region, c.point), to = tensorOf(c.to, c.point);
  const MediumRecord &A = rec(b.region), &B = rec(c.to);
  const bool isoA = from.symmetry() == Symmetry::Isotropic;
  const std::optional<Uniaxial> uA =
      A.uniaxial ? std::optional<Uniaxial>(from.asUniaxial()) : std::nullopt;
  const std::optional<Uniaxial> uB =
      B.uniaxial ? std::optional<Uniaxial>(to.asUniaxial()) : std::nullopt;
  const glm::dvec3 s = glm::normalize(b.p);
  std::vector<maxwell::Wave> basis;
  if (isoA) {  // the s and p waves of the branch's wave vector, unit E
    const glm::dvec3 m = glm::dot(c.normal, s) < 0.0 ? -c.normal : c.normal;
    const glm::dvec3 pt = b.p - glm::dot(b.p, m) * m;
    for (const maxwell::Wave& w : maxwell::isotropicWaves(pt, m, from.n_alpha, true))
      basis.push_back(maxwell::makeWave(w.p, (1.0 / maxwell::norm(w.E)) * w.E));
  } else {
    // The branch's crystal mode: a uniaxial o-wave is the fast mode of a positive crystal.
    WaveMode wm = b.mode == Mode::Ordinary ? WaveMode::Fast : WaveMode::Slow;
    if (uA && uA->n_e < uA->n_o) wm = b.mode == Mode::Ordinary ? WaveMode::Slow : WaveMode::Fast;
    basis.push_back(modeWave(from, wm, s));
  }
  InterfaceMap map;
  map.basis_count = int(basis.size());
  for (size_t k = 0; k < basis.size(); ++k) {
    const TensorInterfaceSolution sol = solveTensorInterface(from, basis[k], c.normal, to);
    map.basis[k] = maxwell::real(basis[k].E);
    const double f_in = std::abs(maxwell::flux(sol.incident, sol.normal));
    for (size_t w = 0; w < 4; ++w) {
      const bool refl = w < 2;
      const OutgoingWave& o = refl ? sol.reflected[w] : sol.transmitted[w - 2];
      if (!o.propagating) continue;
      const TensorMedium& md = refl ? from : to;
      const bool iso = md.symmetry() == Symmetry::Isotropic;
      const std::optional<Uniaxial>& u = refl ? uA : uB;
      const size_t slot = (refl ? 0 : 2) + (iso ? 0 : modeSlot(md, u ? &*u : nullptr, o.n, o.s));
      OutgoingBeam& beam = map.beams[slot];
      beam.exists = true;
      beam.p = maxwell::real(o.wave.p);
      beam.ray = iso ? o.s : o.t;
      beam.mode = slot % 2 ? Mode::Extraordinary : Mode::Ordinary;
      const double scale = std::sqrt(std::abs(maxwell::flux(o.wave, sol.normal)) / f_in);
      map.out[slot][k] = map.out[slot][k] + (o.amplitude * scale) * o.wave.E;
    }
  }
  return map;
}

// The sharp marches' search (core/volume/boundary.h crossingOutOf: the planes, the shapes or the
// walk with its sliver rule, as polarised_trace.comp's nextCrossing).
BoundaryCrossing Tracer::nextCrossing(const glm::dvec3& a, const glm::dvec3& b, int region) const {
  return crossingOutOf(*bf_, a, b, region);
}

// An ideal dichroic sheet absorbs the field along its absorbing direction b = normal × axis
// (projected ⊥ the wave normal) and transmits the rest.
void Tracer::applySheets(Branch& b, const glm::dvec3& x, const glm::dvec3& dir, double len) const {
  std::vector<std::pair<double, const PolarizerSheet*>> hits;
  for (const PolarizerSheet& sh : sheets_) {
    const double dn = glm::dot(dir, sh.normal);
    if (std::abs(dn) < 1e-15) continue;
    const double t = glm::dot(sh.center - x, sh.normal) / dn;
    if (!(t > 0.0 && t <= len)) continue;
    const glm::dvec3 r = x + t * dir - sh.center;
    if (std::abs(glm::dot(r, sh.axis)) <= 0.5 * sh.width &&
        std::abs(glm::dot(r, glm::cross(sh.normal, sh.axis))) <= 0.5 * sh.height)
      hits.push_back({t, &sh});
  }
  std::sort(hits.begin(), hits.end(),
            [](const auto& u, const auto& v) { return u.first < v.first; });
  const glm::dvec3 k = glm::normalize(b.p);
  for (const auto& [t, sh] : hits) {
    glm::dvec3 a = glm::cross(sh->normal, sh->axis);
    a -= glm::dot(a, k) * k;
    if (glm::length(a) < 1e-12) continue;  // grazing: the absorbing direction is along k
    a = glm::normalize(a);
    for (CV& g : b.G) g = g - maxwell::dot(g, a) * maxwell::cv(a);
  }
}

// A straight piece of length len along b.ray in b's region: sheets, the phase k₀∫p·dx (carried as
// the optical path) and the pleochroic amplitude exp(−½σL), σ per unit ray length.
void Tracer::segment(Branch& b, double len) const {
  applySheets(b, b.x, b.ray, len);
  b.opl += glm::dot(b.p, b.ray) * len;
  const MediumRecord& m = rec(b.region);
  double sigma = mediumSigmaAt(m, 0, lambda_);
  if (m.biaxial) {  // trichroic, per unit ray length (the scalar march's absorbAlong)
    TensorMedium t = tensorOf(b.region, b.x);
    t.sigma = {sigma, mediumSigmaAt(m, 2, lambda_), mediumSigmaAt(m, 1, lambda_)};
    const glm::dvec3 s = glm::normalize(b.p);
    const TensorMode md = t.modes(s)[b.mode == Mode::Ordinary ? WaveMode::Fast : WaveMode::Slow];
    sigma = t.attenuation(md.D, md.n) * glm::dot(s, md.t);
  } else if (m.uniaxial && b.mode == Mode::Extraordinary) {
    const glm::dvec3 a = glm::dvec3(mediumAxisField(m, b.x));
    sigma =
        field::attenuationE(glm::dvec3(sigma), glm::dvec3(mediumSigmaAt(m, 1, lambda_)), b.p, a,
                            mediumIndexAt(m, 0, lambda_, b.x), mediumIndexAt(m, 1, lambda_, b.x))
            .x;
  }
  if (sigma > 0.0) {
    const Complex f(std::exp(-0.5 * sigma * len));
    for (CV& g : b.G) g = f * g;
  }
  b.x += b.ray * len;
}

// The exact interface map; the branch goes on as the transmitted beam(s) (the o and e modes
// into a crystal), or the reflected one(s) (both modes in a crystal: mode conversion) on total
// internal reflection, where asked, or, with Transport::Full, where its random choice takes them:
// the reflection with probability p = the reflected share of the branch's power, summed over both
// input basis states (its unpolarised reflected power fraction), the chosen fields scaled by 1/√p
// or 1/√(1 − p) so that every |G|² and every product of fields is unbiased. The uniform is the
// branch's choices-th of the trace's seed: o and e branches of one path draw the same numbers and
// so make the same choice wherever their p are alike, which keeps their coherent sums together.
// The path's first choice (choices = 0), where split_first_choice, is no draw: the branch goes on
// as both, the reflected and the transmitted beams with their exact fields (FirstChoice), and
// uniform 0 is left unused, as the scalar march leaves it.
void Tracer::cross(const Branch& b, const BoundaryCrossing& c, std::vector<Branch>& stack) const {
  const MediumRecord &A = rec(b.region), &B = rec(c.to);
  if (B.opaque()) return;                      // absorbed: nothing of this branch leaves
  const bool tensor = A.biaxial || B.biaxial;  // the tensor solve; else interfaceMap
  const OpticalMedium from = mediumOf(b.region, c.point), to = mediumOf(c.to, c.point);
  if (tensor ? sameMedium(b.region, c.to)
             : A.medium == B.medium && (!from.crystal || from.crystal->axis == to.crystal->axis)) {
    Branch same = b;
    same.region = c.to;
    stack.push_back(same);
    return;
  }
  if (grazes(b.p, b.ray, c.normal)) {  // along the face: not a crossing (see kGrazeCos)
    Branch along = b;
    along.events = b.events + 1;  // bounds a ray that runs along a face from graze to graze
    stack.push_back(along);
    return;
  }
  const InterfaceMap map =
      tensor ? tensorMap(b, c) : interfaceMap(from, b.mode, glm::normalize(b.p), c.normal, to);
  const std::array<CV, 4> out0 = map.apply(b.G[0]), out1 = map.apply(b.G[1]);
  auto slotPower = [&](size_t slot) {
    if (!map.beams[slot].exists) return 0.0;
    const double a = maxwell::norm(out0[slot]), e = maxwell::norm(out1[slot]);
    return a * a + e * e;
  };
  const bool asked =
      std::find(s_.reflect_at.begin(), s_.reflect_at.end(), b.events) != s_.reflect_at.end();
  bool reflect = asked || !(map.beams[2].exists || map.beams[3].exists), split = false;
  double scale = 1.0;
  int choices = b.choices;
  if (!reflect && s_.transport == Transport::Full && b.choices < s_.max_reflections) {
    const double pr = slotPower(0) + slotPower(1), pt = slotPower(2) + slotPower(3);
    if (pr + pt > 0.0) {
      const double p = pr / (pr + pt);
      split = b.choices == 0 && s_.split_first_choice;
      reflect = !split && transportUniform(seed_, std::uint32_t(b.choices)) < p;
      if (!split) scale = 1.0 / std::sqrt(reflect ? p : 1.0 - p);
      ++choices;
    }
  }
  // Split: the reflected slots (0, 1), then the transmitted (2, 3); else the chosen pair.
  for (size_t slot = reflect || split ? 0 : 2; slot < (reflect ? 2u : 4u); ++slot) {
    const OutgoingBeam& beam = map.beams[slot];
    if (!beam.exists) continue;
    const bool reflected = slot < 2;
    Branch nb = b;
    nb.G = {Complex(scale) * out0[slot], Complex(scale) * out1[slot]};
    if (power(nb) < 1e-14) continue;
    nb.p = beam.p;
    nb.ray = beam.ray;
    nb.mode = beam.mode;
    nb.region = reflected ? b.region : c.to;
    nb.x = c.point;
    nb.events = b.events + 1;
    nb.choices = choices;
    if (split) nb.side = reflected ? 2 : 1;
    const MediumRecord& side = reflected ? A : B;
    if (side.uniaxial || side.biaxial) nb.modes += beam.mode == Mode::Ordinary ? 'o' : 'e';
    stack.push_back(nb);
  }
}

void Tracer::run(const Branch& start, std::vector<Branch>& exits, bool& truncated) const {
  std::vector<Branch> stack{start};
  while (!stack.empty()) {
    Branch b = stack.back();
    stack.pop_back();
    if (b.events > s_.max_events || int(exits.size() + stack.size()) + 1 > s_.max_branches) {
      truncated = true;
      continue;
    }
    if (rec(b.region).opaque()) continue;
    mediumOf(b.region, b.x);  // refuses unsupported regions
    double t0, t1;
    boxHit(b.x, b.ray, bmin_, bmax_, t0, t1);
    double len = std::max(t1, 0.0);
    const BoundaryCrossing c = nextCrossing(b.x, b.x + b.ray * len, b.region);
    if (c.found) len *= c.t;
    segment(b, len);
    if (!c.found) {  // out of the volume: straight on, through any sheets beyond it
      Branch out = b;
      applySheets(out, b.x, b.ray, kFarMm);
      exits.push_back(out);
      continue;
    }
    b.x = c.point;
    cross(b, c, stack);
  }
}

/// Branches leaving in one direction, recombined: coherent groups (Jones matrices added with their
/// phases on a common wavefront) added as Stokes vectors.
PolarisedBeam recombine(const std::vector<const Branch*>& group, const Stokes& input,
                        double lambda_nm, const PolarisedTraceSettings& s) {
  const Branch& first = *group.front();
  PolarisedBeam beam;
  beam.direction = glm::normalize(first.ray);
  beam.exit_point = first.x;
  beam.frame_x = stokesBasis(beam.direction);
  const glm::dvec3 x = beam.frame_x, y = glm::cross(beam.direction, x);
  const double k0 = 2.0 * std::numbers::pi / (lambda_nm * 1e-6);
  const double width = lambda_nm * 1e-6 / s.source_angle_rad,
               length = lambda_nm * lambda_nm * 1e-6 / s.bandwidth_nm;
  // The phase difference of two branches' plane waves at ONE point, the reference branch's exit
  // point x_r: (S_b + p_b·(x_r − x_b)) − S_r, as the GPU twin does. (Extrapolating each to the
  // world origin, S − p·x, made the o−e phase of a wedge, whose o and e leave in slightly
  // different directions, depend on where the origin lies: a quartz wedge between crossed sheets
  // showed one colour along its whole length.)
  auto pathDifference = [](const Branch& b, const Branch& ref) {
    return b.opl - ref.opl + glm::dot(b.p, ref.x - b.x);
  };
  std::vector<bool> used(group.size(), false);
  for (size_t r = 0; r < group.size(); ++r) {
    if (used[r]) continue;
    const Branch& ref = *group[r];
    JonesMatrix J;
    J.m = {};
    for (size_t j = r; j < group.size(); ++j) {
      const Branch& b = *group[j];
      const glm::dvec3 sep = b.x - ref.x;
      const double lateral = glm::length(sep - glm::dot(sep, beam.direction) * beam.direction);
      const double opd = pathDifference(b, ref);  // the o−e (or path) difference
      // The two sides of a split first choice are two estimates, added as such (incoherently).
      if (used[j] || b.side != ref.side || lateral > width || std::abs(opd) > length) continue;
      used[j] = true;
      const Complex ph = std::exp(Complex(0.0, k0 * opd));
      for (size_t c = 0; c < 2; ++c) {
        J.m[0][c] += ph * maxwell::dot(b.G[c], x);
        J.m[1][c] += ph * maxwell::dot(b.G[c], y);
      }
      beam.modes += (beam.modes.empty() ? "" : ",") + (b.modes.empty() ? "-" : b.modes);
      beam.branches++;
    }
    const Mueller M = muellerOf(J);
    beam.stokes += s.mueller_row ? Stokes(M.m[0][0], M.m[0][1], M.m[0][2], M.m[0][3]) : M * input;
    beam.coherent_groups++;
  }
  return beam;
}

}  // namespace

PolarisedTrace tracePolarised(const Field& field, const std::vector<PolarizerSheet>& sheets,
                              const TraceRequest& ray, const Stokes& input,
                              const PolarisedTraceSettings& settings, std::uint32_t seed) {
  checkPolarisedTrace(ray, input, settings);
  if (!field.boundary() || !field.media())
    throw std::runtime_error(
        "polarised trace: the field has no sharp boundaries (it needs "
        "\"interfaces\": \"sharp\")");
  const glm::dvec3 d = glm::normalize(ray.direction);
  const Tracer tracer(field, sheets, ray.wavelength_nm, settings, seed);
  PolarisedTrace out;
  out.frame_x_in = stokesBasis(d);
  Branch b;
  b.x = ray.origin;
  b.ray = d;
  b.p = field.ambientIndex() * d;
  b.G = {maxwell::cv(out.frame_x_in), maxwell::cv(glm::cross(d, out.frame_x_in))};
  std::vector<Branch> exits;
  double t0, t1;
  if (!boxHit(ray.origin, d, field.boundsMin(), field.boundsMax(), t0, t1)) {
    tracer.applySheets(b, b.x, d, kFarMm);
    exits.push_back(b);
  } else {
    t0 = std::max(t0, 0.0);
    tracer.applySheets(b, b.x, d, t0);
    b.x += d * t0;
    b.opl = field.ambientIndex() * t0;
    b.region = regionAt(*field.boundary(), b.x);  // exact path: on the shapes
    if (b.region != 0)
      throw std::runtime_error("polarised trace: the ray enters the volume inside an object");
    tracer.run(b, exits, out.truncated);
  }
  std::vector<bool> used(exits.size(), false);
  for (size_t i = 0; i < exits.size(); ++i) {  // one beam per direction
    if (used[i]) continue;
    std::vector<const Branch*> group;
    for (size_t j = i; j < exits.size(); ++j) {
      const double angle = std::acos(std::clamp(glm::dot(exits[i].ray, exits[j].ray), -1.0, 1.0));
      if (!used[j] && angle <= settings.source_angle_rad) {
        used[j] = true;
        group.push_back(&exits[j]);
      }
    }
    out.beams.push_back(recombine(group, input, ray.wavelength_nm, settings));
  }
  std::sort(out.beams.begin(), out.beams.end(), [](const PolarisedBeam& u, const PolarisedBeam& v) {
    return u.stokes[0] > v.stokes[0];
  });
  return out;
}

}  // namespace eikon
