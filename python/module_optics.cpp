// Uniaxial optics: the crystal (eikon.Uniaxial), the Beyerle–McDermid mapping, refraction,
// reflection, Fresnel and the power split at interfaces, pleochroism.
#include <pybind11/functional.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>

#include "anisotropic/bm_mapping.h"
#include "anisotropic/fresnel.h"
#include "anisotropic/interface.h"
#include "anisotropic/pleochroism.h"
#include "python/module.h"

namespace eikon::python {
namespace {
PleochroismModel parsePleo(const std::string& s) {
  if (s == "first_order") return PleochroismModel::FirstOrder;
  if (s == "tevs") return PleochroismModel::TevsThesis;
  throw std::invalid_argument("pleochroism model must be 'first_order' or 'tevs'");
}

// An angle argument (radians): any finite number.
double checkAngle(double t, const char* name) {
  if (!std::isfinite(t))
    throw std::invalid_argument(std::string(name) + " must be a finite angle (rad), got " +
                                formatNumber(t));
  return t;
}

// cos of an angle of incidence: in [-1, 1], with rounding (a dot product of unit vectors) let
// through; cos_i = 5 was taken for 1.
double checkCosine(double c) {
  if (!(std::abs(c) <= 1.0 + 1e-9))
    throw std::invalid_argument("cos_i must be in [-1, 1], got " + formatNumber(c));
  return c;
}

py::dict waveDict(const ModeWave& w) {
  py::dict d;
  d["exists"] = w.exists;
  d["s"] = fromVec3(w.s);
  d["n"] = w.n;
  d["t"] = fromVec3(w.t);
  d["q"] = w.q;
  return d;
}
py::dict pairDict(const ModePair& p) {
  py::dict d;
  d["o"] = waveDict(p.o);
  d["e"] = waveDict(p.e);
  return d;
}
py::dict splitDict(const ModeSplit& s) {
  py::dict d;
  d["o"] = s.o;
  d["e"] = s.e;
  d["reflected"] = s.reflected;
  d["transmitted"] = s.transmitted;
  return d;
}

void bindCrystals(py::module_& m) {
  py::class_<Uniaxial>(m, "Uniaxial",
                       "A homogeneous uniaxial crystal at one wavelength (angles in radians).")
      .def(py::init([](double no, double ne, const py::handle& axis) {
             return Uniaxial(checkIndex(no, "n_o"), checkIndex(ne, "n_e"),
                             toDirection(axis, "axis"));
           }),
           py::arg("n_o"), py::arg("n_e"), py::arg("axis") = std::vector<double>{0, 0, 1})
      .def_readonly("n_o", &Uniaxial::n_o)
      .def_readonly("n_e", &Uniaxial::n_e)
      .def_property_readonly("axis", [](const Uniaxial& c) { return fromVec3(c.axis); })
      .def_property_readonly("is_positive", &Uniaxial::isPositive)
      .def(
          "extraordinary_index_at",
          [](const Uniaxial& c, py::array_t<double> th) {
            return py::vectorize(
                [&c](double t) { return c.extraordinaryIndexAt(checkAngle(t, "theta")); })(th);
          },
          py::arg("theta"), "n(θ), θ = wave normal to axis (rad)")
      .def(
          "extraordinary_index",
          [](const Uniaxial& c, const py::handle& s) {
            return c.extraordinaryIndex(toDirection(s, "s"));
          },
          py::arg("s"))
      .def(
          "index",
          [](const Uniaxial& c, const std::string& mode, const py::handle& s) {
            return c.index(parseMode(mode), toDirection(s, "s"));
          },
          py::arg("mode"), py::arg("s"))
      .def(
          "ray_direction",
          [](const Uniaxial& c, const std::string& mode, const py::handle& s) {
            return fromVec3(c.rayDirection(parseMode(mode), toDirection(s, "s")));
          },
          py::arg("mode"), py::arg("s"), "unit Poynting direction: s (o) or εs/|εs| (e)")
      .def(
          "walk_off_angle",
          [](const Uniaxial& c, const py::handle& s) {
            return c.walkOffAngle(toDirection(s, "s"));
          },
          py::arg("s"), "ρ = acos(s·t) ≥ 0 (rad)")
      .def(
          "walk_off_angle_at",
          [](const Uniaxial& c, py::array_t<double> th) {
            return py::vectorize(
                [&c](double t) { return c.walkOffAngleAt(checkAngle(t, "theta")); })(th);
          },
          py::arg("theta"), "signed ρ(θ) = θ_r − θ (rad); > 0: ray farther from the axis")
      .def(
          "max_walk_off_angle",
          [](const Uniaxial& c) {
            double th = 0.0;
            double r = c.maxWalkOffAngle(&th);
            return py::make_tuple(r, th);
          },
          "(ρ_max, θ at ρ_max) in radians")
      .def("epsilon", [](const Uniaxial& c) { return fromMat3(c.epsilon()); })
      .def(
          "hamiltonian_matrix",
          [](const Uniaxial& c, const std::string& mode) {
            return fromMat3(c.hamiltonianMatrix(parseMode(mode)));
          },
          py::arg("mode"))
      .def(
          "ray_velocity",
          [](const Uniaxial& c, const std::string& mode, const py::handle& p) {
            return fromVec3(c.rayVelocity(parseMode(mode), toDirection(p, "p")));
          },
          py::arg("mode"), py::arg("p"))
      .def("__repr__", [](const Uniaxial& c) {
        return "<eikon.Uniaxial n_o=" + std::to_string(c.n_o) + " n_e=" + std::to_string(c.n_e) +
               ">";
      });

  py::class_<BMMapping>(m, "BMMapping", "Beyerle–McDermid e-mode space mapping of one crystal.")
      .def(py::init<const Uniaxial&>(), py::arg("crystal"))
      .def_property_readonly("gamma", [](const BMMapping& b) { return fromMat3(b.gamma()); })
      .def_property_readonly("gamma_inverse",
                             [](const BMMapping& b) { return fromMat3(b.gammaInverse()); })
      .def("map_wave_normal",
           [](const BMMapping& b, const py::handle& s) {
             return fromVec3(b.mapWaveNormal(toDirection(s, "s")));
           })
      .def("unmap_wave_normal",
           [](const BMMapping& b, const py::handle& s) {
             return fromVec3(b.unmapWaveNormal(toDirection(s, "s")));
           })
      .def("map_normal",
           [](const BMMapping& b, const py::handle& n) {
             return fromVec3(b.mapNormal(toDirection(n, "n")));
           })
      .def("map_point",
           [](const BMMapping& b, const py::handle& x) {
             return fromVec3(b.mapPoint(toFiniteVec3(x, "x")));
           })
      .def("unmap_ray_direction",
           [](const BMMapping& b, const py::handle& t) {
             return fromVec3(b.unmapRayDirection(toDirection(t, "t")));
           })
      .def(
          "refract_e",
          [](const BMMapping& b, const py::handle& p, const py::handle& n) {
            return fromVec3(b.refractE(toDirection(p, "p_in"), toDirection(n, "normal")));
          },
          py::arg("p_in"), py::arg("normal"),
          "refracted e wave vector (|p| = n(θ)); zero when evanescent")
      .def(
          "reflect_e",
          [](const BMMapping& b, const py::handle& p, const py::handle& n) {
            return fromVec3(b.reflectE(toDirection(p, "p_in"), toDirection(n, "normal")));
          },
          py::arg("p_in"), py::arg("normal"));
}

void bindInterfaces(py::module_& m) {
  m.def(
      "refract_into_uniaxial",
      [](const py::handle& s, const py::handle& n, double n1, const Uniaxial& c) {
        return pairDict(refractIntoUniaxial(toDirection(s, "s_in"), toDirection(n, "normal"),
                                            checkIndex(n1, "n1"), c));
      },
      py::arg("s_in"), py::arg("normal"), py::arg("n1"), py::arg("crystal"),
      "{'o': wave, 'e': wave}, wave = {exists, s, n, t, q}");
  m.def(
      "refract_out_of_uniaxial",
      [](const Uniaxial& c, const std::string& mode, const py::handle& s, const py::handle& n,
         double n2) {
        return waveDict(refractOutOfUniaxial(c, parseMode(mode), toDirection(s, "s_in"),
                                             toDirection(n, "normal"), checkIndex(n2, "n2")));
      },
      py::arg("crystal"), py::arg("mode"), py::arg("s_in"), py::arg("normal"), py::arg("n2"));
  m.def(
      "reflect_inside_uniaxial",
      [](const Uniaxial& c, const std::string& mode, const py::handle& s, const py::handle& n) {
        return pairDict(reflectInsideUniaxialBoth(c, parseMode(mode), toDirection(s, "s_in"),
                                                  toDirection(n, "normal")));
      },
      py::arg("crystal"), py::arg("mode"), py::arg("s_in"), py::arg("normal"));
  m.def(
      "refract_isotropic",
      [](const py::handle& s, const py::handle& n, double n1, double n2) {
        return waveDict(refractIsotropic(toDirection(s, "s_in"), toDirection(n, "normal"),
                                         checkIndex(n1, "n1"), checkIndex(n2, "n2")));
      },
      py::arg("s_in"), py::arg("normal"), py::arg("n1"), py::arg("n2"));

  m.def(
      "fresnel_reflectance",
      [](double cos_i, double n1, double n2) {
        auto f = fresnelReflectance(checkCosine(cos_i), checkIndex(n1, "n1"), checkIndex(n2, "n2"));
        return py::make_tuple(f.Rs, f.Rp, f.R);
      },
      py::arg("cos_i"), py::arg("n1"), py::arg("n2"), "(Rs, Rp, R)");
  m.def(
      "critical_angle",
      [](double n1, double n2) {
        checkIndex(n1, "n1");
        checkIndex(n2, "n2");
        if (!(n1 > n2))
          throw std::invalid_argument(
              "no critical angle for n1 = " + formatNumber(n1) + " <= n2 = " + formatNumber(n2) +
              ": total internal reflection needs the denser medium first (n1 > n2)");
        return criticalAngle(n1, n2);
      },
      py::arg("n1"), py::arg("n2"), "asin(n2/n1) in radians; n1 > n2, else ValueError");
  m.def(
      "brewster_angle",
      [](double n1, double n2) {
        return brewsterAngle(checkIndex(n1, "n1"), checkIndex(n2, "n2"));
      },
      py::arg("n1"), py::arg("n2"));
  m.def(
      "uniaxial_entry",
      [](const py::handle& s, const py::handle& n, double n1, const Uniaxial& c, bool exact) {
        const glm::dvec3 si = toDirection(s, "s_in"), nm = toDirection(n, "normal");
        checkIndex(n1, "n1");
        return splitDict(exact ? uniaxialEntryExact(si, nm, n1, c)
                               : uniaxialEntryApprox(si, nm, n1, c));
      },
      py::arg("s_in"), py::arg("normal"), py::arg("n1"), py::arg("crystal"),
      py::arg("exact") = true, "unpolarised power split {o, e, reflected}");
  m.def(
      "uniaxial_exit",
      [](const Uniaxial& c, const std::string& mode, const py::handle& s, const py::handle& n,
         double n2, bool exact) {
        Mode md = parseMode(mode);
        const glm::dvec3 si = toDirection(s, "s_in"), nm = toDirection(n, "normal");
        checkIndex(n2, "n2");
        return splitDict(exact ? uniaxialExitExact(c, md, si, nm, n2)
                               : uniaxialExitApprox(c, md, si, nm, n2));
      },
      py::arg("crystal"), py::arg("mode"), py::arg("s_in"), py::arg("normal"), py::arg("n2"),
      py::arg("exact") = true);
  m.def(
      "pleochroism_weights",
      [](py::array_t<double> th, double no, double ne, const std::string& model) {
        PleochroismModel pm = parsePleo(model);
        checkIndex(no, "n_o");
        checkIndex(ne, "n_e");
        auto w = [=](double t) { return pleochroismWeights(checkAngle(t, "theta"), no, ne, pm); };
        auto wo = py::vectorize([=](double t) { return w(t).o; })(th);
        auto we = py::vectorize([=](double t) { return w(t).e; })(th);
        return py::make_tuple(wo, we);
      },
      py::arg("theta"), py::arg("n_o"), py::arg("n_e"), py::arg("model") = "first_order",
      "(w_o, w_e) with σ(θ) = w_o σ_o + w_e σ_e");
}
}  // namespace

void bindOptics(py::module_& m) {
  bindCrystals(m);
  bindInterfaces(m);
}

}  // namespace eikon::python
