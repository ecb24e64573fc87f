#include "core/session/gem.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <sstream>

#include "core/scene/gem_lighting.h"
#include "core/scene/messages.h"
#include "core/session/session.h"
#include "core/spectrum/wavelength_sampling.h"

namespace eikon {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
/// The thresholds of the metrics (docs/gem-studio.md "Metrics").
constexpr double kExtinctionShare = 0.25;  ///< of the white diffuser's luminance, under `dome`
constexpr double kLeakShare = 0.5;         ///< of a pixel's light from behind, under `idealscope`
constexpr double kFireSaturation = 0.5;    ///< HSV saturation of a fire pixel, under `spot`
constexpr double kFlashShare = 0.25;       ///< of the spot radiance: a flash pixel, under `spot`

double luminance(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

/// The face-up camera of the stone tilted by `tilt_deg` about the camera's horizontal axis: the
/// camera moves by −tilt about the stone's centre (docs/gem-studio.md "Viewing").
struct GemView {
  Camera camera;
  glm::dvec3 stone_up;  ///< the table's normal (the girdle plane's), world
};

GemView gemView(const SceneObject& stone, const GemRequest& r, double tilt_deg) {
  const glm::dvec3 up = gemStoneUp(stone);
  const glm::dvec3 fwd =
      glm::normalize(stone.shape.rotation() * glm::dvec3(0, 0, 1));  // picture up
  const glm::dvec3 axis = glm::cross(up, fwd);                       // the tilt axis
  const auto [lo, hi] = stone.shape.bounds();
  const glm::dvec3 centre = 0.5 * (lo + hi);
  const double radius = 0.5 * glm::length(hi - lo);
  const double a = -tilt_deg * kDeg;  // Rodrigues: the view direction turned by −tilt
  const auto turn = [&](const glm::dvec3& v) {
    return v * std::cos(a) + glm::cross(axis, v) * std::sin(a) +
           axis * glm::dot(axis, v) * (1.0 - std::cos(a));
  };
  GemView g;
  g.camera.look_at = centre;
  g.camera.position = centre + kGemViewDistanceMm * turn(up);
  g.camera.up = turn(fwd);
  g.camera.fov_deg = 2.0 * std::atan(1.05 * radius / kGemViewDistanceMm) / kDeg;
  g.camera.width = r.width;
  g.camera.height = r.height;
  if (r.seed != 0) {  // the pixel grid moved by a sub-pixel offset (the camera translated)
    const std::uint32_t h = spectrum::pcgHash(r.seed * 0x9E3779B1u + 0x7F4A7C15u);
    const double du = double(h & 0xffffu) / 65536.0 - 0.5, dv = double(h >> 16u) / 65536.0 - 0.5;
    const double pixel_mm = 2.0 * 1.05 * radius / r.height;  // at the stone's centre
    const glm::dvec3 shift = pixel_mm * (du * glm::cross(turn(up), turn(fwd)) + dv * turn(fwd));
    g.camera.look_at += shift;
    g.camera.position += shift;
  }
  g.stone_up = up;
  return g;
}

/// One render of the scene's stone under `preset` from `view`.
RenderImage renderUnder(Session& session, Scene& scene, const GemRequest& r, GemPreset preset,
                        const GemView& view, int wavelengths, bool aov) {
  scene.camera = view.camera;
  makeGemEnvironment(gemAnalysisLighting(preset), view.camera, scene.environment);
  ViewRequest req;
  req.width = r.width;
  req.height = r.height;
  req.spp = r.spp;
  req.wavelengths = wavelengths;
  // Stratified passes: every wavelength marches its own path (the same Fresnel choices), so a
  // pixel's colour is the dispersion's; hero sampling would leave only the hero wavelength after
  // the first dispersive refraction (docs/spectra.md), colouring every pixel with its noise.
  req.sampling = SpectralSampling::Stratified;
  req.aov_layer = aov;
  return session.render(renderSettings(scene, req), false);
}

/// The stone's pixels of a render with the AOV layer: those whose first interface is `stone`'s.
std::vector<unsigned char> stoneMask(const RenderImage& img, size_t stone) {
  const size_t n = size_t(img.width) * size_t(img.height);
  std::vector<unsigned char> mask(n, 0);
  if (img.aov.size() < n * kAovChannels) return mask;
  for (size_t i = 0; i < n; ++i)
    mask[i] = std::lround(img.aov[i * kAovChannels + 7]) == long(stone);
  return mask;
}

/// Under `dome`: brightness (mean luminance over the white diffuser's) and extinction.
void measureDome(const RenderImage& dome, const std::vector<unsigned char>& mask, double white_y,
                 GemTilt& t) {
  double sum_y = 0, dark = 0, count = 0;
  for (size_t i = 0; i < mask.size(); ++i) {
    if (!mask[i]) continue;
    count += 1;
    const double y = luminance(&dome.rgb[3 * i]);
    sum_y += y;
    if (y < kExtinctionShare * white_y) dark += 1;
  }
  t.outline_px = count;
  if (count == 0) return;
  t.brightness = white_y > 0 ? sum_y / count / white_y : 0.0;
  t.extinction = dark / count;
}

/// Under `spot`: fire (the saturated part of the light), and the flash pixels.
void measureSpot(const RenderImage& spot, const std::vector<unsigned char>& mask, GemTilt& t,
                 std::vector<unsigned char>& flash) {
  flash.assign(mask.size(), 0);
  double fire = 0, count = 0;
  for (size_t i = 0; i < mask.size(); ++i) {
    if (!mask[i]) continue;
    count += 1;
    const float* s = &spot.rgb[3 * i];
    const double hi = std::max({s[0], s[1], s[2], 0.0f}),
                 lo = std::max(0.0f, std::min({s[0], s[1], s[2]}));
    if (hi > 0 && 1.0 - lo / hi > kFireSaturation) fire += hi - lo;
    if (luminance(s) > kFlashShare) flash[i] = 1;
  }
  if (count > 0) t.fire = fire / count;
}

/// Under `idealscope`: windowing (pixels lit mostly from behind the stone).
void measureScope(const RenderImage& scope, const std::vector<unsigned char>& mask, GemTilt& t) {
  double leak = 0, count = 0;
  for (size_t i = 0; i < mask.size(); ++i) {
    if (!mask[i]) continue;
    count += 1;
    if (scope.rgb[3 * i + 1] > kLeakShare) leak += 1;
  }
  if (count > 0) t.windowing = leak / count;
}

/// 4-connected groups of flash pixels.
int countFlashes(const std::vector<unsigned char>& flash, int w, int h) {
  std::vector<unsigned char> seen(flash.size(), 0);
  std::vector<size_t> stack;
  int groups = 0;
  for (size_t start = 0; start < flash.size(); ++start) {
    if (!flash[start] || seen[start]) continue;
    ++groups;
    stack.assign(1, start);
    seen[start] = 1;
    while (!stack.empty()) {
      const size_t p = stack.back();
      stack.pop_back();
      const int x = int(p % size_t(w)), y = int(p / size_t(w));
      const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
      for (int k = 0; k < 4; ++k) {
        if (nx[k] < 0 || ny[k] < 0 || nx[k] >= w || ny[k] >= h) continue;
        const size_t q = size_t(ny[k]) * size_t(w) + size_t(nx[k]);
        if (flash[q] && !seen[q]) {
          seen[q] = 1;
          stack.push_back(q);
        }
      }
    }
  }
  return groups;
}

std::string formatDegrees(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

glm::dvec3 gemStoneUp(const SceneObject& stone) {
  return glm::normalize(stone.shape.rotation() * glm::dvec3(0, 1, 0));
}

GemLighting gemAnalysisLighting(GemPreset preset) {
  GemLighting g;
  g.preset = preset;
  if (preset == GemPreset::IdealScope) g.head_shadow_deg = 15.0;
  return g;
}

GemTilt measureGemView(GemPreset preset, const RenderImage& img, double white_y, size_t stone) {
  GemTilt t;
  const std::vector<unsigned char> mask = stoneMask(img, stone);
  t.outline_px = double(std::count(mask.begin(), mask.end(), 1));
  std::vector<unsigned char> flash;
  if (preset == GemPreset::Dome) measureDome(img, mask, white_y, t);
  if (preset == GemPreset::Spot) {
    measureSpot(img, mask, t, flash);
    t.flashes = countFlashes(flash, img.width, img.height);
  }
  if (preset == GemPreset::IdealScope) measureScope(img, mask, t);
  return t;
}

Camera gemCamera(const Scene& scene, size_t object, const GemRequest& request, double tilt_deg) {
  if (object >= scene.objects.size())
    throw std::invalid_argument("object " + std::to_string(object) + " is not in the scene");
  return gemView(scene.objects[object], request, tilt_deg).camera;
}

std::vector<double> parseGemTilts(const std::string& text) {
  const auto refuse = [&](const std::string& why) {
    return SettingError("tilts",
                        "must be FROM:TO:STEP or a comma-separated list of degrees in "
                        "[-60, 60], got '" +
                            text + "'" + why);
  };
  const auto number = [&](const std::string& s) {
    size_t used = 0;
    double v = 0;
    try {
      v = std::stod(s, &used);
    } catch (const std::exception&) {
      throw refuse("");
    }
    if (used != s.size() || !std::isfinite(v)) throw refuse("");
    return v;
  };
  std::vector<std::string> parts;
  const char sep = text.find(':') != std::string::npos ? ':' : ',';
  std::stringstream ss(text);
  for (std::string p; std::getline(ss, p, sep);) parts.push_back(p);
  if (!text.empty() && text.back() == sep) parts.push_back("");
  std::vector<double> tilts;
  if (sep == ':') {
    if (parts.size() != 3) throw refuse(" (three fields FROM:TO:STEP)");
    const double from = number(parts[0]), to = number(parts[1]), step = number(parts[2]);
    if (!(step > 0) || to < from) throw refuse(" (STEP > 0 and TO >= FROM)");
    const double count = std::floor((to - from) / step + 1e-9) + 1;
    if (count > 181) throw refuse(" (at most 181 tilts)");
    for (int i = 0; i < int(count); ++i) tilts.push_back(from + i * step);
  } else {
    for (const std::string& p : parts) tilts.push_back(number(p));
  }
  if (tilts.empty() || tilts.size() > 181) throw refuse(" (1 to 181 tilts)");
  for (double t : tilts)
    if (t < -60 || t > 60) throw refuse(" (" + formatDegrees(t) + " is outside [-60, 60])");
  return tilts;
}

void checkGemRequest(const GemRequest& r) {
  const auto range = [](const char* name, int v, int lo, int hi) {
    if (v < lo || v > hi)
      throw SettingError(name, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                                   "], got " + std::to_string(v));
  };
  range("width", r.width, 16, 2048);
  range("height", r.height, 16, 2048);
  range("spp", r.spp, 1, 256);
  range("wavelengths", r.wavelengths, 1, 64);
  if (r.tilts_deg.empty() || r.tilts_deg.size() > 181)
    throw SettingError("tilts",
                       "must hold 1 to 181 tilts, got " + std::to_string(r.tilts_deg.size()));
  for (double t : r.tilts_deg)
    if (!(t >= -60 && t <= 60))
      throw SettingError("tilts", "must be in [-60, 60] degrees, got " + formatDegrees(t));
  checkThreads(r.threads);
}

size_t gemStone(const Scene& scene, std::optional<int> object) {
  const auto opaque = [&](size_t i) {
    const auto it = scene.materials.find(scene.objects[i].material);
    return it != scene.materials.end() && it->second.opacity >= 1.0;
  };
  if (object) {
    if (*object < 0 || size_t(*object) >= scene.objects.size())
      throw std::invalid_argument("object " + std::to_string(*object) + " is not in the scene's " +
                                  std::to_string(scene.objects.size()) + " objects");
    if (opaque(size_t(*object)))
      throw std::invalid_argument("object " + std::to_string(*object) +
                                  " is opaque; a gem must be transparent");
    return size_t(*object);
  }
  for (size_t i = 0; i < scene.objects.size(); ++i)
    if (!opaque(i)) return i;
  throw std::invalid_argument("the scene has no transparent object to view as a gem");
}

GemReport analyseGem(const std::shared_ptr<Scene>& scene, const GemRequest& r,
                     const std::function<void(double)>& progress) {
  checkGemRequest(r);
  const auto start = std::chrono::steady_clock::now();
  GemReport report;
  report.object = gemStone(*scene, r.object);
  const SceneObject stone = scene->objects[report.object];
  Session session(scene);
  session.setThreads(r.threads);
  const int n = int(r.tilts_deg.size());
  size_t face_up = 0;
  for (size_t i = 1; i < r.tilts_deg.size(); ++i)
    if (std::abs(r.tilts_deg[i]) < std::abs(r.tilts_deg[face_up])) face_up = i;
  std::vector<unsigned char> mask, flash, prev_mask, prev_flash;
  std::vector<float> prev_y;
  double toggles = 0, contrast = 0;
  for (int k = 0; k < n; ++k) {
    const GemView view = gemView(stone, r, r.tilts_deg[size_t(k)]);
    const RenderImage dome = renderUnder(session, *scene, r, GemPreset::Dome, view, 0, true);
    const glm::dvec3 white = whiteDiffuserRadiance(scene->environment, view.stone_up);
    const double white_y = 0.2126 * white.x + 0.7152 * white.y + 0.0722 * white.z;
    const RenderImage spot =
        renderUnder(session, *scene, r, GemPreset::Spot, view, r.wavelengths, false);
    const RenderImage scope =
        renderUnder(session, *scene, r, GemPreset::IdealScope, view, 0, false);
    GemTilt t;
    t.tilt_deg = r.tilts_deg[size_t(k)];
    mask = stoneMask(dome, report.object);
    measureDome(dome, mask, white_y, t);
    measureSpot(spot, mask, t, flash);
    measureScope(scope, mask, t);
    t.flashes = countFlashes(flash, r.width, r.height);
    std::vector<float> y(mask.size());
    for (size_t i = 0; i < y.size(); ++i) y[i] = float(luminance(&dome.rgb[3 * i]) / white_y);
    if (k > 0) {  // scintillation: flash pixels that change, and the contrast change
      double both = 0, changed = 0, dy = 0;
      for (size_t i = 0; i < mask.size(); ++i)
        if (mask[i] && prev_mask[i]) {
          both += 1;
          changed += flash[i] != prev_flash[i];
          dy += std::abs(y[i] - prev_y[i]);
        }
      if (both > 0) {
        toggles += changed / both;
        contrast += dy / both;
      }
    }
    prev_mask = mask;
    prev_flash = flash;
    prev_y = y;
    report.per_tilt.push_back(t);
    if (r.keep_images) {
      report.images.dome.push_back(dome.rgb);
      report.images.spot.push_back(spot.rgb);
      if (size_t(k) == face_up) {
        report.images.idealscope = scope.rgb;
        report.images.aset = renderUnder(session, *scene, r, GemPreset::Aset, view, 0, false).rgb;
        GemRequest fine = r;  // a picture: four times the samples
        fine.spp = std::min(256, 4 * r.spp);
        report.images.lightbox =
            renderUnder(session, *scene, fine, GemPreset::Lightbox, view, r.wavelengths, false).rgb;
      }
    }
    if (progress) progress(double(k + 1) / n);
  }
  for (const GemTilt& t : report.per_tilt) {
    report.brightness += t.brightness / n;
    report.fire += t.fire / n;
    report.windowing += t.windowing / n;
    report.extinction += t.extinction / n;
  }
  if (n > 1) {
    report.scintillation = toggles / (n - 1);
    report.contrast_change = contrast / (n - 1);
  }
  report.images.width = r.width;
  report.images.height = r.height;
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

nlohmann::json gemReportJson(const GemReport& r, const std::string& scene) {
  nlohmann::json j;
  j["brightness"] = r.brightness;
  j["fire"] = r.fire;
  j["scintillation"] = r.scintillation;
  j["windowing"] = r.windowing;
  j["extinction"] = r.extinction;
  j["contrast_change"] = r.contrast_change;
  j["object"] = r.object;
  j["scene"] = scene;
  j["seconds"] = r.seconds;
  j["per_tilt"] = nlohmann::json::array();
  for (const GemTilt& t : r.per_tilt)
    j["per_tilt"].push_back({{"tilt_deg", t.tilt_deg},
                             {"brightness", t.brightness},
                             {"fire", t.fire},
                             {"windowing", t.windowing},
                             {"extinction", t.extinction},
                             {"flashes", t.flashes},
                             {"outline_px", t.outline_px}});
  return j;
}

}  // namespace eikon
