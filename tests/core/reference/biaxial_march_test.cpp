// The CPU twin's sharp march through biaxial crystals (docs/biaxial-optics.md "In the renderer")
// against closed forms, on 64³ volumes with plane-parallel plates (faces located exactly):
//  - reduction: a biaxial material given with n_α = n_β (or n_β = n_γ) traces as the uniaxial
//    material with those indices — exit point, direction, optical path and transmittance within
//    1e-12 (mode 0 = fast: the o-wave of a positive crystal, the e-wave of a negative one);
//  - principal planes: a plate ⊥ γ̂ traced in the αγ and βγ planes: one mode has the constant
//    index of the axis ⊥ the plane (Snell), the other the index ellipse of the plane (B&W §15.3),
//    its ray along M p; the exit line's lateral displacement and the plane-wave phase within 1e-12
//    mm;
//  - the optic axes: the plane-wave phases of fast and slow through a plate ⊥ the acute bisectrix
//    meet exactly at the melatope, incidence E with sin E = n_β sin V; along an optic axis both
//    modes are finite, the fast ray goes straight and the slow one walks off by the internal
//    conical refraction angle tan χ = n_β²√((1/n_α² − 1/n_β²)(1/n_β² − 1/n_γ²));
//  - trichroism: along a principal axis a mode with D along axis i transmits e^{−σ_i t} per band.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "anisotropic/tensor_medium.h"
#include "core/reference/reference_marcher.h"
#include "core/scene/scene.h"
#include "core/volume/field.h"
#include "core/volume/volume_set.h"

namespace eikon {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kLambda = 587.5618;

std::string num(double v) {
  char b[64];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}
std::string vec(const glm::dvec3& v) {
  return "[" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + "]";
}

/// One voxelised 64³ scene (sharp interfaces) and the CPU twin over it.
struct Cpu {
  Scene scene;
  VolumeSet volume;
  VolumeField field;
  ReferenceMarcher ref;
  Cpu(const std::string& materials, const std::string& objects)
      : scene(parseScene(R"({"environment": {"type": "constant", "radiance": 1},
                             "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8],
                             "resolution": 64}, "materials": )" +
                             materials + R"(, "objects": [)" + objects + "]}",
                         "biaxial.json")),
        volume(voxelize(scene)),
        field(volume),
        ref(field, scene.environment) {}
  TraceOutcome trace(const glm::dvec3& o, const glm::dvec3& d, int mode, double nm = kLambda,
                     bool fresnel = true) const {
    MarchSettings m;
    m.fresnel = fresnel;
    return ref.trace({o, d, nm}, m, mode);
  }
};

std::string biaxialMaterial(double a, double b, double g, const glm::dvec3& alpha,
                            const glm::dvec3& gamma, const std::string& extra = "") {
  return R"({"x": {"n_alpha": )" + num(a) + R"(, "n_beta": )" + num(b) + R"(, "n_gamma": )" +
         num(g) + R"(, "alpha_axis": )" + vec(alpha) + R"(, "gamma_axis": )" + vec(gamma) + extra +
         "}}";
}
/// A plate |z| ≤ 1.5 (t = 3 mm), 12 mm wide.
const char* kPlate = R"({"shape": "box", "size": [12, 12, 3], "material": "x"})";
constexpr double kT = 3.0;

// ------------------------------------------------------------------ reduction to uniaxial
void expectSameTrace(const TraceOutcome& b, const TraceOutcome& u) {
  EXPECT_LT(glm::length(b.exit_point - u.exit_point), 1e-12);
  EXPECT_LT(glm::length(b.exit_direction - u.exit_direction), 1e-12);
  EXPECT_NEAR(b.optical_path_mm, u.optical_path_mm, 1e-12);
  EXPECT_NEAR(b.transmittance, u.transmittance, 1e-12);
  EXPECT_EQ(b.interfaces, u.interfaces);
  EXPECT_EQ(b.total_internal_reflections, u.total_internal_reflections);
}

// n_α = n_β: a positive uniaxial crystal, optic axis γ̂, fast = o; n_β = n_γ: a negative one,
// optic axis α̂, fast = e. Tilted axis, oblique rays, dichroic attenuation (first order in both).
TEST(BiaxialMarch, ReducesToTheUniaxialMaterialWithTheSameIndices) {
  const glm::dvec3 axis = glm::normalize(glm::dvec3(0.3, 0.5, 0.8));
  const glm::dvec3 perp = glm::normalize(glm::cross(axis, glm::dvec3(1, 0, 0)));
  struct Case {
    double a, b, g, no, ne;
    glm::dvec3 alpha, gamma;
    int fastIs;  // the uniaxial mode (0 o, 1 e) that is the biaxial fast mode
  };
  const Case cases[] = {{1.544, 1.544, 1.553, 1.544, 1.553, perp, axis, 0},
                        {1.486, 1.658, 1.658, 1.658, 1.486, axis, perp, 1}};
  for (const Case& c : cases) {
    // σ along α̂, β̂, γ̂: the uniaxial σ_o ⊥ the axis, σ_e along it.
    const bool pos = c.fastIs == 0;
    const std::string sig = pos ? R"(, "attenuation_alpha_per_mm": [0.05, 0.1, 0.2],
        "attenuation_beta_per_mm": [0.05, 0.1, 0.2], "attenuation_gamma_per_mm": [0.3, 0.02, 0.07])"
                                : R"(, "attenuation_alpha_per_mm": [0.3, 0.02, 0.07],
        "attenuation_beta_per_mm": [0.05, 0.1, 0.2], "attenuation_gamma_per_mm": [0.05, 0.1, 0.2])";
    const Cpu bi(biaxialMaterial(c.a, c.b, c.g, c.alpha, c.gamma, sig), kPlate);
    const Cpu uni(R"({"x": {"n_o": )" + num(c.no) + R"(, "n_e": )" + num(c.ne) +
                      R"(, "optic_axis": )" + vec(axis) +
                      R"(, "attenuation_o_per_mm": [0.05, 0.1, 0.2],
                      "attenuation_e_per_mm": [0.3, 0.02, 0.07]}})",
                  kPlate);
    for (double deg : {0.0, 20.0, 45.0, 70.0})
      for (double nm : {465.0, 549.0, 612.0})
        for (int mode = 0; mode < 2; ++mode) {
          SCOPED_TRACE("n_beta " + num(c.b) + ", " + num(deg) + " deg, " + num(nm) + " nm, mode " +
                       std::to_string(mode));
          const glm::dvec3 d(std::sin(deg * kDeg) * 0.6, std::sin(deg * kDeg) * 0.8,
                             std::cos(deg * kDeg));
          const glm::dvec3 o = glm::dvec3(0.4, -0.3, 0.0) - 20.0 * d;
          const int umode = mode == 0 ? c.fastIs : 1 - c.fastIs;
          expectSameTrace(bi.trace(o, d, mode, nm), uni.trace(o, d, umode, nm));
        }
  }
}

// ------------------------------------------------------------------ principal planes
// A plate ⊥ γ̂ (z); the ray in the plane of z and the principal axis u (x = α̂ or y = β̂), at
// incidence i from air. Mode "perp": D along the axis ⊥ the plane, index n_perp (Snell). Mode "in":
// D in the plane, p_u²/n_γ² + p_z²/n_u² = 1 (the index ellipse), ray ∥ (p_u/n_γ², p_z/n_u²).
struct PlaneWave {
  double n, pz, tanRay;
};
PlaneWave perpMode(double sinI, double nPerp) {
  const double pz = std::sqrt(nPerp * nPerp - sinI * sinI);
  return {nPerp, pz, sinI / pz};
}
PlaneWave inPlaneMode(double sinI, double nU, double nG) {
  const double pz = nU * std::sqrt(1.0 - sinI * sinI / (nG * nG));
  return {std::sqrt(sinI * sinI + pz * pz), pz, (sinI / (nG * nG)) / (pz / (nU * nU))};
}

/// The exit line's lateral displacement from the incident line through the entry point P and the
/// plane-wave phase ψ = OPL − d·(X − O) = (p_z − d_z)t of a ray entering at P along d.
struct PlateNumbers {
  double displacement, phase;
};
PlateNumbers measured(const TraceOutcome& o, const glm::dvec3& O, const glm::dvec3& P,
                      const glm::dvec3& d) {
  const glm::dvec3 r = o.exit_point - P;
  return {glm::length(r - glm::dot(r, d) * d), o.optical_path_mm - glm::dot(d, o.exit_point - O)};
}
PlateNumbers closedForm(const PlaneWave& w, const glm::dvec3& u, const glm::dvec3& d) {
  const glm::dvec3 q = kT * (w.tanRay * u + glm::dvec3(0, 0, 1));  // entry → exit inside
  return {glm::length(q - glm::dot(q, d) * d), (w.pz - d.z) * kT};
}

TEST(BiaxialMarch, PrincipalPlanesHaveSnellAndTheIndexEllipse) {
  const double na = 1.53, nb = 1.60, ng = 1.685;  // strongly biaxial, 2V_z ≈ 79°
  const Cpu cpu(biaxialMaterial(na, nb, ng, {1, 0, 0}, {0, 0, 1}), kPlate);
  for (int plane = 0; plane < 2; ++plane) {
    const glm::dvec3 u = plane == 0 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const double nPerp = plane == 0 ? nb : na, nU = plane == 0 ? na : nb;
    for (double deg : {0.0, 10.0, 30.0, 50.0, 75.0}) {
      const double sinI = std::sin(deg * kDeg);
      const PlaneWave a = perpMode(sinI, nPerp), b = inPlaneMode(sinI, nU, ng);
      const PlaneWave& fast = a.n <= b.n ? a : b;
      const PlaneWave& slow = a.n <= b.n ? b : a;
      const glm::dvec3 d = sinI * u + std::cos(deg * kDeg) * glm::dvec3(0, 0, 1);
      const glm::dvec3 P = -1.5 * glm::dvec3(0, 0, 1) + 0.3 * u, O = P - 20.0 * d;
      for (int mode = 0; mode < 2; ++mode) {
        SCOPED_TRACE(std::string(plane == 0 ? "alpha-gamma" : "beta-gamma") + " plane, " +
                     num(deg) + " deg, mode " + std::to_string(mode));
        const TraceOutcome o = cpu.trace(O, d, mode);
        const PlateNumbers m = measured(o, O, P, d), c = closedForm(mode ? slow : fast, u, d);
        EXPECT_NEAR(m.displacement, c.displacement, 1e-12);
        EXPECT_NEAR(m.phase, c.phase, 1e-12);
        EXPECT_LT(glm::length(o.exit_direction - d), 1e-12);  // parallel faces
      }
    }
  }
}

// ------------------------------------------------------------------ the optic axes
TEST(BiaxialMarch, FastAndSlowMeetAtTheMelatopes) {
  const double na = 1.53, nb = 1.56, ng = 1.685;  // positive: γ̂ is the acute bisectrix
  const TensorMedium tm(na, nb, ng, {1, 0, 0}, {0, 0, 1});
  const double a_a = 1 / (na * na), a_b = 1 / (nb * nb), a_g = 1 / (ng * ng);
  const double V = std::atan(std::sqrt((a_a - a_b) / (a_b - a_g)));  // tan²V from the indices
  ASSERT_LT(V, 45.0 * kDeg);
  const double E = std::asin(nb * std::sin(V));  // outside, by Snell with n_β
  const Cpu cpu(biaxialMaterial(na, nb, ng, {1, 0, 0}, {0, 0, 1}), kPlate);
  auto phaseSplit = [&](double inc) {
    const glm::dvec3 d(std::sin(inc), 0.0, std::cos(inc)), P(0.2, 0.0, -1.5), O = P - 20.0 * d;
    const TraceOutcome f = cpu.trace(O, d, 0), s = cpu.trace(O, d, 1);
    EXPECT_TRUE(std::isfinite(f.optical_path_mm) && std::isfinite(s.optical_path_mm));
    return measured(s, O, P, d).phase - measured(f, O, P, d).phase;
  };
  // The closed form of the split on either side: (p_z,slow − p_z,fast)·t, zero only at E.
  for (double inc : {E - 5 * kDeg, E - 0.5 * kDeg, E + 0.5 * kDeg, E + 5 * kDeg}) {
    const double sinI = std::sin(inc);
    const PlaneWave a = perpMode(sinI, nb), b = inPlaneMode(sinI, na, ng);
    EXPECT_NEAR(phaseSplit(inc), std::abs(a.pz - b.pz) * kT, 1e-12) << inc / kDeg;
    EXPECT_GT(phaseSplit(inc), 1e-5);
  }
  EXPECT_NEAR(phaseSplit(E), 0.0, 1e-12);
  // Inside, exactly along an optic axis (the crystal fills the volume): both finite; the fast ray
  // (D ∥ β̂) goes straight, the slow one (D in the αγ plane) along the far generator of the cone
  // of internal conical refraction.
  const Cpu filled(biaxialMaterial(na, nb, ng, {1, 0, 0}, {0, 0, 1}),
                   R"({"shape": "box", "size": [40, 40, 40], "material": "x"})");
  const double chi = std::atan(nb * nb * std::sqrt((a_a - a_b) * (a_b - a_g)));
  for (const glm::dvec3& c : tm.opticAxes()) {
    const TraceOutcome f = filled.trace(-5.0 * c, c, 0), s = filled.trace(-5.0 * c, c, 1);
    for (const TraceOutcome* o : {&f, &s}) {
      EXPECT_TRUE(std::isfinite(o->optical_path_mm) && std::isfinite(o->exit_point.x) &&
                  std::isfinite(o->exit_direction.x) && o->left_volume);
      EXPECT_NEAR(glm::length(o->wave_normal - c), 0.0, 1e-12);
    }
    EXPECT_NEAR(std::acos(std::min(1.0, glm::dot(f.exit_direction, c))), 0.0, 1e-7);
    EXPECT_NEAR(
        std::atan2(glm::length(glm::cross(s.exit_direction, c)), glm::dot(s.exit_direction, c)),
        chi, 1e-12);
  }
}

// ------------------------------------------------------------------ trichroism
// Normal incidence through a plate ⊥ z, Fresnel off: along γ̂ the fast mode has D ∥ α̂ and the
// slow D ∥ β̂; with α̂ along z (the object's own axes), fast D ∥ β̂, slow D ∥ γ̂. Each band's
// transmittance is e^{−σ_i t} at its band wavelength.
TEST(BiaxialMarch, TrichroicPlateTransmitsEachAxisAttenuation) {
  const glm::dvec3 sa(0.30, 0.05, 0.10), sb(0.02, 0.25, 0.15), sg(0.12, 0.08, 0.40);
  const std::string sig = R"(, "attenuation_alpha_per_mm": )" + vec(sa) +
                          R"(, "attenuation_beta_per_mm": )" + vec(sb) +
                          R"(, "attenuation_gamma_per_mm": )" + vec(sg);
  const std::string mat = biaxialMaterial(1.53, 1.60, 1.685, {1, 0, 0}, {0, 0, 1}, sig);
  const Cpu alongGamma(mat, kPlate);
  const Cpu alongAlpha(mat, R"({"shape": "box", "size": [12, 12, 3], "material": "x",
                               "alpha_axis": [0, 0, 1], "gamma_axis": [1, 0, 0]})");
  const double nm[3] = {612.0, 549.0, 465.0};
  for (int band = 0; band < 3; ++band) {
    const glm::dvec3 O(0.3, 0.2, -20.0), d(0, 0, 1);
    EXPECT_NEAR(alongGamma.trace(O, d, 0, nm[band], false).transmittance, std::exp(-sa[band] * kT),
                1e-12);
    EXPECT_NEAR(alongGamma.trace(O, d, 1, nm[band], false).transmittance, std::exp(-sb[band] * kT),
                1e-12);
    EXPECT_NEAR(alongAlpha.trace(O, d, 0, nm[band], false).transmittance, std::exp(-sb[band] * kT),
                1e-12);
    EXPECT_NEAR(alongAlpha.trace(O, d, 1, nm[band], false).transmittance, std::exp(-sg[band] * kT),
                1e-12);
  }
}

/// CIELAB (D65 white = linear sRGB (1, 1, 1)) of a linear-sRGB colour (IEC 61966-2-1 matrix).
glm::dvec3 lab(const glm::dvec3& rgb) {
  auto xyz = [](const glm::dvec3& c) {
    return glm::dvec3(0.4124 * c.r + 0.3576 * c.g + 0.1805 * c.b,
                      0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b,
                      0.0193 * c.r + 0.1192 * c.g + 0.9505 * c.b);
  };
  const glm::dvec3 v = xyz(rgb) / xyz(glm::dvec3(1.0));
  auto f = [](double t) {
    return t > 216.0 / 24389.0 ? std::cbrt(t) : (24389.0 / 27.0 * t + 16.0) / 116.0;
  };
  return {116.0 * f(v.y) - 16.0, 500.0 * (f(v.x) - f(v.y)), 200.0 * (f(v.y) - f(v.z))};
}

// The plate's colours seen along γ̂ against a white environment (RGB render, the centre pixel of
// a 1° view, Transport::Single): each mode shows R + (1 − R)² e^{−σ t} per band (R of its index at
// normal incidence, the front face's reflection of the environment added), so the fast (D ∥ α̂)
// and slow (D ∥ β̂) images differ by the CIELAB ΔE those closed forms give.
TEST(BiaxialMarch, TrichroicColoursDifferByTheClosedFormDeltaE) {
  const glm::dvec3 sa(0.30, 0.05, 0.10), sb(0.02, 0.25, 0.15), sg(0.12, 0.08, 0.40);
  const double na = 1.53, nb = 1.60;
  const Cpu cpu(biaxialMaterial(na, nb, 1.685, {1, 0, 0}, {0, 0, 1},
                                R"(, "attenuation_alpha_per_mm": )" + vec(sa) +
                                    R"(, "attenuation_beta_per_mm": )" + vec(sb) +
                                    R"(, "attenuation_gamma_per_mm": )" + vec(sg)),
                kPlate);
  Camera cam;
  cam.position = {0, 0, -30};
  cam.look_at = {0, 0, 0};
  cam.fov_deg = 1.0;
  RenderSettings rs;
  rs.width = rs.height = 5;
  rs.march.transport = Transport::Single;
  auto pixel = [&](Modes m) {
    rs.modes = m;
    const RenderImage img = cpu.ref.render(cam, rs, 1);
    const size_t k = 3 * (2 * 5 + 2);
    return glm::dvec3(img.rgb[k], img.rgb[k + 1], img.rgb[k + 2]);
  };
  auto closed = [](double n, const glm::dvec3& sigma) {
    const double R = (n - 1) * (n - 1) / ((n + 1) * (n + 1));
    return R + (1 - R) * (1 - R) * glm::exp(-sigma * kT);
  };
  const glm::dvec3 fast = pixel(Modes::O), slow = pixel(Modes::E);
  const glm::dvec3 cf = closed(na, sa), cs = closed(nb, sb);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(fast[c], cf[c], 1e-6);  // float pixels
    EXPECT_NEAR(slow[c], cs[c], 1e-6);
  }
  const double dE = glm::length(lab(cf) - lab(cs));
  EXPECT_GT(dE, 5.0);  // a visible trichroism
  EXPECT_NEAR(glm::length(lab(fast) - lab(slow)), dE, 1e-3);
}

}  // namespace
}  // namespace eikon
