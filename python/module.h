// What the files of the `eikon` Python module share (python/module_*.cpp): conversions between
// numpy and glm, the dicts a trace returns, and one bind function per area, called in order by
// PYBIND11_MODULE (python/eikon_module.cpp). See eikon_module.cpp for the module's conventions.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <string>
#include <vector>

#include "anisotropic/uniaxial.h"
#include "core/scene/messages.h"  // formatNumber, for messages
#include "core/session/session.h"

namespace eikon::python {
namespace py = pybind11;

// ---------------------------------------------------------------- conversions (module_util.cpp)
glm::dvec3 toVec3(const py::handle& h);
py::array_t<double> fromVec3(const glm::dvec3& v);
py::array_t<double> fromMat3(const glm::dmat3& M);
std::vector<double> toVector(const py::handle& h);
// Arguments checked as the rest of eikon checks them, each ValueError naming the argument:
/// Three finite numbers.
glm::dvec3 toFiniteVec3(const py::handle& h, const char* name);
/// A point within ±kMaxCoordinateMm mm on each axis (core/scene/limits.h), as a scene's.
glm::dvec3 toPosition(const py::handle& h, const char* name);
/// A direction: three finite numbers of non-zero, finite length (not normalised).
glm::dvec3 toDirection(const py::handle& h, const char* name);
/// A refractive index in [kMinIndex, kMaxIndex] = [1, 10] (core/scene/limits.h).
double checkIndex(double n, const char* name);
/// A finite number > 0 (a length in mm, a cell size, ...).
double checkPositive(double v, const char* name);
/// A wavelength in [lo, hi] nm.
double checkWavelength(double nm, const char* name, double lo, double hi);
py::array_t<double> fromVector(const std::vector<double>& v);
Mode parseMode(const std::string& s);
std::string integratorName(Integrator i);
/// A SettingError of the session (core/session/session.h) as Python's ValueError, the setting
/// named by its keyword here ("light-splat" → "splat", the settings table's); the complaint is the
/// CLI's, word for word. Within `scope` ("march": MarchSettings itself) its prefix is dropped
/// ("march.integrator" → "integrator").
[[noreturn]] void rethrowSetting(const SettingError& e, std::string_view scope = {});
/// Makes every exception leaving the module raise as pybind11 would raise it, with its message
/// through printable() (core/scene/messages.h), as the eikon command shows it. Called first by
/// PYBIND11_MODULE.
void registerErrorTranslator();
/// Runs a session check, turning its SettingError into rethrowSetting's ValueError.
template <class F>
void checkSetting(F&& check, std::string_view scope = {}) {
  try {
    check();
  } catch (const SettingError& e) {
    rethrowSetting(e, scope);
  }
}

// ---------------------------------------------------------------- traces (module_util.cpp)
py::dict outcomeDict(const TraceOutcome& t, const char* mode);
/// Column-wise arrays of many outcomes of one mode.
py::dict outcomesArrays(const std::vector<TraceOutcome>& v, const char* mode);
/// The number of rays makeRequests would make, from the shapes alone (nothing is copied).
size_t rayCount(const py::handle& origins, const py::handle& directions,
                const py::handle& wavelengths);
/// (N,3) rays from origins/directions (each (3,) or (N,3)) and wavelengths (scalar or (N,)).
std::vector<TraceRequest> makeRequests(const py::handle& origins, const py::handle& directions,
                                       const py::handle& wavelengths);

// ---------------------------------------------------------------- Vulkan (module_util.cpp)
/// The module's one Vulkan context, made on the first GPU call and shared by every Renderer.
std::shared_ptr<vk::Context> context();

// ---------------------------------------------------------------- one per area
void bindDispersion(py::module_& m);  // module_dispersion.cpp: Dispersion, Material, library
void bindFitting(py::module_& m);     // module_fitting.cpp: index data, fits
void bindOptics(py::module_& m);      // module_optics.cpp: Uniaxial, BMMapping, interfaces
void bindScene(py::module_& m);       // module_scene.cpp: MarchSettings, Camera, VolumeSpec, Scene
void bindRenderer(py::module_& m);    // module_render.cpp: Renderer, render(), trace()
void bindGem(py::module_& m);         // module_gem.cpp: gem() (`eikon gem`)
void bindAnalytic(py::module_& m);    // module_analytic.cpp: AnalyticField
void bindVulkan(py::module_& m);      // module_util.cpp: validation_messages, device_info

}  // namespace eikon::python
