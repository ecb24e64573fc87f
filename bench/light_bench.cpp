// Light-simulator benchmark (issue 6): scenes/caustic_sphere.json (a glass ball over an opaque
// floor under a directional light covering the whole volume), voxelised at its own resolution
// (128 on the long side), simulated with WavefrontSettings defaults by the GPU twin
// (GpuWavefront, shaders/wavefront.comp) and by the double-precision CPU reference
// (WavefrontSimulator), each once, in one run. Prints per twin: seconds, patches processed
// (seeded + 4·splits), patches/s, the flux balance (emitted vs left + caustic + energy + absorbed +
// live at max_steps), the GPU/CPU speed ratio; then the same with straight steps off
// (skip_empty = false) at a lower resolution (default 64: without skipping the 128 run takes
// minutes per twin on a 2-core lavapipe machine), and the speed-up of skipping at that resolution.
// Timings are not asserted anywhere (they vary ±20% on a shared machine).
//
//   light_bench [--resolution N] [--no-skip-resolution M] [--steps-per-dispatch K] [--no-cpu]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "core/reference/reference_marcher.h"
#include "core/reference/wavefront.h"
#include "core/render/light_simulator.h"
#include "core/scene/scene.h"
#include "core/vk/context.h"
#include "core/volume/volume_set.h"

using namespace eikon;

namespace {

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct Run {
  double s = 0;
  WavefrontStats st;
  double patches() const { return double(st.seeded) + 4.0 * double(st.splits); }
};

void print(const char* name, const Run& r) {
  const WavefrontStats& s = r.st;
  const double ended = s.flux_left + s.flux_caustic + s.flux_energy + s.flux_absorbed + s.flux_live_at_end;
  std::printf("  %-4s %8.2f s  %10.0f patches  %9.3g patches/s  steps %5d  splits %zu (refused %zu)\n", name, r.s,
              r.patches(), r.patches() / r.s, s.steps, s.splits, s.splits_refused);
  std::printf("       flux emitted %.9g = left %.9g + caustic %.9g + energy %.9g + absorbed %.9g + live %.9g"
              "  (balance %+.2e relative)\n",
              s.flux_emitted, s.flux_left, s.flux_caustic, s.flux_energy, s.flux_absorbed, s.flux_live_at_end,
              (ended - s.flux_emitted) / s.flux_emitted);
  if (s.straight_steps > 0)
    std::printf("       straight steps %zu covering %zu time steps (%.1f each)\n", s.straight_steps,
                s.straight_time_steps, double(s.straight_time_steps) / double(s.straight_steps));
}

struct Pair {
  Run gpu, cpu;
  bool haveCpu = false;
};

int gStepsPerDispatch = 16;

Pair simulate(vk::Context& ctx, Scene scene, int resolution, bool skip, bool cpu) {
  scene.volume.resolution = resolution;
  const VolumeSet vol = voxelize(scene);
  WavefrontSettings s;
  s.skip_empty = skip;
  std::printf("\nvolume %dx%dx%d (h = %.4g mm), straight steps %s\n", vol.grid.dims[0], vol.grid.dims[1],
              vol.grid.dims[2], vol.grid.h, skip ? "on (skip_empty = true)" : "off (skip_empty = false)");
  Pair p;
  {
    GpuWavefront gpu(ctx, vol, s, gStepsPerDispatch);
    auto t0 = std::chrono::steady_clock::now();
    WavefrontResult r = gpu.run(scene.lights[0]);
    p.gpu.s = seconds(t0);
    p.gpu.st = r.stats;
  }
  print("GPU", p.gpu);
  if (cpu) {
    VolumeField field(vol);
    WavefrontSimulator sim(field, vol.grid, s);
    auto t0 = std::chrono::steady_clock::now();
    WavefrontResult r = sim.run(scene.lights[0]);
    p.cpu.s = seconds(t0);
    p.cpu.st = r.stats;
    p.haveCpu = true;
    print("CPU", p.cpu);
    std::printf("  GPU/CPU speed ratio (patches/s): %.2f\n",
                (p.gpu.patches() / p.gpu.s) / (p.cpu.patches() / p.cpu.s));
  }
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  int resolution = 0, noSkipResolution = 64;
  bool cpu = true;
  std::string scene_path = std::string(EIKON_SOURCE_DIR) + "/scenes/caustic_sphere.json";
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--resolution") && i + 1 < argc) resolution = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--no-skip-resolution") && i + 1 < argc) noSkipResolution = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--steps-per-dispatch") && i + 1 < argc) gStepsPerDispatch = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--no-cpu")) cpu = false;
    else scene_path = argv[i];
  }
  const Scene scene = loadScene(scene_path);
  if (scene.lights.empty()) {
    std::fprintf(stderr, "light_bench: %s has no light\n", scene_path.c_str());
    return 1;
  }
  if (resolution <= 0) resolution = scene.volume.resolution;
  auto ctx = vk::Context::create();
  std::printf("scene %s, light 0, WavefrontSettings defaults, GPU steps per dispatch %d, device %s\n",
              scene_path.c_str(), gStepsPerDispatch, ctx->deviceName().c_str());

  const Pair full = simulate(*ctx, scene, resolution, true, cpu);
  std::printf("\nWithout straight steps at resolution %d (lower than %d: without skipping the full resolution "
              "takes minutes per twin here):",
              noSkipResolution, resolution);
  const Pair low = simulate(*ctx, scene, noSkipResolution, false, cpu);
  std::printf("\nThe same resolution %d with straight steps, for the speed-up:", noSkipResolution);
  const Pair lowSkip = simulate(*ctx, scene, noSkipResolution, true, cpu);
  std::printf("\nspeed-up of straight steps at resolution %d (time without / with): GPU %.2fx", noSkipResolution,
              low.gpu.s / lowSkip.gpu.s);
  if (cpu) std::printf(", CPU %.2fx", low.cpu.s / lowSkip.cpu.s);
  std::printf("\n");
  (void)full;
  return 0;
}
