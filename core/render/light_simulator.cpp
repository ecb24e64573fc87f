// GPU light simulator: host side of shaders/wavefront.comp. See light_simulator.h and
// docs/light-simulator.md ("GPU kernel").
#include "core/render/light_simulator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <map>
#include <optional>
#include <stdexcept>
#include <variant>
#include <vector>

#include "anisotropic/units.h"
#include "core/light/lighting.h"
#include "core/light/seeding.h"
#include "core/light/sharp_skip.h"
#include "core/render/boundary_device.h"
#include "core/render/view_pipeline_start.h"
#include "core/vk/resources.h"
#include "core/volume/media.h"
#include "shaders/eikon_shared.h"
#include "shaders/scan.spv.h"
#include "shaders/wavefront.spv.h"
#include "shaders/wavefront_count.spv.h"

namespace eikon {

namespace {

/// The accumulation volume's bytes: EIKON_SPLAT_ACC_WORDS + 1 words per voxel.
size_t splatBytes(const Grid& g) {
  return g.count() * (EIKON_SPLAT_ACC_WORDS + 1) * sizeof(uint32_t);
}

}  // namespace

bool gpuLightFits(const vk::Context& ctx, const Grid& grid) {
  return splatBytes(grid) <= ctx.limits().max_storage_buffer_range;
}

void requireGpuLightFits(const vk::Context& ctx, const Grid& g) {
  if (!gpuLightFits(ctx, g))
    throw std::runtime_error(
        "the light simulator's GPU accumulation volume for " + std::to_string(g.dims[0]) + "x" +
        std::to_string(g.dims[1]) + "x" + std::to_string(g.dims[2]) + " voxels needs " +
        std::to_string(splatBytes(g) >> 20) + " MiB of one storage buffer but the device allows " +
        std::to_string(ctx.limits().max_storage_buffer_range >> 20) +
        " MiB: lower the volume's resolution, or simulate the light on the CPU twin "
        "(--light-device cpu or auto)");
}

namespace {

/// Compute → compute memory dependency between two dispatches of one command buffer.
void computeBarrier(VkCommandBuffer c) {
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER, nullptr,
                     VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT,
                     VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT};
  vkCmdPipelineBarrier(c, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &mb, 0, nullptr, 0, nullptr);
}

uint32_t blocksOf(size_t n) { return uint32_t((n + EIKON_SCAN_BLOCK - 1) / EIKON_SCAN_BLOCK); }

/// The multi-level exclusive scan of shaders/scan.comp over one buffer: level 0 holds the n
/// values at word 0, each further level the block totals of the one below, right after it; the
/// single block of the top level writes the grand total to `total_slot`.
struct ScanKernel {
  vk::ComputePipeline pipe;
  explicit ScanKernel(vk::Context& ctx)
      : pipe(ctx, std::span<const uint32_t>(k_scan_spv, sizeof(k_scan_spv) / 4),
             {{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}, sizeof(gpu::ScanPush), "scan") {}
  /// Words a buffer needs to scan up to n values: the levels plus the total slot (the last word).
  static size_t words(size_t n) {
    size_t w = 1;
    for (size_t m = std::max<size_t>(n, 1);; m = blocksOf(m)) {
      w += m;
      if (blocksOf(m) == 1) break;
    }
    return w;
  }
  void bind(const vk::Buffer& b) { pipe.bindBuffer(0, b); }
  /// Record the scan of the first n (≥ 1) words in place; the total goes to word total_slot.
  void record(VkCommandBuffer c, uint32_t n, uint32_t total_slot) const {
    struct Level {
      uint32_t off, n;
    };
    std::vector<Level> lv{{0, n}};
    while (blocksOf(lv.back().n) > 1)
      lv.push_back({lv.back().off + lv.back().n, blocksOf(lv.back().n)});
    for (size_t l = 0; l < lv.size(); ++l) {
      const uint32_t sums = l + 1 < lv.size() ? lv[l + 1].off : total_slot;
      gpu::ScanPush push{glm::uvec4(lv[l].off, lv[l].n, sums, 0u)};
      pipe.dispatch(c, blocksOf(lv[l].n), 1, 1, &push);
      computeBarrier(c);
    }
    for (size_t l = lv.size() - 1; l-- > 0;) {
      gpu::ScanPush push{glm::uvec4(lv[l].off, lv[l].n, lv[l + 1].off, 1u)};
      pipe.dispatch(c, blocksOf(lv[l].n), 1, 1, &push);
      computeBarrier(c);
    }
  }
};

}  // namespace

struct GpuWavefrontShared::Impl {
  vk::Context* ctx = nullptr;         // of the first run given it
  const VolumeSet* volume = nullptr;  // the volume of the runs
  // wavefront.comp per specialisation (kSharpLight, kWaveFlags, kWaveOptions, kExact).
  std::map<std::array<uint32_t, 4>, vk::ComputePipeline> wave;
  std::optional<vk::ComputePipeline> count;  // wavefront_count.comp
  std::optional<ScanKernel> scan;
  std::optional<vk::Image3D> sharpSkip;  // the sharp path's skip distances (w), once computed
  int built = 0;
};

GpuWavefrontShared::GpuWavefrontShared() : impl_(std::make_unique<Impl>()) {}
GpuWavefrontShared::~GpuWavefrontShared() = default;
int GpuWavefrontShared::pipelinesBuilt() const { return impl_->built; }

struct GpuScan::Impl {
  vk::Context& ctx;
  ScanKernel kernel;
  vk::Buffer buf;
  explicit Impl(vk::Context& c) : ctx(c), kernel(c) {}
};

GpuScan::GpuScan(vk::Context& ctx) : impl_(std::make_unique<Impl>(ctx)) {}
GpuScan::~GpuScan() = default;

uint32_t GpuScan::exclusiveScan(std::vector<uint32_t>& values) {
  if (values.empty()) return 0;
  Impl& m = *impl_;
  const size_t words = ScanKernel::words(values.size());
  if (m.buf.handle() == VK_NULL_HANDLE || m.buf.size() < words * sizeof(uint32_t)) {
    m.buf = vk::Buffer(m.ctx, words * sizeof(uint32_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                       "scan test");
    m.kernel.bind(m.buf);
  }
  m.buf.write(values.data(), values.size() * sizeof(uint32_t));
  const uint32_t slot = uint32_t(words - 1);
  m.ctx.submitAndWait(
      [&](VkCommandBuffer c) { m.kernel.record(c, uint32_t(values.size()), slot); });
  m.buf.read(values.data(), values.size() * sizeof(uint32_t));
  uint32_t total = 0;
  m.buf.read(&total, sizeof total, slot * sizeof(uint32_t));
  return total;
}

struct GpuWavefront::Impl {
  vk::Context& ctx;
  const VolumeSet& vol;
  WavefrontSettings s;
  int steps_per_dispatch;
  glm::ivec4 control{
      0};  ///< WaveParams::control as last written (writeParams, setStepsPerDispatch)
  VolumeField field;
  std::vector<vk::Image3D> images;  // the fields read and one placeholder (constructor)
  bool eMode = false;               // settings.mode == 1 and the volume is uniaxial
  // Sharp interfaces (settings.sharp_interfaces and sharpLightApplies): the pipeline is
  // specialised with kSharpLight and the boundary field and media table are uploaded; otherwise
  // 1-voxel placeholders keep those bindings valid.
  bool sharp = false;
  BoundaryDevice boundary;
  vk::Buffer params, splat, patches[2], scan, tally;
  // The pipelines and the sharp skip image: the caller's GpuWavefrontShared, or this run's own.
  std::unique_ptr<GpuWavefrontShared> ownShared;
  GpuWavefrontShared::Impl& sh;
  vk::ComputePipeline* pipe = nullptr;       // wavefront.comp (propagate, scatter)
  vk::ComputePipeline* countPipe = nullptr;  // wavefront_count.comp
  ScanKernel* scanner = nullptr;
  size_t list_cap = 0;                  // patches the scan and tally buffers hold
  std::vector<gpu::WaveTally> tallies;  // the last pass's, read back
  size_t asked_tears = 0;               // tears asked for in the pass addTallies read last
  size_t asked_reflections = 0;         // reflected copies asked for in that pass
  size_t asked_halvings = 0;            // splits into halves asked for in that pass
  double il2 = 0, il4 = 0, n_min = 1.0;

  Impl(vk::Context& c, const VolumeSet& v, WavefrontSettings settings, int k,
       GpuWavefrontShared* shared)
      : ctx(c),
        vol(v),
        s(settings),
        steps_per_dispatch(k),
        field(v),
        ownShared(shared ? nullptr : std::make_unique<GpuWavefrontShared>()),
        sh(*(shared ? shared : ownShared.get())->impl_) {
    if (sh.volume && (sh.volume != &vol || sh.ctx != &ctx))
      throw std::invalid_argument(
          "wavefront: a GpuWavefrontShared serves the runs of one volume and device only");
    checkSettings();
    sh.volume = &vol;
    sh.ctx = &ctx;
    const FieldImages f = uploadFields();
    const Grid& g = vol.grid;
    params = vk::Buffer(ctx, sizeof(gpu::WaveParams), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                        "wavefront params");
    requireGpuLightFits(ctx, g);
    splat = vk::Buffer(ctx, splatBytes(g), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "wavefront splat");
    // With the regions on the shapes (and kExact below) the kernel reads no voxel of the field.
    boundary =
        sharp ? BoundaryDevice(ctx, vol.boundary, vol.media, "", !vol.boundary.regionsOnShapes())
              : BoundaryDevice(ctx, BoundaryField{}, MediaTable{});
    boundary.setRenderWavelength(s.wavelength_nm);  // the media's indices at the run's wavelength
    buildKernels();
    bindKernels(f);
  }

  /// The settings checked (std::invalid_argument) and what follows from them.
  void checkSettings() {
    const Grid& g = vol.grid;
    if (steps_per_dispatch < 1)
      throw std::invalid_argument("wavefront: steps_per_dispatch must be >= 1");
    if (s.max_patches < 1) throw std::invalid_argument("wavefront: max_patches must be >= 1");
    if (!(g.h > 0) || g.count() == 0) throw std::invalid_argument("wavefront: empty volume");
    if (s.dt <= 0) s.dt = 0.5 * g.h;
    if (!(s.wavelength_nm > 0)) throw std::invalid_argument("wavefront: wavelength must be > 0");
    if (s.mode != 0 && s.mode != 1)
      throw std::invalid_argument("wavefront: mode must be 0 (o) or 1 (e)");
    // The e-mode of an isotropic volume is the o-mode (no axis anywhere).
    eMode = s.mode == 1 && vol.uniaxial;
    const double l = micrometresFromNanometres(s.wavelength_nm);
    il2 = 1.0 / (l * l);
    il4 = il2 * il2;
    sharp = s.sharp_interfaces && sharpLightApplies(vol);
    // A corner's word holds its region in 15 bits (EIKON_CORNER_REGION).
    if (sharp && vol.boundary.shapes.size() > size_t(EIKON_CORNER_REGION))
      throw std::invalid_argument("wavefront: more than 32767 objects for the GPU light simulator");
    n_min = smallestIndex();
    if (!(n_min > 0)) throw std::invalid_argument("wavefront: the index volume has n <= 0");
  }

  /// The images bound at EIKON_WB_INDEX_A … EIKON_WB_AXIS (indices into `images`) and the skip
  /// image (this run's, or the shared sharp one).
  struct FieldImages {
    size_t iA, iB, iC, med, eA, eB, eC, eMed, axis;
    const vk::Image3D* skip;
  };

  FieldImages uploadFields() {
    const Grid& g = vol.grid;
    const std::array<uint32_t, 3> ext{uint32_t(g.dims[0]), uint32_t(g.dims[1]),
                                      uint32_t(g.dims[2])};
    auto upload = [&](const std::vector<glm::vec4>& data, const char* name) {
      vk::Image3D img(ctx, data.size() == 1 ? std::array<uint32_t, 3>{1, 1, 1} : ext,
                      VK_FORMAT_R32G32B32A32_SFLOAT, name);
      img.upload(ctx, data.data(), data.size() * sizeof(glm::vec4));
      images.push_back(std::move(img));
      return images.size() - 1;
    };
    // The volume's fields the kernel reads are uploaded; a one-voxel placeholder keeps the other
    // bindings valid. A sharp run reads no index, axis or e-mode image (its corners move in the
    // media table's media: KernelBindings.TheSharpLightReadsNoIndexFieldOfTheVolume), an o-mode
    // run no e-mode one.
    FieldImages f{};
    const size_t none = upload(std::vector<glm::vec4>(1, glm::vec4(0.0f)), "wavefront unread");
    const bool fields = !sharp, eFields = fields && eMode, disp = vol.dispersive;
    f.iA = fields ? upload(vol.index[0][0], "wavefront index A") : none;
    f.iB = fields && disp ? upload(vol.index[0][1], "wavefront index B") : f.iA;
    f.iC = fields && disp ? upload(vol.index[0][2], "wavefront index C") : f.iA;
    f.med = upload(vol.medium[0], "wavefront medium");
    f.eA = eFields ? upload(vol.index[1][0], "wavefront index e A") : f.iA;
    f.eB = eFields && disp ? upload(vol.index[1][1], "wavefront index e B") : f.eA;
    f.eC = eFields && disp ? upload(vol.index[1][2], "wavefront index e C") : f.eA;
    f.eMed = eFields ? upload(vol.medium[1], "wavefront medium e") : f.med;
    f.axis = eFields ? upload(vol.axis, "wavefront axis") : none;
    // Skip distances for straight steps (w of the emission image; zeros where none was computed).
    // Sharp light reads the sharp path's own, as the CPU twin (core/light/sharp_skip.h): they
    // depend on the regions alone, so the runs of a GpuWavefrontShared compute them once.
    if (sharp) {
      if (!sh.sharpSkip) {
        const std::vector<uint8_t> d = sharpSkipDistances(vol);
        std::vector<glm::vec4> skip(g.count(), glm::vec4(0.0f));
        for (size_t i = 0; i < skip.size(); ++i) skip[i].w = float(d[i]);
        sh.sharpSkip.emplace(ctx, ext, VK_FORMAT_R32G32B32A32_SFLOAT, "wavefront skip");
        sh.sharpSkip->upload(ctx, skip.data(), skip.size() * sizeof(glm::vec4));
      }
      f.skip = &*sh.sharpSkip;
    } else {  // the last image uploaded: the pointer into `images` stays valid
      const bool have = vol.emission.size() == g.count();
      f.skip =
          &images[upload(have ? vol.emission : std::vector<glm::vec4>(g.count(), glm::vec4(0.0f)),
                         "wavefront skip")];
    }
    return f;
  }

  /// The run's pipelines, from the shared object or built into it. The run's feature set is the
  /// specialisation (wavefront.comp: kSharpLight, kWaveFlags, kWaveOptions, kExact), so that
  /// llvmpipe, which runs every branch under masks, compiles out what this run never does
  /// (docs/performance.md, "Light simulator"); the bands of a mode share one.
  void buildKernels() {
    std::vector<vk::BindingSpec> b;
    for (uint32_t i :
         {uint32_t(EIKON_WB_INDEX_A), uint32_t(EIKON_WB_INDEX_B), uint32_t(EIKON_WB_INDEX_C),
          uint32_t(EIKON_WB_MEDIUM), uint32_t(EIKON_WB_INDEX_E_A), uint32_t(EIKON_WB_INDEX_E_B),
          uint32_t(EIKON_WB_INDEX_E_C), uint32_t(EIKON_WB_MEDIUM_E), uint32_t(EIKON_WB_AXIS),
          uint32_t(EIKON_WB_SKIP)})
      b.push_back({i, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE});
    for (uint32_t i :
         {uint32_t(EIKON_WB_PARAMS), uint32_t(EIKON_WB_PATCHES), uint32_t(EIKON_WB_SPLAT),
          uint32_t(EIKON_WB_PATCHES_B), uint32_t(EIKON_WB_SCAN), uint32_t(EIKON_WB_TALLY)})
      b.push_back({i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
    for (const vk::BindingSpec& bs : boundaryBindings()) b.push_back(bs);
    for (const vk::BindingSpec& bs : uniformTableBindings()) b.push_back(bs);
    const std::array<uint32_t, 4> key{sharp ? 1u : 0u, uint32_t(featureFlags()),
                                      uint32_t(options()),
                                      uint32_t(sharp ? volumeExactConstant(vol) : 0)};
    auto it = sh.wave.find(key);
    if (it == sh.wave.end()) {
      const std::span<const uint32_t> code(k_wavefront_spv, sizeof(k_wavefront_spv) / 4);
      vk::ComputePipeline built(ctx, code, b, sizeof(gpu::WavePush),
                                sharp ? "wavefront sharp" : "wavefront",
                                std::vector<uint32_t>(key.begin(), key.end()));
      it = sh.wave.emplace(key, std::move(built)).first;
      ++sh.built;
    }
    pipe = &it->second;
    std::vector<vk::BindingSpec> cb;
    for (uint32_t i :
         {uint32_t(EIKON_WB_PARAMS), uint32_t(EIKON_WB_PATCHES), uint32_t(EIKON_WB_PATCHES_B),
          uint32_t(EIKON_WB_SCAN), uint32_t(EIKON_WB_TALLY)})
      cb.push_back({i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
    if (!sh.count) {
      sh.count.emplace(
          ctx, std::span<const uint32_t>(k_wavefront_count_spv, sizeof(k_wavefront_count_spv) / 4),
          cb, sizeof(gpu::WavePush), "wavefront count");
      ++sh.built;
    }
    countPipe = &*sh.count;
    if (!sh.scan) {
      sh.scan.emplace(ctx);
      ++sh.built;
    }
    scanner = &*sh.scan;
  }

  /// Every binding set again: a shared pipeline still holds the previous run's (the patch lists
  /// and scan buffers are bound as propagate() makes them).
  void bindKernels(const FieldImages& f) {
    boundary.bind(*pipe);
    boundary.bindUniformTables(*pipe);
    pipe->bindImage(EIKON_WB_INDEX_A, images[f.iA]);
    pipe->bindImage(EIKON_WB_INDEX_B, images[f.iB]);
    pipe->bindImage(EIKON_WB_INDEX_C, images[f.iC]);
    pipe->bindImage(EIKON_WB_MEDIUM, images[f.med]);
    pipe->bindImage(EIKON_WB_INDEX_E_A, images[f.eA]);
    pipe->bindImage(EIKON_WB_INDEX_E_B, images[f.eB]);
    pipe->bindImage(EIKON_WB_INDEX_E_C, images[f.eC]);
    pipe->bindImage(EIKON_WB_MEDIUM_E, images[f.eMed]);
    pipe->bindImage(EIKON_WB_AXIS, images[f.axis]);
    pipe->bindImage(EIKON_WB_SKIP, *f.skip);
    pipe->bindBuffer(EIKON_WB_PARAMS, params);
    pipe->bindBuffer(EIKON_WB_SPLAT, splat);
    countPipe->bindBuffer(EIKON_WB_PARAMS, params);
  }

  /// Smallest index in the volume (bounds the centre's step length Δs ≤ dt/n_min for the splat
  /// scale). The e-mode's ray speed |M_e p| on the shell is at most 1/min(n_o, n_e) (the ray
  /// velocity surface is an ellipsoid with semi-axes 1/n_o and 1/n_e), so both fields count.
  /// Sharp light: the media's own indices too (a corner moves dt/n in its region's medium).
  double smallestIndex() const {
    const Grid& g = vol.grid;
    double n_lo = 1e300;
    for (int md = 0; md <= (eMode ? 1 : 0); ++md)
      for (size_t i = 0; i < g.count(); ++i) {
        double n = vol.index[size_t(md)][0][i].x;
        if (vol.dispersive)
          n += vol.index[size_t(md)][1][i].x * il2 + vol.index[size_t(md)][2][i].x * il4;
        n_lo = std::min(n_lo, n);
      }
    if (sharp)
      for (const MediumRecord& r : vol.media.regions)
        for (const MediumDispersion* d : {&r.n_o, &r.n_e})
          n_lo = std::min(n_lo, mediumIndex(*d, s.wavelength_nm));
    return n_lo;
  }

  /// The EIKON_F_* flags of the run (wavefront.comp's kWaveFlags and WaveParams.grid_dims.w):
  /// what the volume holds, EIKON_F_UNIAXIAL for an e-mode run in a uniaxial volume, and
  /// EIKON_F_CONVEX when the sharp path's boundary has a convex polyhedron (its plane loops),
  /// EIKON_F_MESH when it has a non-convex mesh (its hierarchy's traversal).
  int featureFlags() const {
    int flags = 0;
    if (vol.dispersive) flags |= EIKON_F_DISPERSIVE;
    if (vol.attenuating) flags |= EIKON_F_ATTENUATION;
    if (vol.opaque) flags |= EIKON_F_OPACITY;
    if (eMode) flags |= EIKON_F_UNIAXIAL;
    if (sharp) {
      for (const Shape& shape : vol.boundary.shapes) {
        if (std::holds_alternative<ConvexShape>(shape.geometry())) flags |= EIKON_F_CONVEX;
        if (std::holds_alternative<MeshShape>(shape.geometry())) flags |= EIKON_F_MESH;
      }
      // A biaxial crystal's laws (sharp.glsl mediumBiaxial reads the media's flag only then).
      for (const MediumRecord& r : vol.media.regions)
        if (r.biaxial) flags |= EIKON_F_BIAXIAL;
      flags |= uniformTableFlags(vol.boundary, vol.media);  // the tables as uniform blocks
      flags |= crossingPathFlags(vol.boundary);             // with kExact: the crossing dispatch
    }
    return flags;
  }
  /// wavefront.comp's kWaveOptions: bit 0 straight steps, bit 1 pass caustics, bit 2 probe plane,
  /// bit 3 the highest-energy maximum (readSplat reads it only for Splat::HighestEnergy), bit 4
  /// straight steps up to the next boundary (straight_to_boundary), reflected wavefronts (sharp,
  /// max_reflection_generations > 0).
  int options() const {
    return (s.skip_empty ? 1 : 0) | (s.pass_caustics ? 2 : 0) |
           (s.probe_axis >= 0 && s.probe_axis < 3 ? 4 : 0) |
           (s.splat == WavefrontSettings::Splat::HighestEnergy ? 8 : 0) |
           (s.straight_to_boundary ? 16 : 0) | (sharp && s.max_reflection_generations > 0 ? 32 : 0);
  }

  // Patch list `which` (0: EIKON_WB_PATCHES, 1: _B) holds at least n patches. Only called between
  // submissions, and never for the list a pending scatter reads.
  void ensurePatchCapacity(int which, size_t n) {
    vk::Buffer& buf = patches[which];
    const VkDeviceSize bytes = std::max<size_t>(n, 64) * sizeof(gpu::WavePatch);
    if (buf.handle() != VK_NULL_HANDLE && buf.size() >= bytes) return;
    // Grow geometrically, but never past the storage-buffer range when the request itself fits
    // (vk::Buffer refuses larger requests with a message: lavapipe allows 128 MiB ≈ 838k patches).
    const VkDeviceSize range = ctx.limits().max_storage_buffer_range;
    const VkDeviceSize grown =
        std::max<VkDeviceSize>(bytes, std::min<VkDeviceSize>(2 * buf.size(), range));
    buf = vk::Buffer(ctx, grown, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                     which ? "wavefront patches B" : "wavefront patches A");
    pipe->bindBuffer(which ? EIKON_WB_PATCHES_B : EIKON_WB_PATCHES, buf);
    countPipe->bindBuffer(which ? EIKON_WB_PATCHES_B : EIKON_WB_PATCHES, buf);
  }

  // The scan and tally buffers hold any list of this run: the list never exceeds
  // max(seeds, max_patches) patches (the budget is applied before a list is written), nor what
  // one storage buffer can hold.
  void ensureListCapacity(size_t n) {
    if (n <= list_cap) return;
    scan = vk::Buffer(ctx, ScanKernel::words(n) * sizeof(uint32_t),
                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "wavefront scan");
    tally = vk::Buffer(ctx, ((n + EIKON_WAVE_WG - 1) / EIKON_WAVE_WG) * sizeof(gpu::WaveTally),
                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "wavefront tally");
    pipe->bindBuffer(EIKON_WB_SCAN, scan);
    pipe->bindBuffer(EIKON_WB_TALLY, tally);
    countPipe->bindBuffer(EIKON_WB_SCAN, scan);
    countPipe->bindBuffer(EIKON_WB_TALLY, tally);
    scanner->bind(scan);
    list_cap = n;
  }
  uint32_t totalSlot() const { return uint32_t(ScanKernel::words(list_cap) - 1); }

  static gpu::WavePatch toGpu(const Patch& p) {
    gpu::WavePatch g{};
    for (int k = 0; k < 4; ++k) {
      g.x[k] = glm::vec4(glm::vec3(p.x[size_t(k)]), 0.0f);
      g.w[k] = glm::vec4(glm::vec3(p.w[size_t(k)]), 0.0f);
    }
    g.flux = glm::vec4(float(p.energy), float(p.area0), float(p.seed_energy), 0.0f);
    g.state = glm::ivec4(EIKON_PATCH_ALIVE, p.orientation, p.entered ? 1 : 0, 0);
    g.region = glm::ivec4(-1);  // sharp interfaces: located by the first propagation
    return g;
  }

  static uint32_t groups(size_t n) { return uint32_t((n + EIKON_WAVE_WG - 1) / EIKON_WAVE_WG); }
  void pass(VkCommandBuffer c, uint32_t mode, uint32_t n, int src, uint32_t z = 0) const {
    gpu::WavePush push{glm::uvec4(n, mode, z, uint32_t(src))};
    const bool count = mode != EIKON_WM_PROPAGATE && mode != EIKON_WM_SCATTER;
    (count ? countPipe : pipe)->dispatch(c, groups(n), 1, 1, &push);
    computeBarrier(c);
  }
  // Propagate list `src` (n patches), count its outputs with the kill tallies, scan the counts.
  void recordStep(VkCommandBuffer c, uint32_t n, int src) const {
    pass(c, EIKON_WM_PROPAGATE, n, src);
    pass(c, EIKON_WM_COUNT, n, src);
    scanner->record(c, n, totalSlot());
  }
  uint32_t readTotal() const {
    uint32_t t = 0;
    scan.read(&t, sizeof t, VkDeviceSize(totalSlot()) * sizeof(uint32_t));
    return t;
  }

  // Stages of run(): seed, scale and parameters, propagate (the dispatch loop), read back.

  /// The seed patches (core/light/seeding.h, as the CPU twin's) in the kernel's layout; counts
  /// them and their flux into st and returns the largest seed flux in max_seed.
  std::vector<gpu::WavePatch> seedList(const Light& light, WavefrontStats& st,
                                       double& max_seed) const {
    const Grid& g = vol.grid;
    std::vector<Patch> seeds = seedWavefront(field, g, s, light);
    st.seeded = seeds.size();
    const glm::dvec3 lo = g.origin, hi = g.boundsMax();
    max_seed = 0;
    std::vector<gpu::WavePatch> cur;
    cur.reserve(seeds.size());
    for (Patch& p : seeds) {
      st.flux_emitted += p.energy;
      max_seed = std::max(max_seed, p.energy);
      const glm::dvec3 c = 0.25 * (p.x[0] + p.x[1] + p.x[2] + p.x[3]);
      p.entered =
          c.x >= lo.x && c.y >= lo.y && c.z >= lo.z && c.x <= hi.x && c.y <= hi.y && c.z <= hi.z;
      cur.push_back(toGpu(p));
    }
    st.max_live = cur.size();
    return cur;
  }

  /// Fixed-point scale: one splat is flux_mid·Δs/h³ ≤ maxSeed·(dt/n_min)/h³ =: vmax (a patch's flux
  /// never grows; the centre moves at most dt/n_min per step). With scale = 2^29/(2·vmax) a splat
  /// is ≤ 2^28 units and a biased direction term (≤ 2 × the splat) ≤ 2^29, inside int32 (the
  /// factor 2 covers RK4's overshoot in steep gradients),
  /// and its rounding error is ≤ 0.5/scale = 2^-29·vmax. A 64-bit voxel sum overflows only after
  /// 2^34 maximal splats into one voxel, i.e. never for runs of ≤ 2^20 patches × 2^14 steps.
  /// With straight steps a splat is one voxel's piece of a straight path, at most the voxel
  /// diagonal √3·h long, so that bounds Δs too.
  double splatScale(double max_seed) const {
    const Grid& g = vol.grid;
    const double h3 = g.h * g.h * g.h;
    const double dsMax = s.skip_empty ? std::max(s.dt / n_min, std::sqrt(3.0) * g.h) : s.dt / n_min;
    const double vmax = std::max(max_seed, 1e-300) * dsMax / h3;
    return std::ldexp(1.0, 29) / (2.0 * vmax);
  }

  /// Upload the run's parameters (gpu::WaveParams) and zero the splat buffer.
  void writeParams(double scale) {
    const Grid& g = vol.grid;
    const double h3 = g.h * g.h * g.h;
    gpu::WaveParams P{};
    P.grid_origin = glm::vec4(glm::vec3(g.origin), float(g.h));
    P.grid_max = glm::vec4(glm::vec3(g.boundsMax()), float(1.0 / g.h));
    P.grid_dims = glm::ivec4(g.dims[0], g.dims[1], g.dims[2], featureFlags());
    P.step = glm::vec4(float(s.dt), float(s.split_span_voxels * g.h), float(s.min_energy_fraction),
                       float(1.0 / h3));
    const double l = micrometresFromNanometres(s.wavelength_nm);
    P.wavelength = glm::vec4(float(l), float(il2), float(il4), float(scale));
    P.control = glm::ivec4(s.probe_axis >= 0 && s.probe_axis < 3 ? s.probe_axis : -1,
                           steps_per_dispatch, s.max_steps, eMode ? 1 : 0);
    control = P.control;
    P.probe = glm::vec4(float(s.probe_position), s.split_halves ? 1.0f : 0.0f, 0.0f, 0.0f);
    P.options = glm::ivec4(s.skip_empty ? 1 : 0, s.pass_caustics ? 1 : 0,
                           s.straight_to_boundary ? 1 : 0, s.max_reflection_generations);
    params.write(&P, sizeof P);
    // Zeroed in place (the buffer is mapped): no 50 MB staging vector at 128³.
    std::memset(splat.mapped(), 0, splatWords() * sizeof(uint32_t));
  }
  size_t splatWords() const { return vol.grid.count() * (EIKON_SPLAT_ACC_WORDS + 1); }

  /// Add the kill tallies of the pass over n patches to st; the pass's split requests and
  /// survivors go to want_split and survivors.
  void addTallies(uint32_t n, WavefrontStats& st, size_t& survivors, size_t& want_split) {
    tallies.resize(groups(n));
    tally.read(tallies.data(), tallies.size() * sizeof(gpu::WaveTally));
    survivors = 0, want_split = 0;
    size_t pass_tears = 0, pass_reflections = 0, pass_halvings = 0;
    for (const gpu::WaveTally& t : tallies) {
      st.flux_left += t.flux_a.x, st.flux_caustic += t.flux_a.y, st.flux_energy += t.flux_a.z;
      st.flux_absorbed += double(t.flux_a.w) + double(t.flux_b.x);
      st.flux_live_at_end += t.flux_b.y;
      st.caustic_centroid += glm::dvec3(glm::vec3(t.caustic_sum));
      pass_tears += size_t(t.caustic_sum.w);  // asked for: grantSplits counts those granted
      st.kills_left += t.count_a.x, st.kills_caustic += t.count_a.y, st.kills_energy += t.count_a.z;
      st.kills_opaque += t.count_a.w;
      st.live_at_end += t.count_b.x;
      want_split += t.count_b.y;
      survivors += t.count_b.z;
      st.steps = std::max(st.steps, int(t.count_b.w));
      st.probe_centroid += glm::dvec3(glm::vec3(t.probe_pos));
      st.flux_probe += t.probe_pos.w;
      st.probe_direction += glm::dvec3(glm::vec3(t.probe_dir));
      st.flux_reflected += t.probe_dir.w;
      pass_reflections += t.count_c.x;
      pass_halvings += t.count_c.y;
    }
    st.tears += pass_tears;
    asked_tears = pass_tears;
    // A reflected copy is asked for as a split is (ranked with them under the budget) but adds
    // one patch and is no split.
    st.reflections += pass_reflections;
    asked_reflections = pass_reflections;
    // A split into halves is asked for and ranked as any split; it adds one patch.
    st.halvings += pass_halvings;
    asked_halvings = pass_halvings;
  }

  /// The next list's length when the pass over list `src` (n patches) asks for more than the
  /// budget. The reference refuses a split when live + 3 (quarters, pencils) or live + 1 (halves, a
  /// reflected copy) > max_patches, in list order. Here: grant the first `granted` requests of the
  /// list (rank by a scan of 0/1 flags), each counted as adding 3, and the survivors of this pass
  /// as live, so the list never exceeds the budget.
  uint32_t grantSplits(uint32_t n, int src, size_t survivors, size_t want_split,
                       WavefrontStats& st) {
    const size_t budget = size_t(s.max_patches);
    const size_t granted = survivors >= budget ? 0 : std::min(want_split, (budget - survivors) / 3);
    ctx.submitAndWait([&](VkCommandBuffer c) {
      pass(c, EIKON_WM_COUNT_SPLITS, n, src);
      scanner->record(c, n, totalSlot());
      pass(c, EIKON_WM_COUNT_BUDGET, n, src, uint32_t(granted));
      scanner->record(c, n, totalSlot());
    });
    st.splits_refused += want_split - granted;
    // The BUDGET pass tallied again, counting only the tears and reflected copies granted (a
    // refused one goes on whole).
    tally.read(tallies.data(), tallies.size() * sizeof(gpu::WaveTally));
    size_t granted_tears = 0, granted_reflections = 0, granted_halvings = 0;
    for (const gpu::WaveTally& t : tallies) {
      granted_tears += size_t(t.caustic_sum.w);
      granted_reflections += t.count_c.x;
      granted_halvings += t.count_c.y;
    }
    st.tears = st.tears - asked_tears + granted_tears;
    st.reflections = st.reflections - asked_reflections + granted_reflections;
    st.halvings = st.halvings - asked_halvings + granted_halvings;
    st.splits += granted - granted_reflections - granted_halvings;
    return readTotal();
  }

  /// Time steps per propagation for a list of n patches: steps_per_dispatch, or kTailSteps once
  /// at most kTailPatches are left. Patches keep their own clocks (state.w), so the count changes
  /// no result; it only saves the submissions of a run's tail, where a few patches (light trapped
  /// in a gem by total internal reflection) outlive the rest by thousands of steps and each
  /// submission of 16 steps cost more than its work (lit faceted_oval, 64³: 14 s of 726
  /// submissions against the CPU twin's 0.65 s).
  static constexpr uint32_t kTailPatches = 2048;
  static constexpr int kTailSteps = 256;
  int stepsFor(uint32_t n) const {
    return n <= kTailPatches ? std::max(steps_per_dispatch, kTailSteps) : steps_per_dispatch;
  }
  /// Rewrite WaveParams::control.y between submissions (the device is idle then).
  void setStepsPerDispatch(int k) {
    if (control.y == k) return;
    control.y = k;
    params.write(&control, sizeof control, offsetof(gpu::WaveParams, control));
  }

  /// The list lives on the GPU. Per pass, one submission: scatter of the previous pass's list
  /// (survivors and children, into the other buffer), propagation, count, scan; the host reads
  /// back the scan total and one WaveTally per 64 patches. Only when the total exceeds
  /// max_patches is there a second submission (rank the split requests, grant the first ones).
  void propagate(const std::vector<gpu::WavePatch>& cur, WavefrontStats& st) {
    const Grid& g = vol.grid;
    const size_t budget = size_t(s.max_patches);
    uint32_t n = uint32_t(cur.size());
    int src = 0;
    if (n > 0) {
      // A list longer than the storage-buffer range allows cannot exist (ensurePatchCapacity
      // throws).
      const size_t fits = size_t(ctx.limits().max_storage_buffer_range / sizeof(gpu::WavePatch));
      ensureListCapacity(std::max(cur.size(), std::min(budget, fits)));
      ensurePatchCapacity(0, n);
      ensurePatchCapacity(1, n);  // every binding must be valid from the first dispatch on
      patches[0].write(cur.data(), cur.size() * sizeof(gpu::WavePatch));
      setStepsPerDispatch(stepsFor(n));
      ctx.submitAndWait([&](VkCommandBuffer c) { recordStep(c, n, src); });
    }
    long long steps = control.y;  // time steps the dispatches so far may have advanced
    while (n > 0) {
      size_t survivors = 0, wantSplit = 0;
      addTallies(n, st, survivors, wantSplit);
      uint32_t total = readTotal();
      if (total > budget) {
        total = grantSplits(n, src, survivors, wantSplit, st);
      } else {
        st.splits += wantSplit - asked_reflections - asked_halvings;
      }
      st.max_live = std::max<size_t>(st.max_live, total);
      if (s.progress)
        s.progress(wavefrontRunFraction(
            steps, s.dt, g.extent,
            st.flux_left + st.flux_caustic + st.flux_energy + st.flux_absorbed + st.flux_reflected,
            st.flux_emitted));
      if (total == 0) break;
      const int dst = 1 - src;
      ensurePatchCapacity(dst, total);
      setStepsPerDispatch(stepsFor(total));
      steps += control.y;
      ctx.submitAndWait([&](VkCommandBuffer c) {
        pass(c, EIKON_WM_SCATTER, n, src, totalSlot());
        recordStep(c, total, dst);
      });
      n = total;
      src = dst;
    }
  }

  /// The splat buffer as the result's volumes: fixed point (scale) to W/mm², mean direction.
  void readSplat(double scale, WavefrontResult& res) const {
    const Grid& g = vol.grid;
    // Read in place from the mapped buffer (the device is idle: every submission was waited on).
    const uint32_t* words = static_cast<const uint32_t*>(splat.mapped());
    res.irradiance.resize(g.count());
    res.direction.resize(g.count());
    const bool highest = s.splat == WavefrontSettings::Splat::HighestEnergy;
    auto rawAt = [&](size_t i) {
      const uint64_t u = (uint64_t(words[i + 1]) << 32) | uint64_t(words[i]);
      int64_t v;
      std::memcpy(&v, &u, sizeof v);
      return v;
    };
    for (size_t v = 0; v < g.count(); ++v) {
      const size_t b = v * EIKON_SPLAT_ACC_WORDS;
      // The direction's sums are Σ value·(1 + dir) (wavefront.comp splatVoxel): the weight comes
      // off in integers, exactly.
      const int64_t w = rawAt(b);
      const double acc = double(w) / scale;
      const glm::dvec3 d(double(rawAt(b + 2) - w) / scale, double(rawAt(b + 4) - w) / scale,
                         double(rawAt(b + 6) - w) / scale);
      float best;
      std::memcpy(&best, &words[g.count() * EIKON_SPLAT_ACC_WORDS + v], sizeof best);
      res.irradiance[v] = highest ? best : float(acc);
      res.direction[v] = glm::vec4(glm::vec3(acc > 0 ? d / acc : glm::dvec3(0.0)), float(acc));
    }
  }

  WavefrontResult run(const Light& light) {
    WavefrontResult res;
    WavefrontStats& st = res.stats;
    double maxSeed = 0;
    const std::vector<gpu::WavePatch> cur = seedList(light, st, maxSeed);
    const double scale = splatScale(maxSeed);
    writeParams(scale);
    propagate(cur, st);
    if (s.progress) s.progress(1.0);  // every patch has ended (or reached max_steps)
    if (st.flux_caustic > 0) st.caustic_centroid /= st.flux_caustic;
    if (st.flux_probe != 0) {
      st.probe_centroid /= st.flux_probe;
      st.probe_direction /= st.flux_probe;
    }
    readSplat(scale, res);
    return res;
  }
};

GpuWavefront::GpuWavefront(vk::Context& ctx, const VolumeSet& volume, WavefrontSettings settings,
                           int steps_per_dispatch, GpuWavefrontShared* shared)
    : impl_(std::make_unique<Impl>(ctx, volume, settings, steps_per_dispatch, shared)) {}
GpuWavefront::~GpuWavefront() = default;
WavefrontResult GpuWavefront::run(const Light& light) { return impl_->run(light); }

}  // namespace eikon
