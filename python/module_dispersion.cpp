// eikon.Dispersion, eikon.Material and the material library (load_material).
#include <pybind11/functional.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>

#include "anisotropic/dispersion.h"
#include "core/scene/limits.h"
#include "core/scene/material_library.h"
#include "core/scene/scene.h"
#include "fitting/index_data.h"
#include "python/module.h"

namespace eikon::python {

namespace {
// The wavelengths a dispersion model is evaluated at: those a fit takes (fitting/index_data.h),
// which hold every material eikon writes or reads (λ = -5 nm gave an index).
double checkLambda(double nm) {
  return checkWavelength(nm, "lambda_nm", kMinFitWavelengthNm, kMaxFitWavelengthNm);
}

// The approximation's window inside the wavelengths above, and the model a refractive index in
// [1, 10] on it: a Sellmeier pole there gave coefficients of ~1e15 without a word.
void checkApproximationWindow(const Dispersion& d, double lo, double hi) {
  checkWavelength(lo, "lo_nm", kMinFitWavelengthNm, kMaxFitWavelengthNm);
  checkWavelength(hi, "hi_nm", kMinFitWavelengthNm, kMaxFitWavelengthNm);
  if (!(lo < hi))
    throw std::invalid_argument("lo_nm must be below hi_nm, got " + formatNumber(lo) +
                                " >= " + formatNumber(hi));
  if (d.kind() == Dispersion::Kind::Sellmeier)
    for (size_t i = 0; i < d.sellmeierC().size(); ++i) {
      const double pole = 1e3 * std::sqrt(d.sellmeierC()[i]);  // C in µm²
      if (pole >= lo && pole <= hi)
        throw std::invalid_argument(
            "the Sellmeier term " + std::to_string(i + 1) + " has a pole at " + formatNumber(pole) +
            " nm (C" + std::to_string(i + 1) + " = " + formatNumber(d.sellmeierC()[i]) +
            " um^2), inside [" + formatNumber(lo) + ", " + formatNumber(hi) + "] nm");
    }
  const int samples = std::max(3, int(std::lround(hi - lo)) + 1);  // as cauchyApproximation
  for (int i = 0; i < samples; ++i) {
    const double l = lo + (hi - lo) * i / double(samples - 1), n = d.index(l);
    if (!(n >= kMinIndex && n <= kMaxIndex))
      throw std::invalid_argument("the model gives n = " + formatNumber(n) + " at " +
                                  formatNumber(l) + " nm, inside [" + formatNumber(lo) + ", " +
                                  formatNumber(hi) + "] nm: not a refractive index in [1, 10]");
  }
}

// A material's index at one wavelength, refused (naming the material) outside [1, 10].
double materialIndex(const Material& x, const Dispersion& d, const char* which, double nm) {
  const double n = d.index(nm);
  if (!(n >= kMinIndex && n <= kMaxIndex))
    throw std::invalid_argument("material '" + x.name + "' " + which + " = " + formatNumber(n) +
                                " at " + formatNumber(nm) +
                                " nm is not a refractive index in [1, 10]");
  return n;
}

void bindDispersionClass(py::module_& m) {
  py::dict fr;
  fr["F"] = fraunhofer::F;
  fr["d"] = fraunhofer::d;
  fr["D"] = fraunhofer::D;
  fr["C"] = fraunhofer::C;
  m.attr("FRAUNHOFER") = fr;

  py::class_<Dispersion>(m, "Dispersion", "n(λ) of one material or mode; λ in nm.")
      .def_static(
          "constant", [](double n) { return Dispersion::constant(checkIndex(n, "n")); },
          py::arg("n"), "n(λ) = n, n in [1, 10]")
      .def_static(
          "cauchy", [](const py::handle& c) { return Dispersion::cauchy(toVector(c)); },
          py::arg("coeffs"), "n = Σ c_k/λ^{2k}, λ in µm")
      .def_static(
          "sellmeier",
          [](const py::handle& b, const py::handle& c) {
            return Dispersion::sellmeier(toVector(b), toVector(c));
          },
          py::arg("B"), py::arg("C"), "SCHOTT Sellmeier, C in µm²")
      .def_static("conrady", &Dispersion::conrady, py::arg("n0"), py::arg("A"), py::arg("B"),
                  "n = n0 + A/λ + B/λ^3.5, λ in µm")
      .def(
          "with_range",
          [](Dispersion d, double lo, double hi) {
            d.withRange(lo, hi);
            return d;
          },
          py::arg("lo_nm"), py::arg("hi_nm"))
      .def_property_readonly("kind",
                             [](const Dispersion& d) -> const char* {
                               switch (d.kind()) {
                                 case Dispersion::Kind::Constant:
                                   return "constant";
                                 case Dispersion::Kind::Cauchy:
                                   return "cauchy";
                                 case Dispersion::Kind::Sellmeier:
                                   return "sellmeier";
                                 case Dispersion::Kind::Conrady:
                                   return "conrady";
                               }
                               return "unknown";
                             })
      .def_property_readonly("coefficients",
                             [](const Dispersion& d) { return fromVector(d.coefficients()); })
      .def_property_readonly("sellmeier_c",
                             [](const Dispersion& d) { return fromVector(d.sellmeierC()); })
      .def_property_readonly("range_nm",
                             [](const Dispersion& d) -> py::object {
                               if (!d.rangeNm()) return py::none();
                               return py::make_tuple((*d.rangeNm())[0], (*d.rangeNm())[1]);
                             })
      .def(
          "index",
          [](const Dispersion& d, py::array_t<double> l) {
            return py::vectorize([&d](double x) { return d.index(checkLambda(x)); })(l);
          },
          py::arg("lambda_nm"),
          "n(λ), broadcasting over arrays, λ in [100, 100000] nm; NaN where a Sellmeier model has "
          "no real index (n² ≤ 0 or a pole)")
      .def(
          "derivative",
          [](const Dispersion& d, py::array_t<double> l) {
            return py::vectorize([&d](double x) { return d.derivative(checkLambda(x)); })(l);
          },
          py::arg("lambda_nm"), "dn/dλ in 1/nm")
      .def("abbe_number", &Dispersion::abbeNumber, "V_d = (n_d − 1)/(n_F − n_C)")
      .def(
          "cauchy_approximation",
          [](const Dispersion& d, double lo, double hi) {
            checkApproximationWindow(d, lo, hi);
            auto c = d.cauchyApproximation(lo, hi);
            py::dict r;
            r["coeffs"] = py::make_tuple(c.coeffs[0], c.coeffs[1], c.coeffs[2]);
            r["max_error"] = c.max_error;
            r["rms_error"] = c.rms_error;
            return r;
          },
          py::arg("lo_nm"), py::arg("hi_nm"),
          "Cauchy {A, B, C} over [lo, hi] nm (within [100, 100000], lo < hi); ValueError where "
          "the model has no index in [1, 10] there (a Sellmeier pole)")
      .def("describe", &Dispersion::describe)
      .def("__repr__",
           [](const Dispersion& d) { return "<eikon.Dispersion " + d.describe() + ">"; });
}

// Materials: the scene's and the library's (materials/<name>.json).
void bindMaterials(py::module_& m) {
  py::class_<Material>(m, "Material", "A material from the library or a scene (read-only view).")
      .def_readonly("name", &Material::name)
      .def_readonly("source", &Material::source)
      .def_readonly("uniaxial", &Material::uniaxial)
      .def_readonly("biaxial", &Material::biaxial, "n_alpha/n_beta/n_gamma (listed, not rendered)")
      .def_readonly("n_alpha", &Material::n_alpha)
      .def_readonly("n_beta", &Material::n_beta)
      .def_readonly("n_gamma", &Material::n_gamma)
      .def_property_readonly("alpha_axis", [](const Material& x) { return fromVec3(x.alpha_axis); })
      .def_property_readonly("gamma_axis", [](const Material& x) { return fromVec3(x.gamma_axis); })
      .def_property_readonly(
          "n", [](const Material& x) { return x.n_o; }, "index (isotropic) = n_o")
      .def_readonly("n_o", &Material::n_o)
      .def_readonly("n_e", &Material::n_e)
      .def_property_readonly("optic_axis",
                             [](const Material& x) -> py::object {
                               return x.optic_axis ? py::object(fromVec3(*x.optic_axis))
                                                   : py::none();
                             })
      .def(
          "uniaxial_at",
          [](const Material& x, double lambda_nm, py::object axis) {
            if (!x.uniaxial) throw std::invalid_argument(x.name + " is not uniaxial");
            checkLambda(lambda_nm);
            glm::dvec3 a = axis.is_none() ? x.optic_axis.value_or(glm::dvec3(0, 0, 1))
                                          : toDirection(axis, "axis");
            return Uniaxial(materialIndex(x, x.n_o, "n_o", lambda_nm),
                            materialIndex(x, x.n_e, "n_e", lambda_nm), a);
          },
          py::arg("lambda_nm"), py::arg("axis") = py::none(), "the crystal at one wavelength")
      .def("__repr__", [](const Material& x) {
        return "<eikon.Material " + x.name +
               (x.uniaxial  ? " (uniaxial)>"
                : x.biaxial ? " (biaxial)>"
                            : ">");
      });

  m.def(
      "load_material",
      [](const std::string& name_or_path) {
        std::filesystem::path p(name_or_path);
        std::error_code ec;  // a name too long for the file system is not found, never a raw
                             // filesystem_error
        if (p.extension() == ".json" && std::filesystem::exists(p, ec)) return loadMaterialFile(p);
        const bool plain = !name_or_path.empty() && name_or_path != "." && name_or_path != ".." &&
                           name_or_path.find_first_of(std::string("/\\\0", 3)) == std::string::npos;
        std::optional<std::filesystem::path> f;
        try {
          if (plain) f = findLibraryMaterial(name_or_path);   // case, spaces, '_' forgiven
        } catch (const std::filesystem::filesystem_error&) {  // a name too long: not found
        }
        if (f) return loadMaterialFile(*f);
        throw std::invalid_argument("no material '" + excerpt(name_or_path) +
                                    "' in the library search path; " +
                                    unknownMaterialHint(name_or_path, {}));
      },
      py::arg("name_or_path"),
      "a library material by name (materials/<name>.json) or a material file");
  m.def("material_search_path", &materialSearchPath);
}
}  // namespace

void bindDispersion(py::module_& m) {
  bindDispersionClass(m);
  bindMaterials(m);
}

}  // namespace eikon::python
