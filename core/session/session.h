// One front-end-neutral entry to eikon's pipeline, called by `eikon render`, `eikon trace`
// (apps/) and the Python module (python/): prepare a scene (its Vulkan device and its voxelised
// volume, each made once and on first need), simulate its light (GPU or CPU twin, through the
// light cache), render it and trace rays in both modes, on the GPU twin or the CPU twin. The
// range checks of the user's settings live here too, read from the one settings table
// (core/session/settings.h: each setting's name, default, range and help, from which the CLI's
// options and Python's keywords are made), so that the CLI and Python refuse the same settings
// with the same words (docs/design.md §3).
//
//   auto scene = std::make_shared<eikon::Scene>(eikon::loadScene("scenes/glass_sphere.json"));
//   eikon::ViewRequest view;  view.width = 320;
//   eikon::checkViewRequest(view);                          // throws eikon::SettingError
//   eikon::Session session(scene);                          // nothing made yet
//   RenderImage img = session.render(eikon::renderSettings(*scene, view), /*gpu=*/true);
//   auto both = session.trace({{origin, dir, 587.56}}, MarchSettings{}, /*gpu=*/false);  // [o, e]
//
// A SettingError names the setting in neutral words ("width", "light-splat": the CLI's option
// without its dashes) and says what is wrong ("must be in [1, 16384], got 0"); each front end
// spells the name its way (`--width`, Python's `width=` keyword).
//
// Not thread-safe: one caller at a time (Python holds one per Renderer and releases the GIL only
// around a call). The scene is shared: the caller may edit its camera between renders; edits to
// its volume need a new Session.
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/contract/light_tree.h"
#include "core/contract/march_types.h"
#include "core/contract/polarised.h"
#include "core/light/lighting_driver.h"
#include "core/scene/scene.h"
#include "core/session/settings.h"
#include "core/volume/volume_set.h"

namespace eikon {
namespace vk {
class Context;
}
class ViewRenderer;
class ReferenceMarcher;
class VolumeField;

/// What a render is asked for; an unset value takes the default of core/render/render_defaults.h.
struct ViewRequest {
  std::optional<int> width, height;    ///< [1, 16384]; unset: the scene camera's
  std::optional<int> spp;              ///< [1, 4096] jittered samples; unset: the scene's or 1
  std::optional<int> wavelengths;      ///< [0, 256] (0 = RGB); unset: defaultWavelengths(scene)
  double wavelength_nm = 587.5618;     ///< the index wavelength of the RGB mode, [100, 10000] nm
  std::optional<MarchSettings> march;  ///< step in (0, 4] voxels; unset: the render defaults
  SpectralSampling sampling = SpectralSampling::Auto;  ///< spectral renders (docs/spectra.md)
  bool spectral_layer = false, mode_layers = false;    ///< parseLayers; RenderSettings's
  bool aov_layer = false;                              ///< parseLayers; RenderSettings's
  bool stokes_layers = false;                          ///< parseLayers ("stokes")
  /// A polarised render even without polariser sheets or an analyser (`--polarised`).
  bool polarised = false;
  Modes modes = Modes::Both;  ///< parseModes; RenderSettings's
};

/// "euler", "midpoint" or "rk4"; else SettingError("integrator", ...).
Integrator parseIntegrator(const std::string& name);
/// A comma-separated list of "spectral", "modes", "aov" and "stokes" (the extra image layers)
/// into the request; else SettingError("layers", ...). An empty list asks for none.
void parseLayers(const std::string& list, ViewRequest& view);
/// "auto", "hero" or "stratified"; else SettingError("spectral-sampling", ...).
SpectralSampling parseSpectralSampling(const std::string& name);
/// "both", "o" or "e" (RenderSettings::modes); else SettingError("modes", ...).
Modes parseModes(const std::string& name);
/// March step in (0, 4] voxels; else SettingError("step", ...).
void checkMarchStep(double step_voxels);
/// Every range of a ViewRequest (SettingError for the first one out of range).
void checkViewRequest(const ViewRequest& view);
/// defaultRenderSettings(scene) with what the request sets.
RenderSettings renderSettings(const Scene& scene, const ViewRequest& view);
/// Host memory a render of `settings` holds at its peak, estimated: 16 bytes per image channel
/// per pixel (the image, its layers and the copies the output files are made from; measured 8–12
/// bytes at 2048×2048 with and without layers on lavapipe).
double renderHostBytes(const Scene& scene, const RenderSettings& settings);
/// std::runtime_error (one line, with the numbers) when renderHostBytes exceeds the host memory
/// available to the process (availableHostMemory), before anything is allocated; Session::render
/// checks it too, `eikon render` before voxelising.
void checkRenderFitsHost(const Scene& scene, const RenderSettings& settings);
/// One line per material whose measured range the render leaves ("material 'x' is measured over
/// 400-700 nm; rendering outside that range extrapolates"): spectral renders need 380-780 nm, RGB
/// renders the index wavelength.
std::vector<std::string> materialRangeWarnings(const Scene& scene, const RenderSettings& settings);

/// The light simulator as the user asks for it (defaults: defaultLightingOptions()).
struct LightRequest {
  int bands = 0;                     ///< [0, 64]; 0: defaultLightBands
  std::string splat = "accumulate";  ///< accumulate (fluence rate) or highest
  double step_voxels = 0.0;          ///< time step in voxels, [0, 2]; 0: 0.5
  double split_voxels = 1.0;         ///< split patches longer than this, [0.25, 8]
  int max_patches = 1 << 20;         ///< live patches, [1024, 2^24]
  int reflections = 4;               ///< reflected generations at sharp interfaces, [0, 64]
  std::string caustics = "pass";     ///< pass (through a fold caustic) or kill (Tevs)
  double smoothing_voxels = 1.0;     ///< σ of the final smoothing of the light volumes, [0, 8]
  std::string device = "auto";       ///< auto (lightOnCpu), gpu or cpu
  int threads = 0;                   ///< CPU twin threads (0: all, at most 8)
};
void checkLightRequest(const LightRequest& light);
/// What the settings of the table (core/session/settings.h) fill: a render, its march, the light
/// simulator, the twin and the CPU threads, each at its default until a setting fills it.
struct SettingRequests {
  ViewRequest view;
  MarchSettings march;  ///< render: ViewRequest::march (the CLI sets it); trace: the trace's
  LightRequest light;
  std::string device = "auto";      ///< checkRenderDevice, renderTwin
  int threads = 0;                  ///< Session::setThreads
  double wavelength_nm = 587.5618;  ///< a trace's (TraceRequest::wavelength_nm)
  LightTreeSettings tree;           ///< `eikon trace --tree`'s limits
};
/// The settings of `front` (one SettingFront bit) from `values` (by name), in table order: each
/// given one, and each with a default, checked against its range or choices (SettingError) and
/// filled into `requests`. A setting missing from `values` is left as it is.
void fillSettings(const std::map<std::string, SettingValue, std::less<>>& values, unsigned front,
                  SettingRequests& requests);
/// The twin a render is asked for: "auto" (renderTwin), "gpu" or "cpu"; else
/// SettingError("device", ...).
void checkRenderDevice(const std::string& device);
/// CPU threads: [1, 1024], or 0 for all cores; else SettingError("threads", ...).
void checkThreads(int threads);
/// The simulator options of a request for voxels of `voxel_mm`.
LightingOptions lightingOptions(const LightRequest& light, double voxel_mm);

/// A ray's wavelength in [100, 10000] nm ("wavelength") and a non-zero direction ("dir").
void checkTraceRequest(const TraceRequest& ray);
/// Host memory Session::trace of `rays` rays holds at its peak, estimated: the requests, the
/// outcomes of both modes (held by the twin, by the session and, for an isotropic scene, once
/// more while they are paired), and the GPU twin's staging of each ray and its two results
/// (host memory on a CPU Vulkan device such as lavapipe): about 0.9 KB a ray.
double traceHostBytes(size_t rays);
/// std::runtime_error (one line, with the numbers) when traceHostBytes(rays) plus `caller_bytes`
/// (what the caller holds for the same rays besides: Python's trace_rays counts its input copies
/// and result arrays) exceeds the host memory available to the process (availableHostMemory),
/// before anything is allocated; Session::trace checks it too.
void checkTraceFitsHost(size_t rays, double caller_bytes = 0.0);
/// Every material's refractive index at the wavelength finite and in [1, 10], as the scene's are
/// over 380–780 nm; else SettingError("wavelength", ...) naming the material and the value (a
/// trace at 200 nm through a Sellmeier fit with a pole there). Session::trace checks it.
void checkIndicesAt(const Scene& scene, double lambda_nm);

/// What simulateLight did.
struct LightOutcome {
  LightingSummary summary;            ///< runs == 0 when nothing was simulated
  bool cached = false;                ///< the light volumes came from the cache
  bool on_cpu = false;                ///< which twin simulated (or would have)
  std::vector<std::string> warnings;  ///< "light cache: ..." (unreadable entry, unwritable folder)
};

/// Progress callbacks; both may be empty.
struct SessionProgress {
  std::function<void(const char* what, double fraction)> update;
  std::function<void(const char* what)> working;  ///< a stage without a fraction
};

using ContextSource = std::function<std::shared_ptr<vk::Context>()>;
/// A fresh Vulkan context (validation as EIKON_VALIDATION says), for a session of its own.
std::shared_ptr<vk::Context> newContext();

class Session {
 public:
  explicit Session(std::shared_ptr<Scene> scene, ContextSource context = newContext);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  const std::shared_ptr<Scene>& scene() const { return scene_; }
  void setProgress(SessionProgress progress) { progress_ = std::move(progress); }
  /// Voxelising and the CPU twin; checkThreads (std::invalid_argument) first.
  void setThreads(int threads) {
    checkThreads(threads);
    threads_ = threads;
  }
  /// Read the voxelised volume from, and store it in, the volume cache in `dir`
  /// (core/volume/volume_cache.h) instead of voxelising on every run; empty (the default): no
  /// cache. `note` gets its one-line notices (an unusable entry ignored, a failed save).
  void setVolumeCache(std::filesystem::path dir,
                      std::function<void(const std::string&)> note = {}) {
    volume_cache_ = std::move(dir);
    volume_note_ = std::move(note);
  }

  /// The Vulkan context, made on first use; the scene's volume is checked against its limits
  /// then (checkVolumeFits), before anything is voxelised.
  vk::Context& context();
  bool hasContext() const { return ctx_ != nullptr; }
  /// The context (gpu) and the voxelised volume, each made once (a volume without fields, made
  /// by prepareGpuRender, is voxelised whole here, keeping the light volumes adoptRenderer gave
  /// it).
  VolumeSet& prepare(bool gpu);
  /// What a GPU render without light volumes needs: the context and, for sharp interfaces, only
  /// the volume's interfaces (voxelizeInterfaces: no fields, no volume cache; docs/performance.md
  /// "Start-up"), else prepare(true). Renders, polarised renders and GPU traces use either;
  /// everything else (the CPU twin, a light simulation, prepare) voxelises the fields first.
  const VolumeSet& prepareGpuRender();
  bool voxelized() const { return volume_ != nullptr; }
  /// The scene's volume settings when it was voxelised.
  const VolumeSpec& voxelizedSpec() const { return voxelized_spec_; }
  /// "CPU reference (double)" or the Vulkan device's name.
  std::string deviceName(bool gpu);

  /// Whether simulateLight takes the CPU twin: cpu_render, or lightOnCpu(light.device), or "auto"
  /// where the GPU twin's accumulation volume would not fit the device (gpuLightFits); "gpu"
  /// there throws std::runtime_error (one line), before anything is voxelised.
  bool lightOnCpuTwin(const LightRequest& light, bool cpu_render);

  /// Simulate the scene's lights into the volume (callers skip scenes without lights): by the CPU
  /// twin when lightOnCpuTwin says so, else the GPU twin; through the light
  /// cache in `cache_dir` unless it is empty. A GPU renderer made before with light volumes gets
  /// the new ones written in place (ViewRenderer::updateLight: no pipeline built again); other
  /// renderers made before are rebuilt on their next use.
  LightOutcome simulateLight(const LightRequest& light, bool cpu_render,
                             const std::filesystem::path& cache_dir);
  /// Take a volume voxelised by another session of the same scene (the viewer's own, where its
  /// first frame needed the whole volume: smoothed interfaces; copied for the session that
  /// simulates its light in the background) instead of voxelising the scene again. Throws
  /// std::invalid_argument when this session has a volume already, or `volume` is not whole
  /// (VolumeSet::whole) or not on this scene's grid.
  void adoptVolume(VolumeSet volume);
  /// A GPU renderer of this session's volume, whole and lit (simulateLight before; else
  /// std::logic_error), for another session of the same scene to adopt (adoptRenderer): made on
  /// `ctx`, that session's context, and rendering `scene`, that session's scene. The viewer makes
  /// its lit renderer so, on the thread that simulated its first light, while its window renders
  /// the scene unlit (docs/viewer.md "The first light"): until it renders, the renderer reads no
  /// part of `scene` the viewer changes (the camera), and `ctx`'s queue is shared under its lock
  /// (vk::Context::submitAndWait). `expected`: the render that will follow, whose pipeline then
  /// compiles during the upload.
  std::unique_ptr<ViewRenderer> makeRendererFor(vk::Context& ctx, const Scene& scene,
                                                const RenderSettings* expected);
  /// A GPU renderer another session made for this one (makeRendererFor) from the light volumes
  /// `fluence` and `flux`, which this session's volume takes as they are (a volume of interfaces
  /// only as well: nothing is voxelised here, and setLightVolumes later writes into the renderer
  /// in place). It replaces the renderer made before (the viewer's unlit one). Throws
  /// std::invalid_argument when the session has no volume yet (prepareGpuRender) or the light
  /// volumes are not its size.
  void adoptRenderer(std::unique_ptr<ViewRenderer> renderer, std::vector<glm::vec4> fluence,
                     std::vector<glm::vec4> flux);
  /// Light volumes simulated elsewhere for this session's volume (the viewer's background
  /// simulation of a moved light, on a session of its own), swapped in as simulateLight's are.
  /// Throws std::invalid_argument when their size is not the volume's.
  void setLightVolumes(std::vector<glm::vec4> fluence, std::vector<glm::vec4> flux);
  /// The scene's environment was changed in place (scene()->environment; the viewer's lighting
  /// key): the GPU renderer, if made, takes the new one (ViewRenderer::environmentChanged).
  void environmentChanged();
  RenderImage render(const RenderSettings& settings, bool gpu);
  /// Start compiling the GPU render's view pipeline now, on a thread of its own, before the
  /// volume exists (core/render/view_pipeline_start.h): `eikon render` calls it once the device is
  /// made. `lit`: light volumes will be simulated (or read from the light cache) before the render.
  void startRenderPipeline(const RenderSettings& settings, bool lit);
  /// The GPU twin's ViewRenderer::prefetch and ::ready (the viewer: pipelines of its keys compiled
  /// ahead, and the window kept responding while one compiles).
  void prefetchRender(const RenderSettings& settings);
  bool renderReady(const RenderSettings& settings);
  /// Both modes {o, e} of each ray. Isotropic scenes: one march, reported as both (the e-mode is
  /// the o-mode by definition).
  std::vector<std::array<TraceOutcome, 2>> trace(const std::vector<TraceRequest>& rays,
                                                 const MarchSettings& march, bool gpu);
  /// The light trees of one ray on the CPU twin (ReferenceMarcher::lightTree,
  /// core/contract/light_tree.h; `eikon trace --tree`): {o, e} in a scene with crystals, each of
  /// weight 1, else the one isotropic tree. Throws std::invalid_argument for a bad input.
  std::vector<LightTree> lightTrees(const TraceRequest& ray, const MarchSettings& march,
                                    const LightTreeSettings& tree);
  /// The polarised trace of one ray for the input Stokes vector `input` through the scene's sharp
  /// interfaces and polariser sheets (docs/polarisation.md): the GPU twin
  /// (ViewRenderer::tracePolarised) or the CPU twin (tracePolarised). Throws
  /// std::invalid_argument for a bad input, std::runtime_error for a scene the trace does not
  /// support (no sharp interfaces, a varying region on the path).
  PolarisedTrace tracePolarised(const TraceRequest& ray, const Stokes& input,
                                const PolarisedTraceSettings& settings, bool gpu);

 private:
  void dropRenderers();
  /// The light volumes changed: the GPU renderer takes them in place where it can.
  void lightChanged();
  /// `expected`: the render about to run, whose pipeline then compiles during the upload.
  ViewRenderer& gpuRenderer(const RenderSettings* expected = nullptr);
  ReferenceMarcher& cpuMarcher();

  std::shared_ptr<Scene> scene_;
  ContextSource context_source_;
  SessionProgress progress_;
  int threads_ = 0;
  double render_bytes_fitted_ = 0;  ///< the largest renderHostBytes checkRenderFitsHost passed
  size_t trace_rays_fitted_ = 0;    ///< the most rays checkTraceFitsHost passed
  std::shared_ptr<vk::Context> ctx_;
  std::unique_ptr<VolumeSet> volume_;
  std::filesystem::path volume_cache_;
  std::function<void(const std::string&)> volume_note_;
  VolumeSpec voxelized_spec_;
  std::unique_ptr<ViewRenderer> gpu_;
  std::unique_ptr<VolumeField> field_;
  std::unique_ptr<ReferenceMarcher> cpu_;
  std::shared_ptr<void> early_pipeline_;  // startRenderPipeline's; ends before ctx_
};

}  // namespace eikon
