// View-renderer benchmark: glass_sphere at 800×600 from a 128³ volume. Prints, from one
// run: rays/s and steps/ray of the GPU path for several integrators/steps, of the naive fixed-step
// Euler march (no skipping), and of the multi-threaded CPU reference, their ratios, and each
// variant's accuracy: mean and max exit-direction error of 2000 rays through the sphere against
// the CPU reference at RK4 with a 0.05-voxel step.
//
//   build/bench/view_bench [scene.json] [--width W --height H] [--no-cpu] [--interfaces]
//                          [--march sharp|smoothed] [--only SUBSTRING] [--no-accuracy] [--repeat N]
//                          [--transport] [--first-choice [--spp N]]
//
// --march: voxelise with that kind of interface whatever the scene says (the variants' integrator
// and step only matter where the march integrates: every layer when smoothed, varying regions when
// sharp). --only: the variants whose name contains SUBSTRING. --no-accuracy: no CPU truth rays
// (timing only). --repeat: render each variant N times after the warm-up and report the median.
// Steps/s is the rendered steps (the `w` of every pixel) per second of the render.
//
// --interfaces: only the sharp vs smoothed comparison: the scene voxelised both ways
// ("interfaces": "sharp" / "smoothed"), rendered at the default settings; time and steps per ray
// (sharp: one step per straight segment or RK4 step; smoothed: per integration step) and the ratio;
// for the CPU twin also the volume-field reads per ray (every trilinear sample of the index,
// medium and other volumes, and every boundary-field cell locateCrossing evaluates; the GPU's are
// not counted, to keep counters out of the shader's inner loops).
//
// --transport: only full transport against the single transmitted path (docs/view-renderer.md
// "Light transport"), at equal samples: time and steps per ray, their ratio, and the image mean
// lost to the reflection limit (32 against 1024).
//
// --first-choice: only full transport's split first choice (MarchSettings::split_first_choice,
// the default) against pure Russian roulette (every choice drawn, FirstChoice::Drawn), GPU, at
// equal noise: each variant renders N samples per pixel (--spp, default 16); every sample's image
// is recovered from the running means RenderSettings::on_pass reports, so the per-pixel variance
// of ONE sample is the unbiased variance over the N independent samples (each its own seeds),
// averaged over pixels and channels. Efficiency is 1/(variance × seconds per sample); the ratio
// split / drawn is the factor by which the split reaches equal noise sooner (docs/performance.md).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "core/reference/reference_marcher.h"
#include "core/render/view_renderer.h"
#include "core/vk/context.h"

using namespace eikon;

// Render the scene with sharp and with smoothed interfaces (GPU, and the CPU twin unless
// --no-cpu): seconds and steps per ray of each, and their ratios.
int compareInterfaces(vk::Context& ctx, const Scene& scene, int width, int height, bool cpu) {
  RenderSettings rs;
  rs.width = width;
  rs.height = height;
  double t[2][2] = {{0, 0}, {0, 0}}, steps[2][2] = {{0, 0}, {0, 0}}, fetches[2] = {0, 0};
  const Scene::Interfaces kinds[2] = {Scene::Interfaces::Sharp, Scene::Interfaces::Smoothed};
  for (int k = 0; k < 2; ++k) {
    Scene s = scene;
    s.interfaces = kinds[k];
    const VolumeSet vol = voxelize(s);
    ViewRenderer gpu(ctx, s, vol);
    gpu.render(rs);  // warm-up
    const RenderImage g = gpu.render(rs);
    t[k][0] = g.seconds;
    steps[k][0] = g.mean_steps;
    std::printf("%-9s GPU: %8.3f s, %8.1f steps/ray\n", k ? "smoothed" : "sharp", g.seconds,
                g.mean_steps);
    if (!cpu) continue;
    VolumeField field(vol);
    ReferenceMarcher ref(field, s.environment);
    const RenderImage c = ref.render(s.camera, rs);
    t[k][1] = c.seconds;
    steps[k][1] = c.mean_steps;
    fetches[k] = c.mean_fetches;
    std::printf("%-9s CPU: %8.3f s, %8.1f steps/ray, %8.1f field fetches/ray\n",
                k ? "smoothed" : "sharp", c.seconds, c.mean_steps, c.mean_fetches);
  }
  std::printf("ratio smoothed / sharp, GPU: time %.2f, steps %.2f\n", t[1][0] / t[0][0],
              steps[1][0] / std::max(steps[0][0], 1e-9));
  if (cpu)
    std::printf("ratio smoothed / sharp, CPU: time %.2f, steps %.2f, field fetches %.2f\n",
                t[1][1] / t[0][1], steps[1][1] / std::max(steps[0][1], 1e-9),
                fetches[1] / std::max(fetches[0], 1e-9));
  return 0;
}

// Mean of the image's three channels over all pixels.
double imageMean(const RenderImage& img) {
  double sum = 0.0;
  for (float v : img.rgb) sum += v;
  return sum / double(std::max<size_t>(img.rgb.size(), 1));
}

// Full transport against the single transmitted path at equal samples (the scene's "render" spp,
// at least 4), GPU (and the CPU twin unless --no-cpu): seconds and steps per ray of each and their
// ratio; and what the reflection limit loses: the image mean at max_reflections 32 (default)
// against 1024 (GPU), as a relative difference.
int compareTransport(vk::Context& ctx, const Scene& scene, int width, int height, bool cpu) {
  const VolumeSet vol = voxelize(scene);
  ViewRenderer gpu(ctx, scene, vol);
  VolumeField field(vol);
  ReferenceMarcher ref(field, scene.environment);
  RenderSettings rs;
  rs.width = width;
  rs.height = height;
  rs.spp = std::max(4, scene.render.spp.value_or(4));
  rs.march.step_voxels = 0.5;  // the renders' default (`eikon render --step`)
  double t[2][2] = {{0, 0}, {0, 0}};
  const Transport kinds[2] = {Transport::Single, Transport::Full};
  gpu.render(rs);  // warm-up
  for (int k = 0; k < 2; ++k) {
    rs.march.transport = kinds[k];
    const RenderImage g = gpu.render(rs);
    t[k][0] = g.seconds;
    std::printf("%-6s GPU: %8.3f s, %8.1f steps/ray, mean %.5f, cut samples %lld\n",
                k ? "full" : "single", g.seconds, g.mean_steps, imageMean(g), g.cut_samples);
    if (!cpu) continue;
    const RenderImage c = ref.render(scene.camera, rs);
    t[k][1] = c.seconds;
    std::printf("%-6s CPU: %8.3f s, %8.1f steps/ray, mean %.5f\n", k ? "full" : "single", c.seconds,
                c.mean_steps, imageMean(c));
  }
  std::printf("ratio full / single at %d spp: GPU time %.2f", rs.spp, t[1][0] / t[0][0]);
  if (cpu) std::printf(", CPU time %.2f", t[1][1] / t[0][1]);
  std::printf("\n");
  rs.march.transport = Transport::Full;
  const double at32 = imageMean(gpu.render(rs));
  rs.march.max_reflections = 1024;
  const double at1024 = imageMean(gpu.render(rs));
  std::printf("reflection limit: image mean %.6f at 32, %.6f at 1024: %.2e relative\n", at32,
              at1024, (at1024 - at32) / std::max(std::abs(at1024), 1e-30));
  return 0;
}

// One variant of --first-choice: per-sample variance (mean over pixels and channels), seconds per
// sample and the image mean.
struct SampleNoise {
  double variance = 0.0, seconds = 0.0, mean = 0.0;
  long long cut = 0;
};

SampleNoise sampleNoise(ViewRenderer& gpu, RenderSettings rs) {
  const size_t n = size_t(rs.width) * size_t(rs.height) * 3;
  std::vector<double> before(n, 0.0), sum(n, 0.0), sum2(n, 0.0);
  auto take = [&](const RenderImage& img, int done) {  // sample `done`'s image, from the means
    for (size_t i = 0; i < n; ++i) {
      const double total = double(img.rgb[i]) * done, x = total - before[i];
      before[i] = total;
      sum[i] += x;
      sum2[i] += x * x;
    }
  };
  rs.on_pass = [&](const RenderImage& img, int done, int) { take(img, done); };
  const RenderImage img = gpu.render(rs);
  take(img, rs.spp);
  SampleNoise r;
  const double k = rs.spp;
  for (size_t i = 0; i < n; ++i) {
    r.variance += std::max(0.0, sum2[i] - sum[i] * sum[i] / k) / (k - 1.0) / double(n);
    r.mean += sum[i] / k / double(n);
  }
  r.seconds = img.seconds / k;
  r.cut = img.cut_samples;
  return r;
}

// The split first choice against every choice drawn, at equal noise (--first-choice).
int compareFirstChoice(vk::Context& ctx, const Scene& scene, int width, int height, int spp) {
  const VolumeSet vol = voxelize(scene);
  ViewRenderer gpu(ctx, scene, vol);
  RenderSettings rs;
  rs.width = width;
  rs.height = height;
  rs.spp = 1;
  rs.march.step_voxels = 0.5;  // the renders' default (`eikon render --step`)
  gpu.render(rs);              // warm-up
  rs.spp = spp;
  SampleNoise v[2];
  for (int k = 0; k < 2; ++k) {
    rs.march.split_first_choice = k == 0;
    v[k] = sampleNoise(gpu, rs);
    std::printf(
        "%-6s GPU, %d samples: per-sample variance %.4e, %.4f s per sample, efficiency "
        "1/(variance x time) %.4g, image mean %.5f, cut samples %lld\n",
        k ? "drawn" : "split", spp, v[k].variance, v[k].seconds,
        1.0 / (v[k].variance * v[k].seconds), v[k].mean, v[k].cut);
  }
  std::printf(
      "ratio split / drawn: variance %.3f, time %.3f, efficiency %.2f (the split reaches equal "
      "noise %.2fx sooner)\n",
      v[0].variance / v[1].variance, v[0].seconds / v[1].seconds,
      (v[1].variance * v[1].seconds) / (v[0].variance * v[0].seconds),
      (v[1].variance * v[1].seconds) / (v[0].variance * v[0].seconds));
  return 0;
}

int main(int argc, char** argv) {
  std::string scene_path = std::string(EIKON_SOURCE_DIR) + "/scenes/glass_sphere.json";
  int width = 800, height = 600;
  bool cpu = true;
  CLI::App app{
      "View renderer: rays/s, steps/ray and accuracy of the GPU integrators and the CPU reference",
      "view_bench"};
  app.add_option("scene", scene_path, "Scene JSON file (default scenes/glass_sphere.json)");
  app.add_option("--width", width, "Image width (default 800)")->check(CLI::Range(1, 16384));
  app.add_option("--height", height, "Image height (default 600)")->check(CLI::Range(1, 16384));
  app.add_flag("!--no-cpu", cpu, "Skip the CPU reference");
  bool interfaces = false;
  app.add_flag("--interfaces", interfaces, "Only compare sharp and smoothed interfaces");
  bool transport = false;
  app.add_flag("--transport", transport, "Only compare full transport with the single path");
  bool first_choice = false;
  app.add_flag("--first-choice", first_choice,
               "Only compare the split first choice with every choice drawn, at equal noise");
  int spp = 16;
  app.add_option("--spp", spp, "Samples per pixel of --first-choice (default 16)")
      ->check(CLI::Range(2, 4096));
  std::string march_kind, only;
  app.add_option("--march", march_kind, "Voxelise with sharp or smoothed interfaces")
      ->check(CLI::IsMember({"sharp", "smoothed"}));
  app.add_option("--only", only, "Only the variants whose name contains this text");
  bool accuracy = true;
  app.add_flag("!--no-accuracy", accuracy, "Skip the accuracy rays (CPU truth and GPU traces)");
  int repeat = 1;
  app.add_option("--repeat", repeat, "Timed renders per variant (median)")
      ->check(CLI::Range(1, 50));
  CLI11_PARSE(app, argc, argv);
  Scene scene = loadScene(scene_path);
  if (march_kind == "sharp") scene.interfaces = Scene::Interfaces::Sharp;
  if (march_kind == "smoothed") scene.interfaces = Scene::Interfaces::Smoothed;
  auto ctx = vk::Context::create();
  if (interfaces) return compareInterfaces(*ctx, scene, width, height, cpu);
  if (transport) return compareTransport(*ctx, scene, width, height, cpu);
  if (first_choice) return compareFirstChoice(*ctx, scene, width, height, spp);
  auto t0 = std::chrono::steady_clock::now();
  VolumeSet vol = voxelize(scene);
  double vox_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ViewRenderer gpu(*ctx, scene, vol);
  VolumeField field(vol);
  ReferenceMarcher ref(field, scene.environment);
  std::printf("scene %s, %dx%d, volume %dx%dx%d (voxelised in %.2f s), device %s\n",
              scene_path.c_str(), width, height, vol.grid.dims[0], vol.grid.dims[1],
              vol.grid.dims[2], vox_s, ctx->deviceName().c_str());

  // Accuracy rays: aimed at the sphere's disc from the camera.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<TraceRequest> rays;
  while (rays.size() < 2000) {
    double x = u(rng) * 9.0, y = u(rng) * 9.0;
    if (x * x + y * y > 80.0) continue;
    rays.push_back({scene.camera.position,
                    glm::normalize(glm::dvec3(x, y, 0) - scene.camera.position), 587.5618});
  }
  MarchSettings truth;
  truth.step_voxels = 0.05;
  truth.max_steps = 200000;
  std::vector<glm::dvec3> exact;
  if (accuracy)
    for (const auto& r : rays) exact.push_back(ref.trace(r, truth).exit_direction);

  struct Variant {
    const char* name;
    MarchSettings m;
  };
  auto mk = [](Integrator it, double step, bool skip, bool fresnel) {
    MarchSettings m;
    m.integrator = it;
    m.step_voxels = step;
    m.skip_empty = skip;
    m.fresnel = fresnel;
    return m;
  };
  std::vector<Variant> variants = {
      {"naive Euler, 1 voxel, no skip", mk(Integrator::Euler, 1.0, false, false)},
      {"Euler, 1 voxel, skip", mk(Integrator::Euler, 1.0, true, true)},
      {"midpoint, 0.5 voxel, skip", mk(Integrator::Midpoint, 0.5, true, true)},
      {"RK4, 1 voxel, skip", mk(Integrator::RK4, 1.0, true, true)},
      {"RK4, 0.5 voxel, skip", mk(Integrator::RK4, 0.5, true, true)},
      {"RK4, 0.25 voxel, skip (default)", mk(Integrator::RK4, 0.25, true, true)},
  };
  std::printf("\n%-34s %10s %10s %11s %10s %12s %12s\n", "GPU variant", "time [s]", "rays/s",
              "steps/ray", "steps/s", "mean err", "max err");
  double naive_s = 0, default_s = 0;
  for (const auto& v : variants) {
    if (!only.empty() && std::string(v.name).find(only) == std::string::npos) continue;
    RenderSettings rs;
    rs.width = width;
    rs.height = height;
    rs.march = v.m;
    gpu.render(rs);  // warm-up (pipeline compile, caches)
    std::vector<RenderImage> runs;
    for (int k = 0; k < repeat; ++k) runs.push_back(gpu.render(rs));
    std::sort(runs.begin(), runs.end(),
              [](const RenderImage& a, const RenderImage& b) { return a.seconds < b.seconds; });
    const RenderImage& img = runs[runs.size() / 2];
    auto tr = accuracy ? gpu.trace(rays, v.m) : std::vector<TraceOutcome>();
    double mean = 0, mx = 0;
    for (size_t i = 0; i < tr.size(); ++i) {
      double e = std::acos(std::clamp(glm::dot(tr[i].exit_direction, exact[i]), -1.0, 1.0));
      mean += e / double(rays.size());
      mx = std::max(mx, e);
    }
    std::printf("%-34s %10.3f %10.3g %11.1f %10.3g %11.2e° %11.2e°\n", v.name, img.seconds,
                width * height / img.seconds, img.mean_steps,
                img.mean_steps * width * height / img.seconds, mean * 180 / std::numbers::pi,
                mx * 180 / std::numbers::pi);
    if (v.name[0] == 'n') naive_s = img.seconds;
    if (std::string(v.name).find("(default)") != std::string::npos) default_s = img.seconds;
  }
  if (naive_s > 0 && default_s > 0)
    std::printf("\nratio default / naive Euler time: %.2f\n", default_s / naive_s);
  if (cpu) {
    RenderSettings rs;
    rs.width = width;
    rs.height = height;
    RenderImage c = ref.render(scene.camera, rs);
    std::printf("CPU reference (double, %u threads, default settings): %.3f s, %.3g rays/s\n",
                std::thread::hardware_concurrency(), c.seconds, width * height / c.seconds);
    if (default_s > 0)
      std::printf("ratio GPU / CPU reference speed (default settings): %.2f\n",
                  c.seconds / default_s);
  }
  return 0;
}
