// Measured index data (CSV, refractiveindex.info YAML) and the Ceres dispersion fit.
#include <pybind11/functional.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "fitting/fitting.h"
#include "fitting/index_data.h"
#include "python/module.h"

namespace eikon::python {
namespace {
// One column of fit_dispersion: a 1-D sequence of numbers, else ValueError naming it.
std::vector<double> seriesVector(const py::handle& h, const char* name) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(h);
  if (!a || a.ndim() != 1)
    throw std::invalid_argument(std::string(name) + " must be a 1-D sequence of numbers");
  return {a.data(), a.data() + a.size()};
}

void bindIndexData(py::module_& m) {
  py::class_<IndexSeries>(m, "IndexSeries")
      .def_readonly("label", &IndexSeries::label)
      .def_property_readonly("lambda_nm",
                             [](const IndexSeries& s) { return fromVector(s.lambda_nm); })
      .def_property_readonly("n", [](const IndexSeries& s) { return fromVector(s.n); })
      .def_property_readonly("sigma",
                             [](const IndexSeries& s) -> py::object {
                               return s.sigma.empty() ? py::none()
                                                      : py::object(fromVector(s.sigma));
                             })
      .def("__len__", &IndexSeries::size);
  py::class_<IndexData>(m, "IndexData")
      .def_readonly("source", &IndexData::source)
      .def_readonly("modes", &IndexData::modes)
      .def_readonly("warnings", &IndexData::warnings)
      .def_property_readonly("uniaxial", &IndexData::uniaxial)
      .def("__getitem__", [](const IndexData& d, const std::string& label) {
        for (const auto& s : d.modes)
          if (s.label == label) return s;
        throw py::key_error(label);
      });
  auto readOpts = [](std::optional<std::pair<double, double>> w) {
    IndexReadOptions o;
    if (w) o.window_nm = std::array<double, 2>{w->first, w->second};
    return o;
  };
  m.def(
      "read_index_data",
      [readOpts](const std::string& path, std::optional<std::pair<double, double>> window) {
        return readIndexData(path, readOpts(window));
      },
      py::arg("path"), py::arg("window_nm") = py::none(),
      "CSV (wavelength_nm,n[,sigma] or ...,n_o,n_e[,...]) or refractiveindex.info YAML");
  m.def(
      "parse_index_csv",
      [readOpts](const std::string& text, const std::string& name,
                 std::optional<std::pair<double, double>> window) {
        return parseIndexCsv(text, name, readOpts(window));
      },
      py::arg("text"), py::arg("name") = "<string>", py::arg("window_nm") = py::none());
}

void bindFitResult(py::module_& m) {
  py::class_<FitResult>(m, "FitResult")
      .def_property_readonly("model", [](const FitResult& r) { return modelName(r.model); })
      .def_readonly("label", &FitResult::label)
      .def_property_readonly("names", [](const FitResult& r) { return parameterNames(r.model); })
      .def_property_readonly("coeffs", [](const FitResult& r) { return fromVector(r.coeffs); })
      .def_property_readonly("sigma", [](const FitResult& r) { return fromVector(r.sigma); })
      .def_property_readonly("covariance",
                             [](const FitResult& r) {
                               py::ssize_t P = py::ssize_t(r.coeffs.size());
                               py::array_t<double> c({P, P});
                               std::copy(r.covariance.begin(), r.covariance.end(),
                                         c.mutable_data());
                               return c;
                             })
      .def_readonly("points", &FitResult::points)
      .def_readonly("weighted", &FitResult::weighted)
      .def_readonly("chi2", &FitResult::chi2)
      .def_readonly("chi2_reduced", &FitResult::chi2_reduced)
      .def_readonly("residual_std", &FitResult::residual_std)
      .def_readonly("rms", &FitResult::rms)
      .def_readonly("max_residual", &FitResult::max_residual)
      .def_property_readonly(
          "range_nm",
          [](const FitResult& r) { return py::make_tuple(r.range_nm[0], r.range_nm[1]); })
      .def_readonly("n_F", &FitResult::n_F)
      .def_readonly("n_d", &FitResult::n_d)
      .def_readonly("n_C", &FitResult::n_C)
      .def_readonly("abbe", &FitResult::abbe)
      .def_readonly("iterations", &FitResult::iterations)
      .def_readonly("warnings", &FitResult::warnings)
      .def("dispersion", &FitResult::dispersion,
           "the fitted curve as a Dispersion (cauchy, sellmeier or conrady)")
      .def(
          "index",
          [](const FitResult& r, py::array_t<double> l) {
            return py::vectorize(
                [&r](double x) { return modelIndex(r.model, r.coeffs.data(), x); })(l);
          },
          py::arg("lambda_nm"), "fitted n(λ)")
      .def(
          "index_sigma",
          [](const FitResult& r, py::array_t<double> l) {
            // 1σ of the fitted curve: sqrt(Jᵀ C J), J = ∂n/∂p at λ (linear error propagation).
            const size_t P = r.coeffs.size();
            return py::vectorize([&r, P](double x) {
              std::vector<double> J(P);
              modelIndex(r.model, r.coeffs.data(), x, J.data());
              double v = 0.0;
              for (size_t i = 0; i < P; ++i)
                for (size_t j = 0; j < P; ++j) v += J[i] * r.covariance[i * P + j] * J[j];
              return std::sqrt(std::max(v, 0.0));
            })(l);
          },
          py::arg("lambda_nm"), "1σ band of the fitted n(λ) from the coefficient covariance")
      .def("__repr__", [](const FitResult& r) {
        return "<eikon.FitResult " + modelName(r.model) + " " + r.label +
               " N=" + std::to_string(r.points) + ">";
      });
}
}  // namespace

void bindFitting(py::module_& m) {
  bindIndexData(m);
  bindFitResult(m);
  m.def(
      "fit_dispersion",
      [](const py::handle& lambda_nm, const py::handle& n, const py::object& sigma,
         const std::string& model, std::optional<double> huber_delta, const std::string& label,
         int max_iterations) {
        IndexSeries s;
        s.label = label;
        s.lambda_nm = seriesVector(lambda_nm, "lambda_nm");
        s.n = seriesVector(n, "n");
        if (!sigma.is_none()) s.sigma = seriesVector(sigma, "sigma");
        FitOptions o;
        o.model = parseDispersionModel(model);
        o.huber_delta = huber_delta;
        o.max_iterations = max_iterations;
        // The rules of `eikon fit`'s data files (fitting/index_data.h): out-of-order points are
        // sorted with a warning (warnings.warn), the rest refused naming the point.
        std::vector<std::string> warnings;
        s = checkIndexSeries(s, "lambda_nm", warnings);
        for (const std::string& w : warnings)
          if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0) throw py::error_already_set();
        py::gil_scoped_release release;
        return fitDispersion(s, o);
      },
      py::arg("lambda_nm"), py::arg("n"), py::arg("sigma") = py::none(),
      py::arg("model") = "cauchy3", py::arg("huber_delta") = py::none(), py::arg("label") = "n",
      py::arg("max_iterations") = 200,
      "Weighted (robust) least-squares fit: cauchy2|cauchy3|sellmeier1..3|conrady. The data "
      "follow `eikon fit`'s rules: finite, lambda_nm in [100, 100000], n in [1, 10], sigma > 0, "
      "no repeated wavelength (ValueError naming the point); unsorted points are sorted with a "
      "UserWarning; max_iterations in [1, 100000]");
  m.def(
      "fit_series",
      [](const IndexSeries& s, const std::string& model, std::optional<double> huber_delta) {
        FitOptions o;
        o.model = parseDispersionModel(model);
        o.huber_delta = huber_delta;
        py::gil_scoped_release release;
        return fitDispersion(s, o);
      },
      py::arg("series"), py::arg("model") = "cauchy3", py::arg("huber_delta") = py::none());
}

}  // namespace eikon::python
