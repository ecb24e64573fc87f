// eikon.AnalyticField: exact index fields marched by the CPU reference, without voxelising.
#include <pybind11/functional.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <optional>

#include "core/reference/reference_marcher.h"
#include "python/module.h"

namespace eikon::python {
namespace {
// An analytic field for the CPU reference: a named closed-form profile or a Python callable.
struct AnalyticSpec {
  std::shared_ptr<AnalyticField> field;
  Environment env;
};
}  // namespace

void bindAnalytic(py::module_& m) {
  py::class_<AnalyticSpec, std::shared_ptr<AnalyticSpec>>(
      m, "AnalyticField",
      "An exact index field n(x), ∇n(x) in a box, marched by the CPU reference (no voxelisation).")
      .def_static(
          "luneburg",
          [](double R, const py::handle& center, const py::handle& bmin, const py::handle& bmax,
             double cell) {
            glm::dvec3 c = toVec3(center);
            auto fn = [R, c](const glm::dvec3& x, double& n, glm::dvec3& g) {
              glm::dvec3 r = x - c;
              double r2 = glm::dot(r, r);
              if (r2 >= R * R) {
                n = 1.0;
                g = glm::dvec3(0.0);
                return;
              }
              n = std::sqrt(2.0 - r2 / (R * R));
              g = -r / (R * R * n);
            };
            auto s = std::make_shared<AnalyticSpec>();
            s->field = std::make_shared<AnalyticField>(fn, toVec3(bmin), toVec3(bmax), cell);
            return s;
          },
          py::arg("radius"), py::arg("center"), py::arg("bounds_min"), py::arg("bounds_max"),
          py::arg("cell"), "n = √(2 − r²/R²) inside, 1 outside")
      .def_static(
          "linear",
          [](double n0, const py::handle& gradient, const py::handle& origin,
             const py::handle& bmin, const py::handle& bmax, double cell) {
            glm::dvec3 gr = toVec3(gradient), o = toVec3(origin);
            auto fn = [n0, gr, o](const glm::dvec3& x, double& n, glm::dvec3& g) {
              n = n0 + glm::dot(gr, x - o);
              g = gr;
            };
            auto s = std::make_shared<AnalyticSpec>();
            s->field = std::make_shared<AnalyticField>(fn, toVec3(bmin), toVec3(bmax), cell);
            return s;
          },
          py::arg("n0"), py::arg("gradient"), py::arg("origin"), py::arg("bounds_min"),
          py::arg("bounds_max"), py::arg("cell"), "n = n0 + g·(x − origin)")
      .def_static(
          "maxwell_fisheye",
          [](double n0, double R, const py::handle& center, const py::handle& bmin,
             const py::handle& bmax, double cell) {
            glm::dvec3 c = toVec3(center);
            auto fn = [n0, R, c](const glm::dvec3& x, double& n, glm::dvec3& g) {
              glm::dvec3 r = x - c;
              double q = 1.0 + glm::dot(r, r) / (R * R);
              n = n0 / q;
              g = -2.0 * n0 * r / (R * R * q * q);
            };
            auto s = std::make_shared<AnalyticSpec>();
            s->field = std::make_shared<AnalyticField>(fn, toVec3(bmin), toVec3(bmax), cell);
            return s;
          },
          py::arg("n0"), py::arg("radius"), py::arg("center"), py::arg("bounds_min"),
          py::arg("bounds_max"), py::arg("cell"), "n = n0/(1 + r²/R²) everywhere in the box")
      .def_static(
          "from_function",
          [](py::function f, const py::handle& bmin, const py::handle& bmax, double cell) {
            // f(x: ndarray(3)) -> (n, grad(3)); called with the GIL held (slow but general).
            auto fn = [f](const glm::dvec3& x, double& n, glm::dvec3& g) {
              py::gil_scoped_acquire acquire;
              py::tuple r = f(fromVec3(x));
              n = r[0].cast<double>();
              g = toVec3(r[1]);
            };
            auto s = std::make_shared<AnalyticSpec>();
            s->field = std::make_shared<AnalyticField>(fn, toVec3(bmin), toVec3(bmax), cell);
            return s;
          },
          py::arg("fn"), py::arg("bounds_min"), py::arg("bounds_max"), py::arg("cell"))
      .def(
          "trace",
          [](const AnalyticSpec& a, const py::handle& origin, const py::handle& direction,
             std::optional<MarchSettings> march, double wavelength_nm) {
            ReferenceMarcher r(*a.field, a.env);
            TraceRequest q{toVec3(origin), toVec3(direction), wavelength_nm};
            MarchSettings ms = march.value_or(MarchSettings{});
            TraceOutcome t;
            {
              py::gil_scoped_release release;
              t = r.trace(q, ms);
            }
            return outcomeDict(t, "o");
          },
          py::arg("origin"), py::arg("direction"), py::arg("march") = py::none(),
          py::arg("wavelength_nm") = 587.5618,
          "one ray through the exact field: {'mode': 'o', 'exit_point', ...} (CPU reference)");
}

}  // namespace eikon::python
