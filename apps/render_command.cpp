// eikon render SCENE.json -o OUT.exr [options]: voxelise, march on the GPU (or --reference on the
// CPU), write the linear-sRGB EXR and a tone-mapped PNG preview beside it.
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "apps/commands.h"
#include "apps/progress.h"
#include "core/io/exr.h"
#include "core/reference/reference_marcher.h"
#include "core/render/view_renderer.h"
#include "core/vk/context.h"

namespace eikon::cli {

namespace {
struct RenderArgs {
  std::string scene, output;
  int width = 0, height = 0, spp = 1, wavelengths = -1, threads = 0;
  double step = 0.5, exposure = 0.0;
  std::string integrator = "rk4";
  bool reference = false, no_skip = false, no_fresnel = false, quiet = false, strict = false;
};

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
  sub->add_option("--width", args->width, "Image width (default: the scene camera's)");
  sub->add_option("--height", args->height, "Image height (default: the scene camera's)");
  sub->add_option("--spp", args->spp, "Jittered samples per pixel (default 1)");
  sub->add_option("--wavelengths", args->wavelengths,
                  "Spectral samples per pixel sample; 0 = RGB mode (default: 16 for dispersive scenes, else 0)");
  sub->add_option("--step", args->step, "Integration step in voxels (default 0.5; see docs/view-renderer.md)");
  sub->add_option("--integrator", args->integrator, "euler, midpoint or rk4 (default rk4)");
  sub->add_option("--exposure", args->exposure, "PNG preview exposure in stops (default 0)");
  sub->add_option("--threads", args->threads, "CPU threads for --reference and voxelising (default: all)");
  sub->add_flag("--reference", args->reference, "Render with the double-precision CPU reference instead of the GPU");
  sub->add_flag("--no-skip", args->no_skip, "Do not cross homogeneous regions in one step");
  sub->add_flag("--no-fresnel", args->no_fresnel, "Disable Fresnel reflection and transmission losses");
  sub->add_flag("--strict", args->strict, "Treat warnings (e.g. wavelengths outside a material's range) as errors");
  sub->add_flag("-q,--quiet", args->quiet, "No progress lines");
  sub->callback([args] {
    const RenderArgs& a = *args;
    std::filesystem::path out(a.output), png = std::filesystem::path(a.output).replace_extension(".png");
    if (out.extension() != ".exr") throw CliError("output must end in .exr: " + a.output);
    if (a.spp < 1 || a.spp > 4096) throw CliError("--spp must be in [1, 4096]");
    if (a.width < 0 || a.height < 0 || a.width > 16384 || a.height > 16384) throw CliError("--width/--height must be in [1, 16384]");
    if (a.wavelengths < -1 || a.wavelengths > 256) throw CliError("--wavelengths must be in [0, 256]");
    if (!(a.step > 0 && a.step <= 4)) throw CliError("--step must be in (0, 4] voxels");
    Scene scene = loadScene(a.scene);
    for (const std::string& w : scene.warnings) {
      if (a.strict) throw CliError(w + " (--strict)");
      std::fprintf(stderr, "eikon: warning: %s\n", w.c_str());
    }
    checkWritable(out);
    checkWritable(png);
    RenderSettings rs;
    rs.width = a.width;
    rs.height = a.height;
    rs.spp = a.spp;
    rs.wavelengths = a.wavelengths >= 0 ? a.wavelengths : (scene.anyDispersive() ? 16 : 0);
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

    Progress progress(a.quiet);
    std::unique_ptr<vk::Context> ctx;
    if (!a.reference) {
      ctx = vk::Context::create();
      checkVolumeFits(*ctx, makeGrid(scene.volume), scene);
    }
    VoxelizeOptions vo;
    vo.threads = a.threads;
    vo.progress = [&](double f, const char*) { progress.update("voxelising", f); };
    VolumeSet volume = voxelize(scene, vo);
    rs.progress = [&](double f) { progress.update("rendering", f); };
    RenderImage img;
    if (a.reference) {
      VolumeField field(volume);
      ReferenceMarcher ref(field, scene.environment);
      img = ref.render(scene.camera, rs, a.threads);
    } else {
      ViewRenderer renderer(*ctx, scene, volume);
      img = renderer.render(rs);
    }
    progress.finish();
    writeExrRgb(out, img.width, img.height, img.rgb);
    try {
      writePngPreview(png, img.width, img.height, img.rgb, a.exposure);
    } catch (...) {
      std::error_code ec;
      std::filesystem::remove(out, ec);
      throw;
    }
    double rays = double(img.width) * img.height * a.spp * std::max(1, rs.wavelengths);
    std::printf("eikon: rendered %s (%dx%d, %s, %d spp) on %s in %.2f s: %.3g rays/s, %.1f steps/ray -> %s, %s\n",
                a.scene.c_str(), img.width, img.height,
                rs.wavelengths > 0 ? (std::to_string(rs.wavelengths) + " wavelengths").c_str() : "RGB", a.spp,
                a.reference ? "CPU reference" : ctx->deviceName().c_str(), img.seconds, rays / img.seconds,
                img.mean_steps, out.c_str(), png.c_str());
  });
}

}  // namespace eikon::cli
