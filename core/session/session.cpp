#include "core/session/session.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/contract/polarised_render.h"
#include "core/contract/render_layers.h"
#include "core/light/light_cache.h"
#include "core/light/lighting.h"
#include "core/reference/polarised_render.h"
#include "core/reference/polarised_trace.h"
#include "core/reference/reference_lighting.h"
#include "core/reference/reference_marcher.h"
#include "core/render/light_simulator.h"
#include "core/render/light_transport.h"
#include "core/render/render_defaults.h"
#include "core/render/view_pipeline_start.h"
#include "core/render/view_renderer.h"
#include "core/scene/limits.h"
#include "core/vk/context.h"
#include "core/volume/host_memory.h"
#include "core/volume/volume_cache.h"

namespace eikon {

// ---------------------------------------------------------------- settings and their ranges

namespace {
/// Floats per pixel of a render's image and layers (RenderImage).
int renderChannels(const Scene& scene, const RenderSettings& rs) {
  int channels = 3;
  if (rs.spectral_layer) channels += std::max(rs.wavelengths, 1);
  if (rs.mode_layers) channels += 6;
  if (rs.aov_layer) channels += kAovChannels;
  if (rs.stokes_layers || isPolarisedRender(scene, rs)) channels += 12;
  return channels;
}
}  // namespace

Integrator parseIntegrator(const std::string& s) {
  if (s == "euler") return Integrator::Euler;
  if (s == "midpoint") return Integrator::Midpoint;
  if (s == "rk4") return Integrator::RK4;
  checkSettingChoice(setting("integrator"), s);
  throw std::logic_error("parseIntegrator: a choice of the table it does not know");
}

SpectralSampling parseSpectralSampling(const std::string& s) {
  if (s == "auto") return SpectralSampling::Auto;
  if (s == "hero") return SpectralSampling::Hero;
  if (s == "stratified") return SpectralSampling::Stratified;
  checkSettingChoice(setting("spectral-sampling"), s);
  throw std::logic_error("parseSpectralSampling: a choice of the table it does not know");
}

Modes parseModes(const std::string& s) {
  if (s == "both") return Modes::Both;
  if (s == "o" || s == "fast") return Modes::O;  // mode 0: o, or a biaxial crystal's fast mode
  if (s == "e" || s == "slow") return Modes::E;
  checkSettingChoice(setting("modes"), s);
  throw std::logic_error("parseModes: a choice of the table it does not know");
}

void parseLayers(const std::string& list, ViewRequest& view) {
  view.spectral_layer = view.mode_layers = view.aov_layer = view.stokes_layers = false;
  size_t start = 0;
  while (start <= list.size() && !list.empty()) {
    const size_t end = std::min(list.find(',', start), list.size());
    const std::string name = list.substr(start, end - start);
    if (name == "spectral")
      view.spectral_layer = true;
    else if (name == "modes")
      view.mode_layers = true;
    else if (name == "aov")
      view.aov_layer = true;
    else if (name == "stokes")
      view.stokes_layers = true;
    else
      throw SettingError("layers", "must be a comma-separated list of " +
                                       settingChoiceList(setting("layers"), " and ") + ", got '" +
                                       name + "' in '" + list + "'");
    start = end + 1;
  }
}

double renderHostBytes(const Scene& scene, const RenderSettings& rs) {
  const double w = rs.width > 0 ? rs.width : scene.camera.width,
               h = rs.height > 0 ? rs.height : scene.camera.height;
  return w * h * 16.0 * renderChannels(scene, rs);
}

void checkRenderFitsHost(const Scene& scene, const RenderSettings& rs) {
  const double need = renderHostBytes(scene, rs);
  const HostMemory mem = availableHostMemory();
  if (need <= double(mem.available)) return;
  const int w = rs.width > 0 ? rs.width : scene.camera.width,
            h = rs.height > 0 ? rs.height : scene.camera.height;
  throw std::runtime_error(
      "a " + std::to_string(w) + "x" + std::to_string(h) + " image of " +
      std::to_string(renderChannels(scene, rs)) + " channels a pixel needs about " +
      formatBytes(need) + " of host memory, " + formatBytes(double(mem.available)) +
      " available (" + mem.limited_by + "); lower the width and height or leave out layers");
}

double traceHostBytes(size_t rays) {
  // The request; four outcomes of a ray's two modes (the twin's, the session's, an isotropic
  // scene's single-mode copy); a GPU ray (32 bytes) and its two results (2 × 64 bytes), each in a
  // mapped buffer and in a host copy.
  const double per_ray =
      double(sizeof(TraceRequest)) + 5.0 * double(sizeof(TraceOutcome)) + 2.0 * (32.0 + 2.0 * 64.0);
  return double(rays) * per_ray;
}

void checkTraceFitsHost(size_t rays, double caller_bytes) {
  const double need = traceHostBytes(rays) + caller_bytes;
  const HostMemory mem = availableHostMemory();
  if (need <= double(mem.available)) return;
  throw std::runtime_error("a trace of " + std::to_string(rays) + " rays needs about " +
                           formatBytes(need) + " of host memory, " +
                           formatBytes(double(mem.available)) + " available (" + mem.limited_by +
                           "); trace fewer rays at a time");
}

void checkMarchStep(double step_voxels) { checkSettingValue(setting("step"), step_voxels); }

// A size not given is the scene camera's; a given one must be a real size (0 used to mean "the
// scene's" silently, and a negative wavelength count the default).
void checkViewRequest(const ViewRequest& v) {
  if (v.width) checkSettingValue(setting("width"), *v.width);
  if (v.height) checkSettingValue(setting("height"), *v.height);
  if (v.spp) checkSettingValue(setting("spp"), *v.spp);
  if (v.wavelengths) checkSettingValue(setting("wavelengths"), *v.wavelengths);
  if (v.march) checkMarchStep(v.march->step_voxels);
  if (v.march) checkMarchSettings(*v.march);  // the rest, as both twins check them
  checkSettingValue(setting("wavelength"), v.wavelength_nm);
}

RenderSettings renderSettings(const Scene& scene, const ViewRequest& v) {
  RenderSettings rs = defaultRenderSettings(scene);
  rs.width = v.width.value_or(0);
  rs.height = v.height.value_or(0);
  if (v.spp) rs.spp = *v.spp;
  if (v.wavelengths) rs.wavelengths = *v.wavelengths;
  rs.wavelength_nm = v.wavelength_nm;
  if (v.march) rs.march = *v.march;
  rs.sampling = v.sampling;
  rs.spectral_layer = v.spectral_layer;
  rs.mode_layers = v.mode_layers;
  rs.aov_layer = v.aov_layer;
  rs.stokes_layers = v.stokes_layers;
  rs.polarised = v.polarised;
  rs.modes = v.modes;
  if (isPolarisedRender(scene, rs)) {  // refused before anything is voxelised
    if (rs.spectral_layer || rs.mode_layers || rs.aov_layer)
      throw SettingError("layers", "spectral, modes and aov do not go with a polarised render (" +
                                       polarisedBecause(scene, rs) +
                                       "), which writes the stokes layers");
    if (rs.modes != Modes::Both)
      throw SettingError("modes", "a polarised render (" + polarisedBecause(scene, rs) +
                                      ") carries both modes coherently, got one mode alone");
    checkPolarisedScene(scene, rs);
  }
  if (rs.spectral_layer && rs.wavelengths <= 0)
    throw SettingError("layers", "spectral needs a spectral render (wavelengths > 0), got " +
                                     std::to_string(rs.wavelengths) + " wavelengths");
  return rs;
}

namespace {
/// A material's index formulas: n_o (and n_e if uniaxial), or a biaxial one's n_α, n_β, n_γ.
std::vector<const Dispersion*> indexFormulas(const Material& m) {
  if (m.biaxial) return {&m.n_alpha, &m.n_beta, &m.n_gamma};
  if (m.uniaxial) return {&m.n_o, &m.n_e};
  return {&m.n_o};
}
}  // namespace

std::vector<std::string> materialRangeWarnings(const Scene& scene, const RenderSettings& rs) {
  std::vector<std::string> out;
  size_t count = 0;  // the first 10 are said, the rest counted (a scene may hold many materials)
  for (const auto& [name, m] : scene.materials)
    for (const Dispersion* d : indexFormulas(m)) {
      bool outside = rs.wavelengths > 0 ? !(d->inRange(380.0) && d->inRange(780.0))
                                        : !d->inRange(rs.wavelength_nm);
      if (outside && d->rangeNm()) {
        if (++count > 10) break;
        out.push_back("material '" + name + "' is measured over " +
                      std::to_string(int((*d->rangeNm())[0])) + "-" +
                      std::to_string(int((*d->rangeNm())[1])) +
                      " nm; rendering outside that range extrapolates");
        break;
      }
    }
  if (count > 10)
    out.push_back("... and " + std::to_string(count - 10) +
                  " more such warnings (materials measured over a narrower range)");
  return out;
}

void checkThreads(int threads) { checkSettingValue(setting("threads"), threads); }

void checkLightRequest(const LightRequest& l) {
  checkSettingValue(setting("light-bands"), l.bands);
  checkSettingChoice(setting("light-splat"), l.splat);
  checkSettingChoice(setting("light-device"), l.device);
  checkSettingChoice(setting("caustics"), l.caustics);
  checkSettingValue(setting("light-step"), l.step_voxels);
  checkThreads(l.threads);
  checkSettingValue(setting("light-smoothing"), l.smoothing_voxels);
  checkSettingValue(setting("light-split"), l.split_voxels);
  checkSettingValue(setting("max-patches"), l.max_patches);
  checkSettingValue(setting("light-reflections"), l.reflections);
}

void checkRenderDevice(const std::string& device) { checkSettingChoice(setting("device"), device); }

void fillSettings(const std::map<std::string, SettingValue, std::less<>>& values, unsigned front,
                  SettingRequests& requests) {
  for (const Setting& s : settings()) {
    const auto it = values.find(s.name);
    if (!(s.fronts & front) || it == values.end()) continue;
    const SettingValue& v = it->second;
    if (!v.given && !*settingDefault(s, front).value && s.kind != SettingKind::Flag) continue;
    if (s.kind == SettingKind::Integer) checkSettingValue(s, v.integer);
    if (s.kind == SettingKind::Number) checkSettingValue(s, v.number);
    if (s.kind == SettingKind::Choice) checkSettingChoice(s, v.text);
    s.fill(v, requests);  // a Text setting is checked by its parser here
  }
}

LightingOptions lightingOptions(const LightRequest& l, double voxel_mm) {
  LightingOptions lo = defaultLightingOptions();
  lo.bands = l.bands;
  lo.wave.splat = l.splat == "highest" ? WavefrontSettings::Splat::HighestEnergy
                                       : WavefrontSettings::Splat::Accumulate;
  lo.wave.dt = l.step_voxels * voxel_mm;
  lo.wave.split_span_voxels = l.split_voxels;
  lo.wave.max_patches = l.max_patches;
  lo.max_reflection_generations = l.reflections;
  lo.wave.pass_caustics = l.caustics == "pass";
  lo.wave.threads = l.threads;
  lo.smoothing_voxels = l.smoothing_voxels;
  return lo;
}

void checkTraceRequest(const TraceRequest& ray) {
  // As a scene's positions: within ±1e12 mm, so that the ray's points stay finite (an origin at
  // z = -1e300 printed an exit at -inf and NaN Stokes).
  for (int a = 0; a < 3; ++a)
    if (!(std::abs(ray.origin[a]) <= kMaxCoordinateMm)) {
      char got[64];
      std::snprintf(got, sizeof got, "%.10g", ray.origin[a]);
      throw SettingError("origin", std::string("must be within ±1e12 mm on each axis, got ") + got +
                                       " on " + "xyz"[a]);
    }
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(ray.direction[a])) throw SettingError("dir", "must be three finite numbers");
  if (glm::length(ray.direction) < 1e-12) throw SettingError("dir", "must be a non-zero vector");
  if (!std::isfinite(glm::length(ray.direction)))
    throw SettingError("dir", "must have a finite length (scale it down)");
  checkSettingValue(setting("wavelength"), ray.wavelength_nm);
}

// ---------------------------------------------------------------- the session

std::shared_ptr<vk::Context> newContext() { return vk::Context::create(); }

Session::Session(std::shared_ptr<Scene> scene, ContextSource context)
    : scene_(std::move(scene)), context_source_(std::move(context)) {}

Session::~Session() = default;

vk::Context& Session::context() {
  if (!ctx_) {
    checkVolumeSpec(scene_->volume, scene_->file);  // edited since parsing (Python)
    auto ctx = context_source_();
    checkVolumeFits(*ctx, makeGrid(scene_->volume), *scene_);
    ctx_ = std::move(ctx);
  }
  return *ctx_;
}

VolumeSet& Session::prepare(bool gpu) {
  checkVolumeSpec(scene_->volume, scene_->file);  // edited since parsing (Python)
  if (gpu) context();
  std::vector<glm::vec4> fluence, flux;  // a volume of interfaces only: its adopted light kept
  if (volume_ && !volume_->whole()) {    // voxelised whole below; gpu_ stays valid
    fluence = std::move(volume_->light_fluence);
    flux = std::move(volume_->light_flux);
    volume_.reset();
  }
  if (!volume_) {
    VoxelizeOptions vo;
    vo.threads = threads_;
    if (progress_.update)
      vo.progress = [this](double f, const char*) { progress_.update("voxelising", f); };
    auto volume = std::make_unique<VolumeSet>();
    const uint64_t key = volume_cache_.empty() ? 0 : volumeCacheKey(*scene_);
    std::string notice;
    const bool from_cache =
        key != 0 && loadVolumeCache(volume_cache_, key, *scene_, *volume, &notice);
    if (!notice.empty() && volume_note_) volume_note_(printable(notice));
    if (!from_cache) {
      *volume = voxelize(*scene_, vo);
      const std::string err = key != 0 ? saveVolumeCache(volume_cache_, key, *volume) : "";
      if (!err.empty() && volume_note_) volume_note_("volume cache: " + printable(err));
    }
    volume->light_fluence = std::move(fluence);
    volume->light_flux = std::move(flux);
    volume_ = std::move(volume);
    voxelized_spec_ = scene_->volume;
  }
  return *volume_;
}

const VolumeSet& Session::prepareGpuRender() {
  context();
  if (volume_) return *volume_;
  if (scene_->interfaces != Scene::Interfaces::Sharp) return prepare(true);
  VoxelizeOptions vo;
  vo.threads = threads_;
  auto lean = std::make_unique<VolumeSet>(voxelizeInterfaces(*scene_, vo));
  if (lean->boundary.empty() || lean->media.empty()) return prepare(true);  // not EIKON_F_SHARP
  volume_ = std::move(lean);
  voxelized_spec_ = scene_->volume;
  return *volume_;
}

std::string Session::deviceName(bool gpu) {
  return gpu ? context().deviceName() : std::string("CPU reference (double)");
}

void Session::dropRenderers() {
  gpu_.reset();
  cpu_.reset();
  field_.reset();
}

bool Session::lightOnCpuTwin(const LightRequest& light, bool cpu_render) {
  // CPU renders use the CPU throughout; on a CPU Vulkan device (lavapipe) the double-precision
  // CPU twin is also the faster one (docs/light-simulator.md). auto also takes the CPU twin where
  // the GPU twin's accumulation volume would not fit the device; gpu is refused there.
  if (cpu_render || lightOnCpu(light.device, ctx_.get())) return true;
  const Grid grid = makeGrid(scene_->volume);
  if (light.device == "auto") return !gpuLightFits(context(), grid);
  requireGpuLightFits(context(), grid);
  return false;
}

LightOutcome Session::simulateLight(const LightRequest& light, bool cpu_render,
                                    const std::filesystem::path& cache_dir) {
  LightOutcome out;
  out.on_cpu = lightOnCpuTwin(light, cpu_render);
  VolumeSet& volume = prepare(!cpu_render);
  LightingOptions lo = lightingOptions(light, volume.grid.h);
  if (progress_.update)
    lo.progress = [this](double f, const std::string& what) { progress_.update(what.c_str(), f); };
  const bool use_cache = !cache_dir.empty();
  // The key hashes every field of the volume (~0.3 s at 128³): only when the cache is used.
  const uint64_t key = use_cache ? lightCacheKey(*scene_, volume, lo, out.on_cpu) : 0;
  std::string notice;
  if (use_cache && loadLightCache(cache_dir, key, volume, &notice)) out.cached = true;
  if (!notice.empty()) out.warnings.push_back("light cache: " + printable(notice));
  if (!out.cached) {
    out.summary = out.on_cpu ? simulateLightingReference(*scene_, volume, lo)
                             : simulateLighting(context(), *scene_, volume, lo);
    if (use_cache) {
      std::string err = saveLightCache(cache_dir, key, volume);
      if (!err.empty()) out.warnings.push_back("light cache: " + err);
    }
  }
  lightChanged();  // renderers made before hold the former light volumes (or none)
  return out;
}

void Session::adoptVolume(VolumeSet volume) {
  if (volume_) throw std::invalid_argument("adoptVolume: the session has a volume already");
  if (!volume.whole())
    throw std::invalid_argument("adoptVolume: the volume lacks its fields or its boundary voxels");
  const Grid g = makeGrid(scene_->volume);
  if (volume.grid.dims != g.dims || volume.grid.origin != g.origin || volume.grid.h != g.h)
    throw std::invalid_argument("adoptVolume: the volume is not on this scene's grid");
  volume_ = std::make_unique<VolumeSet>(std::move(volume));
  voxelized_spec_ = scene_->volume;
}

std::unique_ptr<ViewRenderer> Session::makeRendererFor(vk::Context& ctx, const Scene& scene,
                                                       const RenderSettings* expected) {
  if (!volume_ || !volume_->whole() || !volume_->lit())
    throw std::logic_error("makeRendererFor: the session's volume is not whole and lit");
  return std::make_unique<ViewRenderer>(ctx, scene, *volume_, expected);
}

void Session::adoptRenderer(std::unique_ptr<ViewRenderer> renderer, std::vector<glm::vec4> fluence,
                            std::vector<glm::vec4> flux) {
  if (!renderer) throw std::invalid_argument("adoptRenderer: no renderer");
  if (!volume_) throw std::invalid_argument("adoptRenderer: the session has no volume yet");
  if (fluence.size() != volume_->grid.count() || flux.size() != volume_->grid.count())
    throw std::invalid_argument("light volumes of " + std::to_string(fluence.size()) +
                                " voxels for a volume of " + std::to_string(volume_->grid.count()));
  volume_->light_fluence = std::move(fluence);
  volume_->light_flux = std::move(flux);
  cpu_.reset();
  field_.reset();
  gpu_ = std::move(renderer);
}

void Session::environmentChanged() {
  if (gpu_) gpu_->environmentChanged();  // the CPU twin reads scene_->environment at each render
}

void Session::setLightVolumes(std::vector<glm::vec4> fluence, std::vector<glm::vec4> flux) {
  // A volume of interfaces only that holds light volumes (adoptRenderer) takes the new ones as it
  // is: its renderer was made lit, and takes them in place.
  VolumeSet& volume = volume_ && volume_->lit() ? *volume_ : prepare(false);
  if (fluence.size() != volume.grid.count() || flux.size() != volume.grid.count())
    throw std::invalid_argument("light volumes of " + std::to_string(fluence.size()) +
                                " voxels for a volume of " + std::to_string(volume.grid.count()));
  volume.light_fluence = std::move(fluence);
  volume.light_flux = std::move(flux);
  lightChanged();
}

void Session::lightChanged() {
  cpu_.reset();
  field_.reset();
  if (gpu_ && !gpu_->updateLight(*volume_)) gpu_.reset();
}

ViewRenderer& Session::gpuRenderer(const RenderSettings* expected) {
  prepareGpuRender();  // the volume made before, with or without its fields
  if (!gpu_) {
    if (volume_->lit() && !volume_->fields) prepare(true);  // a lit render reads the fields
    if (progress_.working) progress_.working("preparing the GPU (pipelines, volume upload)");
    gpu_ = std::make_unique<ViewRenderer>(*ctx_, *scene_, *volume_, expected);
  }
  return *gpu_;
}

ReferenceMarcher& Session::cpuMarcher() {
  prepare(false);
  if (!cpu_) {
    field_ = std::make_unique<VolumeField>(*volume_);
    cpu_ = std::make_unique<ReferenceMarcher>(*field_, scene_->environment);
  }
  return *cpu_;
}

void Session::startRenderPipeline(const RenderSettings& settings, bool lit) {
  if (!gpu_ && !early_pipeline_)
    early_pipeline_ = startViewPipeline(context(), *scene_, lit, settings);
}

void Session::prefetchRender(const RenderSettings& settings) {
  gpuRenderer(&settings).prefetch(settings);
}

bool Session::renderReady(const RenderSettings& settings) {
  return gpuRenderer(&settings).ready(settings);
}

RenderImage Session::render(const RenderSettings& settings, bool gpu) {
  checkCamera(scene_->camera, scene_->file);  // edited since parsing (Python, the viewer)
  if (gpu && isPolarisedRender(*scene_, settings)) checkGpuPolariserSheets(*scene_);
  // The host's memory is read (several /proc and cgroup files) only for an image larger than
  // one this session found room for: not on every frame of the viewer.
  if (renderHostBytes(*scene_, settings) > render_bytes_fitted_) {
    checkRenderFitsHost(*scene_, settings);
    render_bytes_fitted_ = renderHostBytes(*scene_, settings);
  }
  RenderSettings rs = settings;
  if (progress_.update && !rs.progress)
    rs.progress = [this](double f) { progress_.update("rendering", f); };
  if (isPolarisedRender(*scene_, rs)) {  // docs/polarisation.md "Polarised renders"
    if (gpu) return gpuRenderer().renderPolarised(rs);
    cpuMarcher();  // makes field_
    return renderPolarised(*field_, *scene_, rs, threads_);
  }
  RenderImage img;
  if (gpu) {
    img = gpuRenderer(&rs).render(rs);
  } else {
    Camera cam = scene_->camera;
    if (rs.width > 0) cam.width = rs.width;
    if (rs.height > 0) cam.height = rs.height;
    img = cpuMarcher().render(cam, rs, threads_);
  }
  if (rs.aov_layer && scene_->interfaces == Scene::Interfaces::Smoothed) {
    std::vector<Shape> shapes;
    for (const SceneObject& o : scene_->objects) shapes.push_back(o.shape);
    assignAovObjects(shapes, img);
  }
  return img;
}

void checkIndicesAt(const Scene& scene, double lambda_nm) {
  for (const auto& [name, m] : scene.materials) {
    if (m.grin.type != GrinProfile::Type::None) continue;  // checked inside its object on parsing
    for (const Dispersion* d : indexFormulas(m)) {
      const double n = d->index(lambda_nm);
      if (n >= kMinIndex && n <= kMaxIndex) continue;
      char value[64];
      std::snprintf(value, sizeof value, "%.6g at %.6g nm", n, lambda_nm);
      throw SettingError("wavelength", "leaves the index of material '" + name + "'" +
                                           (m.uniaxial ? d == &m.n_o ? " (n_o)" : " (n_e)" : "") +
                                           " outside [1, 10]: " + value);
    }
  }
}

std::vector<std::array<TraceOutcome, 2>> Session::trace(const std::vector<TraceRequest>& rays,
                                                        const MarchSettings& ms, bool gpu) {
  if (rays.size() > trace_rays_fitted_) {  // the host's memory is read for a larger batch only
    checkTraceFitsHost(rays.size());
    trace_rays_fitted_ = rays.size();
  }
  for (const TraceRequest& q : rays) checkIndicesAt(*scene_, q.wavelength_nm);
  const bool uni = scene_->anyUniaxial() || scene_->anyBiaxial();  // two modes
  std::vector<std::array<TraceOutcome, 2>> out;
  if (gpu) {
    ViewRenderer& r = gpuRenderer();
    if (uni) {
      out = r.traceModes(rays, ms);
    } else {
      auto o = r.trace(rays, ms);
      out.reserve(o.size());
      for (const auto& t : o) out.push_back({t, t});
    }
  } else {
    ReferenceMarcher& r = cpuMarcher();
    out.reserve(rays.size());
    for (const auto& q : rays) {
      TraceOutcome o = r.trace(q, ms, 0);
      out.push_back({o, uni ? r.trace(q, ms, 1) : o});
    }
  }
  if (out.size() != rays.size())
    throw std::runtime_error("trace: outcome count differs from the ray count");
  return out;
}

std::vector<LightTree> Session::lightTrees(const TraceRequest& ray, const MarchSettings& march,
                                           const LightTreeSettings& tree) {
  checkTraceRequest(ray);
  checkMarchSettings(march);
  checkLightTreeSettings(tree);
  checkIndicesAt(*scene_, ray.wavelength_nm);
  ReferenceMarcher& r = cpuMarcher();
  std::vector<LightTree> trees;
  const bool twoModes = scene_->anyUniaxial() || scene_->anyBiaxial();
  for (int mode = 0; mode < (twoModes ? 2 : 1); ++mode)
    trees.push_back(r.lightTree(ray, march, mode, tree));
  return trees;
}

PolarisedTrace Session::tracePolarised(const TraceRequest& ray, const Stokes& input,
                                       const PolarisedTraceSettings& settings, bool gpu) {
  checkPolarisedTrace(ray, input, settings);
  checkIndicesAt(*scene_, ray.wavelength_nm);
  if (gpu) checkGpuPolariserSheets(*scene_);  // before the volume is made
  PolarisedTrace t;
  if (gpu) {
    t = gpuRenderer().tracePolarised(scene_->polarizers, {ray}, {input}, settings).front();
  } else {
    cpuMarcher();  // the volume and its field
    t = eikon::tracePolarised(*field_, scene_->polarizers, ray, input, settings);
  }
  // Both twins spell a branch's modes o and e (mode 0, mode 1); a scene whose crystals are all
  // biaxial names them fast and slow: f and s.
  if (scene_->fastSlowModes())
    for (PolarisedBeam& b : t.beams)
      for (char& c : b.modes) c = c == 'o' ? 'f' : c == 'e' ? 's' : c;
  return t;
}

}  // namespace eikon
