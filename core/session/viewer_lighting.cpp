#include "core/session/viewer_lighting.h"

#include <cstdio>

#include "core/session/gem.h"
#include "core/session/session.h"

namespace eikon {
namespace {

bool sameCamera(const Camera& a, const Camera& b) {
  return a.position == b.position && a.look_at == b.look_at && a.up == b.up;
}

}  // namespace

ViewerLighting::ViewerLighting(Session& session)
    : session_(session), own_(session.scene()->environment) {
  try {
    stone_ = gemStone(*session.scene(), std::nullopt);
  } catch (const std::invalid_argument&) {
    stone_.reset();  // no transparent object: the presets light the scene, with no figures
  }
}

void ViewerLighting::next() {
  constexpr GemPreset kOrder[] = {GemPreset::Dome, GemPreset::Spot, GemPreset::Aset,
                                  GemPreset::IdealScope, GemPreset::Lightbox};
  if (!preset_) {
    preset_ = kOrder[0];
  } else {
    size_t i = 0;
    while (kOrder[i] != *preset_) ++i;
    if (i + 1 < std::size(kOrder))
      preset_ = kOrder[i + 1];
    else
      preset_.reset();
  }
  stale_ = true;
}

void ViewerLighting::update(bool follow_camera) {
  Scene& scene = *session_.scene();
  if (!stale_ && (!preset_ || !follow_camera || sameCamera(built_for_, scene.camera))) return;
  if (preset_)
    makeGemEnvironment(gemAnalysisLighting(*preset_), scene.camera, scene.environment);
  else
    scene.environment = own_;
  built_for_ = scene.camera;
  stale_ = false;
  session_.environmentChanged();
}

std::string ViewerLighting::name() const { return preset_ ? gemPresetName(*preset_) : "scene"; }

bool ViewerLighting::wantsAov() const {
  return preset_ && stone_ &&
         (*preset_ == GemPreset::Dome || *preset_ == GemPreset::Spot ||
          *preset_ == GemPreset::IdealScope);
}

std::string ViewerLighting::figures(const RenderImage& img) const {
  if (!preset_) return "";
  const std::string name = gemPresetName(*preset_);
  if (!wantsAov() || img.aov.empty()) return name;
  const Scene& scene = *session_.scene();
  const glm::dvec3 white =
      whiteDiffuserRadiance(scene.environment, gemStoneUp(scene.objects[*stone_]));
  const double white_y = 0.2126 * white.x + 0.7152 * white.y + 0.0722 * white.z;
  const GemTilt t = measureGemView(*preset_, img, white_y, *stone_);
  if (t.outline_px == 0) return name + ": the stone is not in view";
  char buf[128];
  if (*preset_ == GemPreset::Dome)
    std::snprintf(buf, sizeof buf, ": brightness %.3f, extinction %.3f", t.brightness,
                  t.extinction);
  else if (*preset_ == GemPreset::Spot)
    std::snprintf(buf, sizeof buf, ": fire %.4f, %d flashes", t.fire, t.flashes);
  else
    std::snprintf(buf, sizeof buf, ": windowing %.3f", t.windowing);
  return name + buf;
}

}  // namespace eikon
