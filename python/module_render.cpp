// eikon.Renderer and the module-level render()/trace(): a Python face of eikon::Session
// (core/session/session.h), which `eikon render` and `eikon trace` run too, so that Python and
// the CLI prepare, light, render and trace a scene the same way and refuse the same settings.
#include <pybind11/functional.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <atomic>
#include <mutex>
#include <optional>

#include "core/io/exr.h"
#include "core/session/front_end.h"
#include "core/session/light_tree_json.h"
#include "python/module.h"
#include "python/progress.h"

namespace eikon::python {
namespace {

// Voxelisations done by this module (eikon.voxelize_count()): lets tests see that a cached
// prepared scene is reused instead of voxelised again.
std::atomic<long> g_voxelizations{0};

// A Renderer: a session of its own on the module's shared Vulkan context. Calls into the session
// release the GIL (it never calls back into Python).
/// The scene a Renderer or a module-level call is given: None is a TypeError here, where the
/// session would dereference it (a segmentation fault).
std::shared_ptr<Scene> requireScene(std::shared_ptr<Scene> s) {
  if (!s) throw py::type_error("scene must be an eikon.Scene, got None");
  return s;
}

struct Prepared {
  std::shared_ptr<Scene> scene;
  Session session;

  explicit Prepared(std::shared_ptr<Scene> s)
      : scene(requireScene(s)), session(std::move(s), context) {}
  template <class F>
  decltype(auto) run(F&& f) {
    const bool voxelized = session.voxelized();
    struct Count {  // counted also when f throws after voxelising
      Session& s;
      bool before;
      ~Count() {
        if (!before && s.voxelized()) ++g_voxelizations;
      }
    } count{session, voxelized};
    py::gil_scoped_release release;
    return f(session);
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
  requireScene(s);
  std::lock_guard<std::mutex> lock(g_prepared_mutex);
  if (g_last_prepared && g_last_scene.lock() == s &&
      (!g_last_prepared->session.voxelized() ||
       sameSpec(g_last_prepared->session.voxelizedSpec(), s->volume)))
    return g_last_prepared;
  g_last_prepared = std::make_shared<Prepared>(s);
  g_last_scene = s;
  return g_last_prepared;
}

// light_cache=: True (the CLI's folder), False or None (no cache), or a folder as str or
// os.PathLike; anything else is a TypeError (light_cache=5 made a folder named "5").
std::string lightCacheDir(const py::object& light_cache) {
  if (light_cache.is_none()) return {};
  if (py::isinstance<py::bool_>(light_cache))
    return light_cache.cast<bool>() ? defaultLightCacheFolder().string() : std::string();
  const py::object os = py::module_::import("os");
  if (!py::isinstance<py::str>(light_cache) && !py::isinstance(light_cache, os.attr("PathLike")))
    throw py::type_error(
        "light_cache must be True, False, None or a folder (str or os.PathLike), got " +
        py::str(py::type::of(light_cache).attr("__name__")).cast<std::string>());
  const py::object path = os.attr("fspath")(light_cache);
  if (!py::isinstance<py::str>(path))
    throw py::type_error("light_cache must be a folder path as str, got " +
                         py::str(py::type::of(path).attr("__name__")).cast<std::string>());
  const std::string dir = path.cast<std::string>();
  if (dir.empty())
    throw std::invalid_argument("light_cache must name a folder, got '' (False: no cache)");
  return dir;
}

bool isGpu(const std::string& device) {
  if (device == "gpu") return true;
  if (device == "cpu") return false;
  throw std::invalid_argument("device must be 'gpu' or 'cpu', got '" + device + "'");
}

py::array_t<float> imageArray(const RenderImage& img) {
  py::array_t<float> a({py::ssize_t(img.height), py::ssize_t(img.width), py::ssize_t(3)});
  std::copy(img.rgb.begin(), img.rgb.end(), a.mutable_data());
  return a;
}

py::dict grid(Prepared& p) {
  const VolumeSet& v = p.run([](Session& s) -> const VolumeSet& { return s.prepare(false); });
  const Grid& g = v.grid;
  py::dict d;
  d["dims"] = py::make_tuple(g.dims[0], g.dims[1], g.dims[2]);
  d["origin"] = fromVec3(g.origin);
  d["extent"] = fromVec3(g.extent);
  d["h"] = g.h;
  d["uniaxial"] = v.uniaxial;
  d["dispersive"] = v.dispersive;
  return d;
}

// As `eikon render` does by default: a scene with lights gets its light simulated before the
// first render (unless simulate_light() already did), by the twin the session picks (the CPU
// reference for CPU renders, as --reference), through the CLI's light cache when `light_cache`
// names one.
// The render with its layers (`layers` as `eikon render --layers`): a dict of numpy arrays.
py::dict layerArrays(const RenderImage& img, bool fastSlow) {
  py::dict d;
  d["rgb"] = imageArray(img);
  if (img.bins > 0) {
    py::array_t<float> sp({py::ssize_t(img.height), py::ssize_t(img.width), py::ssize_t(img.bins)});
    std::copy(img.spectral.begin(), img.spectral.end(), sp.mutable_data());
    d["spectral"] = sp;
    py::array_t<double> centres(py::ssize_t(img.bins));
    for (int k = 0; k < img.bins; ++k)
      centres.mutable_data()[k] = 380.0 + (k + 0.5) * 400.0 / img.bins;
    d["wavelengths_nm"] = centres;
  }
  if (!img.modes.empty()) {
    for (int m = 0; m < 2; ++m) {
      py::array_t<float> a({py::ssize_t(img.height), py::ssize_t(img.width), py::ssize_t(3)});
      for (size_t i = 0; i < size_t(img.width) * size_t(img.height); ++i)
        for (size_t c = 0; c < 3; ++c) a.mutable_data()[3 * i + c] = img.modes[6 * i + 3 * m + c];
      d[modeName(m, fastSlow)] = a;
    }
  }
  if (!img.stokes.empty()) {  // a polarised render (docs/polarisation.md "Polarised renders")
    py::array_t<float> a(
        {py::ssize_t(img.height), py::ssize_t(img.width), py::ssize_t(4), py::ssize_t(3)});
    std::copy(img.stokes.begin(), img.stokes.end(), a.mutable_data());
    d["stokes"] = a;
    d["stokes_frame"] = std::string(kStokesFrame);
  }
  if (!img.aov.empty()) {
    // The AOV layer (RenderImage::aov): depth (+inf where no interface), point and normal
    // (height, width, 3), object id (int32, −1 where none or unknown) and march steps.
    const size_t n = size_t(img.width) * size_t(img.height);
    const py::ssize_t H = img.height, W = img.width;
    py::array_t<float> depth({H, W}), point({H, W, py::ssize_t(3)}), normal({H, W, py::ssize_t(3)});
    py::array_t<int32_t> object({H, W});
    py::array_t<double> steps({H, W});
    for (size_t i = 0; i < n; ++i) {
      const float* a = &img.aov[i * size_t(kAovChannels)];
      depth.mutable_data()[i] = a[0];
      for (size_t c = 0; c < 3; ++c) {
        point.mutable_data()[3 * i + c] = a[1 + c];
        normal.mutable_data()[3 * i + c] = a[4 + c];
      }
      object.mutable_data()[i] = int32_t(a[7]);
      steps.mutable_data()[i] = a[8];
    }
    d["depth"] = depth;
    d["point"] = point;
    d["normal"] = normal;
    d["object_id"] = object;
    d["steps"] = steps;
  }
  return d;
}

py::object render(Prepared& p, int width, int height, std::optional<int> spp,
                  std::optional<int> wavelengths, double wavelength_nm,
                  std::optional<MarchSettings> march, const std::string& device, int threads,
                  bool light, const py::object& light_cache, const std::string& sampling,
                  const std::string& layers, bool polarised, const std::string& modes,
                  const py::object& progress) {
  checkSetting([&] { checkRenderDevice(device); });  // auto, gpu or cpu (renderTwin)
  ViewRequest view;  // the CLI's defaults (core/session/session.h), then what the caller chose
  if (width != 0) view.width = width;
  if (height != 0) view.height = height;
  view.spp = spp;
  view.wavelengths = wavelengths;
  view.wavelength_nm = wavelength_nm;
  view.march = march;
  checkSetting([&] {
    checkViewRequest(view);
    checkThreads(threads);
    view.sampling = parseSpectralSampling(sampling);
    parseLayers(layers, view);
    view.modes = parseModes(modes);
  });
  view.polarised = polarised;
  RenderSettings settings;
  checkSetting([&] { settings = renderSettings(*p.scene, view); });
  const std::string cache_dir = lightCacheDir(light_cache);  // checked even with light=False
  PyProgress printer(pyProgressMode(progress));
  const RenderImage img = p.run([&](Session& s) {
    return withProgress(s, printer, [&] {
      s.setThreads(threads);
      const bool gpu =
          !renderTwin(device, *p.scene, settings, [&] { return deviceInfo(s.context()).type; }).cpu;
      if (light && !p.scene->lights.empty() && !s.prepare(gpu).lit()) {
        LightRequest l;
        l.threads = threads;
        s.simulateLight(l, !gpu, cache_dir);  // an unwritable cache only costs time next time
      }
      return s.render(settings, gpu);
    });
  });
  printer.close();
  if (settings.spectral_layer || settings.mode_layers || settings.aov_layer ||
      settings.stokes_layers)
    return layerArrays(img, p.scene->fastSlowModes());
  return imageArray(img);
}

py::dict simulateLight(Prepared& p, int bands, const std::string& splat, double step_voxels,
                       double smoothing_voxels, const std::string& caustics,
                       const std::string& device, const py::object& progress, double split_voxels,
                       int max_patches, int reflections) {
  const bool gpu = isGpu(device);
  LightRequest l;
  l.bands = bands;
  l.splat = splat;
  l.step_voxels = step_voxels;
  l.smoothing_voxels = smoothing_voxels;
  l.caustics = caustics;
  l.device = device;
  l.split_voxels = split_voxels;
  l.max_patches = max_patches;
  l.reflections = reflections;
  checkSetting([&] { checkLightRequest(l); });
  PyProgress printer(pyProgressMode(progress));
  const LightingSummary sum = p.run([&](Session& s) {
    return withProgress(s, printer, [&] { return s.simulateLight(l, !gpu, {}).summary; });
  });
  printer.close();
  py::dict d;
  d["runs"] = sum.runs;
  d["seconds"] = sum.seconds;
  d["patches"] = sum.patches;
  d["flux_emitted"] = sum.flux_emitted;
  d["flux_left"] = sum.flux_left;
  d["flux_caustic"] = sum.flux_caustic;
  d["flux_energy"] = sum.flux_energy;
  d["flux_absorbed"] = sum.flux_absorbed;
  d["flux_reflected"] = sum.flux_reflected;  // sharp interfaces: Fresnel reflection not followed
  d["conservation_error"] = sum.conservationError();
  d["device"] = device;
  return d;
}

py::dict lightVolumes(Prepared& p) {
  const VolumeSet& v = p.run([](Session& s) -> const VolumeSet& { return s.prepare(false); });
  if (!v.lit()) throw std::runtime_error("no light volumes: call simulate_light() first");
  const Grid& g = v.grid;
  auto arr = [&](const std::vector<glm::vec4>& x) {
    py::array_t<float> a(
        {py::ssize_t(g.dims[2]), py::ssize_t(g.dims[1]), py::ssize_t(g.dims[0]), py::ssize_t(4)});
    std::copy(&x[0].x, &x[0].x + 4 * x.size(), a.mutable_data());
    return a;
  };
  py::dict d;
  d["fluence"] = arr(v.light_fluence);
  d["flux"] = arr(v.light_flux);
  return d;
}

std::vector<std::array<TraceOutcome, 2>> traceBoth(Prepared& p,
                                                   const std::vector<TraceRequest>& req,
                                                   const std::optional<MarchSettings>& march,
                                                   const std::string& device) {
  const bool gpu = isGpu(device);
  const MarchSettings ms = march.value_or(MarchSettings{});
  checkSetting([&] {
    for (const TraceRequest& q : req) checkTraceRequest(q);
    checkMarchStep(ms.step_voxels);
    checkMarchSettings(ms);
  });
  return p.run([&](Session& s) { return s.trace(req, ms, gpu); });
}

// Host memory trace_rays holds a ray besides the session's (traceHostBytes): its float64 copies
// of an origin, a direction and a wavelength; the result arrays of both modes (three (N, 3) and
// three (N,) float64, three int32 and a bool a ray each) and the wavelengths returned; and the
// one mode's outcomes gathered at a time.
constexpr double kTraceRaysBytesPerRay =
    7 * 8.0 + 2 * (9 * 8.0 + 3 * 8.0 + 3 * 4.0 + 1.0) + 8.0 + double(sizeof(TraceOutcome));

py::dict traceRays(Prepared& p, const py::handle& origins, const py::handle& directions,
                   const py::handle& wavelength_nm, std::optional<MarchSettings> march,
                   const std::string& device) {
  // Refused with the numbers before any copy (1e9 rays of a broadcast view were copied until the
  // kernel killed the process; 1e8 under a 6 GB limit raised a bare std::bad_alloc).
  const size_t rays = rayCount(origins, directions, wavelength_nm);
  checkTraceFitsHost(rays, double(rays) * kTraceRaysBytesPerRay);
  auto req = makeRequests(origins, directions, wavelength_nm);
  auto both = traceBoth(p, req, march, device);
  py::dict modes;
  const bool fs = p.scene->fastSlowModes();
  const char* names[2] = {modeName(0, fs), modeName(1, fs)};
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
  return d;
}

py::dict traceOne(Prepared& p, const py::handle& origin, const py::handle& direction,
                  double wavelength_nm, std::optional<MarchSettings> march,
                  const std::string& device) {
  TraceRequest q{toVec3(origin), toVec3(direction), wavelength_nm};
  auto both = traceBoth(p, {q}, march, device).at(0);
  py::list modes;
  const bool fs = p.scene->fastSlowModes();
  modes.append(outcomeDict(both[0], modeName(0, fs)));
  modes.append(outcomeDict(both[1], modeName(1, fs)));
  py::dict d;
  d["wavelength_nm"] = wavelength_nm;
  d["device"] = device;
  d["modes"] = modes;
  return d;
}

// The light trees of one ray (Session::lightTrees, `eikon trace --tree`) on the CPU twin: the
// CLI's JSON as Python objects (json.loads of the same text).
py::object lightTreeOne(Prepared& p, const py::handle& origin, const py::handle& direction,
                        double wavelength_nm, std::optional<MarchSettings> march, double min_weight,
                        int max_depth) {
  const TraceRequest q{toVec3(origin), toVec3(direction), wavelength_nm};
  const MarchSettings ms = march.value_or(MarchSettings{});
  LightTreeSettings tree;
  tree.min_weight = min_weight;
  tree.max_depth = max_depth;
  checkSetting([&] {
    checkTraceRequest(q);
    checkMarchStep(ms.step_voxels);
    checkMarchSettings(ms);
    checkSettingValue(setting("tree-min-weight"), min_weight);
    checkSettingValue(setting("tree-max-depth"), max_depth);
  });
  const std::string text = p.run([&](Session& s) {
    return lightTreesJson(q, tree, s.lightTrees(q, ms, tree), s.deviceName(false)).dump();
  });
  return py::module_::import("json").attr("loads")(text);
}

py::array_t<double> stokesArray(const Stokes& s) {
  py::array_t<double> a(4);
  for (int k = 0; k < 4; ++k) a.mutable_at(k) = s[k];
  return a;
}

// The polarised trace of one ray (Session::tracePolarised, as `eikon trace --stokes`):
// {'stokes_out': (4,) of the strongest beam, 'beams': [{'direction', 'exit_point', 'frame_x',
// 'stokes', 'branches', 'coherent_groups', 'modes'}], 'frame_x_in', 'truncated', 'device'}.
py::dict tracePolarisedOne(Prepared& p, const py::handle& origin, const py::handle& direction,
                           double wavelength_nm, const py::handle& stokes,
                           const std::string& device, double bandwidth_nm, double source_angle_rad,
                           const std::vector<int>& reflect_at) {
  const bool gpu = isGpu(device);
  TraceRequest q{toVec3(origin), toVec3(direction), wavelength_nm};
  const auto in = py::cast<std::vector<double>>(stokes);
  if (in.size() != 4)
    throw std::invalid_argument("stokes must be four numbers S0, S1, S2, S3, got " +
                                std::to_string(in.size()));
  PolarisedTraceSettings set;
  set.bandwidth_nm = bandwidth_nm;
  set.source_angle_rad = source_angle_rad;
  set.reflect_at = reflect_at;
  checkSetting([&] { checkTraceRequest(q); });
  const Stokes s_in(in[0], in[1], in[2], in[3]);
  const PolarisedTrace t = p.run([&](Session& s) { return s.tracePolarised(q, s_in, set, gpu); });
  py::list beams;
  for (const PolarisedBeam& b : t.beams) {
    py::dict d;
    d["direction"] = fromVec3(b.direction);
    d["exit_point"] = fromVec3(b.exit_point);
    d["frame_x"] = fromVec3(b.frame_x);
    d["stokes"] = stokesArray(b.stokes);
    d["branches"] = b.branches;
    d["coherent_groups"] = b.coherent_groups;
    d["modes"] = b.modes;
    beams.append(d);
  }
  py::dict d;
  d["stokes_out"] = stokesArray(t.beams.empty() ? Stokes(0.0) : t.beams[0].stokes);
  d["beams"] = beams;
  d["frame_x_in"] = fromVec3(t.frame_x_in);
  d["truncated"] = t.truncated;
  d["device"] = device;
  return d;
}

py::array_t<float> readExr(const std::string& path) {
  RgbaImage im = readExrRgba(path, 16384, 16384);
  py::array_t<float> a({py::ssize_t(im.height), py::ssize_t(im.width), py::ssize_t(3)});
  float* d = a.mutable_data();
  for (size_t i = 0; i < size_t(im.width) * size_t(im.height); ++i)
    for (int c = 0; c < 3; ++c) d[3 * i + size_t(c)] = im.rgba[4 * i + size_t(c)];
  return a;
}

/// eikon.write_image: an (H, W, 3) linear RGB image as `eikon render` writes it, the EXR (and the
/// PNG preview) as one set, atomically (core/io/atomic_write.h): both files or neither.
void writeImage(const std::string& exr,
                py::array_t<float, py::array::c_style | py::array::forcecast> rgb,
                const std::string& png, double exposure) {
  if (rgb.ndim() != 3 || rgb.shape(2) != 3 || rgb.shape(0) < 1 || rgb.shape(1) < 1)
    throw py::value_error("write_image: rgb must be an (H, W, 3) array");
  const int h = int(rgb.shape(0)), w = int(rgb.shape(1));
  std::vector<float> pixels(rgb.data(), rgb.data() + rgb.size());
  std::vector<OutputFile> files{{exr, exrRgbContent(w, h, pixels)}};
  if (!png.empty()) files.push_back({png, pngPreviewContent(w, h, pixels, exposure)});
  py::gil_scoped_release release;
  writeFilesTogether(files);
}

// ---------------------------------------------------------------- keywords from the settings table

/// A keyword's default on a Python front end: None for an unset number, else the table's value.
py::object settingDefaultObject(const Setting& s, unsigned front) {
  const std::string value = settingDefault(s, front).value;
  switch (s.kind) {
    case SettingKind::Flag:
      return py::bool_(value == "true");
    case SettingKind::Choice:
    case SettingKind::Text:
      return py::str(value);
    case SettingKind::Integer:
      return value.empty() ? py::object(py::none()) : py::object(py::int_(std::stoi(value)));
    case SettingKind::Number:
      return value.empty() ? py::object(py::none()) : py::object(py::float_(std::stod(value)));
  }
  return py::none();
}

/// The keyword of the setting `name` (core/session/settings.h) with its default on `front`.
py::arg_v settingArg(const char* name, unsigned front) {
  const Setting& s = setting(name);
  // py::arg keeps the pointer: the table's strings live as long as the module.
  const char* keyword = *s.keyword ? s.keyword : s.name;
  if (settingKeyword(s) != keyword || !(s.fronts & front))
    throw std::logic_error(std::string("setting '") + name + "' has no Python keyword here");
  return py::arg_v(keyword, settingDefaultObject(s, front));
}

/// "keyword=default (--option): help" of each named setting on `front`, one a line, for a
/// docstring.
std::string settingsDoc(std::initializer_list<const char*> names, unsigned front) {
  std::string doc;
  for (const char* name : names) {
    const Setting& s = setting(name);
    doc += "\n  " + settingKeyword(s) + "=" +
           py::repr(settingDefaultObject(s, front)).cast<std::string>() +
           ((s.fronts & SettingFront::Cli) ? std::string(" (--") + s.name + ")" : "") + ": " +
           settingHelp(s, front);
  }
  return doc;
}

/// The table itself (eikon.settings()): what the tests compare the keywords and the CLI with.
py::list settingsList() {
  const std::pair<unsigned, const char*> fronts[] = {
      {SettingFront::RenderCli, "render"},
      {SettingFront::TraceCli, "trace"},
      {SettingFront::ViewCli, "view"},
      {SettingFront::PyRender, "Renderer.render"},
      {SettingFront::PyLight, "Renderer.simulate_light"},
      {SettingFront::PyTrace, "Renderer.trace"}};
  const char* kinds[] = {"integer", "number", "choice", "flag", "text"};
  py::list out;
  for (const Setting& s : settings()) {
    py::dict d, help, defaults;
    py::list choices;
    for (const SettingChoice& c : s.choices) choices.append(c.name);
    for (const auto& [bit, where] : fronts) {
      if (!(s.fronts & bit)) continue;
      help[where] = settingHelp(s, bit);
      defaults[where] = settingDefault(s, bit).value;
    }
    d["name"] = s.name;
    d["kind"] = kinds[int(s.kind)];
    d["keyword"] = settingKeyword(s);
    d["help"] = help;
    d["defaults"] = defaults;
    d["range"] = settingRange(s);
    d["choices"] = choices;
    d["field"] = s.field;
    out.append(d);
  }
  return out;
}

void bindModuleCalls(py::module_& m) {
  m.def(
      "render",
      [](std::shared_ptr<Scene> s, py::kwargs kw) {
        auto p = py::cast(cachedPrepared(s));
        return p.attr("render")(**kw);
      },
      py::arg("scene"),
      "render(scene, width=, height=, spp=, wavelengths=, wavelength_nm=, march=, "
      "device='auto'|'gpu'|'cpu', light=, "
      "light_cache=) — Renderer.render on the module's cached prepared scene (voxelised once per "
      "Scene object "
      "and volume settings)");
  m.def(
      "trace",
      [](std::shared_ptr<Scene> s, py::args a, py::kwargs kw) {
        auto p = py::cast(cachedPrepared(s));
        return p.attr("trace")(*a, **kw);
      },
      py::arg("scene"),
      "trace(scene, origin, direction, wavelength_nm=, march=, device=) — see Renderer.trace");
  m.def(
      "light_tree",
      [](std::shared_ptr<Scene> s, py::args a, py::kwargs kw) {
        auto p = py::cast(cachedPrepared(s));
        return p.attr("light_tree")(*a, **kw);
      },
      py::arg("scene"),
      "light_tree(scene, origin, direction, wavelength_nm=, march=, min_weight=, max_depth=) — "
      "see Renderer.light_tree");
  m.def(
      "trace_polarised",
      [](std::shared_ptr<Scene> s, py::args a, py::kwargs kw) {
        auto p = py::cast(cachedPrepared(s));
        return p.attr("trace_polarised")(*a, **kw);
      },
      py::arg("scene"),
      "trace_polarised(scene, origin, direction, wavelength_nm=, stokes=, device=, ...) — see "
      "Renderer.trace_polarised");
  m.def(
      "clear_cache",
      [] {
        std::lock_guard<std::mutex> lock(g_prepared_mutex);
        g_last_prepared.reset();
        g_last_scene.reset();
      },
      "drop the scene that module-level render()/trace() keep prepared");
  m.def(
      "voxelize_count", [] { return g_voxelizations.load(); },
      "how many times this module has voxelised a scene (each Renderer once, module-level calls "
      "once per scene)");
  m.def("settings", &settingsList,
        "the settings table (core/session/settings.h) that `eikon render`'s options and these "
        "keywords are made from: [{'name', 'kind', 'keyword', 'help': {front: text}, 'defaults': "
        "{front: value}, 'range', 'choices', 'field'}]");
  m.def("read_exr", &readExr, py::arg("path"),
        "(H, W, 3) float32 linear RGB of an EXR (e.g. what `eikon render` wrote)");
  m.def("write_image", &writeImage, py::arg("exr"), py::arg("rgb"), py::arg("png") = "",
        py::arg("exposure") = 0.0,
        "write an (H, W, 3) linear RGB image as `eikon render` does: the EXR and, with png=, its "
        "8-bit preview (exposure in stops), as one set, atomically (both files or neither)");
}
}  // namespace

constexpr unsigned kR = SettingFront::PyRender, kL = SettingFront::PyLight,
                   kT = SettingFront::PyTrace;

const std::string& renderDoc() {
  static const std::string doc =
      "(H, W, 3) float32 linear sRGB, rendered as `eikon render` renders, with its defaults and "
      "its checks. The keywords of the settings table (eikon.settings()), each with its option of "
      "`eikon render`:" +
      settingsDoc({"width", "height", "spp", "wavelengths", "wavelength", "device", "threads",
                   "spectral-sampling", "layers", "polarised", "modes"},
                  kR) +
      "\nThe others:"
      "\n  march=None: MarchSettings (its step_voxels, integrator, skip_empty and fresnel are "
      "--step, --integrator, --no-skip and --no-fresnel); None is 0.5-voxel RK4 steps"
      "\n  light=True: a lit scene's lights are simulated before its first render (unless "
      "simulate_light() did), on the twin the CLI picks; light=False leaves an unsimulated scene "
      "unlit (--no-light)"
      "\n  light_cache=True: the CLI's light cache folder; a path: that folder; False: none"
      "\n  progress=None|True|False: a tqdm bar per stage on stderr (plain lines without tqdm), "
      "None shows stages that run over a second unless $EIKON_PROGRESS=never (or always)"
      "\nWith layers the result is a dict: rgb, spectral (H, W, N bins) with wavelengths_nm (the "
      "bin centres), o and e (H, W, 3 each), and for aov depth (H, W; mm, inf where none), point "
      "and normal (H, W, 3), object_id (H, W; int32, -1 where none) and steps (H, W); "
      "layers='stokes' adds stokes (H, W, 4, 3: S0..S3 x RGB) and stokes_frame "
      "(docs/polarisation.md). A polarised render without layers='stokes' (polarised=True, "
      "polariser sheets or a camera analyzer) returns the plain (H, W, 3) S0.";
  return doc;
}

const std::string& lightDoc() {
  static const std::string doc =
      "simulate the scene's lights (docs/lighting.md) into the volume that later renders read; "
      "returns the summed run statistics. The keywords of the settings table (eikon.settings()), "
      "each with its option of `eikon render`:" +
      settingsDoc({"light-bands", "light-splat", "light-step", "light-smoothing", "caustics",
                   "light-device", "light-split", "max-patches", "light-reflections"},
                  kL) +
      "\n  progress= as render's";
  return doc;
}

/// A trace's docstring, with its keywords of the settings table (kept for the module's life).
const char* traceDoc(const char* what) {
  static std::vector<std::unique_ptr<std::string>> docs;
  docs.push_back(std::make_unique<std::string>(
      what +
      std::string(". The keywords of the settings table (eikon.settings()), each with its "
                  "option of `eikon trace`:") +
      settingsDoc({"wavelength"}, kT) +
      "\n  march=None: MarchSettings() (its step_voxels is --step; 0.25 voxels by default)"));
  return docs.back()->c_str();
}

void bindRenderer(py::module_& m) {
  py::class_<Prepared, std::shared_ptr<Prepared>>(
      m, "Renderer",
      "A scene voxelised once and marched on the GPU (ViewRenderer) or the CPU (ReferenceMarcher).")
      .def(py::init(
               [](std::shared_ptr<Scene> s) { return std::make_shared<Prepared>(std::move(s)); }),
           py::arg("scene"))
      .def_property_readonly("scene", [](const Prepared& p) { return p.scene; })
      .def("grid", &grid, "voxel grid facts (voxelises on first call)")
      .def("render", &render, settingArg("width", kR), settingArg("height", kR),
           settingArg("spp", kR), settingArg("wavelengths", kR), settingArg("wavelength", kR),
           py::arg("march") = py::none(), settingArg("device", kR), settingArg("threads", kR),
           py::arg("light") = true, py::arg("light_cache") = true,
           settingArg("spectral-sampling", kR), settingArg("layers", kR),
           settingArg("polarised", kR), settingArg("modes", kR), py::arg("progress") = py::none(),
           renderDoc().c_str())
      .def("simulate_light", &simulateLight, settingArg("light-bands", kL),
           settingArg("light-splat", kL), settingArg("light-step", kL),
           settingArg("light-smoothing", kL), settingArg("caustics", kL),
           settingArg("light-device", kL), py::arg("progress") = py::none(),
           settingArg("light-split", kL), settingArg("max-patches", kL),
           settingArg("light-reflections", kL), lightDoc().c_str())
      .def("light_volumes", &lightVolumes,
           "{'fluence': (Z, Y, X, 4) φ_r, φ_g, φ_b, φ_Y (W/mm²), 'flux': (Z, Y, X, 4) net flux "
           "vector} "
           "on the voxel grid (index [k, j, i] is the voxel centred at origin + (i + ½, j + ½, k + "
           "½)·h)")
      .def("trace_rays", &traceRays, py::arg("origins"), py::arg("directions"),
           settingArg("wavelength", kT), py::arg("march") = py::none(), py::arg("device") = "gpu",
           traceDoc("many rays: {'wavelength_nm': (N,), 'device', 'modes': {'o': {key: "
                    "(N,3)|(N,)}, 'e': ...}}"))
      .def("trace", &traceOne, py::arg("origin"), py::arg("direction"),
           settingArg("wavelength", kT), py::arg("march") = py::none(), py::arg("device") = "gpu",
           traceDoc("one ray, the CLI JSON shape: {'wavelength_nm', 'device', 'modes': [{'mode': "
                    "'o', ...}, ...]}"))
      .def("light_tree", &lightTreeOne, py::arg("origin"), py::arg("direction"),
           settingArg("wavelength", kT), py::arg("march") = py::none(),
           py::arg("min_weight") = LightTreeSettings{}.min_weight,
           py::arg("max_depth") = LightTreeSettings{}.max_depth,
           "the light tree of one ray on the CPU twin (`eikon trace --tree`; docs/design.md §3): "
           "every Fresnel split followed both ways, {'ray', 'limits', 'trees': [{'mode', 'nodes': "
           "[{'id', 'parent', 'event', 'point', 'direction', 'weight', ...}], 'exits', 'totals': "
           "{'exit', 'stopped', 'absorbed', 'cut'}, 'marches'}], 'device'}; min_weight in "
           "[1e-15, 1] and max_depth in [1, 1024] as --tree-min-weight and --tree-max-depth")
      .def("trace_polarised", &tracePolarisedOne, py::arg("origin"), py::arg("direction"),
           settingArg("wavelength", kT), py::arg("stokes") = std::vector<double>{1, 0, 0, 0},
           py::arg("device") = "gpu", py::arg("bandwidth_nm") = 10.0,
           py::arg("source_angle_rad") = 1e-3, py::arg("reflect_at") = std::vector<int>{},
           "the polarised trace of one ray (`eikon trace --stokes`; docs/polarisation.md) for the "
           "input Stokes vector `stokes` in Mitsuba 3's stokes_basis of `direction`: "
           "{'stokes_out': (4,), 'beams': [{'direction', 'exit_point', 'frame_x', 'stokes', "
           "'branches', 'coherent_groups', 'modes'}], 'frame_x_in', 'truncated', 'device'}; each "
           "beam's Stokes vector is in the stokes_basis of its direction (frame_x)");

  bindModuleCalls(m);
}

}  // namespace eikon::python
