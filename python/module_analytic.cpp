// eikon.AnalyticField: exact index fields marched by the CPU reference, without voxelising.
// Every factory checks its arguments as a scene's gradient-index material is checked (core/scene/
// scene.cpp): positions within ±1e12 mm, a box with bounds_min < bounds_max, a cell and a radius
// > 0, and an index in [1, 10] everywhere in the box (a cell of 0 or NaN, swapped bounds or a
// negative n0 traced to NaN exit points or negative optical paths); from_function's values are
// checked where the march samples them.
#include <pybind11/functional.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <optional>

#include "core/scene/limits.h"
#include "core/session/analytic_trace.h"
#include "python/module.h"

namespace eikon::python {
namespace {
// An analytic field for the CPU reference: a named closed-form profile or a Python callable.
struct AnalyticSpec {
  std::shared_ptr<AnalyticTrace> field;
};

struct Box {
  glm::dvec3 lo, hi;
  double cell;
};

std::string point(const glm::dvec3& x) {
  return "(" + formatNumber(x.x) + ", " + formatNumber(x.y) + ", " + formatNumber(x.z) + ")";
}

Box checkedBox(const py::handle& bmin, const py::handle& bmax, double cell) {
  const Box b{toPosition(bmin, "bounds_min"), toPosition(bmax, "bounds_max"),
              checkPositive(cell, "cell")};
  for (int k = 0; k < 3; ++k)
    if (!(b.lo[k] < b.hi[k]))
      throw std::invalid_argument("bounds_min must be below bounds_max on every axis, got " +
                                  formatNumber(b.lo[k]) + " >= " + formatNumber(b.hi[k]) + " on " +
                                  "xyz"[k]);
  return b;
}

double checkedRadius(double R) {
  checkPositive(R, "radius");
  if (R > kMaxCoordinateMm)
    throw std::invalid_argument("radius must be at most 1e12 mm, got " + formatNumber(R));
  return R;
}

// The index `what` gives at x must be a refractive index, as a scene's everywhere in its object.
void checkFieldIndex(double n, const glm::dvec3& x, const std::string& what) {
  if (!(n >= kMinIndex && n <= kMaxIndex))
    throw std::invalid_argument(what + " gives n = " + formatNumber(n) + " at " + point(x) +
                                ": indices must be in [1, 10]");
}

// For a field whose extremes in the box lie at its corners (linear; the fisheye's minimum).
template <class F>
void checkCorners(const Box& b, const std::string& what, F&& index) {
  for (int c = 0; c < 8; ++c) {
    const glm::dvec3 x(c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y, c & 4 ? b.hi.z : b.lo.z);
    checkFieldIndex(index(x), x, what);
  }
}

std::shared_ptr<AnalyticSpec> makeSpec(AnalyticTrace::IndexFn fn, const Box& b) {
  auto s = std::make_shared<AnalyticSpec>();
  s->field = std::make_shared<AnalyticTrace>(std::move(fn), b.lo, b.hi, b.cell);
  return s;
}

std::shared_ptr<AnalyticSpec> makeLuneburg(double radius, const py::handle& center,
                                           const py::handle& bmin, const py::handle& bmax,
                                           double cell) {
  const double R = checkedRadius(radius);  // n in [1, √2] everywhere
  const glm::dvec3 c = toPosition(center, "center");
  return makeSpec(
      [R, c](const glm::dvec3& x, double& n, glm::dvec3& g) {
        glm::dvec3 r = x - c;
        double r2 = glm::dot(r, r);
        if (r2 >= R * R) {
          n = 1.0;
          g = glm::dvec3(0.0);
          return;
        }
        n = std::sqrt(2.0 - r2 / (R * R));
        g = -r / (R * R * n);
      },
      checkedBox(bmin, bmax, cell));
}

std::shared_ptr<AnalyticSpec> makeLinear(double n0, const py::handle& gradient,
                                         const py::handle& origin, const py::handle& bmin,
                                         const py::handle& bmax, double cell) {
  checkIndex(n0, "n0");
  const glm::dvec3 gr = toFiniteVec3(gradient, "gradient"), o = toPosition(origin, "origin");
  const Box b = checkedBox(bmin, bmax, cell);
  auto index = [n0, gr, o](const glm::dvec3& x) { return n0 + glm::dot(gr, x - o); };
  checkCorners(b, "the linear field n0 + gradient·(x − origin)", index);
  return makeSpec(
      [index, gr](const glm::dvec3& x, double& n, glm::dvec3& g) {
        n = index(x);
        g = gr;
      },
      b);
}

std::shared_ptr<AnalyticSpec> makeMaxwellFisheye(double n0, double radius, const py::handle& center,
                                                 const py::handle& bmin, const py::handle& bmax,
                                                 double cell) {
  checkIndex(n0, "n0");  // the largest index; the smallest is at the corner farthest from c
  const double R = checkedRadius(radius);
  const glm::dvec3 c = toPosition(center, "center");
  const Box b = checkedBox(bmin, bmax, cell);
  auto index = [n0, R, c](const glm::dvec3& x) {
    return n0 / (1.0 + glm::dot(x - c, x - c) / (R * R));
  };
  checkCorners(b, "the Maxwell fish-eye n0/(1 + r²/R²)", index);
  return makeSpec(
      [n0, R, c](const glm::dvec3& x, double& n, glm::dvec3& g) {
        glm::dvec3 r = x - c;
        double q = 1.0 + glm::dot(r, r) / (R * R);
        n = n0 / q;
        g = -2.0 * n0 * r / (R * R * q * q);
      },
      b);
}

// f(x: ndarray(3)) -> (n, grad(3)); called with the GIL held (slow but general). Each value is
// checked where it is sampled.
std::shared_ptr<AnalyticSpec> makeFromFunction(py::function f, const py::handle& bmin,
                                               const py::handle& bmax, double cell) {
  const Box b = checkedBox(bmin, bmax, cell);
  return makeSpec(
      [f](const glm::dvec3& x, double& n, glm::dvec3& g) {
        py::gil_scoped_acquire acquire;
        const py::object r = f(fromVec3(x));
        if (!py::isinstance<py::sequence>(r) || py::len(r) != 2)
          throw py::type_error("fn must return (n, gradient), got " +
                               py::repr(r).cast<std::string>() + " at " + point(x));
        const py::sequence pair = r.cast<py::sequence>();
        n = pair[0].cast<double>();
        checkFieldIndex(n, x, "fn");
        const std::string at = "fn's gradient at " + point(x);
        g = toFiniteVec3(pair[1], at.c_str());
      },
      b);
}

py::dict traceAnalytic(const AnalyticSpec& a, const py::handle& origin, const py::handle& direction,
                       std::optional<MarchSettings> march, double wavelength_nm) {
  const TraceRequest q{toVec3(origin), toVec3(direction), wavelength_nm};
  const MarchSettings ms = march.value_or(MarchSettings{});
  checkSetting([&] {  // as Renderer.trace's
    checkTraceRequest(q);
    checkMarchStep(ms.step_voxels);
  });
  TraceOutcome t;
  {
    py::gil_scoped_release release;
    t = a.field->trace(q, ms);
  }
  return outcomeDict(t, "o");
}
}  // namespace

void bindAnalytic(py::module_& m) {
  py::class_<AnalyticSpec, std::shared_ptr<AnalyticSpec>>(
      m, "AnalyticField",
      "An exact index field n(x), ∇n(x) in a box, marched by the CPU reference (no "
      "voxelisation). Indices must be in [1, 10] everywhere in the box (ValueError otherwise).")
      .def_static("luneburg", &makeLuneburg, py::arg("radius"), py::arg("center"),
                  py::arg("bounds_min"), py::arg("bounds_max"), py::arg("cell"),
                  "n = √(2 − r²/R²) inside, 1 outside")
      .def_static("linear", &makeLinear, py::arg("n0"), py::arg("gradient"), py::arg("origin"),
                  py::arg("bounds_min"), py::arg("bounds_max"), py::arg("cell"),
                  "n = n0 + g·(x − origin)")
      .def_static("maxwell_fisheye", &makeMaxwellFisheye, py::arg("n0"), py::arg("radius"),
                  py::arg("center"), py::arg("bounds_min"), py::arg("bounds_max"), py::arg("cell"),
                  "n = n0/(1 + r²/R²) everywhere in the box")
      .def_static("from_function", &makeFromFunction, py::arg("fn"), py::arg("bounds_min"),
                  py::arg("bounds_max"), py::arg("cell"),
                  "fn(x: (3,) array) -> (n, gradient (3,)); a value outside [1, 10] or a "
                  "non-finite gradient raises ValueError naming the point when sampled")
      .def("trace", &traceAnalytic, py::arg("origin"), py::arg("direction"),
           py::arg("march") = py::none(), py::arg("wavelength_nm") = 587.5618,
           "one ray through the exact field: {'mode': 'o', 'exit_point', ...} (CPU reference)");
}

}  // namespace eikon::python
