// The Beyerle–McDermid mapping in the pipeline: both twins refract the e-wave by the mapping
// (shaders/sharp.glsl solveInterfaceMode, anisotropic/interface.cpp solveUniaxialMode), and are
// held here to the oracle built from the direct quadratic of pᵀM_e p = 1 (solveInterfaceMode with
// M_e) on random calcite plates: a 4 mm plate (faces z = ±2) with a random optic axis, entered
// at a random point by a ray at 0–60° incidence and any azimuth. The oracle: the e-wave of the
// quadratic at the entry face, its ray t_e straight to the back face, Q = P + t_e·4/t_e,z, and the
// ray leaving parallel to the incident one (a parallel plate). The traced exit line must pass
// through Q and run along d: the CPU twin (double, exact crossings of the box) within 1e-9 mm and
// 1e-12 rad; the GPU twin (float: a few ulp per crossing) within 1e-4 mm and 1e-5 rad, as the
// other sharp twin tests. The o-mode is held to Snell alike.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "anisotropic/interface.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

glm::dvec3 unitFrom(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  glm::dvec3 v;
  do v = {g(rng), g(rng), g(rng)};
  while (glm::length(v) < 1e-3);
  return glm::normalize(v);
}

struct Plate {
  glm::dvec3 axis, P, d;
};

/// Where the mode's exit line must pass (Q) by the direct solve, for a plate of axis `axis`.
glm::dvec3 oracleBackFace(const Plate& p, double no, double ne, int mode) {
  const Uniaxial crystal(no, ne, p.axis);
  const glm::dvec3 m(0, 0, 1), pt = p.d - glm::dot(p.d, m) * m;  // ambient index 1
  const Mode md = mode == 1 ? Mode::Extraordinary : Mode::Ordinary;
  const ModeWave w = solveInterfaceMode(pt, m, crystal.hamiltonianMatrix(md), true);
  EXPECT_TRUE(w.exists);
  return p.P + w.t * (4.0 / w.t.z);
}

double lineMiss(const TraceOutcome& o, const glm::dvec3& Q) {
  const glm::dvec3 r = Q - o.exit_point, u = glm::normalize(o.exit_direction);
  return glm::length(r - glm::dot(r, u) * u);
}

double angleBetween(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

TEST(BmPipeline, RandomCalcitePlatesMatchTheDirectSolveInBothTwins) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double nm = fraunhofer::D;
  double cpu_point = 0, cpu_dir = 0, gpu_point = 0, gpu_dir = 0;
  for (int plate = 0; plate < 6; ++plate) {
    Plate p;
    p.axis = unitFrom(rng);
    const std::string json =
        R"({"environment": {"type": "constant", "radiance": 1},
            "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "width": 8, "height": 8},
            "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 64},
            "objects": [{"shape": "box", "center": [0, 0, 0], "size": [14, 14, 4],
                         "material": "calcite", "optic_axis": [)" +
        std::to_string(p.axis.x) + ", " + std::to_string(p.axis.y) + ", " +
        std::to_string(p.axis.z) + "]}]}";
    Twins t(json);
    p.axis = *t.scene.objects[0].optic_axis;  // as the scene holds it (printed to 6 digits)
    const Material& mat = t.scene.materials.at("calcite");
    const double no = mat.n_o.index(nm), ne = mat.n_e.index(nm);
    std::vector<TraceRequest> reqs;
    std::vector<Plate> plates;
    for (int k = 0; k < 8; ++k) {
      const double th = 60.0 * kDeg * u01(rng), ph = 2.0 * std::numbers::pi * u01(rng);
      p.d = {std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)};
      p.P = {2.0 * u01(rng) - 1.0, 2.0 * u01(rng) - 1.0, -2.0};
      reqs.push_back({p.P - 30.0 * p.d, p.d, nm});
      plates.push_back(p);
    }
    MarchSettings ms;
    ms.fresnel = false;
    const auto gpu = t.gpu->traceModes(reqs, ms);
    for (size_t k = 0; k < reqs.size(); ++k)
      for (int mode = 0; mode < 2; ++mode) {
        SCOPED_TRACE("plate " + std::to_string(plate) + " ray " + std::to_string(k) + " mode " +
                     std::to_string(mode));
        const glm::dvec3 Q = oracleBackFace(plates[k], no, ne, mode);
        const TraceOutcome c = t.cpu->trace(reqs[k], ms, mode), &g = gpu[k][size_t(mode)];
        ASSERT_TRUE(c.left_volume && g.left_volume);
        EXPECT_EQ(c.interfaces, 2);
        EXPECT_EQ(g.interfaces, 2);
        cpu_point = std::max(cpu_point, lineMiss(c, Q));
        gpu_point = std::max(gpu_point, lineMiss(g, Q));
        cpu_dir = std::max(cpu_dir, angleBetween(c.exit_direction, plates[k].d));
        gpu_dir = std::max(gpu_dir, angleBetween(g.exit_direction, plates[k].d));
      }
    expectNoValidationMessages();
  }
  std::printf(
      "[ measured ] random calcite plates against the direct solve: CPU %.2e mm, %.2e rad; GPU "
      "%.2e mm, %.2e rad\n",
      cpu_point, cpu_dir, gpu_point, gpu_dir);
  EXPECT_LE(cpu_point, 1e-9);
  EXPECT_LE(cpu_dir, 1e-12);
  EXPECT_LE(gpu_point, 1e-4);
  EXPECT_LE(gpu_dir, 1e-5);
}

}  // namespace
}  // namespace eikon::test
