#include "core/scene/gem_lighting.h"

#include <algorithm>
#include <cmath>
#include <list>
#include <memory>
#include <mutex>
#include <numbers>
#include <vector>

namespace eikon {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

struct PresetName {
  GemPreset preset;
  const char* name;
};
constexpr PresetName kPresets[] = {{GemPreset::Dome, "dome"},
                                   {GemPreset::Spot, "spot"},
                                   {GemPreset::Aset, "aset"},
                                   {GemPreset::IdealScope, "idealscope"},
                                   {GemPreset::Lightbox, "lightbox"}};

/// The unit direction of elevation `el` and azimuth `az` (radians) in the frame.
glm::dvec3 frameDirection(const GemFrame& f, double el, double az) {
  return std::sin(el) * f.v + std::cos(el) * (std::cos(az) * f.up + std::sin(az) * f.side);
}

/// The spot sources: kSpots small discs on a golden-angle spiral over elevations 25–80° (equal
/// areas of that band), so that some source lies near every facet's view at any tilt
/// (docs/gem-studio.md "spot").
constexpr int kSpots = 24;

glm::dvec3 spotDirection(const GemFrame& f, int k) {
  const double lo = std::sin(25.0 * kDeg), hi = std::sin(80.0 * kDeg);
  const double sin_el = lo + (hi - lo) * (k + 0.5) / kSpots;
  const double az = k * std::numbers::pi * (3.0 - std::sqrt(5.0));  // the golden angle
  return frameDirection(f, std::asin(sin_el), az);
}

/// AGS ASET bands by elevation: blue 75–90° (the observer's zone), red 45–75°, green 0–45°,
/// black below the girdle plane (leakage).
glm::dvec3 asetRadiance(double sin_el) {
  if (sin_el >= std::sin(75.0 * kDeg)) return {0, 0, 1};
  if (sin_el >= std::sin(45.0 * kDeg)) return {1, 0, 0};
  if (sin_el >= 0.0) return {0, 1, 0};
  return {0, 0, 0};
}

/// A lightbox: a white upper hemisphere of radiance 0.5 with two strip lamps of radiance 4 along
/// the sides (elevation 35–65°, within 10° of azimuth ±90°), a grey floor of 0.1 below the
/// girdle plane, and the observer's head (10°) dark.
glm::dvec3 lightboxRadiance(const GemFrame& f, const glm::dvec3& d) {
  const double sin_el = glm::dot(d, f.v);
  if (sin_el < 0.0) return glm::dvec3(0.1);
  if (sin_el >= std::cos(10.0 * kDeg)) return glm::dvec3(0.0);
  const double el = std::asin(std::min(1.0, sin_el));
  const double az = std::atan2(glm::dot(d, f.side), glm::dot(d, f.up));
  const bool strip = el >= 35.0 * kDeg && el <= 65.0 * kDeg &&
                     std::abs(std::abs(az) - 0.5 * std::numbers::pi) <= 10.0 * kDeg;
  return glm::dvec3(strip ? 4.0 : 0.5);
}

/// The spot sources' directions in the frame (computed once per image, not per texel).
std::vector<glm::dvec3> spotDirections(const GemFrame& f) {
  std::vector<glm::dvec3> dirs;
  for (int k = 0; k < kSpots; ++k) dirs.push_back(spotDirection(f, k));
  return dirs;
}

glm::dvec3 spotRadiance(const GemLighting& g, const std::vector<glm::dvec3>& spots,
                        const glm::dvec3& d) {
  const double cos_r = std::cos(g.spot_radius_deg * kDeg);
  for (const glm::dvec3& s : spots)
    if (glm::dot(d, s) >= cos_r) return glm::dvec3(g.spot_radiance);
  return glm::dvec3(0.0);
}

/// gemRadiance with the spot directions given.
glm::dvec3 presetRadiance(const GemLighting& g, const GemFrame& f,
                          const std::vector<glm::dvec3>& spots, const glm::dvec3& d) {
  const double sin_el = glm::dot(d, f.v);
  switch (g.preset) {
    case GemPreset::Dome:  // uniform above the girdle plane, the head's cone dark, black below
      return glm::dvec3(sin_el >= 0.0 && sin_el < std::cos(g.head_shadow_deg * kDeg) ? 1.0 : 0.0);
    case GemPreset::Spot:
      return spotRadiance(g, spots, d);
    case GemPreset::Aset:
      return asetRadiance(sin_el);
    case GemPreset::IdealScope:  // red reflector, the viewing hole black, white light behind
      if (sin_el < 0.0) return glm::dvec3(1.0);
      return sin_el >= std::cos(g.head_shadow_deg * kDeg) ? glm::dvec3(0.0)
                                                          : glm::dvec3(1.0, 0.0, 0.0);
    case GemPreset::Lightbox:
      return lightboxRadiance(f, d);
  }
  return glm::dvec3(0.0);
}

}  // namespace

bool parseGemPreset(const std::string& name, GemPreset& out) {
  for (const PresetName& p : kPresets)
    if (name == p.name) {
      out = p.preset;
      return true;
    }
  return false;
}

const char* gemPresetName(GemPreset preset) {
  for (const PresetName& p : kPresets)
    if (p.preset == preset) return p.name;
  return "dome";
}

const char* gemPresetNames() { return "dome, spot, aset, idealscope, lightbox"; }

GemFrame gemFrame(const Camera& camera) {
  GemFrame f;
  f.v = glm::normalize(camera.position - camera.look_at);
  glm::dvec3 up = camera.up - glm::dot(camera.up, f.v) * f.v;
  if (glm::length(up) < 1e-9)
    up = std::abs(f.v.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
  up -= glm::dot(up, f.v) * f.v;
  f.up = glm::normalize(up);
  f.side = glm::cross(f.v, f.up);
  return f;
}

glm::dvec3 gemRadiance(const GemLighting& g, const GemFrame& f, const glm::dvec3& d) {
  return presetRadiance(
      g, f, g.preset == GemPreset::Spot ? spotDirections(f) : std::vector<glm::dvec3>{}, d);
}

namespace {

/// The preset's image for a frame, texel by texel (makeGemEnvironment's work).
std::vector<float> gemImage(const GemLighting& g, const GemFrame& f, int w, int h) {
  const std::vector<glm::dvec3> spots = spotDirections(f);
  std::vector<float> rgba(size_t(4) * size_t(w) * size_t(h), 0.0f);
  // Each texel is the mean of 2×2 directions in it (Environment::lookup's parameterisation:
  // u = atan2(x, −z)/2π + 0.5, v = acos(y)/π), so band edges are anti-aliased.
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      glm::dvec3 sum(0.0);
      for (int s = 0; s < 4; ++s) {
        const double u = (i + 0.25 + 0.5 * (s & 1)) / w, t = (j + 0.25 + 0.5 * (s >> 1)) / h;
        const double theta = t * std::numbers::pi, phi = (u - 0.5) * 2.0 * std::numbers::pi;
        const glm::dvec3 d(std::sin(theta) * std::sin(phi), std::cos(theta),
                           -std::sin(theta) * std::cos(phi));
        sum += presetRadiance(g, f, spots, d);
      }
      float* p = &rgba[size_t(4) * (size_t(j) * size_t(w) + size_t(i))];
      for (int k = 0; k < 3; ++k) p[k] = float(0.25 * sum[k]);
      p[3] = 1.0f;
    }
  return rgba;
}

/// The images made last, by everything they depend on (the preset's parameters and the frame,
/// bit for bit): a scene loaded again, a sweep's next item or a gem analysis' next stone at the
/// same tilts reuses them. Bounded to kCacheBytes (six images of the default 1024 × 512, 8 MiB
/// each; an image over kCachedImageBytes is made every time), least recently used out first;
/// safe from any thread.
struct GemImageKey {
  GemPreset preset;
  double head_shadow_deg, spot_radius_deg, spot_radiance;
  int width;
  glm::dvec3 v, up;
  bool operator==(const GemImageKey&) const = default;
};
constexpr size_t kCacheBytes = size_t(48) << 20, kCachedImageBytes = size_t(16) << 20;
std::mutex gem_image_mutex;
std::list<std::pair<GemImageKey, std::shared_ptr<const std::vector<float>>>> gem_images;

std::shared_ptr<const std::vector<float>> cachedGemImage(const GemLighting& g, const GemFrame& f,
                                                         int w, int h) {
  const GemImageKey key{g.preset, g.head_shadow_deg, g.spot_radius_deg, g.spot_radiance, w, f.v,
                        f.up};
  {
    const std::lock_guard<std::mutex> lock(gem_image_mutex);
    for (auto it = gem_images.begin(); it != gem_images.end(); ++it)
      if (it->first == key) {
        gem_images.splice(gem_images.begin(), gem_images, it);
        return it->second;
      }
  }
  auto image = std::make_shared<const std::vector<float>>(gemImage(g, f, w, h));
  const auto bytes = [](const auto& entry) { return entry.second->size() * sizeof(float); };
  if (image->size() * sizeof(float) > kCachedImageBytes) return image;
  const std::lock_guard<std::mutex> lock(gem_image_mutex);
  gem_images.emplace_front(key, image);
  size_t total = 0;
  for (const auto& entry : gem_images) total += bytes(entry);
  while (total > kCacheBytes) {
    total -= bytes(gem_images.back());
    gem_images.pop_back();
  }
  return image;
}

}  // namespace

void makeGemEnvironment(const GemLighting& g, const Camera& camera, Environment& env) {
  const GemFrame f = gemFrame(camera);
  const int w = std::max(8, g.width), h = std::max(4, g.width / 2);
  const std::shared_ptr<const std::vector<float>> image = cachedGemImage(g, f, w, h);
  env = Environment{};
  env.type = Environment::Type::LatLong;
  env.image_width = w;
  env.image_height = h;
  env.image_rgba = *image;
}

glm::dvec3 whiteDiffuserRadiance(const Environment& env, const glm::dvec3& n) {
  if (env.type != Environment::Type::LatLong || env.image_width <= 0) return glm::dvec3(0.0);
  const int w = env.image_width, h = env.image_height;
  glm::dvec3 sum(0.0);
  for (int j = 0; j < h; ++j) {
    const double theta = (j + 0.5) / h * std::numbers::pi;
    // The texel's solid angle: (2π/w) · (cos θ0 − cos θ1).
    const double d_omega = 2.0 * std::numbers::pi / w *
                           (std::cos(double(j) / h * std::numbers::pi) -
                            std::cos(double(j + 1) / h * std::numbers::pi));
    for (int i = 0; i < w; ++i) {
      const double phi = ((i + 0.5) / w - 0.5) * 2.0 * std::numbers::pi;
      const glm::dvec3 d(std::sin(theta) * std::sin(phi), std::cos(theta),
                         -std::sin(theta) * std::cos(phi));
      const double c = glm::dot(d, n);
      if (c <= 0.0) continue;
      const float* p = &env.image_rgba[size_t(4) * (size_t(j) * size_t(w) + size_t(i))];
      sum += glm::dvec3(p[0], p[1], p[2]) * (c * d_omega);
    }
  }
  return sum * env.intensity / std::numbers::pi;
}

}  // namespace eikon
