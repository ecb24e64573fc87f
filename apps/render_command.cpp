// eikon render SCENE.json -o OUT.exr [options]: voxelise, march on the GPU twin or the CPU twin
// (--device: auto picks the faster, renderTwin in core/render/render_defaults.h), write the
// linear-sRGB EXR and a tone-mapped PNG preview beside it.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "apps/commands.h"
#include "apps/progress.h"
#include "core/io/cache_dir.h"
#include "core/io/exr.h"
#include "core/scene/scene_warnings.h"
#include "core/session/front_end.h"
#include "core/session/render_cost.h"
#include "core/session/session.h"

namespace eikon::cli {

namespace {
struct RenderArgs {
  std::string scene, output;
  double exposure = 0.0;
  std::string progress = "auto", light_cache;
  bool reference = false, quiet = false, strict = false;
  bool no_light = false, no_light_cache = false, no_volume_cache = false;
  bool timings = false;
  /// The render, march, light and twin settings: options made from the settings table
  /// (core/session/settings.h), as Python's keywords are.
  SettingValues settings;
};

/// The progressive preview's file for the output `out` (x.exr → x.partial.png): see Preview.
std::filesystem::path partialPreviewPath(const std::filesystem::path& out) {
  return std::filesystem::path(out).replace_extension(".partial.png");
}

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

void addRenderOptions(CLI::App* sub, RenderArgs& a) {
  sub->add_option("scene", a.scene, "Scene JSON file")->required();
  sub->add_option("-o,--output", a.output, "Output EXR path (the PNG preview is written beside it)")
      ->required();
  addSettingOptions(sub, SettingFront::RenderCli, a.settings);
  sub->add_option(
      "--exposure", a.exposure,
      "PNG preview exposure in stops (default: the scene's \"render\" exposure, else 0)");
  sub->add_flag("--reference", a.reference, "Same as --device cpu");
  sub->add_flag("--strict", a.strict,
                "Treat warnings (e.g. wavelengths outside a material's range) as errors");
  sub->add_flag("-q,--quiet", a.quiet, "No progress lines (same as --progress never)");
  sub->add_option(
      "--progress", a.progress,
      "auto (default: progress with ETA on stderr when it is a terminal), always or never");
  sub->add_option("--light-cache", a.light_cache,
                  "Directory of cached light volumes (default $EIKON_CACHE_DIR, "
                  "$XDG_CACHE_HOME/eikon or ~/.cache/eikon)");
  sub->add_flag("--no-light-cache", a.no_light_cache,
                "Simulate the light even if a cached result exists, and store none");
  sub->add_flag("--no-volume-cache", a.no_volume_cache,
                "Voxelise the scene even if a cached volume exists, and store none (GPU renders "
                "that read the volume's fields keep them in $EIKON_CACHE_DIR, "
                "$XDG_CACHE_HOME/eikon or ~/.cache/eikon; sharp interfaces without light "
                "voxelise only the interfaces, in milliseconds, and keep nothing)");
  sub->add_flag("--no-light", a.no_light,
                "Do not simulate the scene's lights (no caustics, in-scatter or lit surfaces)");
  sub->add_flag("--timings", a.timings,
                "Print on stderr the seconds since the process started at the end of each "
                "start-up stage (also EIKON_TIMINGS=1)");
}

/// The settings as given: an option not given keeps the session's default (the scene camera's
/// size, its default wavelength count), so only given ones and those with a default are checked,
/// by the table's ranges (core/session/settings.h) as Python's.
SettingRequests settingRequests(const RenderArgs& a) {
  SettingRequests r;
  fillSettings(a.settings, SettingFront::RenderCli, r);
  r.view.march = r.march;  // the CLI always gives the march (the table's defaults)
  return r;
}

std::filesystem::path lightCacheDir(const RenderArgs& a) {
  return a.light_cache.empty() ? defaultLightCacheFolder() : std::filesystem::path(a.light_cache);
}

/// The EXR channel names of img.aov (empty without the AOV layer).
std::vector<std::string> aovNames(const RenderImage& img) {
  if (img.aov.empty()) return {};
  return std::vector<std::string>(std::begin(kAovChannelNames), std::end(kAovChannelNames));
}

/// A warning, or with --strict the error it becomes.
void warn(const std::string& w, bool strict) {
  if (strict) throw CliError(w + " (--strict)");
  std::fprintf(stderr, "eikon: warning: %s\n", w.c_str());
}

/// The light summary and the render summary on stdout, the simulator's notes on stderr.
void printSummary(const RenderArgs& a, Session& session, const RenderTwin& twin,
                  const LightOutcome& light, const RenderSettings& rs, const RenderImage& img,
                  const std::filesystem::path& out, const std::filesystem::path& png) {
  for (const std::string& n : light.summary.notes)
    std::fprintf(stderr, "eikon: note: %s\n", n.c_str());
  if (light.cached)
    std::printf("eikon: light volumes from the cache (%s)\n", lightCacheDir(a).c_str());
  else if (light.summary.runs > 0)
    std::printf(
        "eikon: simulated %zu light runs on %s in %.2f s: %zu patches (%.3g patches/s), flux "
        "balance %.1e, reflected %.3g of emitted\n",
        light.summary.runs, light.on_cpu ? "the CPU reference" : session.deviceName(true).c_str(),
        light.summary.seconds, light.summary.patches,
        double(light.summary.patches) / std::max(light.summary.seconds, 1e-9),
        light.summary.conservationError(),
        light.summary.flux_emitted > 0 ? light.summary.flux_reflected / light.summary.flux_emitted
                                       : 0.0);
  double rays = double(img.width) * img.height * rs.spp * std::max(1, rs.wavelengths);
  std::printf(
      "eikon: rendered %s (%dx%d, %s%s, %d spp) on %s (%s twin: %s) in %.2f s: %.3g rays/s, %.1f "
      "steps/ray -> %s, %s\n",
      a.scene.c_str(), img.width, img.height,
      rs.wavelengths > 0 ? (std::to_string(rs.wavelengths) + " wavelengths").c_str() : "RGB",
      isPolarisedRender(*session.scene(), rs) ? ", polarised" : "", rs.spp,
      twin.cpu ? "CPU reference" : session.deviceName(true).c_str(), twin.cpu ? "CPU" : "GPU",
      twin.why.c_str(), img.seconds, rays / img.seconds, img.mean_steps, out.c_str(), png.c_str());
}

/// Progressive output: a preview of the image so far rewritten (atomically) as pixel samples
/// finish, at most once a second, so a long render shows the picture forming. It goes to its own
/// file, "NAME.partial.png" beside the pair (partialPreviewPath), never over NAME.png: the pair
/// NAME.exr and NAME.png is only ever replaced whole, so a render killed mid-way leaves the
/// previous pair as it was. The partial preview is removed when the render ends, after the final
/// pair is written or when it fails (~Preview), and so is one a killed render left there.
struct Preview {
  std::filesystem::path partial;
  double exposure = 0.0;
  std::chrono::steady_clock::time_point last = std::chrono::steady_clock::now();
  ~Preview() {
    std::error_code ec;
    std::filesystem::remove(partial, ec);
  }
  RenderSettings attach(RenderSettings rs) {
    rs.on_pass = [this](const RenderImage& so_far, int, int) {
      const auto now = std::chrono::steady_clock::now();
      if (now - last < std::chrono::seconds(1)) return;
      writeFilesTogether(
          {{partial, pngPreviewContent(so_far.width, so_far.height, so_far.rgb, exposure)}});
      last = now;
    };
    return rs;
  }
};

/// Renders said to be long before they start: by their time (the trial's estimate) or their
/// host memory.
constexpr double kLongRenderSeconds = 10.0, kLongRenderBytes = 1e9;

void runRender(const RenderArgs& a, const CLI::App& sub) {
  if (a.timings) timings::enable(true);
  timings::mark("command line");
  std::filesystem::path out(a.output),
      png = std::filesystem::path(a.output).replace_extension(".png"),
      partial = partialPreviewPath(out);
  if (out.extension() != ".exr") throw CliError("output must end in .exr: " + a.output);
  (void)progressMode(a.progress, a.quiet);  // a bad --progress fails before any work
  checkExposure(a.exposure);
  // The range checks are the session's, as Python's (core/session/session.h).
  const SettingRequests requests = settingRequests(a);
  const ViewRequest& view = requests.view;
  checkViewRequest(view);
  const LightRequest& light_request = requests.light;
  checkLightRequest(light_request);
  checkRenderDevice(requests.device);
  if (a.reference && requests.device != "cpu" && sub.count("--device"))
    throw CliError("--reference is --device cpu; it does not go with --device " + requests.device);
  const std::string device = a.reference ? "cpu" : requests.device;
  auto scene = std::make_shared<Scene>(loadScene(a.scene));
  for (const std::string& w : scene->warnings) warn(w, a.strict);
  refuseOverwritingInputs(
      *scene, a.scene,
      {{out, "the output"}, {png, "the PNG preview"}, {partial, "the partial PNG preview"}});
  checkWritable(out);
  checkWritable(png);
  checkWritable(partial);
  const RenderSettings rs = renderSettings(*scene, view);  // the scene's "render" under options
  const double exposure =
      sub.count("--exposure") ? a.exposure : scene->render.exposure.value_or(0.0);
  // (auto renders every polarised render on the GPU twin: cpuTwinFasterBecause)
  if (device != "cpu" && isPolarisedRender(*scene, rs)) checkPolariserSheetsOnGpu(*scene);
  checkRenderFitsHost(*scene, rs);  // before voxelising: the image's memory, with the numbers
  for (const std::string& w : materialRangeWarnings(*scene, rs)) warn(w, a.strict);
  timings::mark("scene parsed");

  Progress progress(progressMode(a.progress, a.quiet));
  RenderCost cost = renderWork(*scene, rs);
  if (cost.host_bytes >= kLongRenderBytes) progress.note("cost: " + describeRenderCost(cost), true);
  Session session(scene);
  session.setThreads(requests.threads);
  const RenderTwin twin =
      renderTwin(device, *scene, rs, [&] { return deviceInfo(session.context()).type; });
  const bool cpu = twin.cpu;
  // The GPU render's start-up (docs/performance.md "Start-up"); the CPU twin takes far longer to
  // render than to voxelise, and voxelises every time.
  if (!cpu && !a.no_volume_cache)
    session.setVolumeCache(defaultCacheDir(), [](const std::string& note) {
      std::fprintf(stderr, "eikon: note: %s\n", note.c_str());
    });
  session.setProgress({[&](const char* what, double f) { progress.update(what, f); },
                       [&](const char* what) { progress.working(what); }});
  // The light volumes show only where a material has an albedo (in-scatter, diffuse surfaces):
  // without one a simulation (an hour for a lit faceted gem) would change no pixel.
  // Nor where every light's beam or cone misses every object (a scene warning says so).
  const bool lit = !scene->lights.empty() && !a.no_light && scene->anyScattering() &&
                   anyLightReachesAnObject(*scene);
  if (!scene->lights.empty() && !a.no_light && !scene->anyScattering())
    std::fputs(kLightsNotSimulatedNote, stderr);
  if (!cpu) {
    session.context();  // what prepare() does first, marked apart from the voxelising
    timings::mark("device created");
    // The view pipeline compiles beside the voxelising and the upload (docs/performance.md). A
    // polarised render runs another kernel, which that compile would only compete with for a core.
    if (!isPolarisedRender(*scene, rs)) session.startRenderPipeline(rs, lit);
  }
  // Without light volumes a GPU render of sharp interfaces reads no per-voxel field: only the
  // interfaces are voxelised then (docs/performance.md "Start-up").
  // A light the chosen twin cannot hold is refused before the voxelising.
  if (lit) (void)session.lightOnCpuTwin(light_request, cpu);
  if (cpu || lit)
    session.prepare(!cpu);
  else
    session.prepareGpuRender();
  timings::mark("voxelised");
  LightOutcome light;
  if (lit) {
    light = session.simulateLight(light_request, cpu,
                                  a.no_light_cache ? std::filesystem::path() : lightCacheDir(a));
    timings::mark(light.cached ? "light (from the cache)" : "light simulated");
  }
  for (const std::string& w : light.warnings)
    std::fprintf(stderr, "eikon: warning: %s\n", w.c_str());
  // Long renders say their time first, from a trial (core/session/render_cost.h).
  if (!a.quiet && a.progress != "never" && worthATrial(cost)) {
    timeRenderTrial(session, rs, !cpu, cost);
    if (cost.seconds + cost.write_seconds >= kLongRenderSeconds)
      progress.note("cost: " + describeRenderCost(cost), true);
    progress.update("rendering", 0.0);  // the trial's stage ("preparing the GPU") has ended
  }
  Preview preview{partial, exposure};
  RenderImage img = session.render(preview.attach(rs), !cpu);
  progress.finish();
  timings::mark("rendered");
  if (img.cut_samples > 0)
    warn(std::to_string(img.cut_samples) +
             (!img.stokes.empty()
                  ? " pixel samples were cut short by the polarised trace's limits (max_branches, "
                    "max_events; on the GPU twin also the driver's loop limit) and lack the "
                    "light they would have reached"
                  : " pixel samples were cut short and lack the light they would have reached: "
                    "a march ran out of its " +
                        std::to_string(rs.march.max_steps) +
                        " steps (a larger --step takes fewer) or, on the GPU, of the Vulkan "
                        "driver's loop limit (docs/view-renderer.md; --reference has none)"),
         a.strict);
  // The pair as a pair (core/io/atomic_write.h): both files or neither replace what is there,
  // and a concurrent render to the same -o cannot interleave its pair with this one. The
  // preview first: it is the smaller, so a full disk is usually met before the EXR is encoded.
  writeFilesTogether({{png, pngPreviewContent(img.width, img.height, img.rgb, exposure)},
                      {out, !img.stokes.empty() ? exrStokesContent(img.width, img.height, img.rgb,
                                                                   img.stokes, kStokesFrame)
                            : rs.spectral_layer || rs.mode_layers || rs.aov_layer
                                ? exrLayersContent(img.width, img.height, img.rgb, img.bins,
                                                   img.spectral, img.modes, aovNames(img), img.aov,
                                                   session.scene()->fastSlowModes())
                                : exrRgbContent(img.width, img.height, img.rgb)}});
  timings::mark("written");
  printSummary(a, session, twin, light, rs, img, out, png);
}
}  // namespace

void addRenderCommand(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  auto* sub =
      app.add_subcommand("render", "Render a scene to an EXR (linear sRGB) and a PNG preview");
  addRenderOptions(sub, *args);
  sub->callback([args, sub] {
    markGivenSettings(*sub, args->settings);
    runRender(*args, *sub);
  });
}

}  // namespace eikon::cli
