// Python bindings of eikon (pybind11): materials and dispersion, fitting, uniaxial optics, and the
// two twins of the march (GPU ViewRenderer, CPU ReferenceMarcher) returning numpy arrays. One
// file per area (python/module_*.cpp, each with its bind function, python/module.h); renders and
// traces go through eikon::Session (core/session/session.h), as `eikon render` and `eikon trace`
// do, so both refuse the same settings with the same words (a ValueError naming the keyword).
//
// Units follow the C++ library everywhere: wavelengths in nm, lengths in mm, angles in RADIANS
// (numpy users convert with np.radians/np.degrees), directions as length-3 sequences in world
// space. Scalar functions of λ or θ accept numpy arrays and broadcast (py::vectorize).
//
//   import eikon   # after scripts/install_python.sh (setup.sh); or sys.path.insert(0,
//   "build/python") bk7 = eikon.load_material("N-BK7").n            # Dispersion
//   bk7.index([486.1327, 587.5618, 656.2725]);  bk7.abbe_number()
//   fit = eikon.fit_dispersion(lam, n, sigma, model="cauchy3");  fit.index_sigma(lam)
//   cal = eikon.Uniaxial(1.658344, 1.486130, [0, 0, 1]);  cal.walk_off_angle_at(np.radians(45))
//   sc = eikon.Scene.load("scenes/glass_sphere.json");  r = eikon.Renderer(sc)
//   img = r.render(width=160, height=120)    # (H, W, 3) float32 linear sRGB; the CLI's defaults
//   res = r.trace([0, 0, -30], [0, 0, 1], wavelength_nm=587.56)   # CLI-shaped dict, per mode
//
// Trace results. One ray gives the CLI JSON shape
//   {"wavelength_nm": W, "device": "gpu"|"cpu", "modes": [{"mode": "o", "exit_point": array(3),
//    "exit_direction", "wave_normal", "optical_path_mm", "transmittance", "left_volume", "steps",
//    "invariant_drift", "interfaces", "total_internal_reflections"}, {"mode": "e", ...}]}
// and trace_rays() gives the same keys with arrays of shape (N, 3) / (N,). Both modes appear for
// every scene: uniaxial scenes march each ray twice (GPU: ViewRenderer::traceModes, CPU:
// ReferenceMarcher::trace(..., mode 0 = o, 1 = e)); isotropic scenes march once and report the
// same outcome as "o" and "e" (as the CLI prints it). A scene whose crystals are all biaxial
// names its modes "fast" and "slow" instead (docs/biaxial-optics.md "In the renderer"). Look modes
// up by name, never by position; `modes_traced(scene)` returns the two names.
//
// Vulkan: one vk::Context is created lazily, on the first GPU call, and shared by every Renderer.
// EIKON_VALIDATION=1 enables the Khronos validation layer (the context reads it); the messages it
// collects are returned by validation_messages().
#include <pybind11/pybind11.h>

#include "python/module.h"

namespace py = pybind11;
using namespace eikon::python;

PYBIND11_MODULE(eikon, m) {
  m.doc() =
      "eikon: eikonal rendering of refractive, dispersive and birefringent objects "
      "(wavelengths nm, lengths mm, angles radians). See python/eikon_module.cpp.";
  registerErrorTranslator();
  bindDispersion(m);
  bindFitting(m);
  bindOptics(m);
  bindScene(m);
  bindRenderer(m);
  bindGem(m);
  bindAnalytic(m);
  bindVulkan(m);
  m.attr("__version__") = "0.1.0";
  // The module's Python half (python/eikon/: eikon.sweeps, `python3 -m eikon.sweeps`) is its
  // submodules: a module with __path__ is a package to the import system.
  py::list path;
  path.append(EIKON_PYTHON_PACKAGE_DIR);
  m.attr("__path__") = path;
  m.def(
      "sweep",
      [](py::args a, py::kwargs kw) {
        return py::module_::import("eikon.sweeps").attr("sweep")(*a, **kw);
      },
      "sweep(sweep, out, workers=None, scheduler=None, progress=None) -> pandas.DataFrame: many "
      "renders of one kind on Dask (eikon.sweeps.sweep; docs/sweep.md)");
}
