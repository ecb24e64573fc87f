// The gem studio's analysis (docs/gem-studio.md): one stone of a scene viewed face-up from the
// standard distance, tilted through a series, rendered under the standard lighting presets
// (core/scene/gem_lighting.h) and measured: brightness, fire, scintillation, windowing and
// extinction per tilt and overall. `eikon gem` and its tests call it.
//
//   auto scene = std::make_shared<eikon::Scene>(eikon::loadScene("scenes/diamond_brilliant.json"));
//   eikon::GemRequest req;                       // 9 tilts, 128×128, 4 spp
//   eikon::checkGemRequest(req);                 // SettingError
//   eikon::GemReport r = eikon::analyseGem(scene, req);
//
// The renders run on the CPU twin (core/reference), in one session: its marcher reads the
// scene's environment and camera at each render, so every tilt and preset reuses one voxelised
// volume. The scene's camera and environment are replaced by the analysis' own.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/contract/march_types.h"
#include "core/scene/gem_lighting.h"
#include "core/scene/scene.h"
#include "core/session/settings.h"

namespace eikon {

/// The observer's distance from the stone's centre: 250 mm, the conventional least distance of
/// distinct vision (docs/gem-studio.md "Viewing").
inline constexpr double kGemViewDistanceMm = 250.0;

struct GemRequest {
  std::vector<double> tilts_deg = {-20, -15, -10, -5, 0, 5, 10, 15, 20};  ///< each in [-60, 60]
  int width = 128, height = 128;                                          ///< [16, 2048]
  int spp = 4;                                                            ///< [1, 256]
  int wavelengths = 8;        ///< the fire render's spectral samples, [1, 64]
  std::optional<int> object;  ///< the stone's index in "objects"; unset: the first transparent
  bool keep_images = false;   ///< GemReport::images (the report's pictures)
  int threads = 0;            ///< CPU threads (0: all)
  /// 0: the pixel grid centred on the stone. Otherwise the grid is shifted by a sub-pixel offset
  /// drawn from the seed (each axis uniform in [-0.5, 0.5) pixel): every ray the renders march
  /// moves, so the metrics are another draw of the same estimate (docs/gem-studio.md "Viewing").
  std::uint32_t seed = 0;
};

/// Every range of a request; SettingError naming the setting ("tilts", "width", ...).
void checkGemRequest(const GemRequest& request);
/// "-20:20:5" (from:to:step, inclusive) or a comma-separated list "-10,0,10" into tilts; else
/// SettingError("tilts", ...).
std::vector<double> parseGemTilts(const std::string& text);
/// The stone: `object` when given (std::invalid_argument when out of range or opaque), else the
/// first object whose material is not opaque (std::invalid_argument when none is).
size_t gemStone(const Scene& scene, std::optional<int> object);

struct GemTilt {
  double tilt_deg = 0.0;
  double brightness = 0.0, fire = 0.0, windowing = 0.0, extinction = 0.0;
  int flashes = 0;        ///< bright spots under `spot` (4-connected groups of flash pixels)
  double outline_px = 0;  ///< pixels of the stone's outline
};

/// A tilt's pictures (linear sRGB, width×height×3, rows from the top).
struct GemImages {
  int width = 0, height = 0;
  std::vector<std::vector<float>> dome, spot;     ///< per tilt
  std::vector<float> aset, idealscope, lightbox;  ///< face-up (tilt 0, or the tilt nearest it)
};

struct GemReport {
  size_t object = 0;
  double brightness = 0.0, fire = 0.0, scintillation = 0.0, windowing = 0.0, extinction = 0.0;
  double contrast_change = 0.0;  ///< mean |ΔY| between neighbouring tilts under `dome`
  std::vector<GemTilt> per_tilt;
  double seconds = 0.0;
  GemImages images;
};

/// The stone's up: the normal of its girdle plane towards the table (world), the direction the
/// analysis views it face-up from, and the white diffuser's normal of the brightness metric.
glm::dvec3 gemStoneUp(const SceneObject& stone);

/// The lighting the analysis renders `preset` with: the preset's defaults, with the Ideal-scope's
/// viewing hole at 15° (docs/gem-studio.md "Lighting presets").
GemLighting gemAnalysisLighting(GemPreset preset);

/// The figures one render (with the AOV layer: RenderSettings::aov_layer) gives of the stone
/// `object` under `preset`, as the analysis measures each tilt (docs/gem-studio.md "Metrics"):
/// under dome brightness and extinction (`white_y`: the luminance of a white diffuser under the
/// same lighting, whiteDiffuserRadiance), under spot fire and flashes, under idealscope
/// windowing; outline_px is the stone's pixel count (0: the stone is not in view). The other
/// figures stay 0. The viewer's live figures.
GemTilt measureGemView(GemPreset preset, const RenderImage& img, double white_y, size_t object);

/// The observer's camera of the stone `object` of `scene` tilted by `tilt_deg` (the renders'
/// camera; its width and height are the request's).
Camera gemCamera(const Scene& scene, size_t object, const GemRequest& request, double tilt_deg);

/// Run the analysis on `scene` (whose camera and environment it replaces). `progress` (may be
/// empty) gets the fraction done.
GemReport analyseGem(const std::shared_ptr<Scene>& scene, const GemRequest& request,
                     const std::function<void(double)>& progress = {});

/// A report as `eikon gem --json` prints it and Python's `eikon.gem` returns it: the overall
/// figures, "object", "scene" (the scene file named), "seconds" and "per_tilt".
nlohmann::json gemReportJson(const GemReport& report, const std::string& scene);

}  // namespace eikon
