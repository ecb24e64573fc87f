// eikon gem SCENE.json [--tilts -20:20:5] [--json] [-o DIR]: the gem studio (docs/gem-studio.md).
// The stone (the first transparent object, or --object N) is viewed face-up from 250 mm, tilted
// through a series and rendered under the standard lighting presets; brightness, fire,
// scintillation, windowing and extinction are printed per tilt and overall, and -o writes the
// report's pictures and its JSON into DIR as one set (core/io/atomic_write.h).
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "apps/progress.h"
#include "core/io/exr.h"
#include "core/scene/messages.h"
#include "core/session/gem.h"
#include "core/session/session.h"

namespace eikon::cli {
namespace {

struct GemArgs {
  std::string scene, output, tilts = "-20:20:5", progress = "auto", seed = "0";
  int width = 128, height = 128, spp = 4, wavelengths = 8, object = -1, threads = 0;
  bool json = false, quiet = false;
};

/// The tilts' face-up images side by side, five to a row (black where a row is short).
std::vector<float> contactSheet(const std::vector<std::vector<float>>& tiles, int w, int h,
                                int& sheet_w, int& sheet_h) {
  const int n = int(tiles.size()), cols = std::min(n, 5), rows = (n + cols - 1) / cols;
  sheet_w = cols * w;
  sheet_h = rows * h;
  std::vector<float> sheet(size_t(3) * size_t(sheet_w) * size_t(sheet_h), 0.0f);
  for (int k = 0; k < n; ++k)
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c)
          sheet[3 * (size_t((k / cols) * h + y) * size_t(sheet_w) + size_t((k % cols) * w + x)) +
                size_t(c)] = tiles[size_t(k)][3 * (size_t(y) * size_t(w) + size_t(x)) + size_t(c)];
  return sheet;
}

/// The report's files, written as one set: all of them or none.
void writeReport(const std::filesystem::path& dir, const GemReport& r, const nlohmann::json& j) {
  const GemImages& im = r.images;
  int sw = 0, sh = 0;
  const std::vector<float> sheet = contactSheet(im.dome, im.width, im.height, sw, sh);
  int fw = 0, fh = 0;
  const std::vector<float> fire = contactSheet(im.spot, im.width, im.height, fw, fh);
  writeFilesTogether(
      {{dir / "report.json", bytesWriter(j.dump(2) + "\n")},
       {dir / "dome_tilts.png", pngPreviewContent(sw, sh, sheet, 0.0)},
       {dir / "dome_tilts.exr", exrRgbContent(sw, sh, sheet)},
       {dir / "fire_tilts.png", pngPreviewContent(fw, fh, fire, 0.0)},
       {dir / "fire_tilts.exr", exrRgbContent(fw, fh, fire)},
       {dir / "aset.png", pngPreviewContent(im.width, im.height, im.aset, 0.0)},
       {dir / "idealscope.png", pngPreviewContent(im.width, im.height, im.idealscope, 0.0)},
       {dir / "lightbox.png", pngPreviewContent(im.width, im.height, im.lightbox, -1.0)}});
}

/// --seed: an integer in [0, 2³² − 1] as typed (digits only), else one line quoting it.
std::uint32_t parseSeed(const std::string& text) {
  const bool digits = !text.empty() && text.size() <= 10 &&
                      text.find_first_not_of("0123456789") == std::string::npos;
  if (!digits || std::stoull(text) > 4294967295ULL)
    throw CliError("--seed must be in [0, 4294967295], got " + excerpt(text));
  return std::uint32_t(std::stoull(text));
}

void runGem(const GemArgs& a) {
  GemRequest req;
  req.tilts_deg = parseGemTilts(a.tilts);
  req.width = a.width;
  req.height = a.height;
  req.spp = a.spp;
  req.wavelengths = a.wavelengths;
  req.threads = a.threads;
  req.seed = parseSeed(a.seed);
  if (a.object >= 0) req.object = a.object;
  req.keep_images = !a.output.empty();
  checkGemRequest(req);  // every bad option before the scene is read
  const ProgressMode mode = progressMode(a.progress, a.quiet);
  const std::filesystem::path dir(a.output);
  if (!a.output.empty()) {
    if (std::filesystem::exists(dir) && !std::filesystem::is_directory(dir))
      throw CliError("-o '" + a.output + "' is a file; it must name a folder");
    checkWritable(dir / "report.json");
  }
  auto scene = std::make_shared<Scene>(loadScene(a.scene));
  for (const std::string& w : scene->warnings)
    std::fprintf(stderr, "eikon: warning: %s\n", w.c_str());
  try {
    (void)gemStone(*scene, req.object);
  } catch (const std::invalid_argument& e) {
    throw CliError(a.scene + ": " + e.what());
  }
  Progress progress(mode);
  progress.update("tilts", 0.0);
  const GemReport r = analyseGem(scene, req, [&](double f) { progress.update("tilts", f); });
  progress.finish();
  const nlohmann::json j = gemReportJson(r, a.scene);
  if (!a.output.empty()) writeReport(dir, r, j);
  if (a.json) {
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("eikon gem: %s, object %zu, %zu tilts, %dx%d, %d spp, %.2f s\n", a.scene.c_str(),
              r.object, r.per_tilt.size(), a.width, a.height, a.spp, r.seconds);
  std::printf("  tilt   brightness  fire     windowing  extinction  flashes\n");
  for (const GemTilt& t : r.per_tilt)
    std::printf("  %5.1f  %9.3f  %7.4f  %9.3f  %10.3f  %7d\n", t.tilt_deg, t.brightness, t.fire,
                t.windowing, t.extinction, t.flashes);
  std::printf("  brightness %.3f, fire %.4f, scintillation %.3f, windowing %.3f, extinction %.3f\n",
              r.brightness, r.fire, r.scintillation, r.windowing, r.extinction);
  if (!a.output.empty()) std::printf("  report in %s\n", a.output.c_str());
}

}  // namespace

void addGemCommand(CLI::App& app) {
  auto a = std::make_shared<GemArgs>();
  auto* sub = app.add_subcommand(
      "gem",
      "Measure a gem's brightness, fire, scintillation, windowing and extinction under "
      "standard lighting over a tilt series (docs/gem-studio.md)");
  sub->add_option("scene", a->scene, "Scene JSON file")->required();
  sub->add_option("--tilts", a->tilts,
                  "Tilts in degrees: FROM:TO:STEP or a comma-separated list (default -20:20:5)");
  sub->add_option("--object", a->object,
                  "Index of the stone in the scene's objects (default: the first transparent one)");
  sub->add_option("--width", a->width, "Image width of each render (default 128)");
  sub->add_option("--height", a->height, "Image height of each render (default 128)");
  sub->add_option("--spp", a->spp, "Samples per pixel (default 4)");
  sub->add_option("--wavelengths", a->wavelengths,
                  "Spectral samples of the fire render (default 8)");
  sub->add_option("--threads", a->threads, "CPU threads (default 0: all)");
  sub->add_option("--seed", a->seed,
                  "0 (default): the pixel grid centred on the stone; N > 0: shifted by a "
                  "sub-pixel offset drawn from N (another draw of the same estimate)");
  sub->add_flag("-q,--quiet", a->quiet, "No progress lines (same as --progress never)");
  sub->add_option(
      "--progress", a->progress,
      "auto (default: progress over the tilts with ETA on stderr when it is a terminal), always "
      "or never");
  sub->add_flag("--json", a->json, "Print the metrics as JSON");
  sub->add_option("-o,--output", a->output,
                  "Folder for the report: report.json, dome_tilts.png/.exr (contact sheet), "
                  "fire_tilts.png/.exr, aset.png, idealscope.png, lightbox.png");
  sub->callback([a] { runGem(*a); });
}

}  // namespace eikon::cli
