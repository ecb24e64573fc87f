#include "core/render/view_renderer.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <future>
#include <map>
#include <mutex>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <thread>
#include <tuple>
#include <variant>

#include "anisotropic/units.h"
#include "core/contract/polarised_render.h"
#include "core/contract/render_layers.h"
#include "core/render/boundary_device.h"
#include "core/render/view_pipeline_start.h"
#include "core/spectrum/cie1931.h"
#include "core/spectrum/color.h"
#include "core/spectrum/rgb_to_spectrum.h"
#include "core/vk/timings.h"
#include "shaders/eikon_shared.h"
#include "shaders/polarised_trace.spv.h"
#include "shaders/trace.spv.h"
#include "shaders/view.spv.h"

namespace eikon {
namespace {

// ViewParams.pass.w's bits are named in shaders/eikon_shared.h (EIKON_PASS_*). The AOV bit only
// keys the pipeline: the kernel reads kAov, a specialisation constant.
constexpr int kAovPassBit = EIKON_PASS_AOV;
constexpr int kSharedPassBit = EIKON_PASS_SHARED;  // view.comp's sharing across passes (render())
void validate(const MarchSettings& m) { checkMarchSettings(m); }

/// The view kernel's ViewParams.pass.w for a pass of render(): hero sampling, the layers and
/// whether they keep the modes apart, the modes marched, the AOV layer, the sharing across passes.
int passBits(const RenderSettings& s, bool hero, const LayerSums& layers, bool crossShare) {
  int bits = (hero ? EIKON_PASS_HERO : 0) | (int(s.modes) << EIKON_PASS_MODES_SHIFT) |
             (s.aov_layer ? kAovPassBit : 0) | (crossShare ? kSharedPassBit : 0);
  if (layers.active())
    bits |= EIKON_PASS_LAYERS | (layers.modes() == 2 ? EIKON_PASS_LAYER_MODES : 0);
  return bits;
}

}  // namespace

void checkGpuPolariserSheets(const Scene& scene) {
  const size_t most = EIKON_POL_MAX_SHEETS;
  if (scene.polarizers.size() <= most) return;
  throw std::runtime_error(
      scene.file.string() + ": /objects/" + std::to_string(scene.polarizers[most].object_index) +
      ": the GPU polarised render and trace take at most " + std::to_string(most) +
      " polariser sheets; this is sheet " + std::to_string(most + 1) + " of " +
      std::to_string(scene.polarizers.size()) +
      " (the CPU reference takes any number: eikon render or trace --reference, device=\"cpu\" "
      "in Python)");
}

namespace {

/// The sheets buffer of polarised_trace.comp: a header (count, bandwidth, source angle, reflect_at
/// bit mask), then three vec4s per sheet (eikon_shared.h).
std::vector<glm::vec4> packSheets(const std::vector<PolarizerSheet>& sheets,
                                  const PolarisedTraceSettings& s) {
  if (sheets.size() > size_t(EIKON_POL_MAX_SHEETS))
    throw std::invalid_argument("the GPU polarised trace takes at most " +
                                std::to_string(EIKON_POL_MAX_SHEETS) + " polariser sheets, got " +
                                std::to_string(sheets.size()));
  int mask = 0;
  for (int e : s.reflect_at) {
    if (e < 0 || e >= 24)
      throw std::invalid_argument("the GPU polarised trace's reflect_at events must be in [0, 23]");
    mask |= 1 << e;
  }
  std::vector<glm::vec4> out{glm::vec4(float(sheets.size()), float(s.bandwidth_nm),
                                       float(s.source_angle_rad), float(mask))};
  for (const PolarizerSheet& sh : sheets) {
    out.push_back(glm::vec4(glm::vec3(sh.center), float(sh.width)));
    out.push_back(glm::vec4(glm::vec3(sh.normal), float(sh.height)));
    out.push_back(glm::vec4(glm::vec3(sh.axis), 0.0f));
  }
  return out;
}

/// One ray's result of polarised_trace.comp as the CPU twin's PolarisedTrace (beams by S0).
PolarisedTrace unpackPolarised(const gpu::PolarisedResult& r, const glm::dvec3& dir) {
  if (r.head.z > 0)
    throw std::runtime_error("polarised trace: region " + std::to_string(r.head.z - 1) +
                             " is a gradient-index or radial-axis medium, which the polarised "
                             "trace does not support yet");
  if (r.head.w > 0)
    throw std::runtime_error("polarised trace: the ray enters the volume inside an object");
  PolarisedTrace t;
  t.frame_x_in = stokesBasis(dir);
  t.truncated = r.head.y != 0;
  for (int k = 0; k < std::min(r.head.x, EIKON_POL_MAX_BEAMS); ++k) {
    const gpu::PolarisedBeamOut& o = r.beams[k];
    PolarisedBeam b;
    b.exit_point = glm::dvec3(o.exit_point);
    b.direction = glm::dvec3(o.direction);
    b.frame_x = glm::dvec3(o.frame_x);
    b.stokes = Stokes(o.stokes);
    b.branches = int(o.exit_point.w);
    b.coherent_groups = int(o.direction.w);
    for (int j = 0; j < std::min(b.branches, EIKON_POL_MAX_GROUPED); ++j) {
      std::string m;
      for (int c = 0; c < (o.modes[j] >> 16); ++c) m += ((o.modes[j] >> c) & 1) ? 'e' : 'o';
      b.modes += (j ? "," : "") + (m.empty() ? std::string("-") : m);
    }
    t.beams.push_back(b);
  }
  std::sort(t.beams.begin(), t.beams.end(), [](const PolarisedBeam& u, const PolarisedBeam& v) {
    return u.stokes[0] > v.stokes[0];
  });
  return t;
}

/// What render() refuses, checked before anything is compiled for it.
void validateRender(const RenderSettings& s, const Scene& scene) {
  validate(s.march);
  const int width = s.width > 0 ? s.width : scene.camera.width;
  const int height = s.height > 0 ? s.height : scene.camera.height;
  if (width > 16384 || height > 16384)
    throw std::invalid_argument("image larger than 16384 pixels per side");
  if (s.spp < 1 || s.spp > 4096) throw std::invalid_argument("spp must be in [1, 4096]");
  if (s.wavelengths < 0 || s.wavelengths > 256)
    throw std::invalid_argument("wavelengths must be in [0, 256]");
  if (int(s.modes) < 0 || int(s.modes) > 2)
    throw std::invalid_argument("modes must be both, o or e");
}

/// Pipelines compiled on a thread of its own, one at a time, in the order asked
/// (ViewRenderer::prefetch): a compile keeps one core busy for seconds on lavapipe, and the
/// renderer's dispatches (and the viewer's window) go on meanwhile. The destructor drops what is
/// still queued and waits for the compile in progress.
template <class Key>
class BackgroundCompiler {
 public:
  using Build = std::function<vk::ComputePipeline(const Key&)>;
  explicit BackgroundCompiler(Build build) : build_(std::move(build)) {}
  ~BackgroundCompiler() {
    {
      std::lock_guard<std::mutex> lock(m_);
      stop_ = true;
      queue_.clear();
    }
    cv_.notify_all();
    if (worker_.joinable()) worker_.join();
  }
  BackgroundCompiler(const BackgroundCompiler&) = delete;
  BackgroundCompiler& operator=(const BackgroundCompiler&) = delete;

  /// Queues `key` unless it is queued, compiling or compiled already.
  void request(const Key& key) {
    {
      std::lock_guard<std::mutex> lock(m_);
      if (done_.count(key) || building_ == key ||
          std::find(queue_.begin(), queue_.end(), key) != queue_.end())
        return;
      queue_.push_back(key);
      if (!worker_.joinable()) worker_ = std::thread([this] { run(); });
    }
    cv_.notify_all();
  }
  /// Whether `key` was compiled (or its compile failed) and waits to be taken.
  bool ready(const Key& key) {
    std::lock_guard<std::mutex> lock(m_);
    return done_.count(key) > 0;
  }
  /// `key`'s pipeline: waited for while it compiles; not built (the caller builds it) if it was
  /// never asked for or has not started (it is then taken off the queue). Rethrows what the
  /// compile threw.
  vk::ComputePipeline take(const Key& key) {
    std::unique_lock<std::mutex> lock(m_);
    const auto queued = std::find(queue_.begin(), queue_.end(), key);
    if (queued != queue_.end()) {
      queue_.erase(queued);
      return {};
    }
    cv_.wait(lock, [&] { return building_ != key; });
    const auto it = done_.find(key);
    if (it == done_.end()) return {};
    Result r = std::move(it->second);
    done_.erase(it);
    if (r.error) std::rethrow_exception(r.error);
    return std::move(r.pipeline);
  }

 private:
  struct Result {
    vk::ComputePipeline pipeline;
    std::exception_ptr error;
  };
  void run() {
    std::unique_lock<std::mutex> lock(m_);
    for (;;) {
      cv_.wait(lock, [&] { return stop_ || !queue_.empty(); });
      if (stop_) return;
      const Key key = queue_.front();
      queue_.pop_front();
      building_ = key;
      lock.unlock();
      Result r;
      try {
        r.pipeline = build_(key);
      } catch (...) {
        r.error = std::current_exception();
      }
      lock.lock();
      done_.emplace(key, std::move(r));
      building_.reset();
      cv_.notify_all();
    }
  }
  Build build_;
  std::mutex m_;
  std::condition_variable cv_;
  std::deque<Key> queue_;
  std::optional<Key> building_;
  std::map<Key, Result> done_;
  bool stop_ = false;
  std::thread worker_;
};

// A pipeline's key: kernel, flags, integrator, sharp, AOV, kExact; kernel 0 is
// ViewRenderer::Impl::kView.
using PipelineKey = std::tuple<int, int, int, int, int, int>;
constexpr int kViewKernel = 0;

/// The bindings every march kernel has (the view kernel adds its shared paths, the traces theirs).
std::vector<vk::BindingSpec> marchKernelBindings() {
  std::vector<vk::BindingSpec> common;
  for (uint32_t b = EIKON_B_INDEX_O_A; b <= EIKON_B_AXIS; ++b)
    common.push_back({b, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE});
  for (uint32_t b :
       {uint32_t(EIKON_B_SCATTER), uint32_t(EIKON_B_LIGHT_FLUENCE), uint32_t(EIKON_B_LIGHT_FLUX)})
    common.push_back({b, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE});
  for (uint32_t b :
       {uint32_t(EIKON_B_PARAMS), uint32_t(EIKON_B_ENV_IMAGE), uint32_t(EIKON_B_OUTPUT)})
    common.push_back({b, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
  common.push_back({uint32_t(EIKON_B_TABLES), VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER});
  for (const vk::BindingSpec& b : boundaryBindings()) common.push_back(b);
  for (const vk::BindingSpec& b : uniformTableBindings()) common.push_back(b);
  return common;
}

/// The bindings of the view kernel.
std::vector<vk::BindingSpec> viewKernelBindings() {
  std::vector<vk::BindingSpec> b = marchKernelBindings();
  b.push_back({uint32_t(EIKON_B_SHARED_PATHS), VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
  return b;
}

// kExact (march.glsl): the shape table's rows, the shape count, the kinds present and bit 25,
// which makes it non-zero for a scene without shapes (on the exact path too: shapesTakeExactPath).
int exactConstant(const BoundaryField& bf) {
  int kinds = 0;
  for (const Shape& shape : bf.shapes)
    std::visit(
        [&](const auto& g) {
          using T = std::decay_t<decltype(g)>;
          if constexpr (std::is_same_v<T, SphereShape>) kinds |= 1 << EIKON_SHAPE_SPHERE;
          if constexpr (std::is_same_v<T, BoxShape>) kinds |= 1 << EIKON_SHAPE_BOX;
          if constexpr (std::is_same_v<T, RoundedBoxShape>) kinds |= 1 << EIKON_SHAPE_ROUNDED_BOX;
          if constexpr (std::is_same_v<T, ConvexShape>) kinds |= 1 << EIKON_SHAPE_CONVEX;
          if constexpr (std::is_same_v<T, MeshShape>) kinds |= 1 << EIKON_SHAPE_MESH;
        },
        shape.geometry());
  const int rows = exactTableRows(bf.shapes);  // ≤ kExactMaxRows (256) on the exact path
  return rows | int(bf.shapes.size()) << 10 | kinds << 20 | 1 << 25;
}

/// The specialisation constants of a key: constant_id 0: kSharpMarch, 1: kViewFlags,
/// 2: kIntegrator, 3: kAov, 4: kExact (march.glsl).
std::vector<uint32_t> specialisationOf(const PipelineKey& key) {
  const auto [kernel, flags, integrator, sharpMarch, aov, exact] = key;
  return {uint32_t(sharpMarch), uint32_t(flags), uint32_t(integrator), uint32_t(aov),
          uint32_t(exact)};
}

/// The EIKON_F_* flags of a render's settings (spectral) and march (no skipping, no Fresnel).
int renderFlagsOf(const RenderSettings& s) { return s.wavelengths > 0 ? EIKON_F_SPECTRAL : 0; }

int marchFlagsOf(const MarchSettings& m) {
  return (m.skip_empty ? 0 : EIKON_F_NO_SKIP) | (m.fresnel ? 0 : EIKON_F_NO_FRESNEL);
}

/// The EIKON_F_* flag of the scene's environment kind (march.glsl environmentRgb; none: checker).
int environmentFlagsOf(const Environment& e) {
  return e.type == Environment::Type::Constant  ? EIKON_F_ENV_CONSTANT
         : e.type == Environment::Type::LatLong ? EIKON_F_ENV_LATLONG
                                                : 0;
}

/// View pipelines started before their renderer (startViewPipeline): compiled on a thread of their
/// own; the first renderer on the same context whose key matches takes the result.
struct EarlyPipeline {
  const vk::Context* ctx = nullptr;
  PipelineKey key;
  std::future<vk::ComputePipeline> result;  // waited for when dropped
};
std::mutex early_mutex;
std::vector<EarlyPipeline*> early_pipelines;

/// Whether a started pipeline of `key` on `ctx` waits to be taken.
bool earlyPending(const vk::Context* ctx, const PipelineKey& key) {
  std::lock_guard<std::mutex> lock(early_mutex);
  for (const EarlyPipeline* e : early_pipelines)
    if (e->ctx == ctx && e->key == key && e->result.valid()) return true;
  return false;
}

/// The started pipeline of `key` on `ctx`, waited for (rethrowing what its compile threw); an
/// unbuilt pipeline when none was started.
vk::ComputePipeline takeEarly(const vk::Context* ctx, const PipelineKey& key) {
  std::future<vk::ComputePipeline> f;
  {
    std::lock_guard<std::mutex> lock(early_mutex);
    for (EarlyPipeline* e : early_pipelines)
      if (e->ctx == ctx && e->key == key && e->result.valid()) {
        f = std::move(e->result);
        break;
      }
  }
  return f.valid() ? f.get() : vk::ComputePipeline{};
}

}  // namespace

int volumeFeatureFlags(const VolumeSet& v) {
  const bool sharp = !v.boundary.empty() && !v.media.empty();
  bool varying = false, convex = false, mesh = false, biaxial = false, attenuating = false;
  for (const MediumRecord& r : v.media.regions) {
    varying = varying || !r.homogeneous;
    biaxial = biaxial || r.biaxial;
    // A biaxial crystal's σ_α, σ_β, σ_γ live in the medium table only (the voxel fields hold
    // the isotropic and uniaxial materials' attenuation).
    attenuating = attenuating || r.sigma_o != glm::dvec3(0.0) || r.sigma_e != glm::dvec3(0.0) ||
                  r.sigma_beta != glm::dvec3(0.0) || !r.sigma_spectrum.empty();
  }
  for (const Shape& shape : v.boundary.shapes) {
    convex = convex || std::holds_alternative<ConvexShape>(shape.geometry());
    mesh = mesh || std::holds_alternative<MeshShape>(shape.geometry());
  }
  int flags = 0;
  if (v.dispersive) flags |= EIKON_F_DISPERSIVE;
  if (v.uniaxial) flags |= EIKON_F_UNIAXIAL;
  if (v.attenuating) flags |= EIKON_F_ATTENUATION;
  if (v.emissive) flags |= EIKON_F_EMISSION;
  if (v.opaque) flags |= EIKON_F_OPACITY;
  if (v.scattering) flags |= EIKON_F_SCATTER;
  if (v.lit()) flags |= EIKON_F_LIT;
  if (sharp) flags |= EIKON_F_SHARP;
  if (sharp && varying) flags |= EIKON_F_VARYING;
  if (sharp && convex) flags |= EIKON_F_CONVEX;
  if (sharp && mesh) flags |= EIKON_F_MESH;
  if (sharp && biaxial) flags |= EIKON_F_BIAXIAL;  // fast and slow modes (sharp.glsl)
  if (sharp && attenuating) flags |= EIKON_F_ATTENUATION;
  if (sharp) flags |= crossingPathFlags(v.boundary);
  if (sharp) flags |= uniformTableFlags(v.boundary, v.media);
  return flags;
}

int volumeExactConstant(const VolumeSet& v) {
  const bool sharp = !v.boundary.empty() && !v.media.empty();
  // Also for convex_apart scenes whose table fits the uniform block: their constants unroll the
  // planes' loops (boundary.glsl convexCrossingUnrolled) and find regions on the shapes
  // (regionAt); EIKON_F_EXACT alone selects the exact path.
  return sharp && v.boundary.regionsOnShapes() ? exactConstant(v.boundary) : 0;
}

// The volume's features without voxelising at the scene's resolution. The flags come from the
// materials and the shapes (voxelize's materialValues, the boundary field's shapes and the media
// table), not from the grid, except convex_apart and with it exact: a 4-voxel voxelisation of the
// same scene gives them in milliseconds, convex_apart taken at the real h.
static VolumeSet predictedVolume(const Scene& scene, bool lit) {
  Scene tiny = scene;
  tiny.environment = Environment{};  // not read by the voxeliser; not copied needlessly
  tiny.volume.resolution = 4;
  VolumeSet v = voxelize(tiny, VoxelizeOptions{{}, 1});
  v.boundary.convex_apart = convexShapesApart(v.boundary.shapes, makeGrid(scene.volume).h);
  v.boundary.exact = shapesTakeExactPath(v.boundary.shapes, v.boundary.convex_apart);
  if (lit) v.light_fluence.assign(1, glm::vec4(0.0f));
  return v;
}

int predictVolumeFeatureFlags(const Scene& scene, bool lit) {
  return volumeFeatureFlags(predictedVolume(scene, lit));
}

std::shared_ptr<void> startViewPipeline(vk::Context& ctx, const Scene& scene, bool lit,
                                        const RenderSettings& s) {
  try {
    validateRender(s, scene);
  } catch (const std::invalid_argument&) {
    return nullptr;  // render() refuses them
  }
  if (isPolarisedRender(scene, s)) return nullptr;  // another kernel
  int volume_flags = 0, exact = 0;
  try {
    const VolumeSet v = predictedVolume(scene, lit);
    volume_flags = volumeFeatureFlags(v);
    exact = volumeExactConstant(v);
  } catch (const std::exception&) {
    return nullptr;  // the voxeliser reports what is wrong with the scene, in its own words
  }
  auto early = std::make_shared<EarlyPipeline>();
  early->ctx = &ctx;
  early->key = {kViewKernel,
                volume_flags | environmentFlagsOf(scene.environment) | renderFlagsOf(s) |
                    marchFlagsOf(s.march),
                int(s.march.integrator),
                (volume_flags & EIKON_F_SHARP) ? 1 : 0,
                s.aov_layer ? 1 : 0,
                exact};
  const vk::Context* context = &ctx;
  const PipelineKey key = early->key;
  early->result = std::async(std::launch::async, [context, key] {
    const std::vector<vk::BindingSpec> bindings = viewKernelBindings();
    return vk::ComputePipeline(*context, {k_view_spv, sizeof(k_view_spv) / 4}, bindings, 0, "view",
                               specialisationOf(key));
  });
  {
    std::lock_guard<std::mutex> lock(early_mutex);
    early_pipelines.push_back(early.get());
  }
  // Dropped: off the list, then the future's destructor waits for a compile still running.
  return std::shared_ptr<void>(early.get(), [early](void*) mutable {
    {
      std::lock_guard<std::mutex> lock(early_mutex);
      early_pipelines.erase(std::find(early_pipelines.begin(), early_pipelines.end(), early.get()));
    }
    early.reset();
  });
}

void checkVolumeFits(const vk::Context& ctx, const Grid& grid, const Scene& scene) {
  const auto& lim = ctx.limits();
  for (int a = 0; a < 3; ++a)
    if (uint32_t(grid.dims[size_t(a)]) > lim.max_image_dimension_3d)
      throw std::runtime_error(scene.file.string() + ": /volume/resolution: the volume needs " +
                               std::to_string(grid.dims[0]) + "x" + std::to_string(grid.dims[1]) +
                               "x" + std::to_string(grid.dims[2]) + " voxels but the device '" +
                               ctx.deviceName() + "' allows at most " +
                               std::to_string(lim.max_image_dimension_3d) + " per side");
  // Images: 3 index fields + medium + emission (+ 3 e-index, medium e, axis when uniaxial)
  // (+ scatter when a material has an albedo, + 2 light volumes when the scene has lights).
  size_t images = scene.anyUniaxial() || scene.anyBiaxial() ? 10 : 5;  // two modes
  bool scattering = false;
  for (const auto& [name, m] : scene.materials)
    scattering = scattering || glm::length(m.albedo) > 0;
  if (scattering) images += 1;
  if (!scene.lights.empty()) images += 2;
  double bytes = double(grid.count()) * 16.0 * double(images);
  // The sharp-boundary field: a 32-bit region id and a float distance per voxel.
  if (scene.interfaces == Scene::Interfaces::Sharp) bytes += double(grid.count()) * 8.0;
  if (bytes > 0.9 * double(lim.heap_size))
    throw std::runtime_error(scene.file.string() + ": /volume/resolution: the volume needs " +
                             std::to_string(int64_t(bytes / (1 << 20))) +
                             " MiB of device memory but the device heap has " +
                             std::to_string(lim.heap_size >> 20) + " MiB; lower the resolution");
}

struct ViewRenderer::Impl {
  vk::Context& ctx;
  const Scene& scene;
  Grid grid;
  bool uniaxial = false, scattering = false, lit = false;
  bool sharp = false;    // march region by region (shaders/sharp.glsl), as the CPU twin does
  int volume_flags = 0;  // volumeFeatureFlags: the EIKON_F_* of the volume's features
  int exact = 0;         // volumeExactConstant: kExact (march.glsl), the shapes of the exact path
  // [oA, oB, oC, (eA, eB, eC), medO, (medE), emission, (axis), (scatter), (fluence, flux)]
  std::vector<vk::Image3D> images;
  size_t scatterImage = 0, fluenceImage = 0,
         fluxImage = 0;  // 0: not present (index A bound instead)
  vk::Buffer params, env, tables;
  // The polarised trace's ray and result buffers, kept between its calls and grown as needed: a
  // render calls it once per batch of rays, and fresh buffers cost lavapipe a fault per page of
  // every batch (0.9 s of a 2.1 s render, with the host copies; docs/performance.md).
  vk::Buffer polarisedRays, polarisedResults;
  BoundaryDevice boundary;  // the sharp-boundary field (placeholders when smoothed)
  // One pipeline per kernel and feature set, made on first use (specialization constants 0–2 of
  // march.glsl: the march kind, the EIKON_F_* flags, the integrator). lavapipe executes every
  // branch of a kernel masked, so a kernel with the scene's and the settings' features folded in
  // marches many times faster than one that tests them at run time (docs/performance.md).
  std::vector<vk::BindingSpec> viewBindings, traceBindings, polarisedBindings;
  enum Kernel { kView = 0, kTrace = 1, kPolarised = 2 };
  using Key = PipelineKey;  // kernel, flags, integrator, sharp, AOV, kExact
  static_assert(kView == kViewKernel, "startViewPipeline's key names the view kernel");
  std::map<Key, vk::ComputePipeline> pipelines;
  // View pipelines compiled ahead on a thread of their own (prefetch()): the expected render's
  // while the volume is uploaded (the compile runs on one core, the upload mostly on the other),
  // the viewer's alternatives (its keys) while it shows a view; adopted by pipeline() when their
  // key comes up. Declared after what build() reads, so that it ends first.
  BackgroundCompiler<Key> compiler{[this](const Key& key) { return build(key); }};
  int skip_cap = 32;
  double ambient = 1.0;

  Impl(vk::Context& context, const Scene& s, const VolumeSet& v, const RenderSettings* expected)
      : ctx(context), scene(s), grid(v.grid) {
    checkVolumeFits(ctx, grid, scene);
    uniaxial = v.uniaxial;
    scattering = v.scattering;
    lit = v.lit();
    skip_cap = v.skip_cap;
    ambient = v.ambient_index;
    volume_flags = volumeFeatureFlags(v);
    sharp = (volume_flags & EIKON_F_SHARP) != 0;
    exact = volumeExactConstant(v);
    const std::vector<vk::BindingSpec> common = marchKernelBindings();  // the trace's add rays
    viewBindings = viewKernelBindings();
    traceBindings = common;
    traceBindings.push_back({EIKON_B_RAYS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
    polarisedBindings = traceBindings;
    polarisedBindings.push_back({EIKON_B_SHEETS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
    if (expected) prefetch(*expected);
    std::array<uint32_t, 3> ext{uint32_t(grid.dims[0]), uint32_t(grid.dims[1]),
                                uint32_t(grid.dims[2])};
    // Without light volumes no kernel of the sharp march reads the volume's fields: the view,
    // trace and polarised marches take every index and medium from the medium table, every
    // crossing from the shapes or the boundary field (BoundaryDevice), as the specialised
    // modules show (tests/core/render/kernel_bindings_test.cpp). One-voxel placeholders are bound
    // instead, which saves the upload (~0.5 s for a 128³ sphere) and lets the session skip
    // voxelising the fields (voxelizeInterfaces; docs/performance.md "Start-up").
    const bool fields_unread = sharp && !lit;
    if (!v.fields && !fields_unread)
      throw std::invalid_argument(
          "the volume has no fields (voxelizeInterfaces) but this render reads them");
    const std::vector<glm::vec4> placeholder(1, glm::vec4(0.0f));
    auto upload = [&](const std::vector<glm::vec4>& data, const char* name) {
      const auto& d = fields_unread ? placeholder : data;
      vk::Image3D img(ctx, fields_unread ? std::array<uint32_t, 3>{1, 1, 1} : ext,
                      VK_FORMAT_R32G32B32A32_SFLOAT, name);
      img.upload(ctx, d.data(), d.size() * sizeof(glm::vec4));
      images.push_back(std::move(img));
    };
    const char* names[3] = {"index A", "index B", "index C"};
    for (int c = 0; c < 3; ++c) upload(v.index[0][size_t(c)], names[c]);
    if (uniaxial)
      for (int c = 0; c < 3; ++c) upload(v.index[1][size_t(c)], names[c]);
    upload(v.medium[0], "medium o");
    if (uniaxial) upload(v.medium[1], "medium e");
    upload(v.emission, "emission");
    if (uniaxial) upload(v.axis, "optic axis");
    if (scattering) {
      scatterImage = images.size();
      upload(v.scatter, "scatter");
    }
    if (lit) {
      if (v.light_fluence.size() != grid.count() || v.light_flux.size() != grid.count())
        throw std::invalid_argument("light volumes do not match the volume's grid");
      fluenceImage = images.size();
      upload(v.light_fluence, "light fluence");
      fluxImage = images.size();
      upload(v.light_flux, "light flux");
    }

    boundary = BoundaryDevice(ctx, v.boundary, v.media, scene.file.string());
    params =
        vk::Buffer(ctx, sizeof(gpu::ViewParams), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "view params");
    uploadEnvironment();
    std::vector<glm::vec4> tab(EIKON_TABLE_COUNT, glm::vec4(0.0f));
    for (int i = 0; i < EIKON_CMF_COUNT; ++i)
      tab[size_t(EIKON_CMF_OFFSET + i)] = glm::vec4(glm::vec3(spectrum::cmfTableRow(i)), 0.0f);
    const auto& basis = spectrum::basisTable();
    for (int i = 0; i < EIKON_BASIS_COUNT; ++i)
      tab[size_t(EIKON_BASIS_OFFSET + i)] =
          glm::vec4(basis[size_t(3 * i)], basis[size_t(3 * i + 1)], basis[size_t(3 * i + 2)], 0.0f);
    glm::dmat3 M = spectrum::spectralToLinearSrgbMatrix();
    for (int r = 0; r < 3; ++r)
      tab[size_t(EIKON_MATRIX_OFFSET + r)] =
          glm::vec4(float(M[0][r]), float(M[1][r]), float(M[2][r]), 0.0f);
    tables = vk::Buffer(ctx, tab.size() * sizeof(glm::vec4), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                        "spectral tables");
    tables.write(tab.data(), tab.size() * sizeof(glm::vec4));
    timings::mark("volume uploaded");
  }

  /// The scene's latitude-longitude image into `env` (in place where its size is the same; a
  /// buffer of 16 zero bytes for the other kinds, which march.glsl computes).
  void uploadEnvironment() {
    const auto& e = scene.environment;
    const bool image = e.type == Environment::Type::LatLong;
    const size_t bytes = image ? e.image_rgba.size() * sizeof(float) : 16;
    if (env.handle() == VK_NULL_HANDLE || env.size() != bytes)
      env = vk::Buffer(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                       image ? "environment" : "environment (unused)");
    const float zero[4] = {0, 0, 0, 0};
    env.write(image ? static_cast<const void*>(e.image_rgba.data()) : zero, bytes);
  }

  // The AOV layer is view.comp's pass.w bit EIKON_PASS_AOV (render()), its kAov constant.
  Key keyOf(Kernel kernel, const gpu::ViewParams& p) const {
    const int aov = kernel == kView && (p.pass.w & kAovPassBit) != 0 ? 1 : 0;
    return std::make_tuple(int(kernel), p.grid_dims.w, int(p.march.w), sharp ? 1 : 0, aov, exact);
  }

  // The view, trace or polarised-trace kernel specialised for the flags and integrator of a key.
  vk::ComputePipeline build(const Key& key) const {
    const int kernel = std::get<0>(key);
    const std::vector<uint32_t> spec = specialisationOf(key);
    auto make = [&](std::span<const uint32_t> code, const std::vector<vk::BindingSpec>& b,
                    const char* name) { return vk::ComputePipeline(ctx, code, b, 0, name, spec); };
    return kernel == kTrace  ? make({k_trace_spv, sizeof(k_trace_spv) / 4}, traceBindings, "trace")
           : kernel == kView ? make({k_view_spv, sizeof(k_view_spv) / 4}, viewBindings, "view")
                             : make({k_polarised_trace_spv, sizeof(k_polarised_trace_spv) / 4},
                                    polarisedBindings, "polarised trace");
  }

  // Queues the view pipeline of a render with settings `s` for the background compiler, unless
  // it is built. Settings render() would refuse start nothing (it reports them, without waiting
  // for a build).
  void prefetch(const RenderSettings& s) {
    try {
      validateRender(s, scene);
    } catch (const std::invalid_argument&) {
      return;
    }
    const Key key = viewKey(s);
    if (!pipelines.count(key) && !earlyPending(&ctx, key)) compiler.request(key);
  }

  // Reads no camera: a renderer made on another thread (the viewer's lit renderer) asks for its
  // pipeline while the window's thread moves the camera.
  Key viewKey(const RenderSettings& s) const {
    gpu::ViewParams p{};
    p.grid_dims.w = flagsOf(s.march, renderFlags(s));
    p.march.w = float(int(s.march.integrator));
    p.pass.w = s.aov_layer ? kAovPassBit : 0;
    return keyOf(kView, p);
  }

  // The pipeline for a dispatch with parameters p, built (or adopted from prefetch()) on first use.
  vk::ComputePipeline& pipeline(Kernel kernel, const gpu::ViewParams& p) {
    const Key key = keyOf(kernel, p);
    auto it = pipelines.find(key);
    if (it != pipelines.end()) return it->second;
    // Started before this renderer (startViewPipeline), else by prefetch(), else built here;
    // each rethrows what its compile threw.
    vk::ComputePipeline pl = takeEarly(&ctx, key);
    if (!pl.built()) pl = compiler.take(key);
    if (!pl.built()) pl = build(key);
    return adopt(key, std::move(pl));
  }

  vk::ComputePipeline& adopt(const Key& key, vk::ComputePipeline pl) {
    bindCommon(pl);
    ctx.savePipelineCache();  // core/vk/pipeline_cache.h: the next run may skip the compilation
    timings::mark("pipelines built");
    return pipelines.emplace(key, std::move(pl)).first->second;
  }

  static int renderFlags(const RenderSettings& s) { return renderFlagsOf(s); }

  void bindCommon(vk::ComputePipeline& p) {
    size_t oA = 0, eA = uniaxial ? 3 : 0;
    size_t medO = uniaxial ? 6 : 3, medE = uniaxial ? 7 : 3, emi = uniaxial ? 8 : 4,
           axis = uniaxial ? 9 : 4;
    p.bindImage(EIKON_B_INDEX_O_A, images[oA]);
    p.bindImage(EIKON_B_INDEX_O_B, images[oA + 1]);
    p.bindImage(EIKON_B_INDEX_O_C, images[oA + 2]);
    p.bindImage(EIKON_B_INDEX_E_A, images[eA]);
    p.bindImage(EIKON_B_INDEX_E_B, images[eA + 1]);
    p.bindImage(EIKON_B_INDEX_E_C, images[eA + 2]);
    p.bindImage(EIKON_B_MEDIUM_O, images[medO]);
    p.bindImage(EIKON_B_MEDIUM_E, images[medE]);
    p.bindImage(EIKON_B_EMISSION, images[emi]);
    p.bindImage(EIKON_B_AXIS, images[axis]);
    p.bindImage(EIKON_B_SCATTER, images[scatterImage]);
    p.bindImage(EIKON_B_LIGHT_FLUENCE, images[fluenceImage]);
    p.bindImage(EIKON_B_LIGHT_FLUX, images[fluxImage]);
    p.bindBuffer(EIKON_B_PARAMS, params);
    p.bindBuffer(EIKON_B_ENV_IMAGE, env);
    p.bindBuffer(EIKON_B_TABLES, tables);
    boundary.bind(p);
    boundary.bindUniformTables(p);
  }

  // The EIKON_F_* of a dispatch: the volume's, the environment's, the march's and `extra`.
  int flagsOf(const MarchSettings& m, int extra) const {
    return extra | volume_flags | environmentFlagsOf(scene.environment) | marchFlagsOf(m);
  }

  gpu::ViewParams baseParams(const MarchSettings& m, int flags_extra) const {
    gpu::ViewParams p{};
    const Camera& cam = scene.camera;
    glm::dvec3 fwd = glm::normalize(cam.look_at - cam.position);
    glm::dvec3 right = glm::normalize(glm::cross(fwd, cam.up));
    glm::dvec3 up = glm::cross(right, fwd);
    p.cam_pos = glm::vec4(glm::vec3(cam.position),
                          float(std::tan(0.5 * cam.fov_deg * std::numbers::pi / 180.0)));
    p.cam_forward = glm::vec4(glm::vec3(fwd), float(double(cam.width) / cam.height));
    p.cam_right = glm::vec4(glm::vec3(right), 0.0f);
    p.cam_up = glm::vec4(glm::vec3(up), 0.0f);
    p.grid_origin = glm::vec4(glm::vec3(grid.origin), float(grid.h));
    p.grid_extent = glm::vec4(glm::vec3(grid.extent), float(1.0 / grid.h));
    p.grid_dims = glm::ivec4(grid.dims[0], grid.dims[1], grid.dims[2], flagsOf(m, flags_extra));
    p.march = glm::vec4(float(m.step_voxels), float(m.interface_threshold), float(ambient),
                        float(int(m.integrator)));
    p.limits = glm::ivec4(m.max_steps, 1, 1, skip_cap);
    const auto& e = scene.environment;
    int type = e.type == Environment::Type::Checker    ? EIKON_ENV_CHECKER
               : e.type == Environment::Type::Constant ? EIKON_ENV_CONSTANT
                                                       : EIKON_ENV_LATLONG;
    p.env = glm::vec4(float(type), float(e.squares), float(e.intensity), 0.0f);
    p.env_a =
        glm::vec4(glm::vec3(e.type == Environment::Type::Constant ? e.radiance : e.color_a), 0.0f);
    p.env_b = glm::vec4(glm::vec3(e.color_b), 0.0f);
    p.env_size = glm::ivec4(e.image_width, e.image_height, 0, 0);
    return p;
  }
};

ViewRenderer::ViewRenderer(vk::Context& ctx, const Scene& scene, const VolumeSet& volume,
                           const RenderSettings* expected)
    : impl_(std::make_unique<Impl>(ctx, scene, volume, expected)) {}
ViewRenderer::~ViewRenderer() = default;

void ViewRenderer::prefetch(const RenderSettings& settings) { impl_->prefetch(settings); }

void ViewRenderer::environmentChanged() {
  Impl& I = *impl_;
  I.uploadEnvironment();
  for (auto& [key, pipeline] : I.pipelines) pipeline.bindBuffer(EIKON_B_ENV_IMAGE, I.env);
}

bool ViewRenderer::ready(const RenderSettings& settings) {
  Impl& I = *impl_;
  try {
    validateRender(settings, I.scene);
  } catch (const std::invalid_argument&) {
    return true;  // render() refuses it at once
  }
  const auto key = I.viewKey(settings);
  return I.pipelines.count(key) > 0 || I.compiler.ready(key);
}

bool ViewRenderer::updateLight(const VolumeSet& v) {
  Impl& I = *impl_;
  if (!I.lit || !v.lit()) return false;
  if (v.grid.dims != I.grid.dims || v.light_fluence.size() != I.grid.count() ||
      v.light_flux.size() != I.grid.count())
    throw std::invalid_argument("light volumes do not match the renderer's grid");
  // Renders are synchronous (submitAndWait), so no dispatch reads the images while they change.
  I.images[I.fluenceImage].upload(I.ctx, v.light_fluence.data(),
                                  v.light_fluence.size() * sizeof(glm::vec4));
  I.images[I.fluxImage].upload(I.ctx, v.light_flux.data(), v.light_flux.size() * sizeof(glm::vec4));
  return true;
}

namespace {
// Adds one band's layer values (view.comp layerWrite) to the sums: channels [c0, c1) of each mode
// kept apart (the pass's wavelength bins, all N for a hero pass; r, g, b in RGB mode).
void addLayers(LayerSums& layers, const std::vector<glm::vec4>& band, int width, int rows, int y0,
               int c0, int c1, size_t stride) {
  const int C = layers.channels(), M = layers.modes();
  const size_t base = size_t(width) * size_t(rows);
  const float* all = reinterpret_cast<const float*>(band.data());  // tightly packed vec4s
  for (size_t i = 0; i < size_t(width) * size_t(rows); ++i) {
    const float* v = all + (base + i * stride) * 4;
    for (int m = 0; m < M; ++m) {
      double* sum = layers.at(size_t(y0) * size_t(width) + i, m);
      for (int c = c0; c < c1; ++c) sum[c] += v[m * C + c];
    }
  }
}

// Adds one band's AOV records (view.comp aovWrite, after the band's pixels and layers) to the
// image: every pass's march steps, and the first pass's first interface (sample 0, its first
// wavelength, the o-mode); a zero normal is a march that met none.
void addAov(RenderImage& img, const std::vector<glm::vec4>& band, int rows, int y0, size_t stride,
            bool firstPass, const glm::dvec3& eye) {
  const size_t n = size_t(img.width) * size_t(rows);
  const glm::vec4* aov = band.data() + n * (1 + stride);
  for (size_t i = 0; i < n; ++i) {
    const size_t pixel = size_t(y0) * size_t(img.width) + i;
    const glm::vec4 a = aov[2 * i], b = aov[2 * i + 1];
    addAovSteps(img, pixel, b.w);
    if (!firstPass || glm::vec3(b) == glm::vec3(0.0f)) continue;
    setAovGeometry(
        img, pixel, eye,
        FirstInterface{true, glm::dvec3(glm::vec3(a)), glm::dvec3(glm::vec3(b)), int(a.w)});
  }
}

/// How render() splits a pixel sample into passes, by the wavelength strategy view.comp's main
/// chooses from the pass bits: RGB (one pass at the fixed wavelength), stratified spectral (one
/// wavelength per pass, or all N where wavelength sharing makes one march serve every
/// wavelength, with sharing across passes where it does not) or hero spectral (one pass, all N).
/// Passes are one pixel sample at one wavelength (both modes) per dispatch because lavapipe's
/// loop budget is per invocation, all loops together (view.comp's header,
/// docs/view-renderer.md).
enum class Strategy { Rgb, Stratified, Hero };
struct PassPlan {
  Strategy strategy = Strategy::Rgb;
  int N = 1;                ///< wavelengths per pixel sample (1 in RGB mode)
  int perPass = 1;          ///< wavelengths a pass marches (or shares)
  int passesPerSample = 1;  ///< passes per pixel sample
  int passes = 1;           ///< passes in all (spp of them per sample)
  bool crossShare = false;  ///< sharing across stratified passes (EIKON_PASS_SHARED)
};

/// The plan for the scene's flags (EIKON_F_*): strategy and sharing as view.comp applies them.
/// Sharing across passes (view.comp, EIKON_PASS_SHARED): where the passes march one wavelength
/// each (a crystal, dispersive medium, attenuation, emission or opaque object in the scene), a
/// pixel sample's first pass also adds the other wavelengths of every pixel whose path met nothing
/// that depends on λ (from its record), notes it in one word per pixel, and the sample's later
/// passes skip that pixel. The spectral and modes layers keep the plain passes (their bins are
/// written pass by pass); an image whose words exceed one storage buffer too.
PassPlan planPasses(const RenderSettings& s, int flags, const LayerSums& layers, size_t pixels,
                    const vk::DeviceLimits& limits) {
  PassPlan plan;
  if (s.wavelengths > 0) {
    const bool weightsDependOnLambda =
        (flags & (EIKON_F_ATTENUATION | EIKON_F_EMISSION | EIKON_F_OPACITY)) != 0;
    plan.strategy =
        useHeroSampling(s.sampling, weightsDependOnLambda) ? Strategy::Hero : Strategy::Stratified;
    plan.N = s.wavelengths;
  }
  const int lambdaDependent = EIKON_F_ATTENUATION | EIKON_F_EMISSION | EIKON_F_OPACITY |
                              EIKON_F_TWO_MODES | EIKON_F_DISPERSIVE;
  // Hero: one pass per pixel sample, all N wavelengths; stratified: all N in one pass where no
  // march depends on λ (the others are table lookups), else one each.
  const bool share = plan.strategy == Strategy::Hero ||
                     (plan.strategy == Strategy::Stratified && (flags & lambdaDependent) == 0);
  plan.perPass = share ? plan.N : 1;
  plan.passesPerSample = (plan.N + plan.perPass - 1) / plan.perPass;
  plan.passes = s.spp * plan.passesPerSample;
  plan.crossShare = plan.strategy == Strategy::Stratified && s.wavelengths > 1 && !share &&
                    !layers.active() &&
                    pixels * sizeof(uint32_t) <= limits.max_storage_buffer_range;
  return plan;
}

/// ViewParams.pass of pass `pass`: (pixel sample, first wavelength, wavelengths, pass bits). A
/// pixel sample's first pass with sharing across passes is told to cover all N.
glm::ivec4 passOf(const PassPlan& plan, int pass, const RenderSettings& s,
                  const LayerSums& layers) {
  const int k = pass % plan.passesPerSample;
  return glm::ivec4(pass / plan.passesPerSample, k * plan.perPass,
                    plan.crossShare && k == 0 ? plan.N : plan.perPass,
                    passBits(s, plan.strategy == Strategy::Hero, layers, plan.crossShare));
}

/// The layer channels [c0, c1) a pass writes: r, g, b (RGB), all N bins (hero), the pass's
/// wavelength bins (stratified).
std::pair<int, int> layerChannelsOf(const PassPlan& plan, const glm::ivec4& pass) {
  switch (plan.strategy) {
    case Strategy::Rgb:
      return {0, 3};
    case Strategy::Hero:
      return {0, plan.N};
    case Strategy::Stratified:
      break;
  }
  return {pass.y, std::min(pass.y + pass.z, plan.N)};
}

/// Adds one band's pixels (view.comp: this pass's share of linear sRGB, w = its steps, or
/// −(steps + 1) where a march was cut) to the sums.
void addPixels(std::vector<double>& acc, RenderImage& img, double& steps,
               const std::vector<glm::vec4>& band, int rows, int y0) {
  for (size_t i = 0; i < size_t(img.width) * size_t(rows); ++i) {
    const glm::vec4& v = band[i];
    const size_t o = (size_t(y0) * size_t(img.width) + i) * 3;
    acc[o] += v.x;
    acc[o + 1] += v.y;
    acc[o + 2] += v.z;
    if (v.w < 0.0f) ++img.cut_samples;
    steps += v.w < 0.0f ? -double(v.w) - 1.0 : double(v.w);
  }
}
}  // namespace

RenderImage ViewRenderer::render(const RenderSettings& s) {
  Impl& I = *impl_;
  validateRender(s, I.scene);
  RenderImage img;
  img.width = s.width > 0 ? s.width : I.scene.camera.width;
  img.height = s.height > 0 ? s.height : I.scene.camera.height;
  gpu::ViewParams p = I.baseParams(s.march, Impl::renderFlags(s));
  // Keep the camera's aspect from the requested image size.
  p.cam_forward.w = float(double(img.width) / img.height);
  p.limits.y = s.spp;
  p.limits.z = std::max(1, s.wavelengths);
  // The view march's transport (the trace kernel's parameters keep 0: the transmitted path).
  p.transport = glm::ivec4(s.march.transport == Transport::Full ? 1 : 0, s.march.max_reflections,
                           s.march.split_first_choice ? 1 : 0, 0);
  double l = micrometresFromNanometres(s.wavelength_nm);
  p.wavelength = glm::vec4(float(l), float(1.0 / (l * l)), float(1.0 / (l * l * l * l)), 0.0f);
  I.boundary.setRenderWavelength(s.wavelength_nm);  // the RGB march's indices (sharp.glsl)

  // Passes (planPasses) are outermost so that every finished pass is a whole (noisier) image:
  // RenderSettings::on_pass shows the picture forming.
  // Bands of rows within a pass so that progress is reported and no dispatch runs for long: the
  // band buffer holds up to ~2e5 rays' worth of rows; the first band is one workgroup row, each
  // next one is sized from the last one's time to take ~0.25 s.
  // Layers (core/contract/render_layers.h): per pixel, after the band's RGB, `stride` vec4s of
  // channel values per mode (view.comp layerWrite); the pass's bins are added on the host.
  const bool twoModes = (p.grid_dims.w & EIKON_F_TWO_MODES) != 0;  // uniaxial or biaxial
  LayerSums layers(s, size_t(img.width) * size_t(img.height), twoModes);
  const size_t pixels = size_t(img.width) * size_t(img.height);
  const PassPlan plan = planPasses(s, p.grid_dims.w, layers, pixels, I.ctx.limits());
  const int passes = plan.passes, passesPerSample = plan.passesPerSample;
  const size_t stride = layers.active() ? size_t((layers.channels() * layers.modes() + 3) / 4) : 0;
  // The AOV layer: two vec4s per pixel after those (view.comp aovWrite).
  const size_t perPixel = 1 + stride + (s.aov_layer ? 2 : 0);
  if (s.aov_layer) initAov(img);
  const double rowWork = double(img.width) * plan.perPass;
  int max_rows = std::clamp(int(std::ceil(2.0e5 / std::max(rowWork, 1.0))), EIKON_WG_Y, img.height);
  max_rows = (max_rows + EIKON_WG_Y - 1) / EIKON_WG_Y * EIKON_WG_Y;
  int rows = EIKON_WG_Y;
  vk::Buffer out(I.ctx, size_t(img.width) * size_t(max_rows) * perPixel * sizeof(glm::vec4),
                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "pixels");
  p.pass.w = s.aov_layer ? kAovPassBit : 0;  // the pipeline's key (keyOf)
  vk::ComputePipeline& view = I.pipeline(Impl::kView, p);
  view.bindBuffer(EIKON_B_OUTPUT, out);
  vk::Buffer sharedPaths(I.ctx, (plan.crossShare ? pixels : 1) * sizeof(uint32_t),
                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "shared paths");
  view.bindBuffer(EIKON_B_SHARED_PATHS, sharedPaths);
  std::vector<double> acc(pixels * 3, 0.0);
  img.rgb.assign(pixels * 3, 0.0f);
  std::vector<glm::vec4> band(size_t(img.width) * size_t(max_rows) * perPixel);
  double steps = 0.0;
  auto t0 = std::chrono::steady_clock::now();
  for (int pass = 0; pass < passes; ++pass) {
    p.pass = passOf(plan, pass, s, layers);
    for (int y0 = 0, n = 0; y0 < img.height; y0 += n) {
      n = std::min(rows, img.height - y0);
      const auto band_start = std::chrono::steady_clock::now();
      p.image = glm::ivec4(img.width, img.height, y0, n);
      I.params.write(&p, sizeof p);
      if (pass == 0 && y0 == 0) timings::mark("first dispatch");
      I.ctx.submitAndWait([&](VkCommandBuffer cmd) {
        view.dispatch(cmd, uint32_t((img.width + EIKON_WG_X - 1) / EIKON_WG_X),
                      uint32_t((n + EIKON_WG_Y - 1) / EIKON_WG_Y), 1, nullptr);
      });
      out.read(band.data(), size_t(img.width) * size_t(n) * perPixel * sizeof(glm::vec4));
      if (s.aov_layer) addAov(img, band, n, y0, stride, pass == 0, I.scene.camera.position);
      if (layers.active()) {
        const auto [c0, c1] = layerChannelsOf(plan, p.pass);
        addLayers(layers, band, img.width, n, y0, c0, c1, stride);
      }
      addPixels(acc, img, steps, band, n, y0);
      if (s.progress) s.progress((pass + double(y0 + n) / img.height) / passes);
      const double band_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - band_start).count();
      const double next =
          double(n) * 0.25 / std::max(band_s, 1e-3);  // rows for ~0.25 s, at most 8x the last
      rows =
          std::clamp(int(std::min(next, 8.0 * n)) / EIKON_WG_Y * EIKON_WG_Y, EIKON_WG_Y, max_rows);
    }
    // The image so far: the finished samples' mean (a sample's wavelengths all done).
    const bool sampleDone = (pass + 1) % passesPerSample == 0;
    if (sampleDone && (s.on_pass || pass + 1 == passes)) {
      const double scale = 1.0 / double((pass + 1) / passesPerSample);
      for (size_t i = 0; i < acc.size(); ++i) img.rgb[i] = float(acc[i] * scale);
      if (s.on_pass && pass + 1 < passes) s.on_pass(img, (pass + 1) / passesPerSample, s.spp);
    }
  }
  layers.finish(img, s.spp);
  img.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  img.mean_steps = steps / (double(pixels) * s.spp);
  return img;
}

std::vector<TraceOutcome> ViewRenderer::trace(const std::vector<TraceRequest>& rays,
                                              const MarchSettings& m) {
  std::vector<TraceOutcome> out;
  for (const auto& pair : traceModes(rays, m)) out.push_back(pair[0]);
  return out;
}

namespace {
// Rays one trace dispatch takes: their two results must fit one storage buffer (128 MiB on
// lavapipe: 1 Mi rays; 1.1 Mi rays failed to allocate "trace results") and their workgroups the
// 65535 of maxComputeWorkGroupCount[0] every Vulkan device offers.
size_t traceBatchRays(const vk::DeviceLimits& limits) {
  const uint64_t by_buffer = limits.max_storage_buffer_range / (2 * sizeof(gpu::TraceResult));
  return size_t(std::max<uint64_t>(1, std::min<uint64_t>(by_buffer, 65535ull * EIKON_TRACE_WG)));
}

TraceOutcome outcomeOf(const gpu::TraceResult& r) {
  TraceOutcome o;
  o.exit_point = glm::dvec3(r.exit_point);
  o.left_volume = r.exit_point.w > 0.5f;
  o.exit_direction = glm::normalize(glm::dvec3(r.exit_direction));
  o.optical_path_mm = r.exit_direction.w;
  o.wave_normal = glm::normalize(glm::dvec3(r.wave_normal));
  o.transmittance = r.wave_normal.w;
  o.steps = int(r.stats.x);
  o.invariant_drift = r.stats.y;
  o.interfaces = int(r.stats.z);
  o.total_internal_reflections = int(r.stats.w);
  return o;
}
}  // namespace

std::vector<std::array<TraceOutcome, 2>> ViewRenderer::traceModes(
    const std::vector<TraceRequest>& rays, const MarchSettings& m) {
  validate(m);
  Impl& I = *impl_;
  if (rays.empty()) return {};
  for (const TraceRequest& q : rays) {
    const double len = glm::length(q.direction);
    if (!(len > 0) || !std::isfinite(len))
      throw std::invalid_argument("trace direction must be a non-zero finite vector");
    if (!(q.wavelength_nm > 0)) throw std::invalid_argument("trace wavelength must be > 0 nm");
  }
  std::vector<std::array<TraceOutcome, 2>> out(rays.size());
  const size_t batch = traceBatchRays(I.ctx.limits());
  for (size_t first = 0; first < rays.size(); first += batch) {  // one dispatch a batch
    const size_t count = std::min(batch, rays.size() - first);
    std::vector<gpu::TraceRay> in(count);
    for (size_t i = 0; i < count; ++i) {
      const TraceRequest& q = rays[first + i];
      in[i].origin =
          glm::vec4(glm::vec3(q.origin), float(micrometresFromNanometres(q.wavelength_nm)));
      in[i].direction = glm::vec4(glm::vec3(q.direction / glm::length(q.direction)), 0.0f);
    }
    gpu::ViewParams p = I.baseParams(m, 0);
    p.image = glm::ivec4(int(count), 1, 0, 1);
    I.params.write(&p, sizeof p);
    vk::Buffer rb(I.ctx, count * sizeof(gpu::TraceRay), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                  "trace rays");
    rb.write(in.data(), count * sizeof(gpu::TraceRay));
    vk::Buffer ob(I.ctx, 2 * count * sizeof(gpu::TraceResult), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                  "trace results");
    vk::ComputePipeline& tracer = I.pipeline(Impl::kTrace, p);
    tracer.bindBuffer(EIKON_B_RAYS, rb);
    tracer.bindBuffer(EIKON_B_OUTPUT, ob);
    I.ctx.submitAndWait([&](VkCommandBuffer cmd) {
      tracer.dispatch(cmd, uint32_t((count + EIKON_TRACE_WG - 1) / EIKON_TRACE_WG), 1, 1, nullptr);
    });
    std::vector<gpu::TraceResult> res(2 * count);
    ob.read(res.data(), res.size() * sizeof(gpu::TraceResult));
    for (size_t i = 0; i < res.size(); ++i) out[first + i / 2][i % 2] = outcomeOf(res[i]);
  }
  return out;
}

std::vector<PolarisedTrace> ViewRenderer::tracePolarised(const std::vector<PolarizerSheet>& sheets,
                                                         const std::vector<TraceRequest>& rays,
                                                         const std::vector<Stokes>& inputs,
                                                         const PolarisedTraceSettings& settings,
                                                         const std::vector<std::uint32_t>& seeds) {
  Impl& I = *impl_;
  if (inputs.size() != rays.size())
    throw std::invalid_argument("polarised trace: one input Stokes vector per ray");
  if (!seeds.empty() && seeds.size() != rays.size())
    throw std::invalid_argument("polarised trace: one seed per ray");
  for (size_t i = 0; i < rays.size(); ++i) checkPolarisedTrace(rays[i], inputs[i], settings);
  if (!I.sharp)
    throw std::runtime_error(
        "polarised trace: the field has no sharp boundaries (it needs "
        "\"interfaces\": \"sharp\")");
  if (rays.empty()) return {};
  const std::vector<glm::vec4> sheetData = packSheets(sheets, settings);
  const size_t n = rays.size();
  if (I.polarisedRays.size() < n * sizeof(gpu::PolarisedRay)) {
    I.polarisedRays = {};  // the old buffers go before the new ones are allocated
    I.polarisedResults = {};
    I.polarisedRays = vk::Buffer(I.ctx, n * sizeof(gpu::PolarisedRay),
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "polarised rays");
    I.polarisedResults = vk::Buffer(I.ctx, n * sizeof(gpu::PolarisedResult),
                                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "polarised results");
  }
  auto* in = static_cast<gpu::PolarisedRay*>(I.polarisedRays.mapped());
  for (size_t i = 0; i < n; ++i) {
    in[i].origin = glm::vec4(glm::vec3(rays[i].origin),
                             float(micrometresFromNanometres(rays[i].wavelength_nm)));
    // w: the seed's bits (floatBitsToUint in the kernel; copied, never computed with).
    in[i].direction = glm::vec4(glm::vec3(glm::normalize(rays[i].direction)),
                                std::bit_cast<float>(seeds.empty() ? 0u : seeds[i]));
    in[i].stokes = glm::vec4(inputs[i]);
  }
  gpu::ViewParams p = I.baseParams(MarchSettings{}, 0);
  // The shape table from its storage buffer, not the uniform block of its first rows: lavapipe
  // (Mesa 22.3) inlines that block's values into this kernel and compiles it again at every
  // submit, ~45 ms on one core per batch of rays (docs/performance.md "Polarised renders").
  p.grid_dims.w &= ~EIKON_F_SMALL_SHAPES;
  p.image = glm::ivec4(int(n), 1, 0, 1);
  p.pass = glm::ivec4(std::min(settings.max_events, EIKON_POL_MAX_EVENTS),
                      std::min(settings.max_branches, EIKON_POL_MAX_LEAVES),
                      settings.mueller_row ? 1 : 0,
                      settings.transport == Transport::Full ? settings.max_reflections : 0);
  p.transport.z = settings.split_first_choice ? 1 : 0;  // polarised_trace.comp cross
  I.params.write(&p, sizeof p);
  vk::Buffer sb(I.ctx, sheetData.size() * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                "polariser sheets");
  sb.write(sheetData.data(), sheetData.size() * sizeof(glm::vec4));
  vk::ComputePipeline& tracer = I.pipeline(Impl::kPolarised, p);
  tracer.bindBuffer(EIKON_B_RAYS, I.polarisedRays);
  tracer.bindBuffer(EIKON_B_SHEETS, sb);
  tracer.bindBuffer(EIKON_B_OUTPUT, I.polarisedResults);
  // EIKON_POL_GROUP rays per workgroup (one SIMD group of lavapipe; polarised_trace.comp).
  I.ctx.submitAndWait([&](VkCommandBuffer cmd) {
    tracer.dispatch(cmd, uint32_t((n + EIKON_POL_GROUP - 1) / EIKON_POL_GROUP), 1, 1, nullptr);
  });
  // Read in place: the buffer is host-coherent, and the dispatch has ended.
  const auto* res = static_cast<const gpu::PolarisedResult*>(I.polarisedResults.mapped());
  std::vector<PolarisedTrace> out;
  out.reserve(n);
  for (size_t i = 0; i < n; ++i)
    out.push_back(unpackPolarised(res[i], glm::normalize(rays[i].direction)));
  return out;
}

// The shared driver (core/contract/polarised_render.h) over this twin's polarised trace: every
// pixel sample's camera ray (at each wavelength) is one workgroup of polarised_trace.comp in its
// Mueller-row variant (P.pass.z); the environment is looked up on the host per beam, with the
// same Environment::lookup as the CPU twin, so the twins differ only in their traces.
RenderImage ViewRenderer::renderPolarised(const RenderSettings& s,
                                          const PolarisedTraceSettings& trace) {
  const Scene& scene = impl_->scene;
  return renderPolarisedWith(
      scene, s,
      [&](const std::vector<TraceRequest>& rays, const std::vector<std::uint32_t>& seeds,
          const PolarisedTraceSettings& ts) {
        return tracePolarised(scene.polarizers, rays,
                              std::vector<Stokes>(rays.size(), Stokes(1, 0, 0, 0)), ts, seeds);
      },
      trace);
}

}  // namespace eikon
