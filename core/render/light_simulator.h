// The GPU light simulator (docs/design.md §2): the wavefront of patches of
// core/light/wavefront_types.h propagated by a Vulkan compute kernel (shaders/wavefront.comp), one
// thread per patch, RK4 in constant time on the four corners, attenuation, fixed-point atomic
// splat into the irradiance/direction volumes. Same settings, seeds, kill rules, split rule and
// result types as the CPU reference, which it is tested against
// (tests/core/render/wavefront_gpu_test.cpp).
//
//   eikon::VolumeSet vol = eikon::voxelize(scene);
//   eikon::GpuWavefront gpu(ctx, vol, settings);
//   eikon::WavefrontResult r = gpu.run(scene.lights[0]);   // r.irradiance in W/mm², r.stats
//
// Sharp interfaces (WavefrontSettings::sharp_interfaces, where sharpLightApplies): the
// corners refract at the scene's exact boundaries as the CPU twin's do given sharpInterfacesFor
// (the pipeline is specialised with kSharpLight; docs/light-simulator.md, "Sharp interfaces"),
// with one difference: a crystal face takes the D-projection Fresnel split (the CPU: exact).
//
// What differs from the reference: the kernel runs in float32, the splits included; the patch
// list stays on the GPU and is rebuilt between dispatches by a count / exclusive scan / scatter
// into a second buffer (each dispatch advances every live patch by up to `steps_per_dispatch`
// steps; a patch that needs a split stops, is split one level by the rebuild, and children still
// too large are split again by the next rebuild before they move); the host reads back only the
// scan total and per-workgroup kill tallies; of the probe plane, flux_probe, probe_centroid and
// probe_direction are computed (a crossing is judged from the centre's positions before and after
// the step) but not flux_ended_before_probe; stats.max_live is the largest list length after a
// rebuild (the reference counts within a step).
// Common mistakes: expecting bit-identical stats — float32 may move a borderline kill or split by
// a step; expecting identical stats when splits are refused (the budget is applied per rebuild
// against that rebuild's survivors, so which splits are refused depends on steps_per_dispatch);
// forgetting the buffer limits — live patches take 176 B each (two lists) and the splat 36 B per
// voxel, each buffer within the device's storage-buffer range (lavapipe: 128 MiB ≈ 762k live
// patches, 3.7M voxels; run() and the constructor throw with a message beyond that, so lower
// max_patches or the resolution).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/light/wavefront_types.h"
#include "core/vk/context.h"
#include "core/volume/volume_set.h"

namespace eikon {

/// Exclusive prefix sum of uint32 values on the GPU (shaders/scan.comp, the scan GpuWavefront
/// uses to rebuild its patch list); exposed for tests and measurements. Sums wrap modulo 2^32.
class GpuScan {
 public:
  explicit GpuScan(vk::Context& ctx);
  ~GpuScan();
  GpuScan(const GpuScan&) = delete;
  GpuScan& operator=(const GpuScan&) = delete;
  /// Replace values[i] by the sum of values[0..i); returns the sum of all of them.
  uint32_t exclusiveScan(std::vector<uint32_t>& values);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// What the GPU light runs over one volume share (simulateLighting: every band, mode and light
/// of a simulation): the wavefront, count and scan pipelines, built once per feature set — lavapipe
/// spends ~0.15 s of CPU on each, which no pipeline cache of Mesa 22.3 keeps, and a dispersive
/// scene runs 12 bands — and the sharp path's skip distances, uploaded once. Give the same object
/// to the GpuWavefront of each run, one run at a time; it must outlive them, and every run given
/// it must be over the same volume (a run over another throws std::invalid_argument).
class GpuWavefrontShared {
 public:
  GpuWavefrontShared();
  ~GpuWavefrontShared();
  GpuWavefrontShared(const GpuWavefrontShared&) = delete;
  GpuWavefrontShared& operator=(const GpuWavefrontShared&) = delete;
  /// Pipelines built so far (one per feature set, plus the count and scan kernels): for tests.
  int pipelinesBuilt() const;

 private:
  friend class GpuWavefront;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Whether the GPU twin's accumulation volume for this grid fits one of the device's storage
/// buffers (lavapipe: 128 MiB, 36 bytes a voxel: ~3.7M voxels); where it does not, GpuWavefront
/// refuses with one line and `--light-device auto` simulates on the CPU twin.
bool gpuLightFits(const vk::Context& ctx, const Grid& grid);
/// Throws std::runtime_error (one line: the grid, the bytes, the limit and the remedy) where
/// gpuLightFits is false.
void requireGpuLightFits(const vk::Context& ctx, const Grid& grid);

class GpuWavefront {
 public:
  /// The volume is uploaded (o-mode index A/B/C and medium; for settings.mode = 1 in a uniaxial
  /// volume also the e-mode index A/B/C, medium and the optic axis — the e-mode of an isotropic
  /// volume is the o-mode; with settings.sharp_interfaces, where sharpLightApplies(volume), the
  /// boundary field and the media table); it is referenced for seeding and
  /// splitting and must outlive this object. Throws std::invalid_argument for bad settings,
  /// std::runtime_error if the splat buffer exceeds the device's storage-buffer range.
  /// `shared`: the pipelines and skip distances of earlier runs over this volume, reused and
  /// added to (GpuWavefrontShared); null builds this run's own.
  GpuWavefront(vk::Context& ctx, const VolumeSet& volume, WavefrontSettings settings,
               int steps_per_dispatch = 16, GpuWavefrontShared* shared = nullptr);
  ~GpuWavefront();
  GpuWavefront(const GpuWavefront&) = delete;
  GpuWavefront& operator=(const GpuWavefront&) = delete;

  /// Propagate a light's wavefront through the volume; the result is on the volume's grid.
  WavefrontResult run(const Light& light);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace eikon
