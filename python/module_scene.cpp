// Scenes (eikon.Scene, its Camera and VolumeSpec) and the march settings renders and traces take.
#include <pybind11/functional.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "core/scene/scene.h"
#include "python/module.h"

namespace eikon::python {
namespace {
// "full" or "single" (MarchSettings::transport); anything else is a ValueError.
Transport parseTransportName(const std::string& name) {
  if (name == "full") return Transport::Full;
  if (name == "single") return Transport::Single;
  throw py::value_error("transport must be full or single, not '" + name + "'");
}

std::vector<std::string> modesTraced(const Scene& s) {
  // Both twins march the e-mode of uniaxial crystals (the slow mode of biaxial ones); an isotropic
  // scene's e-mode is its o-mode.
  return {modeName(0, s.fastSlowModes()), modeName(1, s.fastSlowModes())};
}
}  // namespace

void bindScene(py::module_& m) {
  py::class_<MarchSettings>(m, "MarchSettings")
      .def(py::init([](double step_voxels, const std::string& integrator, bool skip_empty,
                       bool fresnel, double interface_threshold, int max_steps,
                       const std::string& transport, int max_reflections) {
             MarchSettings s;
             s.step_voxels = step_voxels;
             checkSetting([&] { s.integrator = parseIntegrator(integrator); }, "march");
             s.skip_empty = skip_empty;
             s.fresnel = fresnel;
             s.interface_threshold = interface_threshold;
             s.max_steps = max_steps;
             s.transport = parseTransportName(transport);
             s.max_reflections = max_reflections;
             return s;
           }),
           py::arg("step_voxels") = 0.25, py::arg("integrator") = "rk4",
           py::arg("skip_empty") = true, py::arg("fresnel") = true,
           py::arg("interface_threshold") = 0.02, py::arg("max_steps") = 20000,
           py::arg("transport") = "full", py::arg("max_reflections") = 32)
      .def_readwrite("step_voxels", &MarchSettings::step_voxels)
      .def_property(
          "integrator", [](const MarchSettings& s) { return integratorName(s.integrator); },
          [](MarchSettings& s, const std::string& v) {
            checkSetting([&] { s.integrator = parseIntegrator(v); }, "march");
          })
      .def_readwrite("skip_empty", &MarchSettings::skip_empty)
      .def_readwrite("fresnel", &MarchSettings::fresnel)
      .def_readwrite("interface_threshold", &MarchSettings::interface_threshold)
      .def_readwrite("max_steps", &MarchSettings::max_steps)
      .def_property(
          "transport",
          [](const MarchSettings& s) { return s.transport == Transport::Full ? "full" : "single"; },
          [](MarchSettings& s, const std::string& v) { s.transport = parseTransportName(v); })
      .def_readwrite("max_reflections", &MarchSettings::max_reflections)
      .def("__repr__", [](const MarchSettings& s) {
        return "<eikon.MarchSettings step_voxels=" + std::to_string(s.step_voxels) + " " +
               integratorName(s.integrator) + ">";
      });

  // ------------------------------------------------------------ scenes
  py::class_<Camera>(m, "Camera")
      .def_property(
          "position", [](const Camera& c) { return fromVec3(c.position); },
          [](Camera& c, const py::handle& v) { c.position = toVec3(v); })
      .def_property(
          "look_at", [](const Camera& c) { return fromVec3(c.look_at); },
          [](Camera& c, const py::handle& v) { c.look_at = toVec3(v); })
      .def_property(
          "up", [](const Camera& c) { return fromVec3(c.up); },
          [](Camera& c, const py::handle& v) { c.up = toVec3(v); })
      .def_readwrite("fov_deg", &Camera::fov_deg)
      .def_readwrite("width", &Camera::width)
      .def_readwrite("height", &Camera::height);
  py::class_<VolumeSpec>(m, "VolumeSpec")
      .def_property(
          "bounds_min", [](const VolumeSpec& v) { return fromVec3(v.bounds_min); },
          [](VolumeSpec& v, const py::handle& x) { v.bounds_min = toVec3(x); })
      .def_property(
          "bounds_max", [](const VolumeSpec& v) { return fromVec3(v.bounds_max); },
          [](VolumeSpec& v, const py::handle& x) { v.bounds_max = toVec3(x); })
      .def_readwrite("resolution", &VolumeSpec::resolution)
      .def_readwrite("smoothing_voxels", &VolumeSpec::smoothing_voxels);

  // Scenes are held by shared_ptr so that a Renderer keeps its scene alive. Edit camera/volume
  // BEFORE creating a Renderer: the volume is voxelised once, on the Renderer's first use.
  py::class_<Scene, std::shared_ptr<Scene>>(m, "Scene")
      .def_static(
          "load", [](const std::string& path) { return std::make_shared<Scene>(loadScene(path)); },
          py::arg("path"))
      .def_static(
          "parse",
          [](py::object json, const std::string& origin) {
            std::string text =
                py::isinstance<py::str>(json)
                    ? json.cast<std::string>()
                    : py::module_::import("json").attr("dumps")(json).cast<std::string>();
            return std::make_shared<Scene>(parseScene(text, origin));
          },
          py::arg("json"), py::arg("origin") = "<python>",
          "from JSON text or a dict (library materials resolved by name)")
      .def_property_readonly("file", [](const Scene& s) { return s.file.string(); })
      .def_readwrite("camera", &Scene::camera)
      .def_readwrite("volume", &Scene::volume)
      .def_readonly("warnings", &Scene::warnings)
      .def_readonly("ambient_index", &Scene::ambient_index)
      .def_property_readonly(
          "render",
          [](const Scene& s) {
            auto value = [](const auto& v) { return v ? py::cast(*v) : py::none(); };
            py::dict d;
            d["spp"] = value(s.render.spp);
            d["wavelengths"] = value(s.render.wavelengths);
            d["exposure"] = value(s.render.exposure);
            return d;
          },
          "the scene's \"render\" (its intended spp, wavelengths and exposure; None where it "
          "gives none): render()'s defaults")
      .def_property_readonly("materials", [](const Scene& s) { return s.materials; })
      .def_property_readonly("any_uniaxial", &Scene::anyUniaxial)
      .def_property_readonly("any_dispersive", &Scene::anyDispersive)
      .def("environment_lookup", [](const Scene& s, const py::handle& d) {
        return fromVec3(s.environment.lookup(toVec3(d)));
      });
  m.def(
      "load_scene",
      [](const std::string& path) { return std::make_shared<Scene>(loadScene(path)); },
      py::arg("path"));
  m.def(
      "modes_traced", [](const Scene& s) { return modesTraced(s); }, py::arg("scene"),
      "modes trace() reports for this scene: ['o', 'e'] (isotropic: e identical to o), or "
      "['fast', 'slow'] where its crystals are all biaxial");
}

}  // namespace eikon::python
