// Mode conversion of the CPU twin's view march (docs/view-renderer.md "Light transport"): at a face
// met inside a crystal a full-transport path chooses one of the outgoing propagating waves
// (reflected o or e, transmitted ones) with probability equal to its power fraction for the
// incident mode, and goes on in that wave's mode. ReferenceMarcher::samplePath records, for one
// view sample's seed, each face the path met inside a crystal and the mode it left in; over many
// seeds the shares of the outcomes are binomial with the fractions of Maxwell's boundary
// conditions (anisotropic/tensor_interface.h solveTensorInterface, itself checked against the
// closed forms of anisotropic/interface.h and fresnel.h in tests/anisotropic):
//  - a calcite slab (optic axis oblique to the plane of incidence), light entering in the o- or the
//    e-mode at 60°: at the back face the shares of the reflected o, reflected e and transmitted
//    paths;
//  - calcite in contact with quartz (different axes): the shares of the quartz o and e paths and
//    the reflected calcite o and e paths at the contact face.
// Each share lies within 5 binomial standard deviations, √(p(1 − p)/M) for M paths (a false
// failure once in ~3·10⁶ per share). Keeping the incident mode (no conversion) puts every
// converted share at 0, which each case's largest converted fraction (0.014 to 0.5) puts ≥ 20
// standard deviations away: the cases fail with mode conversion switched off.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "anisotropic/interface.h"
#include "anisotropic/tensor_interface.h"
#include "core/reference/reference_marcher.h"
#include "core/scene/scene.h"
#include "core/volume/field.h"
#include "core/volume/volume_set.h"

namespace eikon {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kCalciteO = 1.6584, kCalciteE = 1.4864, kQuartzO = 1.5443, kQuartzE = 1.5534;
const glm::dvec3 kCalciteAxis{0.6, 0.64, 0.48};  // unit, oblique to the xz plane of incidence
const glm::dvec3 kQuartzAxis{0.0, 0.8, 0.6};

/// One voxelised scene and the CPU twin over it (sharp interfaces, ambient index 1).
struct Cpu {
  Scene scene;
  VolumeSet volume;
  VolumeField field;
  ReferenceMarcher ref;
  explicit Cpu(const std::string& objects)
      : scene(parseScene(
            R"({"environment": {"type": "constant", "radiance": 1},
                "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 64},
                "materials": {"calcite": {"n_o": 1.6584, "n_e": 1.4864,
                                          "optic_axis": [0.6, 0.64, 0.48]},
                              "quartz": {"n_o": 1.5443, "n_e": 1.5534, "optic_axis": [0, 0.8, 0.6]}},
                "objects": [)" +
                objects + "]}",
            "mode_conversion.json")),
        volume(voxelize(scene)),
        field(volume),
        ref(field, scene.environment) {}
};

/// The shares of the outcomes at the first face a path meets inside a crystal (at z = zFace):
/// [0] reflected in mode 0, [1] reflected in mode 1, [2] transmitted in mode 0, [3] in mode 1; M
/// the paths that met it.
struct Shares {
  std::array<double, 4> f{};
  int M = 0;
};

Shares sampleFace(const Cpu& c, const glm::dvec3& o, const glm::dvec3& d, int mode, double zFace,
                  int samples) {
  Shares s;
  for (int k = 0; k < samples; ++k) {
    const std::vector<PathEvent> ev = c.ref.samplePath({o, d, 587.56}, MarchSettings{}, mode,
                                                       transportSeed(7u, uint32_t(k), mode));
    if (ev.empty()) continue;  // reflected at the entry face
    EXPECT_NEAR(ev[0].point.z, zFace, 1e-6);
    s.f[size_t((ev[0].reflected ? 0 : 2) + ev[0].mode)] += 1.0;
    ++s.M;
  }
  for (double& f : s.f) f /= std::max(s.M, 1);
  return s;
}

/// Expected shares [refl mode 0, refl mode 1, trans mode 0, trans mode 1] of a `mode` wave with
/// wave normal s in uniaxial `near` (path mode 0 = o) at the face with normal N into `far`
/// (uniaxial, or isotropic: all transmitted power in slot 2 + mode).
std::array<double, 4> expectedShares(const Uniaxial& near, int mode, const glm::dvec3& s,
                                     const glm::dvec3& N, const TensorMedium& far, double farNo) {
  const TensorMedium t = TensorMedium::fromUniaxial(near);
  const bool oSlow = near.n_e < near.n_o;
  const WaveMode wm = (mode == 0) == oSlow ? WaveMode::Slow : WaveMode::Fast;
  const TensorInterfaceSolution sol = solveTensorInterface(t, wm, s, N, far);
  std::array<double, 4> p{};
  const bool farCrystal = far.symmetry() != Symmetry::Isotropic;
  for (int k = 0; k < 2; ++k) {
    const OutgoingWave& r = sol.reflected[size_t(k)];
    if (r.propagating) p[std::abs(r.n - near.n_o) < 1e-9 ? 0 : 1] += r.power;
    const OutgoingWave& w = sol.transmitted[size_t(k)];
    if (!w.propagating) continue;
    const int m = farCrystal ? (std::abs(w.n - farNo) < 1e-9 ? 0 : 1) : mode;
    p[size_t(2 + m)] += w.power;
  }
  return p;
}

void expectShares(const Shares& got, const std::array<double, 4>& p, const char* what) {
  const char* names[4] = {"reflected o", "reflected e", "transmitted o", "transmitted e"};
  for (size_t k = 0; k < 4; ++k) {
    const double sigma = std::sqrt(p[k] * (1.0 - p[k]) / got.M);
    std::printf("%s, %s: share %.5f, fraction %.5f (%.1f sigma, M %d)\n", what, names[k], got.f[k],
                p[k], sigma > 0 ? (got.f[k] - p[k]) / sigma : 0.0, got.M);
    EXPECT_NEAR(got.f[k], p[k], 5.0 * sigma + 1e-12) << what << ": " << names[k];
  }
}

// A calcite slab (faces z = ±2), light from air at 60° in the xz plane: at the back face the o-
// and the e-wave reflect into both modes (e → o 0.120, o → e 0.016 here) or leave.
TEST(ModeConversion, CalciteSlabBackFaceSharesAreThePowerFractions) {
  const Cpu c(
      R"({"shape": "box", "center": [0, 0, 0], "size": [14, 14, 4], "material": "calcite"})");
  const double th = 60.0 * kDeg;
  const glm::dvec3 d(std::sin(th), 0.0, std::cos(th)), N(0, 0, 1);
  const glm::dvec3 o = glm::dvec3(0, 0, -2) - 8.0 * d;
  const Uniaxial cal(kCalciteO, kCalciteE, kCalciteAxis);
  const ModePair in = refractIntoUniaxial(d, N, 1.0, cal);
  for (int mode = 0; mode < 2; ++mode) {
    const Shares got = sampleFace(c, o, d, mode, 2.0, 40000);
    const auto p = expectedShares(cal, mode, mode == 0 ? in.o.s : in.e.s, N,
                                  TensorMedium::isotropic(1.0), 1.0);
    expectShares(got, p, mode == 0 ? "slab, o incident" : "slab, e incident");
    EXPECT_GT(p[size_t(1 - mode)], 0.005);  // a conversion the test can see
  }
}

// Calcite (z < 0) on quartz (z > 0), light from air at 30°: at the contact the calcite wave
// reflects into both calcite modes or enters quartz as its o- or e-wave; quartz's axis differs, so
// each calcite mode splits between the quartz modes.
TEST(ModeConversion, CalciteOnQuartzTransmittedModeSharesAreThePowerFractions) {
  const Cpu c(R"({"shape": "box", "center": [0, 0, -1], "size": [14, 14, 2], "material": "calcite"},
                 {"shape": "box", "center": [0, 0, 1], "size": [14, 14, 2], "material": "quartz"})");
  const double th = 30.0 * kDeg;
  const glm::dvec3 d(std::sin(th), 0.0, std::cos(th)), N(0, 0, 1);
  const glm::dvec3 o = glm::dvec3(0, 0, -2) - 8.0 * d;
  const Uniaxial cal(kCalciteO, kCalciteE, kCalciteAxis);
  const ModePair in = refractIntoUniaxial(d, N, 1.0, cal);
  const TensorMedium quartz = TensorMedium::uniaxial(kQuartzO, kQuartzE, kQuartzAxis);
  for (int mode = 0; mode < 2; ++mode) {
    const Shares got = sampleFace(c, o, d, mode, 0.0, 40000);
    const auto p = expectedShares(cal, mode, mode == 0 ? in.o.s : in.e.s, N, quartz, kQuartzO);
    expectShares(got, p, mode == 0 ? "calcite o into quartz" : "calcite e into quartz");
    EXPECT_GT(std::min(p[2], p[3]), 0.05);  // both quartz modes well fed
  }
}

}  // namespace
}  // namespace eikon
