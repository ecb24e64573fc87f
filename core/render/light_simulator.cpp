// GPU light simulator: host side of shaders/wavefront.comp. See light_simulator.h and
// docs/light-simulator.md ("GPU kernel").
#include "core/render/light_simulator.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "core/reference/reference_marcher.h"
#include "core/vk/resources.h"
#include "shaders/eikon_shared.h"
#include "shaders/wavefront.spv.h"

namespace eikon {

struct GpuWavefront::Impl {
  vk::Context& ctx;
  const VolumeSet& vol;
  WavefrontSettings s;
  int steps_per_dispatch;
  VolumeField field;
  std::vector<vk::Image3D> images;  // A, B, C (B, C only when dispersive), medium
  vk::Buffer params, splat, patches;
  vk::ComputePipeline pipe;
  double il2 = 0, il4 = 0, n_min = 1.0;

  Impl(vk::Context& c, const VolumeSet& v, WavefrontSettings settings, int k)
      : ctx(c), vol(v), s(settings), steps_per_dispatch(k), field(v) {
    const Grid& g = vol.grid;
    if (k < 1) throw std::invalid_argument("wavefront: steps_per_dispatch must be >= 1");
    if (!(g.h > 0) || g.count() == 0) throw std::invalid_argument("wavefront: empty volume");
    if (s.dt <= 0) s.dt = 0.5 * g.h;
    if (!(s.wavelength_nm > 0)) throw std::invalid_argument("wavefront: wavelength must be > 0");
    const double l = s.wavelength_nm * 1e-3;
    il2 = 1.0 / (l * l);
    il4 = il2 * il2;
    // Smallest index in the volume (bounds the centre's step length Δs ≤ dt/n_min for the splat scale).
    n_min = 1e300;
    for (size_t i = 0; i < g.count(); ++i) {
      double n = vol.index[0][0][i].x;
      if (vol.dispersive) n += vol.index[0][1][i].x * il2 + vol.index[0][2][i].x * il4;
      n_min = std::min(n_min, n);
    }
    if (!(n_min > 0)) throw std::invalid_argument("wavefront: the index volume has n <= 0");

    std::array<uint32_t, 3> ext{uint32_t(g.dims[0]), uint32_t(g.dims[1]), uint32_t(g.dims[2])};
    auto upload = [&](const std::vector<glm::vec4>& data, const char* name) {
      vk::Image3D img(ctx, ext, VK_FORMAT_R32G32B32A32_SFLOAT, name);
      img.upload(ctx, data.data(), data.size() * sizeof(glm::vec4));
      images.push_back(std::move(img));
    };
    upload(vol.index[0][0], "wavefront index A");
    if (vol.dispersive) {
      upload(vol.index[0][1], "wavefront index B");
      upload(vol.index[0][2], "wavefront index C");
    }
    upload(vol.medium[0], "wavefront medium");
    params = vk::Buffer(ctx, sizeof(gpu::WaveParams), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "wavefront params");
    splat = vk::Buffer(ctx, g.count() * (EIKON_SPLAT_ACC_WORDS + 1) * sizeof(uint32_t),
                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "wavefront splat");
    std::vector<vk::BindingSpec> b;
    for (uint32_t i : {uint32_t(EIKON_WB_INDEX_A), uint32_t(EIKON_WB_INDEX_B), uint32_t(EIKON_WB_INDEX_C),
                       uint32_t(EIKON_WB_MEDIUM)})
      b.push_back({i, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE});
    for (uint32_t i : {uint32_t(EIKON_WB_PARAMS), uint32_t(EIKON_WB_PATCHES), uint32_t(EIKON_WB_SPLAT)})
      b.push_back({i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER});
    pipe = vk::ComputePipeline(ctx, std::span<const uint32_t>(k_wavefront_spv, sizeof(k_wavefront_spv) / 4), b, 0,
                               "wavefront");
    const size_t med = vol.dispersive ? 3 : 1;
    pipe.bindImage(EIKON_WB_INDEX_A, images[0]);
    pipe.bindImage(EIKON_WB_INDEX_B, images[vol.dispersive ? 1 : 0]);
    pipe.bindImage(EIKON_WB_INDEX_C, images[vol.dispersive ? 2 : 0]);
    pipe.bindImage(EIKON_WB_MEDIUM, images[med]);
    pipe.bindBuffer(EIKON_WB_PARAMS, params);
    pipe.bindBuffer(EIKON_WB_SPLAT, splat);
  }

  void ensurePatchCapacity(size_t n) {
    const VkDeviceSize bytes = std::max<size_t>(n, 64) * sizeof(gpu::WavePatch);
    if (patches.handle() != VK_NULL_HANDLE && patches.size() >= bytes) return;
    // Grow geometrically, but never past the storage-buffer range when the request itself fits
    // (vk::Buffer refuses larger requests with a message: lavapipe allows 128 MiB ≈ 838k patches).
    const VkDeviceSize range = ctx.limits().max_storage_buffer_range;
    const VkDeviceSize grown = std::max<VkDeviceSize>(bytes, std::min<VkDeviceSize>(2 * patches.size(), range));
    patches = vk::Buffer(ctx, grown, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "wavefront patches");
    pipe.bindBuffer(EIKON_WB_PATCHES, patches);
  }

  static gpu::WavePatch toGpu(const Patch& p) {
    gpu::WavePatch g{};
    for (int k = 0; k < 4; ++k) {
      g.x[k] = glm::vec4(glm::vec3(p.x[size_t(k)]), 0.0f);
      g.w[k] = glm::vec4(glm::vec3(p.w[size_t(k)]), 0.0f);
    }
    g.flux = glm::vec4(float(p.energy), float(p.area0), float(p.seed_energy), 0.0f);
    g.state = glm::ivec4(EIKON_PATCH_ALIVE, p.orientation, p.entered ? 1 : 0, 0);
    return g;
  }

  // Split p (stopped by the kernel with EIKON_PATCH_SPLIT) into children on the bilinear 3×3
  // lattice, recursively until no edge exceeds the split span or the budget is spent — the same
  // rule as WavefrontSimulator::run's emit, in double from the float state.
  void emit(const gpu::WavePatch& p0, std::vector<gpu::WavePatch>& out, size_t& live, WavefrontStats& st) const {
    const double maxEdge = s.split_span_voxels * vol.grid.h;
    std::vector<gpu::WavePatch> work{p0};
    while (!work.empty()) {
      gpu::WavePatch p = work.back();
      work.pop_back();
      p.state.x = EIKON_PATCH_ALIVE;
      glm::dvec3 x[4], w[4];
      for (int k = 0; k < 4; ++k) x[k] = glm::dvec3(p.x[k]), w[k] = glm::dvec3(p.w[k]);
      double e = 0;
      for (int k = 0; k < 4; ++k) e = std::max(e, glm::length(x[(k + 1) % 4] - x[k]));
      if (e <= maxEdge) {
        out.push_back(p);
        continue;
      }
      if (live + 3 > size_t(s.max_patches)) {
        ++st.splits_refused;
        out.push_back(p);
        continue;
      }
      live += 3;
      ++st.splits;
      glm::dvec3 X[3][3], W[3][3];
      for (int b = 0; b < 3; ++b)
        for (int a = 0; a < 3; ++a) {
          const double fa = 0.5 * a, fb = 0.5 * b;
          X[b][a] = (1 - fa) * (1 - fb) * x[0] + fa * (1 - fb) * x[1] + fa * fb * x[2] + (1 - fa) * fb * x[3];
          glm::dvec3 ww = (1 - fa) * (1 - fb) * w[0] + fa * (1 - fb) * w[1] + fa * fb * w[2] + (1 - fa) * fb * w[3];
          if (a == 1 || b == 1) {
            double n;
            glm::dvec3 g;
            field.index(X[b][a], il2, il4, n, g);
            ww = glm::normalize(ww) * n;
          }
          W[b][a] = ww;
        }
      X[0][0] = x[0], X[0][2] = x[1], X[2][2] = x[2], X[2][0] = x[3];
      W[0][0] = w[0], W[0][2] = w[1], W[2][2] = w[2], W[2][0] = w[3];
      for (int cb = 0; cb < 2; ++cb)
        for (int ca = 0; ca < 2; ++ca) {
          gpu::WavePatch c = p;
          const int pa[4] = {ca, ca + 1, ca + 1, ca}, pb[4] = {cb, cb, cb + 1, cb + 1};
          for (int k = 0; k < 4; ++k) {
            c.x[k] = glm::vec4(glm::vec3(X[pb[k]][pa[k]]), 0.0f);
            c.w[k] = glm::vec4(glm::vec3(W[pb[k]][pa[k]]), 0.0f);
          }
          c.flux.x = 0.25f * p.flux.x;
          c.flux.y = 0.25f * p.flux.y;
          work.push_back(c);
        }
    }
  }

  WavefrontResult run(const Light& light) {
    const Grid& g = vol.grid;
    WavefrontResult res;
    WavefrontStats& st = res.stats;
    WavefrontSimulator cpu(field, g, s);
    std::vector<Patch> seeds = cpu.seed(light);
    st.seeded = seeds.size();
    const glm::dvec3 lo = g.origin, hi = g.boundsMax();
    double maxSeed = 0;
    std::vector<gpu::WavePatch> cur;
    cur.reserve(seeds.size());
    for (Patch& p : seeds) {
      st.flux_emitted += p.energy;
      maxSeed = std::max(maxSeed, p.energy);
      const glm::dvec3 c = 0.25 * (p.x[0] + p.x[1] + p.x[2] + p.x[3]);
      p.entered = c.x >= lo.x && c.y >= lo.y && c.z >= lo.z && c.x <= hi.x && c.y <= hi.y && c.z <= hi.z;
      cur.push_back(toGpu(p));
    }
    st.max_live = cur.size();

    // Fixed-point scale: one splat is flux_mid·Δs/h³ ≤ maxSeed·(dt/n_min)/h³ =: vmax (a patch's flux
    // never grows; the centre moves at most dt/n_min per step). With scale = 2^29/(2·vmax) a splat
    // is ≤ 2^28 units, far inside int32 (the factor 2 covers RK4's overshoot in steep gradients),
    // and its rounding error is ≤ 0.5/scale = 2^-29·vmax. A 64-bit voxel sum overflows only after
    // 2^35 maximal splats into one voxel, i.e. never for runs of ≤ 2^20 patches × 2^14 steps.
    const double h3 = g.h * g.h * g.h;
    const double vmax = std::max(maxSeed, 1e-300) * s.dt / (n_min * h3);
    const double scale = std::ldexp(1.0, 29) / (2.0 * vmax);

    gpu::WaveParams P{};
    P.grid_origin = glm::vec4(glm::vec3(lo), float(g.h));
    P.grid_max = glm::vec4(glm::vec3(hi), float(1.0 / g.h));
    int flags = 0;
    if (vol.dispersive) flags |= EIKON_F_DISPERSIVE;
    if (vol.attenuating) flags |= EIKON_F_ATTENUATION;
    if (vol.opaque) flags |= EIKON_F_OPACITY;
    P.grid_dims = glm::ivec4(g.dims[0], g.dims[1], g.dims[2], flags);
    P.step = glm::vec4(float(s.dt), float(s.split_span_voxels * g.h), float(s.min_energy_fraction), float(1.0 / h3));
    const double l = s.wavelength_nm * 1e-3;
    P.wavelength = glm::vec4(float(l), float(il2), float(il4), float(scale));
    std::vector<uint32_t> zero(g.count() * (EIKON_SPLAT_ACC_WORDS + 1), 0u);
    splat.write(zero.data(), zero.size() * sizeof(uint32_t));

    size_t live = cur.size();
    std::vector<gpu::WavePatch> next;
    while (!cur.empty()) {
      ensurePatchCapacity(cur.size());
      patches.write(cur.data(), cur.size() * sizeof(gpu::WavePatch));
      P.control = glm::ivec4(int(cur.size()), steps_per_dispatch, s.max_steps, 0);
      params.write(&P, sizeof P);
      ctx.submitAndWait([&](VkCommandBuffer c) {
        pipe.dispatch(c, uint32_t((cur.size() + EIKON_WAVE_WG - 1) / EIKON_WAVE_WG), 1, 1, nullptr);
      });
      patches.read(cur.data(), cur.size() * sizeof(gpu::WavePatch));
      // Host compaction and splits (the GPU scan is the remaining step, see the docs).
      next.clear();
      for (const gpu::WavePatch& p : cur) {
        st.steps = std::max(st.steps, p.state.w);
        st.flux_absorbed += p.flux.w;
        const double energy = p.flux.x;
        const glm::dvec3 c1 = 0.25 * glm::dvec3(p.x[0] + p.x[1] + p.x[2] + p.x[3]);
        switch (p.state.x) {
          case EIKON_PATCH_OPAQUE:
            ++st.kills_opaque, st.flux_absorbed += energy, --live;
            break;
          case EIKON_PATCH_LEFT:
            ++st.kills_left, st.flux_left += energy, --live;
            break;
          case EIKON_PATCH_CAUSTIC:
            ++st.kills_caustic, st.flux_caustic += energy, st.caustic_centroid += energy * c1, --live;
            break;
          case EIKON_PATCH_ENERGY:
            ++st.kills_energy, st.flux_energy += energy, --live;
            break;
          case EIKON_PATCH_SPLIT:
            emit(p, next, live, st);
            break;
          default:
            if (p.state.w >= s.max_steps) {
              ++st.live_at_end, st.flux_live_at_end += energy;  // out of steps: ends live
              --live;
            } else {
              next.push_back(p);
            }
        }
      }
      st.max_live = std::max(st.max_live, live);
      std::swap(cur, next);
    }
    if (st.flux_caustic > 0) st.caustic_centroid /= st.flux_caustic;

    std::vector<uint32_t> words(zero.size());
    splat.read(words.data(), words.size() * sizeof(uint32_t));
    res.irradiance.resize(g.count());
    res.direction.resize(g.count());
    const bool highest = s.splat == WavefrontSettings::Splat::HighestEnergy;
    auto fixedAt = [&](size_t i) {
      const uint64_t u = (uint64_t(words[i + 1]) << 32) | uint64_t(words[i]);
      int64_t v;
      std::memcpy(&v, &u, sizeof v);
      return double(v) / scale;
    };
    for (size_t v = 0; v < g.count(); ++v) {
      const size_t b = v * EIKON_SPLAT_ACC_WORDS;
      const double acc = fixedAt(b);
      const glm::dvec3 d(fixedAt(b + 2), fixedAt(b + 4), fixedAt(b + 6));
      float best;
      std::memcpy(&best, &words[g.count() * EIKON_SPLAT_ACC_WORDS + v], sizeof best);
      res.irradiance[v] = highest ? best : float(acc);
      res.direction[v] = glm::vec4(glm::vec3(acc > 0 ? d / acc : glm::dvec3(0.0)), float(acc));
    }
    return res;
  }
};

GpuWavefront::GpuWavefront(vk::Context& ctx, const VolumeSet& volume, WavefrontSettings settings, int steps_per_dispatch)
    : impl_(std::make_unique<Impl>(ctx, volume, settings, steps_per_dispatch)) {}
GpuWavefront::~GpuWavefront() = default;
WavefrontResult GpuWavefront::run(const Light& light) { return impl_->run(light); }

}  // namespace eikon
