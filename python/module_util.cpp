// The module's shared helpers: numpy ↔ glm conversions, trace dicts, the session's setting
// errors in Python's words, and the one Vulkan context (python/module.h).
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <new>
#include <stdexcept>

#include "core/scene/limits.h"
#include "core/session/front_end.h"
#include "python/module.h"

namespace eikon::python {

glm::dvec3 toVec3(const py::handle& h) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(h);
  if (!a || a.size() != 3) throw std::invalid_argument("expected a 3-vector");
  const double* p = a.data();
  return {p[0], p[1], p[2]};
}
py::array_t<double> fromVec3(const glm::dvec3& v) {
  py::array_t<double> a(3);
  auto m = a.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < 3; ++i) m(i) = v[int(i)];
  return a;
}
py::array_t<double> fromMat3(const glm::dmat3& M) {  // glm is column-major: M[col][row]
  py::array_t<double> a({3, 3});
  auto m = a.mutable_unchecked<2>();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = M[c][r];
  return a;
}
std::vector<double> toVector(const py::handle& h) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(h);
  if (!a || a.ndim() != 1) throw std::invalid_argument("expected a 1-D sequence of numbers");
  return {a.data(), a.data() + a.size()};
}
glm::dvec3 toFiniteVec3(const py::handle& h, const char* name) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(h);
  if (!a || a.size() != 3)
    throw std::invalid_argument(std::string(name) + " must be three numbers");
  const glm::dvec3 v(a.data()[0], a.data()[1], a.data()[2]);
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(v[k]))
      throw std::invalid_argument(std::string(name) + " must be three finite numbers, got " +
                                  formatNumber(v[k]) + " on " + "xyz"[k]);
  return v;
}

glm::dvec3 toPosition(const py::handle& h, const char* name) {
  const glm::dvec3 v = toFiniteVec3(h, name);
  for (int k = 0; k < 3; ++k)
    if (std::abs(v[k]) > kMaxCoordinateMm)
      throw std::invalid_argument(std::string(name) +
                                  " must be within ±1e12 mm on each axis, got " +
                                  formatNumber(v[k]) + " on " + "xyz"[k]);
  return v;
}

glm::dvec3 toDirection(const py::handle& h, const char* name) {
  const glm::dvec3 v = toFiniteVec3(h, name);
  const double len = glm::length(v);
  if (!(len > 0)) throw std::invalid_argument(std::string(name) + " must be a non-zero vector");
  if (!std::isfinite(len))
    throw std::invalid_argument(std::string(name) + " must have a finite length (scale it down)");
  return v;
}

double checkIndex(double n, const char* name) {
  if (!(n >= kMinIndex && n <= kMaxIndex))
    throw std::invalid_argument(std::string(name) + " must be a refractive index in [" +
                                formatNumber(kMinIndex) + ", " + formatNumber(kMaxIndex) +
                                "], got " + formatNumber(n));
  return n;
}

double checkPositive(double v, const char* name) {
  if (!(v > 0) || !std::isfinite(v))
    throw std::invalid_argument(std::string(name) + " must be a finite number > 0, got " +
                                formatNumber(v));
  return v;
}

double checkWavelength(double nm, const char* name, double lo, double hi) {
  if (!(nm >= lo && nm <= hi))
    throw std::invalid_argument(std::string(name) + " must be in [" + formatNumber(lo) + ", " +
                                formatNumber(hi) + "] nm, got " + formatNumber(nm));
  return nm;
}

py::array_t<double> fromVector(const std::vector<double>& v) {
  return py::array_t<double>(py::ssize_t(v.size()), v.data());
}

Mode parseMode(const std::string& s) {
  if (s == "o" || s == "ordinary") return Mode::Ordinary;
  if (s == "e" || s == "extraordinary") return Mode::Extraordinary;
  throw std::invalid_argument("mode must be 'o' or 'e', got '" + s + "'");
}
std::string integratorName(Integrator i) {
  return i == Integrator::Euler ? "euler" : i == Integrator::Midpoint ? "midpoint" : "rk4";
}
// Python's keyword for each setting the session checks (its SettingError::setting()): the
// settings table's (core/session/settings.h); within `scope` ("march": MarchSettings's own
// attributes) without the scope's prefix.
void rethrowSetting(const SettingError& e, std::string_view scope) {
  std::string keyword = e.setting() == "dir" ? "direction" : e.setting();
  for (const Setting& s : settings())
    if (e.setting() == s.name) keyword = settingKeyword(s);
  if (!scope.empty() && keyword.size() > scope.size() &&
      keyword.compare(0, scope.size(), scope) == 0 && keyword[scope.size()] == '.')
    keyword.erase(0, scope.size() + 1);
  throw std::invalid_argument(keyword + " " + e.complaint());
}

// ---------------------------------------------------------------- errors
// pybind11 turns a C++ exception into a Python one with what() as it is; what() quotes user input
// (a file name, a material name, a JSON string), which may hold raw control characters (an ESC
// that recolours a terminal, a newline that forges a second line). The eikon command shows every
// message through printable() (core/scene/messages.h); this translator, tried before pybind11's
// own, raises the same Python exception as pybind11 would, with the message through printable().
// Python's own exceptions (error_already_set: raised in a callback) pass through untouched.
void registerErrorTranslator() {
  py::register_local_exception_translator([](std::exception_ptr p) {
    if (!p) return;
    auto raise = [](PyObject* type, const std::exception& e) {
      PyErr_SetString(type, printable(e.what()).c_str());
    };
    try {
      std::rethrow_exception(p);
    } catch (const py::error_already_set&) {
      throw;  // pybind11 restores it
    } catch (const py::value_error& e) {
      raise(PyExc_ValueError, e);
    } catch (const py::type_error& e) {
      raise(PyExc_TypeError, e);
    } catch (const py::key_error& e) {
      raise(PyExc_KeyError, e);
    } catch (const py::index_error& e) {
      raise(PyExc_IndexError, e);
    } catch (const py::builtin_exception&) {
      throw;  // the other pybind11 exceptions, as pybind11 raises them
    } catch (const std::bad_alloc&) {
      throw;  // MemoryError
    } catch (const std::out_of_range& e) {
      raise(PyExc_IndexError, e);
    } catch (const std::overflow_error& e) {
      raise(PyExc_OverflowError, e);
    } catch (const std::domain_error& e) {
      raise(PyExc_ValueError, e);
    } catch (const std::invalid_argument& e) {
      raise(PyExc_ValueError, e);
    } catch (const std::length_error& e) {
      raise(PyExc_ValueError, e);
    } catch (const std::range_error& e) {
      raise(PyExc_ValueError, e);
    } catch (const std::exception& e) {
      raise(PyExc_RuntimeError, e);
    }
  });
}

// ---------------------------------------------------------------- Vulkan context (lazy, shared)
namespace {
std::mutex g_ctx_mutex;
std::shared_ptr<vk::Context> g_ctx;
}  // namespace

std::shared_ptr<vk::Context> context() {
  std::lock_guard<std::mutex> lock(g_ctx_mutex);
  if (!g_ctx) {
    g_ctx = newContext();  // validation follows EIKON_VALIDATION=1
  }
  return g_ctx;
}

py::dict outcomeDict(const TraceOutcome& t, const char* mode) {
  py::dict d;
  d["mode"] = mode;
  d["exit_point"] = fromVec3(t.exit_point);
  d["exit_direction"] = fromVec3(t.exit_direction);
  d["wave_normal"] = fromVec3(t.wave_normal);
  d["optical_path_mm"] = t.optical_path_mm;
  d["transmittance"] = t.transmittance;
  d["left_volume"] = t.left_volume;
  d["steps"] = t.steps;
  d["invariant_drift"] = t.invariant_drift;
  d["interfaces"] = t.interfaces;
  d["total_internal_reflections"] = t.total_internal_reflections;
  return d;
}

// Column-wise arrays of many outcomes of one mode.
py::dict outcomesArrays(const std::vector<TraceOutcome>& v, const char* mode) {
  const py::ssize_t N = py::ssize_t(v.size());
  py::array_t<double> xp({N, py::ssize_t(3)}), xd({N, py::ssize_t(3)}), wn({N, py::ssize_t(3)});
  py::array_t<double> opl(N), tr(N), drift(N);
  py::array_t<bool> left(N);
  py::array_t<int> steps(N), ifc(N), tir(N);
  auto a = xp.mutable_unchecked<2>(), b = xd.mutable_unchecked<2>(), c = wn.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < N; ++i) {
    const auto& t = v[size_t(i)];
    for (int k = 0; k < 3; ++k) {
      a(i, k) = t.exit_point[k];
      b(i, k) = t.exit_direction[k];
      c(i, k) = t.wave_normal[k];
    }
    opl.mutable_at(i) = t.optical_path_mm;
    tr.mutable_at(i) = t.transmittance;
    drift.mutable_at(i) = t.invariant_drift;
    left.mutable_at(i) = t.left_volume;
    steps.mutable_at(i) = t.steps;
    ifc.mutable_at(i) = t.interfaces;
    tir.mutable_at(i) = t.total_internal_reflections;
  }
  py::dict d;
  d["mode"] = mode;
  d["exit_point"] = xp;
  d["exit_direction"] = xd;
  d["wave_normal"] = wn;
  d["optical_path_mm"] = opl;
  d["transmittance"] = tr;
  d["left_volume"] = left;
  d["steps"] = steps;
  d["invariant_drift"] = drift;
  d["interfaces"] = ifc;
  d["total_internal_reflections"] = tir;
  return d;
}

// The rows of one input of makeRequests: -1 for a single (3,) vector (or a scalar wavelength).
namespace {
py::ssize_t rows(const py::array& a, const char* what, bool vectors) {
  if (vectors) {
    if (a.ndim() == 1 && a.shape(0) == 3) return -1;
    if (a.ndim() == 2 && a.shape(1) == 3) return a.shape(0);
    throw std::invalid_argument(std::string(what) + " must have shape (3,) or (N, 3)");
  }
  if (a.ndim() == 0) return -1;
  if (a.ndim() == 1) return a.shape(0);
  throw std::invalid_argument(std::string(what) + " must be a scalar or 1-D");
}

py::ssize_t commonRows(py::ssize_t no, py::ssize_t nd, py::ssize_t nl) {
  const py::ssize_t N = std::max({no, nd, nl, py::ssize_t(1)});
  for (py::ssize_t n : {no, nd, nl})
    if (n >= 0 && n != N)
      throw std::invalid_argument("origins, directions and wavelengths disagree in length");
  return N;
}
}  // namespace

// The shapes alone (numpy arrays are looked at, not copied: a broadcast view of 1e9 rays costs
// nothing until converted).
size_t rayCount(const py::handle& origins, const py::handle& directions,
                const py::handle& wavelengths) {
  auto O = py::array::ensure(origins), D = py::array::ensure(directions),
       L = py::array::ensure(wavelengths);
  if (!O || !D || !L)
    throw std::invalid_argument("origins, directions and wavelengths must be numeric");
  return size_t(commonRows(rows(O, "origins", true), rows(D, "directions", true),
                           rows(L, "wavelengths", false)));
}

// (N,3) rays from origins/directions (each (3,) or (N,3)) and wavelengths (scalar or (N,)).
std::vector<TraceRequest> makeRequests(const py::handle& origins, const py::handle& directions,
                                       const py::handle& wavelengths) {
  auto O = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(origins);
  auto D = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(directions);
  auto L = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(wavelengths);
  if (!O || !D || !L)
    throw std::invalid_argument("origins, directions and wavelengths must be numeric");
  const py::ssize_t no = rows(O, "origins", true), nd = rows(D, "directions", true),
                    nl = rows(L, "wavelengths", false);
  const py::ssize_t N = commonRows(no, nd, nl);
  std::vector<TraceRequest> req(static_cast<size_t>(N));
  for (py::ssize_t i = 0; i < N; ++i) {
    const double* o = O.data() + (no < 0 ? 0 : 3 * i);
    const double* d = D.data() + (nd < 0 ? 0 : 3 * i);
    req[size_t(i)].origin = {o[0], o[1], o[2]};
    req[size_t(i)].direction = {d[0], d[1], d[2]};
    req[size_t(i)].wavelength_nm = L.data()[nl < 0 ? 0 : i];
  }
  return req;
}

void bindVulkan(py::module_& m) {
  m.def(
      "validation_messages",
      []() {
        std::lock_guard<std::mutex> lock(g_ctx_mutex);
        return g_ctx ? validationMessages(*g_ctx) : std::vector<std::string>{};
      },
      "messages of the Khronos validation layer so far (EIKON_VALIDATION=1); [] without a context");
  m.def(
      "device_info",
      []() {
        const DeviceInfo c = deviceInfo(*context());
        py::dict d;
        d["name"] = c.name;
        d["type"] = c.type;
        d["api_version"] = c.api_version;
        d["validation"] = c.validation;
        return d;
      },
      "create the Vulkan context if needed and describe its device");
  // Drop the module's reference to the Vulkan context before interpreter teardown (Renderers
  // still alive keep their own reference and release it when collected).
  py::module_::import("atexit").attr("register")(py::cpp_function([]() {
    std::lock_guard<std::mutex> lock(g_ctx_mutex);
    g_ctx.reset();
  }));
}

}  // namespace eikon::python
