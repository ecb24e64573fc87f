// eikon render SCENE.json -o OUT.exr [options]: voxelise, march on the GPU (or --reference on the
// CPU), write the linear-sRGB EXR and a tone-mapped PNG preview beside it.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <utility>
#include <vector>

#include "apps/commands.h"
#include "apps/progress.h"
#include "core/io/exr.h"
#include "core/light/light_cache.h"
#include "core/reference/reference_lighting.h"
#include "core/reference/reference_marcher.h"
#include "core/render/light_transport.h"
#include "core/render/render_defaults.h"
#include "core/render/view_renderer.h"
#include "core/vk/context.h"

namespace eikon::cli {

namespace {
struct RenderArgs {
  std::string scene, output;
  int width = 0, height = 0, spp = 1, wavelengths = -1, threads = 0;
  double step = kDefaultRenderStepVoxels, exposure = 0.0;
  std::string integrator = "rk4", progress = "auto";
  bool reference = false, no_skip = false, no_fresnel = false, quiet = false, strict = false;
  // Light simulator (scenes with "lights").
  int light_bands = 0, max_patches = 1 << 20;
  double light_step = 0.0, light_split = 1.0;
  std::string light_splat = "accumulate", light_cache, caustics = "pass", light_device = "auto";
  bool no_light = false, no_light_cache = false;
};

/// Refuse an output that is one of the render's own inputs (the same file by device and inode:
/// also through a symbolic or hard link): `-o scenes/diamond_lights.exr` used to replace the
/// scene's environment map with the render and exit 0.
void refuseOverwritingInputs(
    const Scene& scene, const std::filesystem::path& scene_path,
    const std::vector<std::pair<std::filesystem::path, const char*>>& outputs) {
  std::vector<std::pair<std::filesystem::path, std::string>> inputs = {
      {scene_path, "the scene file"}};
  if (!scene.environment.image_path.empty())
    inputs.push_back({scene.environment.image_path, "the scene's environment map"});
  for (const auto& [out, what] : outputs)
    for (const auto& [in, role] : inputs) {
      std::error_code ec;
      if (std::filesystem::equivalent(out, in, ec))
        throw CliError(std::string(what) + " '" + out.string() + "' is " + role + " '" +
                       in.string() + "'; refusing to overwrite an input (choose another -o)");
    }
}

Integrator parseIntegrator(const std::string& s) {
  if (s == "euler") return Integrator::Euler;
  if (s == "midpoint") return Integrator::Midpoint;
  if (s == "rk4") return Integrator::RK4;
  throw CliError("--integrator must be euler, midpoint or rk4");
}
}  // namespace

void addRenderCommand(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  auto* sub = app.add_subcommand("render", "Render a scene to an EXR (linear sRGB) and a PNG preview");
  sub->add_option("scene", args->scene, "Scene JSON file")->required();
  sub->add_option("-o,--output", args->output, "Output EXR path (the PNG preview is written beside it)")->required();
  sub->add_option("--width", args->width,
                  "Image width in [1, 16384] (default: the scene camera's)");
  sub->add_option("--height", args->height,
                  "Image height in [1, 16384] (default: the scene camera's)");
  sub->add_option("--spp", args->spp, "Jittered samples per pixel in [1, 4096] (default 1)");
  sub->add_option("--wavelengths", args->wavelengths,
                  "Spectral samples per pixel sample in [1, 256], or 0 for RGB mode (default: 16 "
                  "for dispersive scenes, else 0)");
  sub->add_option("--step", args->step, "Integration step in voxels (default 0.5; see docs/view-renderer.md)");
  sub->add_option("--integrator", args->integrator, "euler, midpoint or rk4 (default rk4)");
  sub->add_option("--exposure", args->exposure, "PNG preview exposure in stops (default 0)");
  sub->add_option("--threads", args->threads, "CPU threads for --reference, voxelising and the CPU light simulator (default: all; the simulator at most 8)");
  sub->add_flag("--reference", args->reference, "Render with the double-precision CPU reference instead of the GPU");
  sub->add_flag("--no-skip", args->no_skip, "Do not cross homogeneous regions in one step");
  sub->add_flag("--no-fresnel", args->no_fresnel, "Disable Fresnel reflection and transmission losses");
  sub->add_flag("--strict", args->strict, "Treat warnings (e.g. wavelengths outside a material's range) as errors");
  sub->add_flag("-q,--quiet", args->quiet, "No progress lines (same as --progress never)");
  sub->add_option(
      "--progress", args->progress,
      "auto (default: progress with ETA on stderr when it is a terminal), always or never");
  sub->add_option("--light-bands", args->light_bands,
                  "Light simulator wavelength bands (default: 12 dispersive, 3 attenuating, else 1)");
  sub->add_option("--light-splat", args->light_splat,
                  "accumulate (fluence rate, default) or highest (the highest patch irradiance per voxel)");
  sub->add_option("--light-device", args->light_device,
                  "auto (default: the CPU reference when the Vulkan device is a CPU, e.g. lavapipe, where it is "
                  "several times faster; else the GPU), gpu or cpu");
  sub->add_option("--caustics", args->caustics,
                  "pass (light continues through a focus, default) or kill (Tevs: patches end at a fold caustic)");
  sub->add_option("--light-step", args->light_step, "Light simulator time step in voxels (default 0.5)");
  sub->add_option("--light-split", args->light_split, "Split wavefront patches longer than this many voxels (default 1)");
  sub->add_option("--max-patches", args->max_patches, "Most live wavefront patches (default 1048576)");
  sub->add_option("--light-cache", args->light_cache,
                  "Directory of cached light volumes (default $EIKON_CACHE_DIR, $XDG_CACHE_HOME/eikon or ~/.cache/eikon)");
  sub->add_flag("--no-light-cache", args->no_light_cache, "Simulate the light even if a cached result exists, and store none");
  sub->add_flag("--no-light", args->no_light, "Do not simulate the scene's lights (no caustics, in-scatter or lit surfaces)");
  sub->callback([args, sub] {
    const RenderArgs& a = *args;
    std::filesystem::path out(a.output), png = std::filesystem::path(a.output).replace_extension(".png");
    if (out.extension() != ".exr") throw CliError("output must end in .exr: " + a.output);
    (void)progressMode(a.progress, a.quiet);  // a bad --progress fails before any work
    // A size not given is the scene camera's; a given one must be a real size (0 used to mean
    // "the scene's" silently, and a negative --wavelengths the default).
    auto checkRange = [&](const char* name, int v, int lo, int hi) {
      if (sub->count(name) && (v < lo || v > hi))
        throw CliError(std::string(name) + " must be in [" + std::to_string(lo) + ", " +
                       std::to_string(hi) + "], got " + std::to_string(v));
    };
    checkRange("--width", a.width, 1, 16384);
    checkRange("--height", a.height, 1, 16384);
    checkRange("--spp", a.spp, 1, 4096);
    checkRange("--wavelengths", a.wavelengths, 0, 256);
    if (!(a.step > 0 && a.step <= 4)) throw CliError("--step must be in (0, 4] voxels");
    if (a.light_bands < 0 || a.light_bands > 64) throw CliError("--light-bands must be in [1, 64]");
    if (a.light_splat != "accumulate" && a.light_splat != "highest")
      throw CliError("--light-splat must be accumulate or highest, got '" + a.light_splat + "'");
    if (a.light_device != "auto" && a.light_device != "gpu" && a.light_device != "cpu")
      throw CliError("--light-device must be auto, gpu or cpu, got '" + a.light_device + "'");
    if (a.caustics != "pass" && a.caustics != "kill")
      throw CliError("--caustics must be pass or kill, got '" + a.caustics + "'");
    if (!(a.light_step >= 0 && a.light_step <= 2))
      throw CliError("--light-step must be in (0, 2] voxels");
    if (!(a.light_split >= 0.25 && a.light_split <= 8))
      throw CliError("--light-split must be in [0.25, 8] voxels");
    if (a.max_patches < 1024 || a.max_patches > (1 << 24))
      throw CliError("--max-patches must be in [1024, 16777216]");
    Scene scene = loadScene(a.scene);
    for (const std::string& w : scene.warnings) {
      if (a.strict) throw CliError(w + " (--strict)");
      std::fprintf(stderr, "eikon: warning: %s\n", w.c_str());
    }
    refuseOverwritingInputs(scene, a.scene, {{out, "the output"}, {png, "the PNG preview"}});
    checkWritable(out);
    checkWritable(png);
    // The defaults are shared with Python (core/render/render_defaults.h).
    RenderSettings rs = defaultRenderSettings(scene);
    rs.width = a.width;
    rs.height = a.height;
    rs.spp = a.spp;
    if (a.wavelengths >= 0) rs.wavelengths = a.wavelengths;
    rs.march.step_voxels = a.step;
    rs.march.integrator = parseIntegrator(a.integrator);
    rs.march.skip_empty = !a.no_skip;
    rs.march.fresnel = !a.no_fresnel;
    for (const auto& [name, m] : scene.materials)
      for (const Dispersion* d : {&m.n_o, &m.n_e}) {
        bool outside = rs.wavelengths > 0 ? !(d->inRange(380.0) && d->inRange(780.0)) : !d->inRange(rs.wavelength_nm);
        if (outside && d->rangeNm()) {
          std::string msg = "material '" + name + "' is measured over " + std::to_string(int((*d->rangeNm())[0])) + "-" +
                            std::to_string(int((*d->rangeNm())[1])) + " nm; rendering outside that range extrapolates";
          if (a.strict) throw CliError(msg + " (--strict)");
          std::fprintf(stderr, "eikon: warning: %s\n", msg.c_str());
          break;
        }
      }

    Progress progress(progressMode(a.progress, a.quiet));
    std::unique_ptr<vk::Context> ctx;
    if (!a.reference) {
      ctx = vk::Context::create();
      checkVolumeFits(*ctx, makeGrid(scene.volume), scene);
    }
    VoxelizeOptions vo;
    vo.threads = a.threads;
    vo.progress = [&](double f, const char*) { progress.update("voxelising", f); };
    VolumeSet volume = voxelize(scene, vo);
    LightingSummary light;
    bool light_cached = false, light_on_cpu = false;
    if (!scene.lights.empty() && !a.no_light) {
      LightingOptions lo = defaultLightingOptions();
      lo.bands = a.light_bands;
      lo.wave.splat = a.light_splat == "highest" ? WavefrontSettings::Splat::HighestEnergy : WavefrontSettings::Splat::Accumulate;
      lo.wave.dt = a.light_step * volume.grid.h;
      lo.wave.split_span_voxels = a.light_split;
      lo.wave.max_patches = a.max_patches;
      lo.wave.pass_caustics = a.caustics == "pass";
      lo.wave.threads = a.threads;
      lo.progress = [&](double f, const std::string& what) { progress.update(what.c_str(), f); };
      std::filesystem::path cache_dir = a.light_cache.empty() ? defaultLightCacheDir() : std::filesystem::path(a.light_cache);
      // Which twin simulates: --reference renders use the CPU throughout; on a CPU Vulkan device
      // (lavapipe) the double-precision CPU twin is also the faster one (docs/light-simulator.md).
      light_on_cpu = a.reference || lightOnCpu(a.light_device, ctx.get());
      // The key hashes every field of the volume (~0.3 s at 128³): only when the cache is used.
      const uint64_t key = a.no_light_cache ? 0 : lightCacheKey(scene, volume, lo, light_on_cpu);
      std::string cache_notice;
      const bool hit = !a.no_light_cache && loadLightCache(cache_dir, key, volume, &cache_notice);
      if (!cache_notice.empty())
        std::fprintf(stderr, "eikon: warning: light cache: %s\n", printable(cache_notice).c_str());
      if (hit) {
        light_cached = true;
      } else {
        light = light_on_cpu ? simulateLightingReference(scene, volume, lo) : simulateLighting(*ctx, scene, volume, lo);
        if (!a.no_light_cache) {
          std::string err = saveLightCache(cache_dir, key, volume);
          if (!err.empty()) std::fprintf(stderr, "eikon: warning: light cache: %s\n", err.c_str());
        }
      }
    }
    rs.progress = [&](double f) { progress.update("rendering", f); };
    RenderImage img;
    if (a.reference) {
      VolumeField field(volume);
      ReferenceMarcher ref(field, scene.environment);
      img = ref.render(scene.camera, rs, a.threads);
    } else {
      progress.working("preparing the GPU (pipelines, volume upload)");
      ViewRenderer renderer(*ctx, scene, volume);
      img = renderer.render(rs);
    }
    progress.finish();
    // The pair as a pair (core/io/atomic_write.h): both files or neither replace what is there,
    // and a concurrent render to the same -o cannot interleave its pair with this one. The
    // preview first: it is the smaller, so a full disk is usually met before the EXR is encoded.
    writeFilesTogether({{png, pngPreviewContent(img.width, img.height, img.rgb, a.exposure)},
                        {out, exrRgbContent(img.width, img.height, img.rgb)}});
    for (const std::string& n : light.notes) std::fprintf(stderr, "eikon: note: %s\n", n.c_str());
    if (light_cached)
      std::printf("eikon: light volumes from the cache (%s)\n", (a.light_cache.empty() ? defaultLightCacheDir() : std::filesystem::path(a.light_cache)).c_str());
    else if (light.runs > 0)
      std::printf("eikon: simulated %zu light runs on %s in %.2f s: %zu patches (%.3g patches/s), flux balance %.1e\n",
                  light.runs, light_on_cpu ? "the CPU reference" : ctx->deviceName().c_str(), light.seconds, light.patches,
                  double(light.patches) / std::max(light.seconds, 1e-9), light.conservationError());
    double rays = double(img.width) * img.height * a.spp * std::max(1, rs.wavelengths);
    std::printf("eikon: rendered %s (%dx%d, %s, %d spp) on %s in %.2f s: %.3g rays/s, %.1f steps/ray -> %s, %s\n",
                a.scene.c_str(), img.width, img.height,
                rs.wavelengths > 0 ? (std::to_string(rs.wavelengths) + " wavelengths").c_str() : "RGB", a.spp,
                a.reference ? "CPU reference" : ctx->deviceName().c_str(), img.seconds, rays / img.seconds,
                img.mean_steps, out.c_str(), png.c_str());
  });
}

}  // namespace eikon::cli
