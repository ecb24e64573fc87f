// Python bindings of eikon (pybind11): materials and dispersion, fitting, uniaxial optics, and the
// two twins of the march (GPU ViewRenderer, CPU ReferenceMarcher) returning numpy arrays.
//
// Units follow the C++ library everywhere: wavelengths in nm, lengths in mm, angles in RADIANS
// (numpy users convert with np.radians/np.degrees), directions as length-3 sequences in world
// space. Scalar functions of λ or θ accept numpy arrays and broadcast (py::vectorize).
//
//   import eikon   # after scripts/install_python.sh (setup.sh); or sys.path.insert(0, "build/python")
//   bk7 = eikon.load_material("N-BK7").n            # Dispersion
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
// same outcome as "o" and "e" (as the CLI prints it). Look modes up by name, never by position;
// `modes_traced(scene)` returns ['o', 'e'].
//
// Vulkan: one vk::Context is created lazily, on the first GPU call, and shared by every Renderer.
// EIKON_VALIDATION=1 enables the Khronos validation layer (the context reads it); the messages it
// collects are returned by validation_messages().
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <array>
#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/io/exr.h"
#include "core/light/light_cache.h"
#include "core/reference/reference_lighting.h"
#include "core/reference/reference_marcher.h"
#include "core/render/light_transport.h"
#include "core/render/render_defaults.h"
#include "core/render/view_renderer.h"
#include "core/scene/scene.h"
#include "core/vk/context.h"
#include "core/volume/march_types.h"
#include "core/volume/volume_set.h"
#include "fitting/fitting.h"
#include "fitting/index_data.h"
#include "optics/bm_mapping.h"
#include "optics/dispersion.h"
#include "optics/fresnel.h"
#include "optics/interface.h"
#include "optics/pleochroism.h"
#include "optics/uniaxial.h"

namespace py = pybind11;
using namespace eikon;

namespace {

// ---------------------------------------------------------------- small conversions
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
py::array_t<double> fromVector(const std::vector<double>& v) { return py::array_t<double>(py::ssize_t(v.size()), v.data()); }

Mode parseMode(const std::string& s) {
  if (s == "o" || s == "ordinary") return Mode::Ordinary;
  if (s == "e" || s == "extraordinary") return Mode::Extraordinary;
  throw std::invalid_argument("mode must be 'o' or 'e', got '" + s + "'");
}
Integrator parseIntegrator(const std::string& s) {
  if (s == "euler") return Integrator::Euler;
  if (s == "midpoint") return Integrator::Midpoint;
  if (s == "rk4") return Integrator::RK4;
  throw std::invalid_argument("integrator must be 'euler', 'midpoint' or 'rk4', got '" + s + "'");
}
std::string integratorName(Integrator i) {
  return i == Integrator::Euler ? "euler" : i == Integrator::Midpoint ? "midpoint" : "rk4";
}
PleochroismModel parsePleo(const std::string& s) {
  if (s == "first_order") return PleochroismModel::FirstOrder;
  if (s == "tevs") return PleochroismModel::TevsThesis;
  throw std::invalid_argument("pleochroism model must be 'first_order' or 'tevs'");
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

// ---------------------------------------------------------------- Vulkan context (lazy, shared)
std::mutex g_ctx_mutex;
std::shared_ptr<vk::Context> g_ctx;
std::shared_ptr<vk::Context> context() {
  std::lock_guard<std::mutex> lock(g_ctx_mutex);
  if (!g_ctx) {
    vk::ContextOptions opt;  // validation follows EIKON_VALIDATION=1
    g_ctx = std::shared_ptr<vk::Context>(vk::Context::create(opt).release());
  }
  return g_ctx;
}

// ---------------------------------------------------------------- fields and tracing helpers
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

// (N,3) rays from origins/directions (each (3,) or (N,3)) and wavelengths (scalar or (N,)).
std::vector<TraceRequest> makeRequests(const py::handle& origins, const py::handle& directions,
                                       const py::handle& wavelengths) {
  auto O = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(origins);
  auto D = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(directions);
  auto L = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(wavelengths);
  if (!O || !D || !L) throw std::invalid_argument("origins, directions and wavelengths must be numeric");
  auto rows = [](const py::array_t<double>& a, const char* what) -> py::ssize_t {
    if (a.ndim() == 1 && a.shape(0) == 3) return -1;
    if (a.ndim() == 2 && a.shape(1) == 3) return a.shape(0);
    throw std::invalid_argument(std::string(what) + " must have shape (3,) or (N, 3)");
  };
  py::ssize_t no = rows(O, "origins"), nd = rows(D, "directions");
  py::ssize_t nl = L.ndim() == 0 ? -1 : (L.ndim() == 1 ? L.shape(0) : -2);
  if (nl == -2) throw std::invalid_argument("wavelengths must be a scalar or 1-D");
  py::ssize_t N = std::max({no, nd, nl, py::ssize_t(1)});
  for (py::ssize_t n : {no, nd, nl})
    if (n >= 0 && n != N) throw std::invalid_argument("origins, directions and wavelengths disagree in length");
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

py::array_t<float> imageArray(const RenderImage& img) {
  py::array_t<float> a({py::ssize_t(img.height), py::ssize_t(img.width), py::ssize_t(3)});
  std::copy(img.rgb.begin(), img.rgb.end(), a.mutable_data());
  return a;
}

// Voxelisations done by this module (eikon.voxelize_count()): lets tests see that a cached
// prepared scene is reused instead of voxelised again.
std::atomic<long> g_voxelizations{0};

// A scene prepared for marching: the voxelised volume, plus (lazily) the GPU renderer and the
// CPU reference. Owns everything the renderers reference, at stable addresses.
struct Prepared {
  std::shared_ptr<Scene> scene;
  std::unique_ptr<VolumeSet> volume;
  std::shared_ptr<vk::Context> ctx;
  std::unique_ptr<ViewRenderer> gpu;
  std::unique_ptr<VolumeField> field;
  std::unique_ptr<ReferenceMarcher> cpu;
  VolumeSpec voxelized_spec;  ///< scene->volume when `volume` was made (for the module cache)

  explicit Prepared(std::shared_ptr<Scene> s) : scene(std::move(s)) {}
  void ensureVolume(bool for_gpu) {
    if (for_gpu && !ctx) {
      ctx = context();
      checkVolumeFits(*ctx, makeGrid(scene->volume), *scene);
    }
    if (!volume) {
      py::gil_scoped_release release;
      volume = std::make_unique<VolumeSet>(voxelize(*scene));
      voxelized_spec = scene->volume;
      ++g_voxelizations;
    }
  }
  void dropRenderers() {  // after the light volumes change: rebuilt on their next use
    gpu.reset();
    cpu.reset();
    field.reset();
  }
  // As `eikon render` does by default: a scene with lights gets its light simulated before the
  // first render (unless simulate_light() already did), by the twin lightOnCpu() picks (the CPU
  // reference for CPU renders, as --reference), through the CLI's light cache when `cache_dir` is
  // not empty. Returns whether the light was taken from the cache.
  bool ensureLit(bool cpu_render, const std::string& cache_dir, int threads) {
    if (scene->lights.empty()) return false;
    ensureVolume(!cpu_render);
    if (volume->lit()) return false;
    LightingOptions lo = defaultLightingOptions();
    lo.wave.threads = threads;
    if (!cpu_render && !ctx) ctx = context();
    const bool on_cpu = cpu_render || lightOnCpu("auto", ctx.get());
    bool cached = false;
    {
      py::gil_scoped_release release;
      const uint64_t key = cache_dir.empty() ? 0 : lightCacheKey(*scene, *volume, lo, on_cpu);
      if (!cache_dir.empty() && loadLightCache(cache_dir, key, *volume)) {
        cached = true;
      } else {
        if (on_cpu)
          simulateLightingReference(*scene, *volume, lo);
        else
          simulateLighting(*ctx, *scene, *volume, lo);
        // A cache that cannot be written only costs time next time.
        if (!cache_dir.empty()) saveLightCache(cache_dir, key, *volume);
      }
    }
    dropRenderers();
    return cached;
  }
  ViewRenderer& gpuRenderer() {
    ensureVolume(true);
    if (!gpu) gpu = std::make_unique<ViewRenderer>(*ctx, *scene, *volume);
    return *gpu;
  }
  ReferenceMarcher& cpuMarcher() {
    ensureVolume(false);
    if (!cpu) {
      field = std::make_unique<VolumeField>(*volume);
      cpu = std::make_unique<ReferenceMarcher>(*field, scene->environment);
    }
    return *cpu;
  }
};

bool sameSpec(const VolumeSpec& a, const VolumeSpec& b) {
  return a.bounds_min == b.bounds_min && a.bounds_max == b.bounds_max &&
         a.resolution == b.resolution && a.smoothing_voxels == b.smoothing_voxels &&
         a.smoothing == b.smoothing;
}

// The module-level render()/trace() keep the last scene they prepared: a second call with the
// same Scene object (and the same volume settings) reuses its voxelised volume, GPU renderer and
// light volumes instead of voxelising again. Camera edits need nothing (renders read the camera);
// a changed `scene.volume` or another Scene object prepares afresh. Only one scene is kept (a
// volume can take hundreds of MB); eikon.clear_cache() drops it.
std::shared_ptr<Prepared> g_last_prepared;
std::weak_ptr<Scene> g_last_scene;
std::mutex g_prepared_mutex;

std::shared_ptr<Prepared> cachedPrepared(const std::shared_ptr<Scene>& s) {
  std::lock_guard<std::mutex> lock(g_prepared_mutex);
  if (g_last_prepared && g_last_scene.lock() == s &&
      (!g_last_prepared->volume || sameSpec(g_last_prepared->voxelized_spec, s->volume)))
    return g_last_prepared;
  g_last_prepared = std::make_shared<Prepared>(s);
  g_last_scene = s;
  return g_last_prepared;
}

std::string lightCacheDir(const py::object& light_cache) {
  if (light_cache.is_none()) return {};
  if (py::isinstance<py::bool_>(light_cache))
    return light_cache.cast<bool>() ? defaultLightCacheDir().string() : std::string();
  return py::str(light_cache).cast<std::string>();
}

std::vector<std::string> modesTraced(const Scene&) {
  // Both twins march the e-mode of uniaxial crystals; an isotropic scene's e-mode is its o-mode.
  return {"o", "e"};
}

// Both modes {o, e} of each ray. Isotropic scenes: one march, duplicated (the e-mode is identical
// by definition, and ViewRenderer::traceModes would only march it again).
std::vector<std::array<TraceOutcome, 2>> traceBoth(Prepared& p, const std::vector<TraceRequest>& req,
                                                   const MarchSettings& ms, bool gpu) {
  const bool uni = p.scene->anyUniaxial();
  std::vector<std::array<TraceOutcome, 2>> out;
  if (gpu) {
    ViewRenderer& r = p.gpuRenderer();
    py::gil_scoped_release release;
    if (uni) {
      out = r.traceModes(req, ms);
    } else {
      auto o = r.trace(req, ms);
      out.reserve(o.size());
      for (const auto& t : o) out.push_back({t, t});
    }
  } else {
    ReferenceMarcher& r = p.cpuMarcher();
    py::gil_scoped_release release;
    out.reserve(req.size());
    for (const auto& q : req) {
      TraceOutcome o = r.trace(q, ms, 0);
      out.push_back({o, uni ? r.trace(q, ms, 1) : o});
    }
  }
  if (out.size() != req.size()) throw std::runtime_error("trace: outcome count differs from the ray count");
  return out;
}

bool isGpu(const std::string& device) {
  if (device == "gpu") return true;
  if (device == "cpu") return false;
  throw std::invalid_argument("device must be 'gpu' or 'cpu', got '" + device + "'");
}

// An analytic field for the CPU reference: a named closed-form profile or a Python callable.
struct AnalyticSpec {
  std::shared_ptr<AnalyticField> field;
  Environment env;
};

}  // namespace

PYBIND11_MODULE(eikon, m) {
  m.doc() = "eikon: eikonal rendering of refractive, dispersive and birefringent objects "
            "(wavelengths nm, lengths mm, angles radians). See python/eikon_module.cpp.";

  // ------------------------------------------------------------ dispersion
  py::dict fr;
  fr["F"] = fraunhofer::F;
  fr["d"] = fraunhofer::d;
  fr["D"] = fraunhofer::D;
  fr["C"] = fraunhofer::C;
  m.attr("FRAUNHOFER") = fr;

  py::class_<Dispersion>(m, "Dispersion", "n(λ) of one material or mode; λ in nm.")
      .def_static("constant", &Dispersion::constant, py::arg("n"))
      .def_static("cauchy", [](const py::handle& c) { return Dispersion::cauchy(toVector(c)); }, py::arg("coeffs"),
                  "n = Σ c_k/λ^{2k}, λ in µm")
      .def_static("sellmeier", [](const py::handle& b, const py::handle& c) {
                    return Dispersion::sellmeier(toVector(b), toVector(c)); }, py::arg("B"), py::arg("C"),
                  "SCHOTT Sellmeier, C in µm²")
      .def_static("conrady", &Dispersion::conrady, py::arg("n0"), py::arg("A"), py::arg("B"),
                  "n = n0 + A/λ + B/λ^3.5, λ in µm")
      .def("with_range", [](Dispersion d, double lo, double hi) { d.withRange(lo, hi); return d; },
           py::arg("lo_nm"), py::arg("hi_nm"))
      .def_property_readonly("kind", [](const Dispersion& d) -> const char* {
        switch (d.kind()) {
          case Dispersion::Kind::Constant: return "constant";
          case Dispersion::Kind::Cauchy: return "cauchy";
          case Dispersion::Kind::Sellmeier: return "sellmeier";
          case Dispersion::Kind::Conrady: return "conrady";
        }
        return "unknown"; })
      .def_property_readonly("coefficients", [](const Dispersion& d) { return fromVector(d.coefficients()); })
      .def_property_readonly("sellmeier_c", [](const Dispersion& d) { return fromVector(d.sellmeierC()); })
      .def_property_readonly("range_nm", [](const Dispersion& d) -> py::object {
        if (!d.rangeNm()) return py::none();
        return py::make_tuple((*d.rangeNm())[0], (*d.rangeNm())[1]); })
      .def("index", [](const Dispersion& d, py::array_t<double> l) {
             return py::vectorize([&d](double x) { return d.index(x); })(l); }, py::arg("lambda_nm"),
           "n(λ), broadcasting over arrays")
      .def("derivative", [](const Dispersion& d, py::array_t<double> l) {
             return py::vectorize([&d](double x) { return d.derivative(x); })(l); }, py::arg("lambda_nm"),
           "dn/dλ in 1/nm")
      .def("abbe_number", &Dispersion::abbeNumber, "V_d = (n_d − 1)/(n_F − n_C)")
      .def("cauchy_approximation", [](const Dispersion& d, double lo, double hi) {
             auto c = d.cauchyApproximation(lo, hi);
             py::dict r;
             r["coeffs"] = py::make_tuple(c.coeffs[0], c.coeffs[1], c.coeffs[2]);
             r["max_error"] = c.max_error;
             r["rms_error"] = c.rms_error;
             return r; }, py::arg("lo_nm"), py::arg("hi_nm"))
      .def("describe", &Dispersion::describe)
      .def("__repr__", [](const Dispersion& d) { return "<eikon.Dispersion " + d.describe() + ">"; });

  py::class_<Material>(m, "Material", "A material from the library or a scene (read-only view).")
      .def_readonly("name", &Material::name)
      .def_readonly("source", &Material::source)
      .def_readonly("uniaxial", &Material::uniaxial)
      .def_property_readonly("n", [](const Material& x) { return x.n_o; }, "index (isotropic) = n_o")
      .def_readonly("n_o", &Material::n_o)
      .def_readonly("n_e", &Material::n_e)
      .def_property_readonly("optic_axis", [](const Material& x) -> py::object {
        return x.optic_axis ? py::object(fromVec3(*x.optic_axis)) : py::none(); })
      .def("uniaxial_at", [](const Material& x, double lambda_nm, py::object axis) {
             if (!x.uniaxial) throw std::invalid_argument(x.name + " is not uniaxial");
             glm::dvec3 a = axis.is_none() ? x.optic_axis.value_or(glm::dvec3(0, 0, 1)) : toVec3(axis);
             return Uniaxial(x.n_o.index(lambda_nm), x.n_e.index(lambda_nm), a); },
           py::arg("lambda_nm"), py::arg("axis") = py::none(), "the crystal at one wavelength")
      .def("__repr__", [](const Material& x) { return "<eikon.Material " + x.name + (x.uniaxial ? " (uniaxial)>" : ">"); });

  m.def("load_material", [](const std::string& name_or_path) {
          std::filesystem::path p(name_or_path);
          if (p.extension() == ".json" && std::filesystem::exists(p)) return loadMaterialFile(p);
          for (const auto& dir : materialSearchPath()) {
            auto f = dir / (name_or_path + ".json");
            if (std::filesystem::exists(f)) return loadMaterialFile(f);
          }
          throw std::invalid_argument("no material '" + name_or_path + "' in the library search path");
        }, py::arg("name_or_path"), "a library material by name (materials/<name>.json) or a material file");
  m.def("material_search_path", &materialSearchPath);

  // ------------------------------------------------------------ index data and fitting
  py::class_<IndexSeries>(m, "IndexSeries")
      .def_readonly("label", &IndexSeries::label)
      .def_property_readonly("lambda_nm", [](const IndexSeries& s) { return fromVector(s.lambda_nm); })
      .def_property_readonly("n", [](const IndexSeries& s) { return fromVector(s.n); })
      .def_property_readonly("sigma", [](const IndexSeries& s) -> py::object {
        return s.sigma.empty() ? py::none() : py::object(fromVector(s.sigma)); })
      .def("__len__", &IndexSeries::size);
  py::class_<IndexData>(m, "IndexData")
      .def_readonly("source", &IndexData::source)
      .def_readonly("modes", &IndexData::modes)
      .def_readonly("warnings", &IndexData::warnings)
      .def_property_readonly("uniaxial", &IndexData::uniaxial)
      .def("__getitem__", [](const IndexData& d, const std::string& label) {
        for (const auto& s : d.modes)
          if (s.label == label) return s;
        throw py::key_error(label); });
  auto readOpts = [](std::optional<std::pair<double, double>> w) {
    IndexReadOptions o;
    if (w) o.window_nm = std::array<double, 2>{w->first, w->second};
    return o;
  };
  m.def("read_index_data", [readOpts](const std::string& path, std::optional<std::pair<double, double>> window) {
          return readIndexData(path, readOpts(window)); }, py::arg("path"), py::arg("window_nm") = py::none(),
        "CSV (wavelength_nm,n[,sigma] or ...,n_o,n_e[,...]) or refractiveindex.info YAML");
  m.def("parse_index_csv", [readOpts](const std::string& text, const std::string& name,
                                      std::optional<std::pair<double, double>> window) {
          return parseIndexCsv(text, name, readOpts(window)); },
        py::arg("text"), py::arg("name") = "<string>", py::arg("window_nm") = py::none());

  py::class_<FitResult>(m, "FitResult")
      .def_property_readonly("model", [](const FitResult& r) { return modelName(r.model); })
      .def_readonly("label", &FitResult::label)
      .def_property_readonly("names", [](const FitResult& r) { return parameterNames(r.model); })
      .def_property_readonly("coeffs", [](const FitResult& r) { return fromVector(r.coeffs); })
      .def_property_readonly("sigma", [](const FitResult& r) { return fromVector(r.sigma); })
      .def_property_readonly("covariance", [](const FitResult& r) {
        py::ssize_t P = py::ssize_t(r.coeffs.size());
        py::array_t<double> c({P, P});
        std::copy(r.covariance.begin(), r.covariance.end(), c.mutable_data());
        return c; })
      .def_readonly("points", &FitResult::points)
      .def_readonly("weighted", &FitResult::weighted)
      .def_readonly("chi2", &FitResult::chi2)
      .def_readonly("chi2_reduced", &FitResult::chi2_reduced)
      .def_readonly("residual_std", &FitResult::residual_std)
      .def_readonly("rms", &FitResult::rms)
      .def_readonly("max_residual", &FitResult::max_residual)
      .def_property_readonly("range_nm", [](const FitResult& r) { return py::make_tuple(r.range_nm[0], r.range_nm[1]); })
      .def_readonly("n_F", &FitResult::n_F)
      .def_readonly("n_d", &FitResult::n_d)
      .def_readonly("n_C", &FitResult::n_C)
      .def_readonly("abbe", &FitResult::abbe)
      .def_readonly("iterations", &FitResult::iterations)
      .def_readonly("warnings", &FitResult::warnings)
      .def("dispersion", &FitResult::dispersion, "the fitted curve as a Dispersion (cauchy, sellmeier or conrady)")
      .def("index", [](const FitResult& r, py::array_t<double> l) {
             return py::vectorize([&r](double x) { return modelIndex(r.model, r.coeffs.data(), x); })(l); },
           py::arg("lambda_nm"), "fitted n(λ)")
      .def("index_sigma", [](const FitResult& r, py::array_t<double> l) {
             // 1σ of the fitted curve: sqrt(Jᵀ C J), J = ∂n/∂p at λ (linear error propagation).
             const size_t P = r.coeffs.size();
             return py::vectorize([&r, P](double x) {
               std::vector<double> J(P);
               modelIndex(r.model, r.coeffs.data(), x, J.data());
               double v = 0.0;
               for (size_t i = 0; i < P; ++i)
                 for (size_t j = 0; j < P; ++j) v += J[i] * r.covariance[i * P + j] * J[j];
               return std::sqrt(std::max(v, 0.0));
             })(l); },
           py::arg("lambda_nm"), "1σ band of the fitted n(λ) from the coefficient covariance")
      .def("__repr__", [](const FitResult& r) {
        return "<eikon.FitResult " + modelName(r.model) + " " + r.label + " N=" + std::to_string(r.points) + ">"; });

  m.def("fit_dispersion", [](const py::handle& lambda_nm, const py::handle& n, const py::object& sigma,
                             const std::string& model, std::optional<double> huber_delta, const std::string& label,
                             int max_iterations) {
          IndexSeries s;
          s.label = label;
          s.lambda_nm = toVector(lambda_nm);
          s.n = toVector(n);
          if (!sigma.is_none()) s.sigma = toVector(sigma);
          FitOptions o;
          o.model = parseDispersionModel(model);
          o.huber_delta = huber_delta;
          o.max_iterations = max_iterations;
          py::gil_scoped_release release;
          return fitDispersion(s, o);
        }, py::arg("lambda_nm"), py::arg("n"), py::arg("sigma") = py::none(), py::arg("model") = "cauchy3",
        py::arg("huber_delta") = py::none(), py::arg("label") = "n", py::arg("max_iterations") = 200,
        "Weighted (robust) least-squares fit: cauchy2|cauchy3|sellmeier1..3|conrady");
  m.def("fit_series", [](const IndexSeries& s, const std::string& model, std::optional<double> huber_delta) {
          FitOptions o;
          o.model = parseDispersionModel(model);
          o.huber_delta = huber_delta;
          py::gil_scoped_release release;
          return fitDispersion(s, o);
        }, py::arg("series"), py::arg("model") = "cauchy3", py::arg("huber_delta") = py::none());

  // ------------------------------------------------------------ uniaxial optics
  py::class_<Uniaxial>(m, "Uniaxial", "A homogeneous uniaxial crystal at one wavelength (angles in radians).")
      .def(py::init([](double no, double ne, const py::handle& axis) { return Uniaxial(no, ne, toVec3(axis)); }),
           py::arg("n_o"), py::arg("n_e"), py::arg("axis") = std::vector<double>{0, 0, 1})
      .def_readonly("n_o", &Uniaxial::n_o)
      .def_readonly("n_e", &Uniaxial::n_e)
      .def_property_readonly("axis", [](const Uniaxial& c) { return fromVec3(c.axis); })
      .def_property_readonly("is_positive", &Uniaxial::isPositive)
      .def("extraordinary_index_at", [](const Uniaxial& c, py::array_t<double> th) {
             return py::vectorize([&c](double t) { return c.extraordinaryIndexAt(t); })(th); }, py::arg("theta"),
           "n(θ), θ = wave normal to axis (rad)")
      .def("extraordinary_index", [](const Uniaxial& c, const py::handle& s) { return c.extraordinaryIndex(toVec3(s)); },
           py::arg("s"))
      .def("index", [](const Uniaxial& c, const std::string& mode, const py::handle& s) {
             return c.index(parseMode(mode), toVec3(s)); }, py::arg("mode"), py::arg("s"))
      .def("ray_direction", [](const Uniaxial& c, const std::string& mode, const py::handle& s) {
             return fromVec3(c.rayDirection(parseMode(mode), toVec3(s))); }, py::arg("mode"), py::arg("s"),
           "unit Poynting direction: s (o) or εs/|εs| (e)")
      .def("walk_off_angle", [](const Uniaxial& c, const py::handle& s) { return c.walkOffAngle(toVec3(s)); },
           py::arg("s"), "ρ = acos(s·t) ≥ 0 (rad)")
      .def("walk_off_angle_at", [](const Uniaxial& c, py::array_t<double> th) {
             return py::vectorize([&c](double t) { return c.walkOffAngleAt(t); })(th); }, py::arg("theta"),
           "signed ρ(θ) = θ_r − θ (rad); > 0: ray farther from the axis")
      .def("max_walk_off_angle", [](const Uniaxial& c) {
             double th = 0.0;
             double r = c.maxWalkOffAngle(&th);
             return py::make_tuple(r, th); }, "(ρ_max, θ at ρ_max) in radians")
      .def("epsilon", [](const Uniaxial& c) { return fromMat3(c.epsilon()); })
      .def("hamiltonian_matrix", [](const Uniaxial& c, const std::string& mode) {
             return fromMat3(c.hamiltonianMatrix(parseMode(mode))); }, py::arg("mode"))
      .def("ray_velocity", [](const Uniaxial& c, const std::string& mode, const py::handle& p) {
             return fromVec3(c.rayVelocity(parseMode(mode), toVec3(p))); }, py::arg("mode"), py::arg("p"))
      .def("__repr__", [](const Uniaxial& c) {
        return "<eikon.Uniaxial n_o=" + std::to_string(c.n_o) + " n_e=" + std::to_string(c.n_e) + ">"; });

  py::class_<BMMapping>(m, "BMMapping", "Beyerle–McDermid e-mode space mapping of one crystal.")
      .def(py::init<const Uniaxial&>(), py::arg("crystal"))
      .def_property_readonly("gamma", [](const BMMapping& b) { return fromMat3(b.gamma()); })
      .def_property_readonly("gamma_inverse", [](const BMMapping& b) { return fromMat3(b.gammaInverse()); })
      .def("map_wave_normal", [](const BMMapping& b, const py::handle& s) { return fromVec3(b.mapWaveNormal(toVec3(s))); })
      .def("unmap_wave_normal", [](const BMMapping& b, const py::handle& s) { return fromVec3(b.unmapWaveNormal(toVec3(s))); })
      .def("map_normal", [](const BMMapping& b, const py::handle& n) { return fromVec3(b.mapNormal(toVec3(n))); })
      .def("map_point", [](const BMMapping& b, const py::handle& x) { return fromVec3(b.mapPoint(toVec3(x))); })
      .def("unmap_ray_direction", [](const BMMapping& b, const py::handle& t) {
        return fromVec3(b.unmapRayDirection(toVec3(t))); })
      .def("refract_e", [](const BMMapping& b, const py::handle& p, const py::handle& n) {
             return fromVec3(b.refractE(toVec3(p), toVec3(n))); }, py::arg("p_in"), py::arg("normal"),
           "refracted e wave vector (|p| = n(θ)); zero when evanescent")
      .def("reflect_e", [](const BMMapping& b, const py::handle& p, const py::handle& n) {
             return fromVec3(b.reflectE(toVec3(p), toVec3(n))); }, py::arg("p_in"), py::arg("normal"));

  m.def("refract_into_uniaxial", [](const py::handle& s, const py::handle& n, double n1, const Uniaxial& c) {
          return pairDict(refractIntoUniaxial(toVec3(s), toVec3(n), n1, c)); },
        py::arg("s_in"), py::arg("normal"), py::arg("n1"), py::arg("crystal"),
        "{'o': wave, 'e': wave}, wave = {exists, s, n, t, q}");
  m.def("refract_out_of_uniaxial", [](const Uniaxial& c, const std::string& mode, const py::handle& s,
                                      const py::handle& n, double n2) {
          return waveDict(refractOutOfUniaxial(c, parseMode(mode), toVec3(s), toVec3(n), n2)); },
        py::arg("crystal"), py::arg("mode"), py::arg("s_in"), py::arg("normal"), py::arg("n2"));
  m.def("reflect_inside_uniaxial", [](const Uniaxial& c, const std::string& mode, const py::handle& s,
                                      const py::handle& n) {
          return pairDict(reflectInsideUniaxialBoth(c, parseMode(mode), toVec3(s), toVec3(n))); },
        py::arg("crystal"), py::arg("mode"), py::arg("s_in"), py::arg("normal"));
  m.def("refract_isotropic", [](const py::handle& s, const py::handle& n, double n1, double n2) {
          return waveDict(refractIsotropic(toVec3(s), toVec3(n), n1, n2)); },
        py::arg("s_in"), py::arg("normal"), py::arg("n1"), py::arg("n2"));

  m.def("fresnel_reflectance", [](double cos_i, double n1, double n2) {
          auto f = fresnelReflectance(cos_i, n1, n2);
          return py::make_tuple(f.Rs, f.Rp, f.R); }, py::arg("cos_i"), py::arg("n1"), py::arg("n2"), "(Rs, Rp, R)");
  m.def("critical_angle", &criticalAngle, py::arg("n1"), py::arg("n2"));
  m.def("brewster_angle", &brewsterAngle, py::arg("n1"), py::arg("n2"));
  m.def("uniaxial_entry", [](const py::handle& s, const py::handle& n, double n1, const Uniaxial& c, bool exact) {
          return splitDict(exact ? uniaxialEntryExact(toVec3(s), toVec3(n), n1, c)
                                 : uniaxialEntryApprox(toVec3(s), toVec3(n), n1, c)); },
        py::arg("s_in"), py::arg("normal"), py::arg("n1"), py::arg("crystal"), py::arg("exact") = true,
        "unpolarised power split {o, e, reflected}");
  m.def("uniaxial_exit", [](const Uniaxial& c, const std::string& mode, const py::handle& s, const py::handle& n,
                            double n2, bool exact) {
          Mode md = parseMode(mode);
          return splitDict(exact ? uniaxialExitExact(c, md, toVec3(s), toVec3(n), n2)
                                 : uniaxialExitApprox(c, md, toVec3(s), toVec3(n), n2)); },
        py::arg("crystal"), py::arg("mode"), py::arg("s_in"), py::arg("normal"), py::arg("n2"), py::arg("exact") = true);
  m.def("pleochroism_weights", [](py::array_t<double> th, double no, double ne, const std::string& model) {
          PleochroismModel pm = parsePleo(model);
          auto wo = py::vectorize([=](double t) { return pleochroismWeights(t, no, ne, pm).o; })(th);
          auto we = py::vectorize([=](double t) { return pleochroismWeights(t, no, ne, pm).e; })(th);
          return py::make_tuple(wo, we); },
        py::arg("theta"), py::arg("n_o"), py::arg("n_e"), py::arg("model") = "first_order",
        "(w_o, w_e) with σ(θ) = w_o σ_o + w_e σ_e");

  // ------------------------------------------------------------ march settings
  py::class_<MarchSettings>(m, "MarchSettings")
      .def(py::init([](double step_voxels, const std::string& integrator, bool skip_empty, bool fresnel,
                       double interface_threshold, int max_steps) {
             MarchSettings s;
             s.step_voxels = step_voxels;
             s.integrator = parseIntegrator(integrator);
             s.skip_empty = skip_empty;
             s.fresnel = fresnel;
             s.interface_threshold = interface_threshold;
             s.max_steps = max_steps;
             return s; }),
           py::arg("step_voxels") = 0.25, py::arg("integrator") = "rk4", py::arg("skip_empty") = true,
           py::arg("fresnel") = true, py::arg("interface_threshold") = 0.02, py::arg("max_steps") = 20000)
      .def_readwrite("step_voxels", &MarchSettings::step_voxels)
      .def_property("integrator", [](const MarchSettings& s) { return integratorName(s.integrator); },
                    [](MarchSettings& s, const std::string& v) { s.integrator = parseIntegrator(v); })
      .def_readwrite("skip_empty", &MarchSettings::skip_empty)
      .def_readwrite("fresnel", &MarchSettings::fresnel)
      .def_readwrite("interface_threshold", &MarchSettings::interface_threshold)
      .def_readwrite("max_steps", &MarchSettings::max_steps)
      .def("__repr__", [](const MarchSettings& s) {
        return "<eikon.MarchSettings step_voxels=" + std::to_string(s.step_voxels) + " " + integratorName(s.integrator) + ">"; });

  // ------------------------------------------------------------ scenes
  py::class_<Camera>(m, "Camera")
      .def_property("position", [](const Camera& c) { return fromVec3(c.position); },
                    [](Camera& c, const py::handle& v) { c.position = toVec3(v); })
      .def_property("look_at", [](const Camera& c) { return fromVec3(c.look_at); },
                    [](Camera& c, const py::handle& v) { c.look_at = toVec3(v); })
      .def_property("up", [](const Camera& c) { return fromVec3(c.up); },
                    [](Camera& c, const py::handle& v) { c.up = toVec3(v); })
      .def_readwrite("fov_deg", &Camera::fov_deg)
      .def_readwrite("width", &Camera::width)
      .def_readwrite("height", &Camera::height);
  py::class_<VolumeSpec>(m, "VolumeSpec")
      .def_property("bounds_min", [](const VolumeSpec& v) { return fromVec3(v.bounds_min); },
                    [](VolumeSpec& v, const py::handle& x) { v.bounds_min = toVec3(x); })
      .def_property("bounds_max", [](const VolumeSpec& v) { return fromVec3(v.bounds_max); },
                    [](VolumeSpec& v, const py::handle& x) { v.bounds_max = toVec3(x); })
      .def_readwrite("resolution", &VolumeSpec::resolution)
      .def_readwrite("smoothing_voxels", &VolumeSpec::smoothing_voxels);

  // Scenes are held by shared_ptr so that a Renderer keeps its scene alive. Edit camera/volume
  // BEFORE creating a Renderer: the volume is voxelised once, on the Renderer's first use.
  py::class_<Scene, std::shared_ptr<Scene>>(m, "Scene")
      .def_static("load", [](const std::string& path) { return std::make_shared<Scene>(loadScene(path)); },
                  py::arg("path"))
      .def_static("parse", [](py::object json, const std::string& origin) {
                    std::string text = py::isinstance<py::str>(json)
                                           ? json.cast<std::string>()
                                           : py::module_::import("json").attr("dumps")(json).cast<std::string>();
                    return std::make_shared<Scene>(parseScene(text, origin)); },
                  py::arg("json"), py::arg("origin") = "<python>",
                  "from JSON text or a dict (library materials resolved by name)")
      .def_property_readonly("file", [](const Scene& s) { return s.file.string(); })
      .def_readwrite("camera", &Scene::camera)
      .def_readwrite("volume", &Scene::volume)
      .def_readonly("warnings", &Scene::warnings)
      .def_readonly("ambient_index", &Scene::ambient_index)
      .def_property_readonly("materials", [](const Scene& s) { return s.materials; })
      .def_property_readonly("any_uniaxial", &Scene::anyUniaxial)
      .def_property_readonly("any_dispersive", &Scene::anyDispersive)
      .def("environment_lookup", [](const Scene& s, const py::handle& d) { return fromVec3(s.environment.lookup(toVec3(d))); });
  m.def("load_scene", [](const std::string& path) { return std::make_shared<Scene>(loadScene(path)); }, py::arg("path"));
  m.def("modes_traced", [](const Scene& s) { return modesTraced(s); }, py::arg("scene"),
        "modes trace() reports for this scene: always ['o', 'e'] (isotropic: e identical to o)");

  // ------------------------------------------------------------ renderer (both twins)
  py::class_<Prepared, std::shared_ptr<Prepared>>(m, "Renderer",
      "A scene voxelised once and marched on the GPU (ViewRenderer) or the CPU (ReferenceMarcher).")
      .def(py::init([](std::shared_ptr<Scene> s) { return std::make_shared<Prepared>(std::move(s)); }), py::arg("scene"))
      .def_property_readonly("scene", [](const Prepared& p) { return p.scene; })
      .def("grid", [](Prepared& p) {
             p.ensureVolume(false);
             const Grid& g = p.volume->grid;
             py::dict d;
             d["dims"] = py::make_tuple(g.dims[0], g.dims[1], g.dims[2]);
             d["origin"] = fromVec3(g.origin);
             d["extent"] = fromVec3(g.extent);
             d["h"] = g.h;
             d["uniaxial"] = p.volume->uniaxial;
             d["dispersive"] = p.volume->dispersive;
             return d; }, "voxel grid facts (voxelises on first call)")
      .def("render", [](Prepared& p, int width, int height, int spp, std::optional<int> wavelengths,
                        double wavelength_nm, std::optional<MarchSettings> march, const std::string& device, int threads,
                        bool light, const py::object& light_cache) {
             const bool gpu = isGpu(device);
             // The CLI's defaults (core/render/render_defaults.h), then what the caller chose.
             RenderSettings s = defaultRenderSettings(*p.scene);
             s.width = width;
             s.height = height;
             s.spp = spp;
             if (wavelengths) s.wavelengths = *wavelengths;
             s.wavelength_nm = wavelength_nm;
             if (march) s.march = *march;
             if (light) p.ensureLit(!gpu, lightCacheDir(light_cache), threads);
             RenderImage img;
             if (gpu) {
               ViewRenderer& r = p.gpuRenderer();
               py::gil_scoped_release release;
               img = r.render(s);
             } else {
               ReferenceMarcher& r = p.cpuMarcher();
               Camera cam = p.scene->camera;
               if (width > 0) cam.width = width;
               if (height > 0) cam.height = height;
               py::gil_scoped_release release;
               img = r.render(cam, s, threads);
             }
             return imageArray(img); },
           py::arg("width") = 0, py::arg("height") = 0, py::arg("spp") = 1, py::arg("wavelengths") = py::none(),
           py::arg("wavelength_nm") = 587.5618, py::arg("march") = py::none(), py::arg("device") = "gpu",
           py::arg("threads") = 0, py::arg("light") = true, py::arg("light_cache") = true,
           "(H, W, 3) float32 linear sRGB, with the defaults of `eikon render`: wavelengths=None is 16 for a "
           "dispersive scene, else 0 (RGB; > 0 = spectral with that many samples); march=None is 0.5-voxel RK4 "
           "steps; light=True simulates a lit scene's lights before its first render (unless simulate_light() "
           "did), on the twin the CLI picks, through the CLI's light cache (light_cache=True: the default "
           "folder, a path: that folder, False: none); light=False leaves an unsimulated scene unlit (--no-light)")
      .def("simulate_light", [](Prepared& p, int bands, const std::string& splat, double step_voxels,
                                double smoothing_voxels, const std::string& caustics, const std::string& device) {
             const bool gpu = isGpu(device);
             p.ensureVolume(gpu);
             LightingOptions o;
             o.bands = bands;
             if (splat != "accumulate" && splat != "highest")
               throw std::invalid_argument("splat must be 'accumulate' or 'highest', got '" + splat + "'");
             o.wave.splat = splat == "highest" ? WavefrontSettings::Splat::HighestEnergy : WavefrontSettings::Splat::Accumulate;
             o.wave.dt = step_voxels * p.volume->grid.h;
             o.smoothing_voxels = smoothing_voxels;
             if (caustics != "pass" && caustics != "kill")
               throw std::invalid_argument("caustics must be 'pass' or 'kill', got '" + caustics + "'");
             o.wave.pass_caustics = caustics == "pass";
             LightingSummary sum;
             {
               py::gil_scoped_release release;
               sum = gpu ? simulateLighting(*p.ctx, *p.scene, *p.volume, o) : simulateLightingReference(*p.scene, *p.volume, o);
             }
             // Renderers built before hold the unlit volume: rebuild them on their next use.
             p.dropRenderers();
             py::dict d;
             d["runs"] = sum.runs;
             d["seconds"] = sum.seconds;
             d["patches"] = sum.patches;
             d["flux_emitted"] = sum.flux_emitted;
             d["flux_left"] = sum.flux_left;
             d["flux_caustic"] = sum.flux_caustic;
             d["flux_energy"] = sum.flux_energy;
             d["flux_absorbed"] = sum.flux_absorbed;
             d["conservation_error"] = sum.conservationError();
             d["device"] = device;
             return d; },
           py::arg("bands") = 0, py::arg("splat") = "accumulate", py::arg("step_voxels") = 0.5,
           py::arg("smoothing_voxels") = 1.0, py::arg("caustics") = "pass", py::arg("device") = "gpu",
           "simulate the scene's lights (docs/lighting.md) into the volume that later renders read; "
           "returns the summed run statistics")
      .def("light_volumes", [](Prepared& p) {
             p.ensureVolume(false);
             if (!p.volume->lit()) throw std::runtime_error("no light volumes: call simulate_light() first");
             const Grid& g = p.volume->grid;
             auto arr = [&](const std::vector<glm::vec4>& v) {
               py::array_t<float> a({py::ssize_t(g.dims[2]), py::ssize_t(g.dims[1]), py::ssize_t(g.dims[0]), py::ssize_t(4)});
               std::copy(&v[0].x, &v[0].x + 4 * v.size(), a.mutable_data());
               return a;
             };
             py::dict d;
             d["fluence"] = arr(p.volume->light_fluence);
             d["flux"] = arr(p.volume->light_flux);
             return d; },
           "{'fluence': (Z, Y, X, 4) φ_r, φ_g, φ_b, φ_Y (W/mm²), 'flux': (Z, Y, X, 4) net flux vector} "
           "on the voxel grid (index [k, j, i] is the voxel centred at origin + (i + ½, j + ½, k + ½)·h)")
      .def("trace_rays", [](Prepared& p, const py::handle& origins, const py::handle& directions,
                            const py::handle& wavelength_nm, std::optional<MarchSettings> march,
                            const std::string& device) {
             auto req = makeRequests(origins, directions, wavelength_nm);
             MarchSettings ms = march.value_or(MarchSettings{});
             auto both = traceBoth(p, req, ms, isGpu(device));
             py::dict modes;
             const char* names[2] = {"o", "e"};
             for (int k = 0; k < 2; ++k) {
               std::vector<TraceOutcome> col;
               col.reserve(both.size());
               for (const auto& b : both) col.push_back(b[size_t(k)]);
               modes[names[k]] = outcomesArrays(col, names[k]);
             }
             py::array_t<double> lam(py::ssize_t(req.size()));
             for (size_t i = 0; i < req.size(); ++i) lam.mutable_at(py::ssize_t(i)) = req[i].wavelength_nm;
             py::dict d;
             d["wavelength_nm"] = lam;
             d["device"] = device;
             d["modes"] = modes;
             return d; },
           py::arg("origins"), py::arg("directions"), py::arg("wavelength_nm") = 587.5618,
           py::arg("march") = py::none(), py::arg("device") = "gpu",
           "many rays: {'wavelength_nm': (N,), 'device', 'modes': {'o': {key: (N,3)|(N,)}, 'e': ...}}")
      .def("trace", [](Prepared& p, const py::handle& origin, const py::handle& direction, double wavelength_nm,
                       std::optional<MarchSettings> march, const std::string& device) {
             TraceRequest q{toVec3(origin), toVec3(direction), wavelength_nm};
             MarchSettings ms = march.value_or(MarchSettings{});
             auto both = traceBoth(p, {q}, ms, isGpu(device)).at(0);
             py::list modes;
             modes.append(outcomeDict(both[0], "o"));
             modes.append(outcomeDict(both[1], "e"));
             py::dict d;
             d["wavelength_nm"] = wavelength_nm;
             d["device"] = device;
             d["modes"] = modes;
             return d; },
           py::arg("origin"), py::arg("direction"), py::arg("wavelength_nm") = 587.5618,
           py::arg("march") = py::none(), py::arg("device") = "gpu",
           "one ray, the CLI JSON shape: {'wavelength_nm', 'device', 'modes': [{'mode': 'o', ...}, ...]}");

  m.def("render", [](std::shared_ptr<Scene> s, py::kwargs kw) {
          auto p = py::cast(cachedPrepared(s));
          return p.attr("render")(**kw); }, py::arg("scene"),
        "render(scene, width=, height=, spp=, wavelengths=, wavelength_nm=, march=, device='gpu'|'cpu', light=, "
        "light_cache=) — Renderer.render on the module's cached prepared scene (voxelised once per Scene object "
        "and volume settings)");
  m.def("trace", [](std::shared_ptr<Scene> s, py::args a, py::kwargs kw) {
          auto p = py::cast(cachedPrepared(s));
          return p.attr("trace")(*a, **kw); }, py::arg("scene"),
        "trace(scene, origin, direction, wavelength_nm=, march=, device=) — see Renderer.trace");
  m.def("clear_cache", [] {
          std::lock_guard<std::mutex> lock(g_prepared_mutex);
          g_last_prepared.reset();
          g_last_scene.reset(); },
        "drop the scene that module-level render()/trace() keep prepared");
  m.def("voxelize_count", [] { return g_voxelizations.load(); },
        "how many times this module has voxelised a scene (each Renderer once, module-level calls once per scene)");
  m.def("read_exr", [](const std::string& path) {
          RgbaImage im = readExrRgba(path, 16384, 16384);
          py::array_t<float> a({py::ssize_t(im.height), py::ssize_t(im.width), py::ssize_t(3)});
          float* d = a.mutable_data();
          for (size_t i = 0; i < size_t(im.width) * size_t(im.height); ++i)
            for (int c = 0; c < 3; ++c) d[3 * i + size_t(c)] = im.rgba[4 * i + size_t(c)];
          return a; }, py::arg("path"),
        "(H, W, 3) float32 linear RGB of an EXR (e.g. what `eikon render` wrote)");

  // ------------------------------------------------------------ analytic fields (CPU reference)
  py::class_<AnalyticSpec, std::shared_ptr<AnalyticSpec>>(m, "AnalyticField",
      "An exact index field n(x), ∇n(x) in a box, marched by the CPU reference (no voxelisation).")
      .def_static("luneburg", [](double R, const py::handle& center, const py::handle& bmin, const py::handle& bmax,
                                 double cell) {
                    glm::dvec3 c = toVec3(center);
                    auto fn = [R, c](const glm::dvec3& x, double& n, glm::dvec3& g) {
                      glm::dvec3 r = x - c;
                      double r2 = glm::dot(r, r);
                      if (r2 >= R * R) { n = 1.0; g = glm::dvec3(0.0); return; }
                      n = std::sqrt(2.0 - r2 / (R * R));
                      g = -r / (R * R * n);
                    };
                    auto s = std::make_shared<AnalyticSpec>();
                    s->field = std::make_shared<AnalyticField>(fn, toVec3(bmin), toVec3(bmax), cell);
                    return s; },
                  py::arg("radius"), py::arg("center"), py::arg("bounds_min"), py::arg("bounds_max"), py::arg("cell"),
                  "n = √(2 − r²/R²) inside, 1 outside")
      .def_static("linear", [](double n0, const py::handle& gradient, const py::handle& origin, const py::handle& bmin,
                               const py::handle& bmax, double cell) {
                    glm::dvec3 gr = toVec3(gradient), o = toVec3(origin);
                    auto fn = [n0, gr, o](const glm::dvec3& x, double& n, glm::dvec3& g) {
                      n = n0 + glm::dot(gr, x - o);
                      g = gr;
                    };
                    auto s = std::make_shared<AnalyticSpec>();
                    s->field = std::make_shared<AnalyticField>(fn, toVec3(bmin), toVec3(bmax), cell);
                    return s; },
                  py::arg("n0"), py::arg("gradient"), py::arg("origin"), py::arg("bounds_min"), py::arg("bounds_max"),
                  py::arg("cell"), "n = n0 + g·(x − origin)")
      .def_static("maxwell_fisheye", [](double n0, double R, const py::handle& center, const py::handle& bmin,
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
                    return s; },
                  py::arg("n0"), py::arg("radius"), py::arg("center"), py::arg("bounds_min"), py::arg("bounds_max"),
                  py::arg("cell"), "n = n0/(1 + r²/R²) everywhere in the box")
      .def_static("from_function", [](py::function f, const py::handle& bmin, const py::handle& bmax, double cell) {
                    // f(x: ndarray(3)) -> (n, grad(3)); called with the GIL held (slow but general).
                    auto fn = [f](const glm::dvec3& x, double& n, glm::dvec3& g) {
                      py::gil_scoped_acquire acquire;
                      py::tuple r = f(fromVec3(x));
                      n = r[0].cast<double>();
                      g = toVec3(r[1]);
                    };
                    auto s = std::make_shared<AnalyticSpec>();
                    s->field = std::make_shared<AnalyticField>(fn, toVec3(bmin), toVec3(bmax), cell);
                    return s; },
                  py::arg("fn"), py::arg("bounds_min"), py::arg("bounds_max"), py::arg("cell"))
      .def("trace", [](const AnalyticSpec& a, const py::handle& origin, const py::handle& direction,
                       std::optional<MarchSettings> march, double wavelength_nm) {
             ReferenceMarcher r(*a.field, a.env);
             TraceRequest q{toVec3(origin), toVec3(direction), wavelength_nm};
             MarchSettings ms = march.value_or(MarchSettings{});
             TraceOutcome t;
             {
               py::gil_scoped_release release;
               t = r.trace(q, ms);
             }
             return outcomeDict(t, "o"); },
           py::arg("origin"), py::arg("direction"), py::arg("march") = py::none(), py::arg("wavelength_nm") = 587.5618,
           "one ray through the exact field: {'mode': 'o', 'exit_point', ...} (CPU reference)");

  // ------------------------------------------------------------ Vulkan
  m.def("validation_messages", []() {
          std::lock_guard<std::mutex> lock(g_ctx_mutex);
          return g_ctx ? g_ctx->validationMessages() : std::vector<std::string>{}; },
        "messages of the Khronos validation layer so far (EIKON_VALIDATION=1); [] without a context");
  m.def("device_info", []() {
          auto c = context();
          py::dict d;
          d["name"] = c->deviceName();
          d["type"] = c->deviceTypeName();
          d["api_version"] = c->apiVersionString();
          d["validation"] = c->validationEnabled();
          return d; }, "create the Vulkan context if needed and describe its device");
  m.attr("__version__") = "0.1.0";
  // Drop the module's reference to the Vulkan context before interpreter teardown (Renderers
  // still alive keep their own reference and release it when collected).
  py::module_::import("atexit").attr("register")(py::cpp_function([]() {
    std::lock_guard<std::mutex> lock(g_ctx_mutex);
    g_ctx.reset();
  }));
}
