// Light-simulator benchmark: scenes/caustic_sphere.json (a glass ball over an opaque
// floor under a directional light covering the whole volume), voxelised at its own resolution
// (128 on the long side), simulated with WavefrontSettings defaults by the GPU twin
// (GpuWavefront, shaders/wavefront.comp) and by the double-precision CPU reference
// (WavefrontSimulator), each once, in one run. Prints per twin: seconds, patches processed
// (seeded + 4·splits + 2·halvings), patches/s, the flux balance (emitted vs left + caustic + energy
// + absorbed + live at max_steps), the GPU/CPU speed ratio; then the same with straight steps off
// (skip_empty = false) at a lower resolution (default 64: without skipping the 128 run takes
// minutes per twin on a 2-core lavapipe machine), and the speed-up of skipping at that resolution.
// Timings are not asserted anywhere (they vary ±20% on a shared machine).
//
// --sharp: every run at the scene's sharp interfaces (WavefrontSettings::
// sharp_interfaces on the GPU, sharpInterfacesFor on the CPU), where they apply.
//
// --interfaces smoothed,sharp: run the full resolution once per listed kind (e.g. both in one
// run, for the ratios of docs/performance.md's "Figures"); --no-low: skip the runs
// without straight steps at the lower resolution.
//
// --threads T1,T2,…: run the CPU reference once per listed thread count
// (WavefrontSettings::threads; default 0 = hardware concurrency) and print each one's speed-up
// over the first; --no-gpu: skip the GPU twin (and Vulkan).
//
// --caustics pass: light goes on through fold caustics, as renders simulate it (the default here
// is the simulator's own, kill). --no-straight-to-boundary: sharp straight steps on the skip
// distances only (WavefrontSettings::straight_to_boundary), to measure what running up to the
// boundary gains (docs/performance.md "Light simulator"). Each run prints its tears (torn patches
// made pencils). --reflections G1,G2,…: run the full resolution once per listed reflected-
// generation limit (WavefrontSettings::max_reflection_generations; default 0), each printing the
// reflected copies made and the flux dropped past the limit, and the time against the first.
// --split halves,quarters: run the full resolution once per listed split rule
// (WavefrontSettings::split_halves: a patch stretched along one pair of edges only is halved, or
// every split makes quarters, the default) and print each one's time and patches against the first.
//
//   light_bench [--resolution N] [--no-skip-resolution M] [--steps-per-dispatch K] [--no-cpu]
//               [--no-gpu] [--threads T1,T2,…] [--sharp] [--interfaces smoothed,sharp] [--no-low]
//               [--caustics kill|pass] [--no-straight-to-boundary] [--reflections G1,G2,…]
//               [--split halves,quarters]
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

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
  double patches() const {
    return double(st.seeded) + 4.0 * double(st.splits) + 2.0 * double(st.halvings);
  }
};

void print(const char* name, const Run& r) {
  const WavefrontStats& s = r.st;
  const double ended = s.flux_left + s.flux_caustic + s.flux_energy + s.flux_absorbed +
                       s.flux_reflected + s.flux_live_at_end;
  std::printf(
      "  %-6s %8.2f s  %10.0f patches  %9.3g patches/s  steps %5d  splits %zu, halvings %zu "
      "(refused %zu, tears %zu)\n",
      name, r.s, r.patches(), r.patches() / r.s, s.steps, s.splits, s.halvings, s.splits_refused,
      s.tears);
  std::printf(
      "       flux emitted %.9g = left %.9g + caustic %.9g + energy %.9g + absorbed %.9g + "
      "reflected %.9g + live %.9g  (balance %+.2e relative)\n",
      s.flux_emitted, s.flux_left, s.flux_caustic, s.flux_energy, s.flux_absorbed, s.flux_reflected,
      s.flux_live_at_end, (ended - s.flux_emitted) / s.flux_emitted);
  if (s.reflections > 0)
    std::printf("       reflected copies %zu, reflected flux dropped %.3e of emitted\n",
                s.reflections, s.flux_reflected / s.flux_emitted);
  if (s.straight_steps > 0)
    std::printf("       straight steps %zu covering %zu time steps (%.1f each)\n", s.straight_steps,
                s.straight_time_steps, double(s.straight_time_steps) / double(s.straight_steps));
}

struct Pair {
  Run gpu;
  std::vector<Run> cpu;  ///< one per entry of gThreads
  bool haveGpu = false;
  double gpuSetup = 0;  ///< seconds to construct the GpuWavefront
  double cpuSetup = 0;  ///< seconds of sharpInterfacesFor and the VolumeField (the CPU twin's)
};

int gStepsPerDispatch = 16;
bool gSharp = false;                                   ///< --sharp
bool gPassCaustics = false;                            ///< --caustics pass
bool gToBoundary = true;                               ///< !--no-straight-to-boundary
int gReflections = 0;                                  ///< the run's --reflections entry
bool gSplitHalves = WavefrontSettings{}.split_halves;  ///< the run's --split entry
std::vector<int> gThreads = {0};  ///< CPU reference thread counts (0: hardware concurrency)

Pair simulate(vk::Context* ctx, Scene scene, int resolution, bool skip, bool cpu) {
  scene.volume.resolution = resolution;
  const VolumeSet vol = voxelize(scene);
  WavefrontSettings s;
  s.skip_empty = skip;
  s.sharp_interfaces = gSharp;
  s.pass_caustics = gPassCaustics;
  s.straight_to_boundary = gToBoundary;
  s.max_reflection_generations = gReflections;
  s.split_halves = gSplitHalves;
  // The CPU twin's set-up (its skip distances and media; the field), timed as the GPU's is.
  const auto tc = std::chrono::steady_clock::now();
  const SharpInterfaces sharp =
      gSharp ? sharpInterfacesFor(vol, s.wavelength_nm) : SharpInterfaces{};
  const VolumeField field(vol);
  const double cpuSetup = seconds(tc);
  std::printf(
      "\nvolume %dx%dx%d (h = %.4g mm), reflected generations %d, split %s, straight steps %s, "
      "interfaces %s\n",
      vol.grid.dims[0], vol.grid.dims[1], vol.grid.dims[2], vol.grid.h, gReflections,
      gSplitHalves ? "halves (and quarters)" : "quarters only",
      skip ? "on (skip_empty = true)" : "off (skip_empty = false)",
      !sharp.active()             ? "smoothed"
      : vol.boundary.convex_apart ? "sharp (crossings on the planes: faces known)"
      : vol.boundary.exact        ? "sharp (crossings on the shapes)"
                                  : "sharp (crossings by the walk)");
  Pair p;
  if (ctx) {
    // Set-up (uploads, the pipelines' compilation) apart: a render pays it once per scene.
    auto t0 = std::chrono::steady_clock::now();
    GpuWavefront gpu(*ctx, vol, s, gStepsPerDispatch);
    p.gpuSetup = seconds(t0);
    t0 = std::chrono::steady_clock::now();
    WavefrontResult r = gpu.run(scene.lights[0]);
    p.gpu.s = seconds(t0);
    p.gpu.st = r.stats;
    p.haveGpu = true;
    print("GPU", p.gpu);
    std::printf("       set-up (upload, pipeline compilation) %.2f s\n", p.gpuSetup);
  }
  if (cpu) {
    p.cpuSetup = cpuSetup;
    std::printf("  CPU set-up (skip distances, media, field) %.2f s\n", cpuSetup);
    for (int threads : gThreads) {
      s.threads = threads;
      WavefrontSimulator sim(field, vol.grid, s, sharp);
      auto t0 = std::chrono::steady_clock::now();
      WavefrontResult r = sim.run(scene.lights[0]);
      Run run;
      run.s = seconds(t0);
      run.st = r.stats;
      char name[16];
      std::snprintf(name, sizeof name, "CPU/%d", threads);
      print(name, run);
      p.cpu.push_back(run);
      if (p.cpu.size() > 1)
        std::printf("  speed-up of %d threads over %d: %.2fx\n", threads, gThreads[0],
                    p.cpu[0].s / run.s);
      if (p.haveGpu)
        std::printf("  GPU/CPU speed ratio (patches/s): %.2f\n",
                    (p.gpu.patches() / p.gpu.s) / (run.patches() / run.s));
    }
  }
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  int resolution = 0, noSkipResolution = 64;
  bool cpu = true, gpu = true;
  std::string scene_path = std::string(EIKON_SOURCE_DIR) + "/scenes/caustic_sphere.json";
  CLI::App app{
      "Light simulator: GPU and CPU reference twins on a lit scene (default "
      "scenes/caustic_sphere.json)",
      "light_bench"};
  app.add_option("scene", scene_path, "Scene JSON file with at least one light");
  app.add_option("--resolution", resolution, "Volume resolution (default: the scene's)")
      ->check(CLI::PositiveNumber);
  app.add_option("--no-skip-resolution", noSkipResolution,
                 "Resolution of the runs without straight steps (default 64)")
      ->check(CLI::PositiveNumber);
  app.add_option("--steps-per-dispatch", gStepsPerDispatch, "GPU time steps per dispatch")
      ->check(CLI::PositiveNumber);
  app.add_flag("!--no-cpu", cpu, "Skip the CPU reference");
  app.add_flag("!--no-gpu", gpu, "Skip the GPU simulator");
  app.add_flag("--sharp", gSharp, "Simulate at the scene's sharp interfaces (both twins)");
  std::vector<std::string> interfaces;
  app.add_option("--interfaces", interfaces,
                 "Full-resolution runs, comma separated: smoothed, sharp (default: --sharp's)")
      ->delimiter(',')
      ->check(CLI::IsMember({"smoothed", "sharp"}));
  std::string caustics = "kill";
  app.add_option(
         "--caustics", caustics,
         "kill (Tevs, WavefrontSettings' default) or pass (light continues through a focus, "
         "as renders simulate it)")
      ->check(CLI::IsMember({"kill", "pass"}));
  app.add_flag("!--no-straight-to-boundary", gToBoundary,
               "Sharp: straight steps on the skip distances only, not up to each corner's next "
               "boundary (WavefrontSettings::straight_to_boundary)");
  bool lowRuns = true;
  app.add_flag("!--no-low", lowRuns,
               "Skip the runs without straight steps at the lower resolution");
  app.add_option("--threads", gThreads,
                 "CPU thread counts to compare, comma separated (0: all cores)")
      ->delimiter(',')
      ->check(CLI::Range(0, 1024));
  std::vector<int> reflections = {0};
  app.add_option("--reflections", reflections,
                 "Reflected-generation limits to compare, comma separated (sharp interfaces; "
                 "WavefrontSettings::max_reflection_generations, default 0)")
      ->delimiter(',')
      ->check(CLI::Range(0, 64));
  const char* defaultRule = WavefrontSettings{}.split_halves ? "halves" : "quarters";
  std::vector<std::string> splitRules = {defaultRule};
  app.add_option("--split", splitRules,
                 "Split rules to compare, comma separated: halves (a patch stretched one way only "
                 "is halved), quarters (every split makes quarters; WavefrontSettings' default)")
      ->delimiter(',')
      ->check(CLI::IsMember({"halves", "quarters"}));
  CLI11_PARSE(app, argc, argv);
  if (gThreads.empty()) gThreads = {0};
  if (splitRules.empty()) splitRules = {defaultRule};
  if (reflections.empty()) reflections = {0};
  gPassCaustics = caustics == "pass";
  const Scene scene = loadScene(scene_path);
  if (scene.lights.empty()) {
    std::fprintf(stderr, "light_bench: %s has no light\n", scene_path.c_str());
    return 1;
  }
  if (resolution <= 0) resolution = scene.volume.resolution;
  std::unique_ptr<vk::Context> ctx;
  if (gpu) ctx = vk::Context::create();
  std::printf(
      "scene %s, light 0, WavefrontSettings defaults, GPU steps per dispatch %d, device %s\n",
      scene_path.c_str(), gStepsPerDispatch, ctx ? ctx->deviceName().c_str() : "(no GPU)");

  if (interfaces.empty()) interfaces = {gSharp ? "sharp" : "smoothed"};
  std::vector<std::string> rows;
  const Pair* first = nullptr;
  std::vector<Pair> fulls;
  fulls.reserve(interfaces.size() * reflections.size() * splitRules.size());
  for (const std::string& kind : interfaces)
    for (int g : reflections)
      for (const std::string& rule : splitRules) {
        gSharp = kind == "sharp";
        gReflections = g;
        gSplitHalves = rule == "halves";
        const Pair& full = fulls.emplace_back(simulate(ctx.get(), scene, resolution, true, cpu));
        if (!first) first = &full;
        char row[400];
        const double c = full.cpu.empty() ? 0.0 : full.cpu.back().s,
                     gs = full.haveGpu ? full.gpu.s : 0.0;
        const Run& r = full.cpu.empty() ? full.gpu : full.cpu.back();
        const Run& r0 = first->cpu.empty() ? first->gpu : first->cpu.back();
        const WavefrontStats& st = r.st;
        std::snprintf(
            row, sizeof row,
            "| %s | %d | %s | %d | %s | %.0f (%.2fx) | %.3e | %.2f (+%.2f set-up; %.2fx) | %.2f "
            "(+%.2f set-up) | %.2f |",
            scene_path.c_str(), resolution, kind.c_str(), g, rule.c_str(), r.patches(),
            r.patches() / r0.patches(),
            st.flux_emitted > 0 ? st.flux_reflected / st.flux_emitted : 0.0, c, full.cpuSetup,
            c > 0 && !first->cpu.empty() ? c / first->cpu.back().s : 0.0, gs, full.gpuSetup,
            c > 0 && gs > 0 ? c / gs : 0.0);
        rows.push_back(row);
      }
  gReflections = reflections.front();
  gSplitHalves = splitRules.front() == "halves";
  std::printf(
      "\n| scene | resolution | interfaces | reflected generations | split | patches (against "
      "the first row) | reflected flux dropped (of emitted) | CPU s (last thread count; against "
      "the first row) | GPU s | CPU/GPU |\n");
  for (const std::string& r : rows) std::printf("%s\n", r.c_str());
  if (!lowRuns) return 0;
  std::printf(
      "\nWithout straight steps at resolution %d (lower than %d: without skipping the full "
      "resolution "
      "takes minutes per twin here):",
      noSkipResolution, resolution);
  const Pair low = simulate(ctx.get(), scene, noSkipResolution, false, cpu);
  std::printf("\nThe same resolution %d with straight steps, for the speed-up:", noSkipResolution);
  const Pair lowSkip = simulate(ctx.get(), scene, noSkipResolution, true, cpu);
  std::printf("\nspeed-up of straight steps at resolution %d (time without / with):",
              noSkipResolution);
  if (gpu) std::printf(" GPU %.2fx", low.gpu.s / lowSkip.gpu.s);
  for (size_t i = 0; i < low.cpu.size(); ++i)
    std::printf(" CPU/%d %.2fx", gThreads[i], low.cpu[i].s / lowSkip.cpu[i].s);
  std::printf("\n");
  return 0;
}
